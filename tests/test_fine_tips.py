"""How much a spherical map crowds a vertex toward its neighbours
(:func:`igl_spheremap.uses.fine_tips.crowding`), against exact geodesics."""

import igl
import numpy as np

from igl_spheremap.mesh.shapes import icosphere
from igl_spheremap.sphere.mobius import mobius_transform
from igl_spheremap.uses.alignment import geodesics
from igl_spheremap.uses.fine_tips import crowding
from igl_spheremap.uses.surface_arap import to_sphere_scale


def _exact_ratio(V, F, U, i, others):
    """The least angle / exact geodesic distance (``igl.exact_geodesic``, surface at 4 pi)."""
    Vs = to_sphere_scale(V, F)
    d = igl.exact_geodesic(Vs, F, np.array([i]), np.zeros(0, np.int64), others,
                           np.zeros(0, np.int64))
    d = d[0] if isinstance(d, tuple) else d
    ang = np.arccos(np.clip(U[others] @ U[i], -1.0, 1.0))
    return np.min(ang / d)


def test_the_identity_map_of_a_round_sphere_crowds_nothing_and_a_mobius_map_crowds_one_cap():
    """On the icosphere's own map the ratio of angle to geodesic distance is about 1 (the
    sphere and the polyhedron at the same area); a Möbius transformation that crowds the cap
    at vertex 0 by about ``(1 - c) / (1 + c)`` makes it that small there, and the value
    matches exact geodesics to the heat method's accuracy."""
    V, F = icosphere(3)
    F = np.asarray(F, dtype=np.int64)
    U = V / np.linalg.norm(V, axis=1, keepdims=True)
    dist = geodesics(to_sphere_scale(V, F), F)
    near = np.argsort(np.linalg.norm(V - V[0], axis=1))[1:7].astype(np.int64)
    r = crowding(U, 0, near, dist)
    assert 0.9 < r < 1.1
    crowded = mobius_transform(U, -0.99 * U[0])
    r = crowding(crowded, 0, near, dist)
    assert r < 0.01
    assert abs(r / _exact_ratio(V, F, crowded, 0, near) - 1) < 0.1
    assert crowding(U, 0, np.array([0]), dist) == np.inf


def test_a_tip_crowded_between_two_placed_landmarks_is_placed_and_they_are_placed_again():
    """A tip grouped with a placed landmark whose nearest placed neighbour is as close as the
    tip (no annulus to fade a similarity over about it), its target turned by 90 degrees:
    the centre joins the group, the similarity turns them about the neighbour, and the bend
    places the tip (before, such a tip was dropped) and puts both landmarks back on their
    targets, fold-free."""
    from igl_spheremap.sphere.folds import count_folds
    from igl_spheremap.sphere.geodesics import angles
    from igl_spheremap.mesh.frames import tangent_bases
    from igl_spheremap.uses.fine_tips import placed_tips
    V, F = icosphere(3)
    F = np.asarray(F, dtype=np.int64)
    U = V / np.linalg.norm(V, axis=1, keepdims=True)
    U = mobius_transform(U, -0.999999 * U[0])
    order = np.argsort(angles(U, np.tile(U[0], (U.shape[0], 1)))).astype(np.int64)
    centre, neighbour, tip = order[0], order[1], order[8]
    E = tangent_bases(U[centre][None])[0]
    r = angles(U[tip][None], U[centre][None])[0]
    d = U[tip] - U[centre]
    t = np.arctan2(d @ E[:, 1], d @ E[:, 0]) + np.pi / 2
    U2 = U.copy()
    U2[tip] = np.cos(r) * U[centre] + np.sin(r) * (np.cos(t) * E[:, 0] + np.sin(t) * E[:, 1])
    lm = np.array([centre, neighbour])
    out, lm1, lm2, placed = placed_tips(V, F, U, lm, lm, np.array([True, True]),
                                        np.array([tip]), np.array([tip]), U2)
    assert lm1.tolist() == [centre, neighbour, tip] and placed.all()
    assert count_folds(F, out) == 0
    assert np.linalg.norm(out[lm1] - U2[lm1], axis=1).max() < 1e-6 * r


def test_a_tip_the_bend_cannot_place_is_dropped_and_the_map_is_kept():
    """A tip whose target lies beyond the other side of the sphere's crowded cap, across the
    placed landmarks, cannot be reached fold-free: :func:`placed_tips` returns the map and
    the landmarks as they were; a tip with room is placed on its target."""
    from igl_spheremap.uses.fine_tips import placed_tips
    V, F = icosphere(3)
    F = np.asarray(F, dtype=np.int64)
    U = V / np.linalg.norm(V, axis=1, keepdims=True)
    U = mobius_transform(U, -0.99 * U[0])
    order = np.argsort(np.linalg.norm(U - U[0], axis=1)).astype(np.int64)
    centre, neighbour, tip = order[0], order[1], order[2]
    lm = np.array([centre, neighbour])
    U2 = U.copy()
    U2[tip] = -U[tip]
    out, lm1, lm2, placed = placed_tips(V, F, U, lm, lm, np.array([True, True]),
                                        np.array([tip]), np.array([tip]), U2)
    assert out is U and lm1.tolist() == lm.tolist() and placed.tolist() == [True, True]
    # alone with the centre, the same tip on its own image as target is kept and placed
    out, lm1, lm2, placed = placed_tips(V, F, U, lm[:1], lm[:1], np.array([True]),
                                        np.array([tip]), np.array([tip]), U)
    assert lm1.tolist() == [centre, tip] and placed.all()
    assert np.linalg.norm(out[tip] - U[tip]) < 1e-12
