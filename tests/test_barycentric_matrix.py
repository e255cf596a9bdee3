"""igl_spheremap.barycentric_matrix: the sparse interpolation operator of located points."""

import igl
import numpy as np
import pytest
import scipy.sparse
from scipy.spatial.transform import Rotation

from igl_spheremap.sphere.transfer import barycentric_matrix
from igl_spheremap.mesh.shapes import icosphere
from igl_spheremap.sphere.locate import locate_on_sphere


def _random_located(rng, k=500, m=40, n=30):
    F = rng.integers(0, n, size=(m, 3))
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])]
    face = rng.integers(0, F.shape[0], size=k)
    bary = rng.exponential(size=(k, 3))
    bary[rng.random(size=(k, 3)) < 0.2] = 0.0  # some points on edges and vertices
    bary[bary.sum(axis=1) == 0, 0] = 1.0
    bary /= bary.sum(axis=1, keepdims=True)
    return face, bary, F, n


def test_identities_and_libigl_interpolation(rng):
    face, bary, F, n = _random_located(rng)
    P = barycentric_matrix(face, bary, F, n)
    assert scipy.sparse.issparse(P) and P.format == "csr" and P.dtype == np.float64
    assert P.shape == (face.size, n)
    assert np.all(P.data > 0)  # non-negative, zero weights not stored
    nnz = np.diff(P.indptr)
    assert np.array_equal(nnz, np.count_nonzero(bary, axis=1))  # at most 3, one per non-zero weight
    assert np.abs(np.asarray(P.sum(axis=1)).ravel() - 1.0).max() < 1e-15
    # Columns are the face's vertices; the product is libigl's barycentric interpolation.
    X = rng.normal(size=(n, 4))
    ref = igl.barycentric_interpolation(X, F, bary, face[:, None])
    assert np.abs(P @ X - ref).max() < 1e-14
    x = X[:, 0]
    assert (P @ x).shape == (face.size,)
    assert np.abs(P @ x - ref[:, 0]).max() < 1e-14
    # Constants are reproduced exactly up to rounding (partition of unity).
    assert np.abs(P @ np.full(n, 3.5) - 3.5).max() < 1e-14


def test_vertex_points_pick_the_vertex_exactly(rng):
    face, _, F, n = _random_located(rng)
    corner = rng.integers(0, 3, size=face.size)
    bary = np.eye(3)[corner]
    P = barycentric_matrix(face, bary, F, n)
    X = rng.normal(size=(n, 2))
    assert np.array_equal(P @ X, X[F[face, corner]])
    assert np.all(np.diff(P.indptr) == 1)


def test_default_column_count_and_explicit_n(rng):
    face, bary, F, _ = _random_located(rng)
    assert barycentric_matrix(face, bary, F).shape[1] == F.max() + 1
    assert barycentric_matrix(face, bary, F, n=F.max() + 7).shape[1] == F.max() + 7


def test_rounding_of_located_coordinates_is_renormalized(rng):
    face, bary, F, n = _random_located(rng)
    noisy = bary + rng.uniform(-1e-12, 1e-12, size=bary.shape)
    P = barycentric_matrix(face, noisy, F, n)
    assert np.all(P.data >= 0)
    assert np.abs(np.asarray(P.sum(axis=1)).ravel() - 1.0).max() < 1e-15


def test_linear_function_between_two_sphere_triangulations():
    # f(x) = a . x on icosphere(l) is carried to the vertices of a rotated icosphere(5):
    # the barycentric value is a . Q for the chordal point Q on the ray, so the error
    # against the known f(P) is O(h^2): about 4x smaller per subdivision level.
    a = np.array([0.3, -1.2, 0.7])
    R = Rotation.from_rotvec([0.3, 0.5, -0.2]).as_matrix()
    P = icosphere(5)[0] @ R.T
    errors = []
    for level in (2, 3, 4):
        U, F = icosphere(level)
        face, bary = locate_on_sphere(U, F, P)
        M = barycentric_matrix(face, bary, F, U.shape[0])
        carried = M @ (U @ a)
        Q = M @ U  # the chordal points themselves: exact, by linearity
        assert np.abs(carried - Q @ a).max() < 1e-14
        errors.append(np.abs(carried - P @ a).max())
    errors = np.array(errors)
    assert errors[0] < 0.05 * np.linalg.norm(a)  # interpolation accuracy on a coarse sphere
    ratios = errors[:-1] / errors[1:]
    assert np.all((ratios > 3.0) & (ratios < 5.0))


@pytest.mark.parametrize("change, msg", [
    (lambda f, b, F: (f[:, None], b, F), "face must be"),
    (lambda f, b, F: (f.astype(float), b, F), "face must be"),
    (lambda f, b, F: (f, b[:-1], F), "bary must have shape"),
    (lambda f, b, F: (f, b, F[:, :2]), "F must be"),
    (lambda f, b, F: (np.where(np.arange(f.size) < 2, F.shape[0], f), b, F), "face has 2 entries"),
    (lambda f, b, F: (f, np.where(np.arange(f.size)[:, None] == 0, np.nan, b), F), "1 row with non-finite"),
    (lambda f, b, F: (f, b + np.array([-1.0, 0.0, 1.0]), F), "negative"),
    (lambda f, b, F: (f, 1.5 * b, F), "do not sum to 1"),
])
def test_bad_inputs_are_refused(rng, change, msg):
    face, bary, F, n = _random_located(rng)
    bary = np.maximum(bary, 0.2)
    bary /= bary.sum(axis=1, keepdims=True)
    with pytest.raises(ValueError, match=msg):
        barycentric_matrix(*change(face, bary, F), n=n)


def test_vertex_index_beyond_n_refused(rng):
    face, bary, F, n = _random_located(rng)
    with pytest.raises(ValueError, match="F has .* outside"):
        barycentric_matrix(face, bary, F, n=int(F.max()))
