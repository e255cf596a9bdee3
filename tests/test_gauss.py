"""igl_spheremap.gauss_map: the initial map of Algorithm 1 (paper Definition 1)."""

import numpy as np
import pytest

from igl_spheremap import count_folds, gauss_map


def _area_weighted_normals(V, F):
    """Sum of the incident face normals weighted by face area (cross products), normalized."""
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])  # 2 * area * unit normal
    out = np.zeros_like(V)
    for c in range(3):
        np.add.at(out, F[:, c], N)
    return out / np.linalg.norm(out, axis=1, keepdims=True)


@pytest.mark.parametrize("name", ["fish_lowres.obj", "goathead.obj"])
def test_area_weighted_vertex_normals(mesh, name):
    V, F = mesh(name)
    U = gauss_map(V, F)
    assert U.shape == V.shape and U.dtype == np.float64
    assert np.abs(np.linalg.norm(U, axis=1) - 1.0).max() < 1e-14
    assert np.abs(U - _area_weighted_normals(V, F)).max() < 1e-12


def test_equivariance(mesh, rng):
    V, F = mesh("fish_lowres.obj")
    U = gauss_map(V, F)
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    R *= np.sign(np.linalg.det(R))
    assert np.abs(gauss_map(250.0 * V @ R.T + [1.0, 2.0, 3.0], F) - U @ R.T).max() < 1e-12
    # inward faces are reoriented (validate_mesh) before the normals are taken
    assert np.abs(gauss_map(V, F[:, ::-1]) - U).max() < 1e-14


def test_invalid_meshes_are_refused(icosphere):
    """A torus (genus 1) has no Gauss map onto the sphere that Algorithm 1 could use."""
    import igl
    from igl_spheremap import MeshError

    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 12, endpoint=False),
                       np.linspace(0, 2 * np.pi, 8, endpoint=False), indexing="ij")
    V = np.column_stack([((2 + np.cos(v)) * np.cos(u)).ravel(),
                         ((2 + np.cos(v)) * np.sin(u)).ravel(), np.sin(v).ravel()])
    i, j = np.meshgrid(np.arange(12), np.arange(8), indexing="ij")
    a, b = (i * 8 + j).ravel(), (i * 8 + (j + 1) % 8).ravel()
    c, d = (((i + 1) % 12) * 8 + j).ravel(), (((i + 1) % 12) * 8 + (j + 1) % 8).ravel()
    F = np.vstack([np.column_stack([a, c, d]), np.column_stack([a, d, b])])
    assert igl.euler_characteristic(F) == 0
    with pytest.raises(MeshError, match="genus 1"):
        gauss_map(V, F)
    V, F = icosphere(1)
    with pytest.raises(MeshError, match="shape"):
        gauss_map(V, np.hstack([F, F[:, :1]]))


def test_sphere(icosphere):
    V, F = icosphere(1)
    assert np.abs(gauss_map(V, F) - V).max() < 1e-14  # symmetric vertices: exact
    worst = []
    for level in (2, 3, 4):
        V, F = icosphere(level)
        U = gauss_map(V, F)
        worst.append(np.arccos(np.clip(np.einsum("ij,ij->i", U, V), -1.0, 1.0)).max())
        assert count_folds(F, U) == 0
    assert worst[0] > worst[1] > worst[2] > 0


def test_convex_ellipsoid_is_fold_free(ellipsoid):
    """The Gauss map of a strictly convex surface is a diffeomorphism."""
    V, F = ellipsoid(3, (1.0, 1.5, 3.0))
    assert count_folds(F, gauss_map(V, F)) == 0


def test_thin_features_fold(mesh):
    """Why Algorithm 2 exists: the fish's fins give a folded Gauss map."""
    V, F = mesh("fish_lowres.obj")
    assert count_folds(F, gauss_map(V, F)) > 0
