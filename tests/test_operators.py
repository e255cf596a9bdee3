"""igl_spheremap.mesh.operators: the cotangent Laplacians and vertex areas of paper Eq. 13."""

import igl
import numpy as np
import pytest
import scipy.sparse as sp

from igl_spheremap.mesh.operators import (LAPLACIANS, count_negative_weights, laplacian, vertex_areas)


def _cotan_from_entries(V, F):
    """Cotangent Laplacian assembled by hand from igl.cotmatrix_entries.

    ``C[f, c]`` is half the cotangent of the angle at corner ``c``; it weighs the
    edge opposite that corner.
    """
    C = igl.cotmatrix_entries(V, F)
    opposite = ((1, 2), (2, 0), (0, 1))
    rows = np.concatenate([F[:, a] for a, b in opposite] + [F[:, b] for a, b in opposite])
    cols = np.concatenate([F[:, b] for a, b in opposite] + [F[:, a] for a, b in opposite])
    vals = np.concatenate([C[:, c] for c in range(3)] * 2)
    n = V.shape[0]
    W = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    return (W - sp.diags(np.asarray(W.sum(axis=1)).ravel())).tocsr()


def _triangle_areas(V, F):
    """Triangle areas from cross products (numpy only)."""
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)


def test_cotan_laplacian_matches_hand_assembly(mesh):
    V, F = mesh("fish_lowres.obj")
    L = laplacian(V, F, "cotan")
    ref = _cotan_from_entries(V, F)
    assert sp.issparse(L) and L.shape == (V.shape[0], V.shape[0])
    assert abs(L - ref).max() <= 1e-12 * abs(ref).max()


@pytest.mark.parametrize("kind", LAPLACIANS)
def test_laplacian_symmetric_zero_row_sums_scale_invariant(mesh, kind, rng):
    V, F = mesh("goathead.obj")
    L = laplacian(V, F, kind)
    scale = abs(L).max()
    assert abs(L - L.T).max() <= 1e-12 * scale
    assert np.abs(L @ np.ones(V.shape[0])).max() <= 1e-11 * scale
    # Negative semidefinite: x^T L x <= 0 for random x.
    X = rng.normal(size=(V.shape[0], 5))
    assert np.all(np.einsum("ij,ij->j", X, L @ X) < 0)
    # Cotangents do not change under a similarity transformation.
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    L2 = laplacian(1e-3 * V @ R.T + np.array([5.0, -2.0, 1.0]), F, kind)
    assert abs(L2 - L).max() <= 1e-9 * scale


def test_intrinsic_delaunay_equals_cotan_on_a_delaunay_mesh(icosphere):
    V, F = icosphere(2)
    Lc = laplacian(V, F, "cotan")
    # Precondition: every edge of the icosphere is Delaunay (cot a + cot b > 0).
    W = sp.triu(Lc, 1).tocoo()
    assert W.data.min() > 1e-3
    assert abs(laplacian(V, F, "intrinsic_delaunay") - Lc).max() <= 1e-12


@pytest.mark.parametrize("name", ["fish_lowres.obj", "ellipsoid"])
def test_intrinsic_delaunay_weights_and_dirichlet_energy(name, mesh, ellipsoid, rng):
    """Rippa / Bobenko-Springborn: the (intrinsic) Delaunay triangulation minimizes the
    Dirichlet energy of every vertex function, and its cotangent weights are >= 0."""
    V, F = ellipsoid(3, (1.0, 1.0, 6.0)) if name == "ellipsoid" else mesh(name)
    Lc = laplacian(V, F, "cotan")
    Li = laplacian(V, F, "intrinsic_delaunay")
    # Negative cotan weights, counted straight from the per-face half cotangents.
    ref = _cotan_from_entries(V, F)
    direct = int(np.count_nonzero(sp.triu(ref, 1).tocoo().data < 0))
    assert direct > 0  # the mesh is not Delaunay: the comparison below is not trivial
    assert count_negative_weights(Lc) == direct
    # Intrinsic Delaunay weights are >= 0 up to rounding (cocircular ties give -1e-16).
    assert sp.triu(Li, 1).tocoo().data.min() >= -1e-12 * abs(Li).max()
    U = rng.normal(size=(V.shape[0], 3, 8))
    for k in range(U.shape[2]):
        Ei = -0.5 * np.sum(U[:, :, k] * (Li @ U[:, :, k]))
        Ec = -0.5 * np.sum(U[:, :, k] * (Lc @ U[:, :, k]))
        assert 0 < Ei < Ec


def test_count_negative_weights_on_a_hand_made_matrix():
    L = sp.csr_matrix(np.array([[-1.0, 2.0, -1.0, 0.0],
                                [2.0, -1.0, 0.0, -1.0],
                                [-1.0, 0.0, 2.0, -1.0],
                                [0.0, -1.0, -1.0, 2.0]]))
    assert count_negative_weights(L) == 3  # pairs (0,2), (1,3), (2,3)


def test_vertex_areas_are_a_third_of_the_incident_triangle_areas(mesh):
    V, F = mesh("hippocampus.obj")
    A = vertex_areas(V, F)
    tri = _triangle_areas(V, F)
    ref = np.bincount(F.ravel(), weights=np.repeat(tri / 3.0, 3), minlength=V.shape[0])
    assert A.shape == (V.shape[0],) and A.dtype == np.float64
    assert np.allclose(A, ref, rtol=1e-12, atol=0)
    assert A.sum() == pytest.approx(igl.doublearea(V, F).sum() / 2.0, rel=1e-13)


def test_unknown_laplacian_is_a_value_error(icosphere):
    V, F = icosphere(0)
    with pytest.raises(ValueError, match="unknown Laplacian"):
        laplacian(V, F, "uniform")


def test_vertex_areas_equal_the_libigl_barycentric_mass(mesh):
    V, F = mesh("fish_lowres.obj")
    M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
    for Fi in (F, F.astype(np.int32), np.asfortranarray(F)):
        assert np.allclose(vertex_areas(V, Fi), M, rtol=1e-12, atol=0)
    # a vertex used by no face (libigl sizes the matrix by max(F) + 1) has zero area
    V2 = np.vstack([V, [[5.0, 5.0, 5.0]]])
    A = vertex_areas(V2, F)
    assert A.shape == (V2.shape[0],) and A[-1] == 0.0
    assert np.allclose(A[:-1], M, rtol=1e-12, atol=0)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_cross_rows_is_numpys_cross_to_the_bit(dtype):
    """``cross_rows`` replaces ``np.cross`` in the hot paths; it must give the same bits, dtype
    and broadcasting (rows against rows, one vector against rows, leading axes)."""
    from igl_spheremap.mesh.arrays import cross_rows

    rng = np.random.default_rng(3)
    for a, b in [((50, 3), (50, 3)), ((50, 3), (3,)), ((3,), (7, 3)), ((2, 4, 3), (2, 4, 3))]:
        X = rng.normal(size=a).astype(dtype)
        Y = (rng.normal(size=b) * 1e-9).astype(dtype)
        Z = cross_rows(X, Y)
        assert Z.dtype == np.cross(X, Y).dtype == dtype
        np.testing.assert_array_equal(Z, np.cross(X, Y))
