"""igl_spheremap.locate_on_sphere: point location by central projection on a spherical mesh."""

import warnings

import igl
import numpy as np
import pytest

from conftest import drag_past_neighbor
from igl_spheremap import SphereField, count_folds
from igl_spheremap.mesh.shapes import icosphere
from igl_spheremap.sphere.locate import chordal_tree, locate_from, locate_on_sphere


def _unit(X):
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def _raw_cone_volumes(U, F, P):
    """det[P, U_j, U_k], det[U_i, P, U_k], det[U_i, U_j, P] of every point against every face.

    Brute-force reference: plain triple products of the raw vectors, (k, m, 3).
    """
    Ui, Uj, Uk = U[F[:, 0]], U[F[:, 1]], U[F[:, 2]]
    return np.stack([P @ np.cross(Uj, Uk).T, P @ np.cross(Uk, Ui).T, P @ np.cross(Ui, Uj).T], axis=2)


def _raw_volumes_of(U, F, face, P):
    """The same triple products, point k against face[k] only: (k, 3)."""
    Ui, Uj, Uk = (U[F[face, c]] for c in range(3))
    return np.stack([np.einsum("kx,kx->k", P, np.cross(a, b))
                     for a, b in ((Uj, Uk), (Uk, Ui), (Ui, Uj))], axis=1)


def _ray_plane_bary(U, F, face, P):
    """Barycentric coordinates of the ray along P hitting the plane of F[face], by libigl."""
    A, B, C = (U[F[face, c]] for c in range(3))
    N = np.cross(B - A, C - A)
    X = P * (np.einsum("ij,ij->i", N, A) / np.einsum("ij,ij->i", N, P))[:, None]
    return igl.barycentric_coordinates(X, A, B, C)


def _check_valid(U, F, P, face, bary, atol=1e-12):
    assert face.dtype == np.int64 and bary.dtype == np.float64
    assert face.shape == (P.shape[0],) and bary.shape == (P.shape[0], 3)
    assert np.all(bary >= 0.0)
    assert np.abs(bary.sum(axis=1) - 1.0).max() < 1e-14
    # The chordal point given by the coordinates lies on the ray along P.
    X = np.einsum("kc,kcx->kx", bary, U[F[face]])
    assert np.abs(_unit(X) - _unit(P)).max() < atol


def test_random_points_match_brute_force_on_real_map(conformal_map, rng):
    _, F, result, _ = conformal_map("hippocampus.obj")
    U = result.U
    P = _unit(rng.normal(size=(400, 3)))
    face, bary = locate_on_sphere(U, F, P)
    _check_valid(U, F, P, face, bary)
    S = _raw_cone_volumes(U, F, P)
    scale = 1e-14
    clearly = np.all(S > scale, axis=2)  # faces whose cone contains P beyond rounding
    maybe = np.all(S > -scale, axis=2)
    assert np.all(maybe.any(axis=1))  # the cones cover every point
    assert np.all(maybe[np.arange(P.shape[0]), face])
    unique = clearly.sum(axis=1) == 1
    assert unique.mean() > 0.95
    assert np.array_equal(face[unique], np.argmax(clearly[unique], axis=1))
    assert np.allclose(bary, _ray_plane_bary(U, F, face, P), rtol=0, atol=1e-9)


def test_finer_icosphere_on_coarser_hits_vertices_and_edges():
    U, F = icosphere(2)
    P, _ = icosphere(4)  # nested: 162 coarse vertices, and points exactly on coarse edges
    face, bary = locate_on_sphere(U, F, P)
    _check_valid(U, F, P, face, bary, atol=1e-15)
    # Coarse vertices: weight 1 on themselves.
    nc = U.shape[0]
    corner = F[face[:nc]] == np.arange(nc)[:, None]
    assert np.all(corner.sum(axis=1) == 1)
    assert np.array_equal(bary[:nc][corner], np.ones(nc))
    # Brute force: each point in the located cone (to rounding), every coarse face checked.
    S = _raw_cone_volumes(U, F, P)
    assert np.all(S[np.arange(P.shape[0]), face] > -1e-15)
    # Points on the great-circle arc of a coarse edge get weight 0 on the opposite corner.
    Fc = F[face]
    on_edge = np.min(np.abs(S[np.arange(P.shape[0]), face]), axis=1) < 1e-15
    assert on_edge.sum() > nc  # vertices of levels 3 and 4 on coarse edges, too
    assert np.all(np.sort(bary[on_edge], axis=1)[:, 0] < 1e-15)
    assert np.all(np.isin(Fc[on_edge], np.arange(U.shape[0])))


def test_points_inside_every_face_of_a_crowded_map(conformal_map, rng):
    # The fish map squeezes the fins into faces 1e-11 of the sphere: a known correspondence
    # (points built inside each face) checks the walk where chordal and cone faces differ.
    _, F, result, _ = conformal_map("fish_lowres.obj")
    U = result.U
    a = igl.doublearea(U, F)
    assert a.max() / a.min() > 1e6  # crowded indeed
    b = rng.uniform(0.05, 1.0, size=F.shape)
    b /= b.sum(axis=1, keepdims=True)
    P = np.einsum("kc,kcx->kx", b, U[F])
    face, bary = locate_on_sphere(U, F, P)
    assert np.array_equal(face, np.arange(F.shape[0]))
    assert np.abs(bary - b).max() < 1e-8


@pytest.mark.parametrize("name", ["fish_lowres.obj", "hippocampus.obj"])
def test_points_exactly_on_vertices_and_edges_of_real_map(conformal_map, name):
    _, F, result, _ = conformal_map(name)
    U = result.U
    n = U.shape[0]
    face, bary = locate_on_sphere(U, F, U)
    corner = F[face] == np.arange(n)[:, None]
    assert np.all(corner.sum(axis=1) == 1)
    assert np.array_equal(bary[corner], np.ones(n))  # exactly the vertex
    E = igl.edges(F)
    P = U[E[:, 0]] + U[E[:, 1]]
    face, bary = locate_on_sphere(U, F, P)
    _check_valid(U, F, P, face, bary, atol=1e-9)
    Fc = F[face]
    has = (Fc == E[:, [0]]).any(axis=1) & (Fc == E[:, [1]]).any(axis=1)
    assert np.all(has)  # a face of the edge itself
    third = (Fc != E[:, [0]]) & (Fc != E[:, [1]])  # per row, the corner off the edge
    assert np.all(bary[third] < 1e-9)


def test_scale_invariance_duplicates_and_empty(rng):
    U, F = icosphere(3)
    P = _unit(rng.normal(size=(50, 3)))
    face, bary = locate_on_sphere(U, F, P)
    f2, b2 = locate_on_sphere(U, F, np.vstack([7.5 * P, P]))
    assert np.array_equal(f2, np.concatenate([face, face]))
    assert np.allclose(b2, np.vstack([bary, bary]), rtol=0, atol=1e-15)
    f0, b0 = locate_on_sphere(U, F, np.zeros((0, 3)))
    assert f0.shape == (0,) and b0.shape == (0, 3)


def test_bad_inputs_are_refused():
    U, F = icosphere(2)
    P = U[:5]
    cases = [
        ((U[:, :2], F, P), "U must be"),
        ((U, F[:, :2], P), "F must be"),
        ((U, F.astype(float), P), "integer"),
        ((U, F, P[:, :2]), "P must be"),
        ((U, F, P[0]), "P must be"),
        ((U, np.where(F == 3, 999, F), P), "outside"),
        ((np.where(np.arange(U.shape[0])[:, None] == 4, np.nan, U), F, P), "1 row with non-finite"),
        ((U * 1.01, F, P), "off the unit sphere"),
        ((U, F[:, ::-1], P), "folded"),
        ((U, F[1:], P), "cover the sphere"),
        ((U, F, np.vstack([P, [[np.inf, 0, 0]]])), "P has 1 row with non-finite"),
        ((U, F, np.vstack([P, np.zeros((2, 3))])), "2 zero-length"),
    ]
    for args, msg in cases:
        with pytest.raises(ValueError, match=msg):
            locate_on_sphere(*args)


def test_folded_map_refused_with_count():
    U, F = icosphere(3)
    Uf = drag_past_neighbor(F, U, 10)
    folds = int(np.count_nonzero(np.linalg.det(Uf[F]) <= 0))
    assert folds > 0
    with pytest.raises(ValueError, match=f"{folds} folded faces"):
        locate_on_sphere(Uf, F, U)


def test_a_single_folded_face_is_counted_in_the_singular():
    # One face wound the other way: exactly one fold, and the message says "1 folded face"
    # (it said "1 folded faces" before igl_spheremap.errors.plural was used here).
    U, F = icosphere(2)
    F1 = F.copy()
    F1[7] = F1[7, ::-1]
    assert count_folds(F1, U) == 1
    with pytest.raises(ValueError, match=r"the spherical map has 1 folded face \(or F") as err:
        locate_on_sphere(U, F1, U[:3])
    assert "faces" not in str(err.value).split("(")[0]
    with pytest.raises(ValueError, match=r"the sphere has 1 folded face; a field needs"):
        SphereField(U, F1)


def test_sphere_covered_twice_refused():
    # Every face twice: no fold, but each direction lies in two cones.
    U, F = icosphere(1)
    with pytest.raises(ValueError, match="cover the sphere 2 times"):
        locate_on_sphere(U, np.vstack([F, F]), U[:3])


def test_walk_corrects_the_nearest_chordal_face(conformal_map, rng):
    # Where the crowded fins meet large faces, the nearest face of the chordal mesh is
    # often not the face whose cone holds the point: those points are checked by brute force.
    _, F, result, _ = conformal_map("fish_lowres.obj")
    U = result.U
    P = _unit(rng.normal(size=(100_000, 3)))
    face, bary = locate_on_sphere(U, F, P)
    _check_valid(U, F, P, face, bary, atol=1e-9)
    nearest = igl.point_mesh_squared_distance(P, U, F)[1]
    moved = np.flatnonzero(nearest != face)
    assert moved.size > 20
    assert np.all(_raw_volumes_of(U, F, face, P) > -1e-15)  # the located cone holds the point
    # libigl's nearest face alone would be wrong for some
    assert not np.all(_raw_volumes_of(U, F, nearest[moved], P[moved]) > -1e-15)
    # and brute force over all faces finds no other cone that clearly holds them
    S = _raw_cone_volumes(U, F, P[moved])
    clearly = np.all(S > 1e-15, axis=2)
    assert np.all(clearly.sum(axis=1) <= 1)
    assert np.all(clearly[np.arange(moved.size), face[moved]] | ~clearly.any(axis=1))


def test_search_over_all_faces_agrees_with_the_walk(conformal_map, rng, monkeypatch):
    import igl_spheremap.sphere.locate as module

    _, F, result, _ = conformal_map("fish_lowres.obj")
    U = result.U
    P = _unit(rng.normal(size=(20_000, 3)))
    face, bary = locate_on_sphere(U, F, P)
    monkeypatch.setattr(module, "WALK_STEPS", 1)  # no step: every candidate not holding P falls back
    face_all, bary_all = locate_on_sphere(U, F, P)
    assert np.count_nonzero(face_all != igl.point_mesh_squared_distance(P, U, F)[1]) > 0
    assert np.all(_raw_volumes_of(U, F, face_all, P) > -1e-15)
    same = face_all == face
    assert same.mean() > 0.999  # differ only on shared edges
    assert np.allclose(bary_all[same], bary[same], rtol=0, atol=1e-12)


def test_the_walk_steps_through_a_face_whose_edge_is_below_rounding_silently():
    """On a crowded map an image edge can be shorter than the rounding of ``U - P``: both its
    ends minus a far point ``P`` are the same vector (the 50k cat of ``benchmarks/correspondence.py
    --large`` warned "invalid value encountered in divide" from the walk).  The octahedron with
    the edge from +x to +y split 1e-17 from +x: the walk from the sliver face must reach the face
    that holds ``P`` without a warning."""
    U = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1],
                  [1.0, 1e-17, 0]])
    F = np.array([[0, 6, 4], [6, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                  [2, 6, 5], [6, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]], dtype=np.int64)
    assert np.all(_raw_volumes_of(U, F, np.arange(len(F)), U[F].mean(axis=1)) > 0)
    P = _unit(np.array([[-1.0, 0.19, -0.5]]))
    assert np.array_equal(U[6] - P, U[0] - P)  # the sliver's short edge is zero seen from P
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        face, s = locate_from(U, F, P, np.array([0]))
    assert F[face[0]].tolist() == [1, 2, 5]
    assert np.all(s > 0) and np.all(_raw_volumes_of(U, F, face, P) > 0)


def test_given_the_tree_points_walking_far_jump_to_their_nearest_chordal_face(conformal_map, rng,
                                                                             monkeypatch):
    """Started from the face of the antipode (the longest walk there is), every point is
    located within :data:`JUMP_AFTER` steps plus the few from its nearest chordal face, where
    the walk alone would need tens of steps: with the steps capped there, no point may fall
    back to the search over all faces, and the faces are the ones of ``locate_on_sphere``."""
    import igl_spheremap.sphere.locate as module

    _, F, result, _ = conformal_map("fish_lowres.obj")
    U = result.U
    P = _unit(rng.normal(size=(2_000, 3)))
    face = locate_on_sphere(U, F, P)[0]
    far = locate_on_sphere(U, F, -P)[0]
    TT = igl.triangle_triangle_adjacency(F)[0]
    tree = chordal_tree(U, F)
    monkeypatch.setattr(module, "WALK_STEPS", module.JUMP_AFTER + 6)
    monkeypatch.setattr(module, "_search_all_faces", lambda *a: pytest.fail("fell back"))
    jumped, volumes = locate_from(U, F, P, far, TT, tree)
    assert np.all(volumes > -1e-15) and np.all(_raw_volumes_of(U, F, jumped, P) > -1e-15)
    assert np.mean(jumped == face) > 0.999  # differ only on shared edges
    with pytest.raises(pytest.fail.Exception):
        locate_from(U, F, P, far, TT)  # without the tree the walk is far from done
