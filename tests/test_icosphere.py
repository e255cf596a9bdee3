"""igl_spheremap.icosphere: subdivided icosahedron on the unit sphere."""

import igl
import numpy as np
import pytest

from igl_spheremap.mesh.shapes import MAX_LEVEL, icosphere
from igl_spheremap.sphere.folds import signed_image_volumes


@pytest.mark.parametrize("level", [0, 1, 2, 3, 4])
def test_counts_unit_norms_and_closed_outward_surface(level):
    V, F = icosphere(level)
    assert V.dtype == np.float64 and F.dtype == np.int64
    assert V.shape == (10 * 4 ** level + 2, 3) and F.shape == (20 * 4 ** level, 3)
    assert np.abs(np.linalg.norm(V, axis=1) - 1.0).max() < 1e-15
    # Closed 2-manifold of Euler characteristic 2: every edge in exactly two faces.
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, counts = np.unique(E, axis=0, return_counts=True)
    assert np.all(counts == 2)
    assert V.shape[0] - counts.size + F.shape[0] == 2
    assert igl.is_edge_manifold(F)[0]
    # Outward: each face's signed volume det[V_i, V_j, V_k] > 0, and igl agrees on the normals.
    assert np.all(signed_image_volumes(F, V) > 0)
    N = igl.per_face_normals(V, F, np.array([0.0, 0.0, 1.0]))
    centroids = V[F].mean(axis=1)
    assert np.all(np.einsum("ij,ij->i", N, centroids) > 0)
    # No duplicate vertices.
    assert np.unique(np.round(V, 12), axis=0).shape[0] == V.shape[0]


def test_level_zero_is_the_regular_icosahedron():
    V, F = icosphere(0)
    edge = np.linalg.norm(V[F] - V[np.roll(F, 1, axis=1)], axis=2)
    # Edge of the regular icosahedron inscribed in the unit sphere: 4 / sqrt(10 + 2 sqrt 5).
    assert np.allclose(edge, 4.0 / np.sqrt(10.0 + 2.0 * np.sqrt(5.0)), rtol=0, atol=1e-14)


@pytest.mark.parametrize("level", [1, 3])
def test_nested_and_new_vertices_are_normalized_edge_midpoints(level):
    Vc, Fc = icosphere(level - 1)
    V, _ = icosphere(level)
    nc = Vc.shape[0]
    assert np.array_equal(V[:nc], Vc)
    E = np.unique(np.sort(np.concatenate([Fc[:, [0, 1]], Fc[:, [1, 2]], Fc[:, [2, 0]]]), axis=1),
                  axis=0)
    mid = Vc[E[:, 0]] + Vc[E[:, 1]]
    mid /= np.linalg.norm(mid, axis=1, keepdims=True)
    new = V[nc:]
    assert new.shape == mid.shape
    # Each new vertex is the normalized midpoint of exactly one coarse edge.
    key = lambda X: np.round(X, 12)  # noqa: E731
    assert np.array_equal(np.unique(key(new), axis=0), np.unique(key(mid), axis=0))


def test_faces_nearly_equal_in_area():
    V, F = icosphere(4)
    a = igl.doublearea(V, F)
    # Geodesic grids keep the face areas within a small factor of each other (about 1.4 here).
    assert a.max() / a.min() < 1.6
    assert np.isclose(a.sum() / 2.0, 4.0 * np.pi, rtol=2e-3)


@pytest.mark.parametrize("bad", [-1, MAX_LEVEL + 1, 100])
def test_level_out_of_range(bad):
    with pytest.raises(ValueError, match="between 0 and"):
        icosphere(bad)


@pytest.mark.parametrize("bad", [1.0, "3", None, True])
def test_level_not_an_integer(bad):
    with pytest.raises(TypeError, match="integer"):
        icosphere(bad)


def test_numpy_integer_level_accepted():
    V, F = icosphere(np.int64(2))
    assert V.shape == (162, 3)


def test_a_template_name_without_freesurfer_order_says_which_order():
    """'fsaverage5' is a level only in FreeSurfer's order; the default order's TypeError said
    only that the level must be an integer."""
    with pytest.raises(TypeError, match=r"icosphere\('fsaverage5', order=\"freesurfer\"\)"):
        icosphere("fsaverage5")

