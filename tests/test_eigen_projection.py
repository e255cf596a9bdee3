"""igl_spheremap.star_map: weighted Laplace-Beltrami eigen-projection (paper Section 4.2)."""

import igl
import numpy as np
import pytest
import scipy.linalg

import igl_spheremap.folding.star_map as star_map_module
from igl_spheremap import MeshError, count_folds, star_map


def _unit(X):
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def _weighted_problem(V, F, U):
    """Stiffness -L (intrinsic Delaunay, the default) and the lumped mass of the image
    (U, F) scaled to total 4 pi: the B_u of paper Eq. 26."""
    L = igl.intrinsic_delaunay_cotmatrix(V, F)[0]
    b = igl.massmatrix(U, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
    return L, b * (4.0 * np.pi / b.sum())


def test_eigenpairs_against_a_dense_solver(icosphere):
    V, F = icosphere(2)
    U = _unit(V * [1.0, 1.3, 0.8])  # a non-uniform conformal factor
    _, Phi, lam, _ = star_map(V, F, U, return_details=True)
    L, b = _weighted_problem(V, F, U)
    dense = scipy.linalg.eigh(-L.toarray(), np.diag(b), eigvals_only=True)
    assert abs(dense[0]) < 1e-10
    assert np.allclose(lam, dense[1:4], rtol=1e-9, atol=0)
    # B-orthonormal eigenvectors that solve -L Phi = B Phi diag(lam).
    assert np.allclose(Phi.T @ (b[:, None] * Phi), np.eye(3), atol=1e-9)
    residual = -(L @ Phi) - b[:, None] * Phi * lam
    assert np.abs(residual).max() < 1e-8 * np.abs(L @ Phi).max()


def test_star_map_against_a_dense_reference(icosphere):
    """Theorem 2's construction done independently with a dense generalized eigensolver
    (scipy.linalg.eigh of -L and B_u): the three nontrivial eigenvectors, centered by
    their area-weighted mean (barycentric areas from igl.massmatrix) and normalized.
    Eigenvectors are defined up to sign: the columns are matched by sign, and the
    result may differ from ours by the reflection flip (first coordinate)."""
    V, F = icosphere(2)
    U = _unit(V * [1.0, 1.3, 0.8] + [0.1, 0.0, 0.0])  # distinct eigenvalues
    S, Phi, lam, _ = star_map(V, F, U, return_details=True)
    L, b = _weighted_problem(V, F, U)
    w, X = scipy.linalg.eigh(-L.toarray(), np.diag(b))
    assert np.min(np.diff(w[1:4])) > 1e-3  # simple eigenvalues: vectors unique up to sign
    X = X[:, 1:4] * np.sign(np.sum(X[:, 1:4] * Phi, axis=0))
    assert np.abs(X - Phi).max() < 1e-8
    A = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
    ref = _unit(X - A @ X / A.sum())
    assert np.abs(S - ref).max() < 1e-8 or np.abs(S - ref * [-1, 1, 1]).max() < 1e-8
    assert count_folds(F, S) == 0


def test_invalid_input_is_refused(icosphere):
    V, F = icosphere(1)
    with pytest.raises(ValueError, match="2 rows with NaN"):
        U = V.copy()
        U[[3, 5]] = np.nan
        star_map(V, F, U)
    with pytest.raises(ValueError, match="rows"):
        star_map(V, F, V[:-1])
    with pytest.raises(MeshError, match="boundary"):
        star_map(V, F[1:], V)


@pytest.mark.parametrize("level", [2, 3, 4])
def test_identity_of_the_sphere(icosphere, fit_rotation, level):
    """On the round sphere the eigenvalue 2 (mesh scaled to area 4 pi) has the coordinate
    functions as eigenspace, so |Phi|^2 = 3 / 4 pi and the star map is a rotation."""
    V, F = icosphere(level)
    S, Phi, lam, _ = star_map(V, F, V, return_details=True)
    # Icosahedral symmetry makes the eigenvalue exactly threefold.
    assert np.ptp(lam) < 1e-10
    assert abs(lam[0] - 2.0) < 0.05 / 4 ** (level - 2)  # O(h^2) from below
    assert lam[0] < 2.0
    r2 = np.sum(Phi ** 2, axis=1) * (4.0 * np.pi / 3.0)
    assert np.abs(r2 - 1.0).max() < 0.02 / 2 ** (level - 2)
    Q, residual = fit_rotation(V, S)
    assert np.linalg.det(Q) > 0
    assert residual < 1e-3 / 2 ** (level - 2)
    assert count_folds(F, S) == 0


def test_identity_of_the_symmetric_icosphere_is_exact(icosphere, fit_rotation):
    V, F = icosphere(1)
    S = star_map(V, F, V)
    Q, residual = fit_rotation(V, S)
    assert np.linalg.det(Q) > 0 and residual < 1e-12


def test_conformal_map_is_reproduced_up_to_rotation(conformal_map, fit_rotation):
    """Theorem 2: with the conformal factor of a conformal map U, the weighted
    eigenfunctions are U's coordinates (eigenvalue 2), so the star map is U rotated."""
    V, F, result, _ = conformal_map("fish_lowres.obj")
    assert result.success
    S, _, lam, _ = star_map(V, F, result.U, return_details=True)
    assert np.abs(lam - 2.0).max() < 0.04
    Q, residual = fit_rotation(result.U, S)
    assert np.linalg.det(Q) > 0 and residual < 0.02
    assert count_folds(F, S) == 0


def test_reflected_eigenbasis_is_flipped(mesh, conformal_map, monkeypatch):
    """Negating one eigenvector makes the eigenbasis a reflection: the star map must
    detect it, flip the first coordinate, and stay fold-free (a rotation by pi of the
    unpatched star map)."""
    V, F, result, _ = conformal_map("fish_lowres.obj")
    S0, _, lam0, reflected0 = star_map(V, F, result.U, return_details=True)
    original = star_map_module.weighted_eigenfunctions

    def negate_second(*args, **kwargs):
        lam, Phi = original(*args, **kwargs)
        Phi = Phi.copy()
        Phi[:, 1] = -Phi[:, 1]
        return lam, Phi

    monkeypatch.setattr(star_map_module, "weighted_eigenfunctions", negate_second)
    S1, _, lam1, reflected1 = star_map(V, F, result.U, return_details=True)
    assert reflected1 != reflected0
    assert count_folds(F, S0) == 0 and count_folds(F, S1) == 0
    assert np.abs(S1 - S0 * [-1.0, -1.0, 1.0]).max() < 1e-14
    assert np.array_equal(lam1, lam0)


def test_deterministic(mesh):
    V, F = mesh("goathead.obj")
    U = _unit(V - V.mean(axis=0))
    a = star_map(V, F, U, return_details=True)
    b = star_map(V.copy(), F.copy(), U.copy(), return_details=True)
    for x, y in zip(a, b):
        assert np.array_equal(x, y)
