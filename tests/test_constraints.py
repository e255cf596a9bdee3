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
