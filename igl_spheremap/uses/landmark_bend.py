"""Bending surface 1's spherical map until its landmarks sit on their targets, fold-free.

Unlike :func:`igl_spheremap.landmark_map`, which returns the unbent map when the
landmarks cannot all be reached without folds, :func:`place` keeps what it
reached: when the smooth deformation of the sphere
(:func:`igl_spheremap.uses.landmarks.deformed`) cannot carry every landmark to
its target at once, the landmarks are placed coarse to fine: first the
:data:`FIRST_STAGE` spread farthest apart on surface 1, then twice as many (the
ones placed stay), and so on, so that the later landmarks start close to their
targets; a stage that cannot be completed is retried one landmark at a time,
and a landmark that still cannot be placed is left where it is (the caller's
distortion stage pulls it on by a spring and places it later).
"""

import numpy as np

from .landmarks import deformed

#: Landmarks of the first stage of the coarse-to-fine bend (then doubled per stage).
FIRST_STAGE = 4

#: ``max_untangled`` of the coarse-to-fine bend's deformations
#: (:func:`igl_spheremap.uses.landmarks.deformed`): its many attempts that cannot succeed
#: would otherwise spend most of their time untangling.
RETRY_UNTANGLED = 0


def spread_order(P):
    """Order of the points ``P`` (k, 3) by farthest-point sampling from the first one ((k,) int64)."""
    if P.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    return farthest_points(P, [0], P.shape[0])


def farthest_points(V, first, count):
    """``first`` followed by farthest-point samples of the points ``V`` in space ((count,) int64).

    Parameters
    ----------
    V : (n, 3) float64 array
    first : (k,) int64 array
        Distinct indices kept first (e.g. landmarks); with none, the samples start at 0.
    count : int
        Number of indices returned (at most ``n``).
    """
    picks = [int(i) for i in first] or [0]
    d = np.full(V.shape[0], np.inf)
    for i in picks:
        d = np.minimum(d, np.linalg.norm(V - V[i], axis=1))
    while len(picks) < min(count, V.shape[0]):
        picks.append(int(np.argmax(d)))
        d = np.minimum(d, np.linalg.norm(V - V[picks[-1]], axis=1))
    return np.array(picks, dtype=np.int64)


def place(F, U, lm, targets, order, placed=None, stages=True):
    """Surface 1's map bent so that as many landmarks as possible sit exactly on their targets.

    Parameters
    ----------
    F : (m1, 3) int64 array
    U : (n1, 3) float64 array
        Fold-free map.
    lm : (k,) int64 array
        Landmark vertices.
    targets : (k, 3) float64 array
        Unit vectors.
    order : (k,) int64 array
        Positions in ``lm`` from coarse to fine (:func:`spread_order` of the
        landmarks on surface 1).
    placed : (k,) bool array, optional
        Landmarks already on their targets (they stay there).
    stages : bool
        False: only the deformation that moves every landmark at once, without untangling
        (a quick first look, e.g. to screen alignments); nothing is placed when it cannot be
        completed.

    Returns
    -------
    U : (n1, 3) float64 array
        Fold-free map.
    placed : (k,) bool array
        Landmarks on their targets.
    """
    placed = np.zeros(lm.size, dtype=bool) if placed is None else placed.copy()
    Y, t = deformed(F, U, lm, targets) if stages else deformed(F, U, lm, targets, RETRY_UNTANGLED)
    if t == 1.0:
        return Y, np.ones(lm.size, dtype=bool)
    if not stages:
        return U, placed
    done = [int(j) for j in np.flatnonzero(placed)]
    todo = [int(j) for j in order if not placed[j]]
    size, tried = min(FIRST_STAGE, len(todo)), set()
    while todo:
        new = [j for j in todo[:size] if j not in tried]
        tried.update(new)
        Z, t = deformed(F, U, lm[done + new], targets[done + new], RETRY_UNTANGLED)
        if t == 1.0:
            U, done = Z, done + new
        elif len(new) > 1:  # a stage of one landmark was that landmark's own attempt
            for j in new:
                Z, t = deformed(F, U, lm[done + [j]], targets[done + [j]], RETRY_UNTANGLED)
                if t == 1.0:
                    U, done = Z, done + [j]
        if size >= len(todo):
            break
        size = min(2 * size, len(todo))
    placed[done] = True
    return U, placed
