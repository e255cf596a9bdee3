"""igl_spheremap.optimize.barrier.FreeVertices: fixed vertices and the fold barrier."""

import numpy as np

from conftest import drag_past_neighbor
from igl_spheremap.optimize.barrier import FreeVertices


def _det_folded(F, U):
    return np.linalg.det(np.stack([U[F[:, k]] for k in range(3)], axis=1)) <= 0


def test_barrier_rejects_exactly_the_newly_folded_faces(icosphere):
    V, F = icosphere(2)
    fixed = np.zeros(V.shape[0], bool)
    fixed[:3] = True
    free = FreeVertices(F, V, fixed=fixed, fold_barrier=True)
    assert free.fold_barrier and not free.allowed.any() and free.frozen_count == 0
    assert np.array_equal(free.free, ~fixed)
    now, flipped = free.check(V)
    assert flipped is None and not now.any()
    Y = drag_past_neighbor(F, V, 40, 2.5)
    now, flipped = free.check(Y)
    assert np.array_equal(now, _det_folded(F, Y)) and np.array_equal(flipped, now)
    free.freeze(flipped, k=7)
    assert free.last_freeze == 7
    frozen = np.zeros(V.shape[0], bool)
    frozen[F[flipped].ravel()] = True
    assert np.array_equal(free.frozen, frozen | fixed)
    assert free.frozen_count == int((frozen & ~fixed).sum())


def test_faces_folded_at_the_start_may_unfold_and_then_stay_unfolded(icosphere):
    V, F = icosphere(2)
    U0 = drag_past_neighbor(F, V, 40, 2.5)
    free = FreeVertices(F, U0, fold_barrier=True)
    assert np.array_equal(free.allowed, _det_folded(F, U0))
    now, flipped = free.check(U0)
    assert flipped is None                 # the start's own folds are allowed
    now, flipped = free.check(V)           # all unfolded
    free.accept(now)
    assert not free.allowed.any()
    now, flipped = free.check(U0)          # folding them again is not allowed now
    assert np.array_equal(flipped, _det_folded(F, U0))


def test_without_the_barrier_nothing_is_checked(icosphere):
    V, F = icosphere(1)
    free = FreeVertices(F, V)
    assert not free.fold_barrier
    assert free.check(-V) == (None, None)
    free.accept(None)


def _below_margin_start(V, F):
    """``V`` with vertex ``F[0, 0]`` moved so that face 0 is fold-free but below its float32
    margin (its signed volume a hundredth of its margin's size estimate)."""
    from igl_spheremap.sphere.folds import unit_roundoff, volumes_and_margins

    i, j, k = F[0]
    normal = np.cross(V[j], V[k])
    chord = V[j] + V[k]
    _, margin = volumes_and_margins(F, V, unit_roundoff("float32"))
    delta = 0.01 * margin[0] / np.linalg.norm(normal) ** 2
    U = V.copy()
    U[i] = chord / np.linalg.norm(chord) + delta * normal
    U[i] /= np.linalg.norm(U[i])
    s, margin = volumes_and_margins(F, U, unit_roundoff("float32"))
    assert 0 < s[0] < margin[0]
    return U


def test_a_feasible_barrier_keeps_the_margin_of_the_faces_above_it_at_the_start_only(icosphere):
    """The energy of a feasible descent guards the faces above the margin at its start; the
    barrier must not hold a face that rose above it later (it would stall the descent)."""
    V, F = icosphere(2)
    U0 = _below_margin_start(V, F)
    for feasible in (False, True):
        free = FreeVertices(F, U0, fold_barrier=True, precision="float32", feasible=feasible)
        assert free.allowed[0] and not free.may_fold.any()
        now, flipped = free.check(V)          # face 0 rises above its margin
        assert flipped is None
        free.accept(now)
        now, flipped = free.check(U0)         # and goes below it again
        if feasible:
            assert flipped is None or not flipped[0]
        else:
            assert flipped[0]
        assert (now[0] & ~now[1])[0]          # below the margin, not folded
