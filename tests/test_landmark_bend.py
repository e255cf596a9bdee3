"""The coarse-to-fine landmark bend (:func:`igl_spheremap.uses.landmark_bend.place`): which
deformations it attempts and what it keeps, with the deformation replaced by a recorder."""

import numpy as np
import pytest

from igl_spheremap.mesh.shapes import icosphere
from igl_spheremap.uses import landmark_bend


@pytest.fixture
def sphere():
    V, F = icosphere(2)
    return np.asarray(F, dtype=np.int64), V / np.linalg.norm(V, axis=1, keepdims=True)


def _recorder(monkeypatch, blocked):
    """Replace ``deformed``: the identity map, reaching its targets (t = 1) unless the landmark
    set holds a vertex of ``blocked``; every call's landmark set is recorded."""
    calls = []

    def deformed(F, U, lm, Q, max_untangled=None):
        calls.append(tuple(int(v) for v in lm))
        return U.copy(), 0.5 if blocked & set(calls[-1]) else 1.0

    monkeypatch.setattr(landmark_bend, "deformed", deformed)
    return calls


@pytest.mark.parametrize("placed, staged", [
    # three placed, the fourth blocked: its stage is its own attempt, made once
    ([True, True, True, False], [(0, 5, 9, 17)]),
    # two unplaced, one blocked: their stage fails, then each is tried alone with the placed ones
    ([True, True, False, False], [(0, 5, 9, 17), (0, 5, 9), (0, 5, 9, 17)]),
])
def test_the_stages_attempt_each_landmark_set_once_and_keep_what_is_placed(sphere, monkeypatch,
                                                                           placed, staged):
    """After the all-at-once deformation fails, the staged attempts are ``staged`` (no
    deformation repeated from the same map), and every landmark that can be placed is."""
    F, U = sphere
    lm = np.array([0, 5, 9, 17])
    calls = _recorder(monkeypatch, {17})
    _, out = landmark_bend.place(F, U, lm, U[lm], np.arange(4), np.array(placed))
    assert out.tolist() == [True, True, True, False]
    assert calls == [(0, 5, 9, 17)] + staged


def test_a_flag_of_a_landmark_off_its_target_is_dropped(sphere, monkeypatch):
    """``placed`` describes the map passed in: a landmark flagged as placed whose image is not
    on its target (a flag carried over from another map of the same landmarks) is bent like
    the unplaced ones, and reported unplaced when that fails; the flags that hold stay."""
    F, U = sphere
    lm = np.array([0, 5, 9, 17])
    targets = U[lm].copy()
    targets[3] = U[30]
    calls = _recorder(monkeypatch, {17})
    _, out = landmark_bend.place(F, U, lm, targets, np.arange(4), np.ones(4, dtype=bool),
                                 quick=True)
    assert out.tolist() == [True, True, True, False]
    assert calls == [(0, 5, 9, 17)]


def _crowded_cap(level=3, depth=0.99):
    """An icosphere map crowded toward vertex 0 by a Möbius transformation (fold-free), with
    its faces: a cap of thin-feature size around vertex 0, as a conformal map makes."""
    from igl_spheremap.sphere.folds import count_folds
    from igl_spheremap.sphere.mobius import mobius_transform
    V, F = icosphere(level)
    F = np.asarray(F, dtype=np.int64)
    U = V / np.linalg.norm(V, axis=1, keepdims=True)
    U = mobius_transform(U, -depth * U[0])
    assert count_folds(F, U) == 0
    return F, U


def _polar(X, c):
    """Angle from ``c`` and azimuth in ``landmark_bend``'s own frame at ``c``."""
    from igl_spheremap.mesh.frames import tangent_bases
    E = tangent_bases(c[None])[0]
    d = X - c
    return 2 * np.arcsin(np.linalg.norm(d, axis=1) / 2), np.arctan2(d @ E[:, 1], d @ E[:, 0])


def test_a_spiral_similarity_about_the_placed_landmark_takes_a_tip_onto_its_target():
    """One unplaced landmark near a placed one on a crowded cap: it lands on its target (the
    similarity of one point is exact), the cap around turns and scales with it (each vertex's
    angle from the centre times the same factor, its azimuth turned by the same angle), the
    map stays fold-free, and the vertices beyond the fade keep their rows bit for bit."""
    from igl_spheremap.sphere.folds import count_folds
    F, U = _crowded_cap(depth=0.9)
    c = U[0]
    tip = int(np.argsort(np.linalg.norm(U - c, axis=1))[3])
    r, t = _polar(U[tip:tip + 1], c)
    target_r, target_t = 1.7 * r, t + np.radians(40)
    from igl_spheremap.mesh.frames import tangent_bases
    E = tangent_bases(c[None])[0]
    Q = (np.cos(target_r)[:, None] * c + np.sin(target_r)[:, None]
         * (np.cos(target_t)[:, None] * E[:, 0] + np.sin(target_t)[:, None] * E[:, 1]))
    lm = np.array([0, tip])
    out, moved = landmark_bend.similar_toward(F, U, lm, np.vstack([c, Q]),
                                              np.array([True, False]))
    assert moved.tolist() == [False, True]
    assert np.linalg.norm(out[tip] - Q[0]) < 1e-9 * r[0]
    assert count_folds(F, out) == 0
    assert np.array_equal(out[0], U[0])
    r0, t0 = _polar(U, c)
    r1, t1 = _polar(out, c)
    inner = (r0 > 0) & (r0 < 2 * target_r[0])
    assert inner.sum() >= 4
    np.testing.assert_allclose(r1[inner] / r0[inner], 1.7, rtol=1e-9)
    np.testing.assert_allclose(np.angle(np.exp(1j * (t1[inner] - t0[inner]))), np.radians(40),
                               atol=1e-9)
    far = r0 >= landmark_bend.FADE_OUT
    assert far.sum() >= 10
    assert np.array_equal(out[far], U[far])


def test_a_spiral_similarity_whose_fade_would_fold_is_not_applied():
    """A target so far out that the annulus up to :data:`FADE_OUT` spans fewer e-folds than
    the scale asks for: the map comes back unchanged, the tip not moved."""
    F, U = _crowded_cap()
    c = U[0]
    tip = int(np.argsort(np.linalg.norm(U - c, axis=1))[3])
    r, _ = _polar(U[tip:tip + 1], c)
    far = U[tip] + 0.0
    scale = 0.8 * landmark_bend.FADE_OUT / r[0]  # the tip's target near the fade's end
    Q = c * np.cos(scale * r[0]) + np.sin(scale * r[0]) * (far - c * (far @ c)) / np.linalg.norm(
        far - c * (far @ c))
    out, moved = landmark_bend.similar_toward(F, U, np.array([0, tip]), np.vstack([c, Q]),
                                              np.array([True, False]))
    assert np.array_equal(out, U) and not moved.any()


def _crowded_pair_and_tip(depth=0.999999, turn=90.0, far=20):
    """An icosphere map crowded toward vertex 0 to 1e-7 (a fingertip's scale on a body), with
    landmarks: vertex 0 and its nearest neighbour, ``far`` vertices spread over the rest, all
    on their targets; and a tip of the cap (unplaced) whose target is its image turned by
    ``turn`` degrees about vertex 0."""
    from igl_spheremap.mesh.frames import tangent_bases
    from igl_spheremap.sphere.geodesics import angles
    F, U = _crowded_cap(level=3, depth=depth)
    c = U[0]
    near = np.argsort(angles(U, np.tile(c, (U.shape[0], 1))))
    tip = int(near[8])
    E = tangent_bases(c[None])[0]
    r = angles(U[tip][None], c[None])[0]
    d = U[tip] - c
    t = np.arctan2(d @ E[:, 1], d @ E[:, 0]) + np.radians(turn)
    Q = np.cos(r) * c + np.sin(r) * (np.cos(t) * E[:, 0] + np.sin(t) * E[:, 1])
    spread = landmark_bend.farthest_points(U, [0], far + 1)[1:]
    lm = np.concatenate([[0, int(near[1])], spread, [tip]]).astype(np.int64)
    placed = np.ones(lm.size, dtype=bool)
    placed[-1] = False
    return F, U, lm, np.vstack([U[lm[:-1]], Q]), placed, r


def test_a_crowded_landmark_is_bent_into_place_inside_its_cap():
    """A cap of 1e-7 with two placed landmarks and a tip to turn by 90 degrees about one of
    them, 20 other landmarks held: the local bend puts the tip on its target to rounding
    relative to the cap, fold-free, with every other landmark held bit for bit and every
    vertex beyond the cap unchanged bit for bit (the human pair of
    ``test_surface_maps.py`` needs it where the deformation of the whole sphere fails)."""
    from igl_spheremap.sphere.folds import count_folds
    from igl_spheremap.sphere.geodesics import angles
    F, U, lm, Q, placed, r = _crowded_pair_and_tip()
    out, placed_now = landmark_bend.local_bend(F, U, lm, Q, placed, lm.size - 1)
    assert placed_now.all()
    assert count_folds(F, out) == 0
    assert np.linalg.norm(out[lm[-1]] - Q[-1]) < 1e-6 * r
    assert np.array_equal(out[lm[:-1]], U[lm[:-1]])
    gap = angles(U[lm[:-1]], np.tile(U[lm[-1]], (lm.size - 1, 1))).min()
    cap = landmark_bend.LOCAL_CAP * max(gap, angles(U[lm[-1]][None], Q[-1:])[0])
    beyond = angles(U, np.tile(U[lm[-1]], (U.shape[0], 1))) >= cap
    assert beyond.sum() > 100 and (~beyond).sum() > 10
    assert np.array_equal(out[beyond], U[beyond])
    assert not np.array_equal(out[~beyond], U[~beyond])


def test_the_local_bend_leaves_a_landmark_whose_cap_is_not_crowded():
    """On the round icosphere the cap the rule asks for is wider than
    :data:`LOCAL_CAP_MAX`: the map and the flags come back as they were."""
    F, U = _crowded_cap(depth=0.0)
    lm = np.array([0, 5, 9])
    Q = U[[0, 5, 12]]
    out, placed = landmark_bend.local_bend(F, U, lm, Q, np.array([True, True, False]), 2)
    assert out is U and placed.tolist() == [True, True, False]
