"""Which vertices Algorithm 1 may move: fixed vertices and the fold barrier, one mechanism.

*Fixed* vertices never move (a Dirichlet boundary: the outside of a local
repair's region, or landmarks held on their targets).  The *fold barrier*
(not in the paper) keeps a fold-free map fold-free: a step may not fold a face
that is not folded; a step that would is shortened a few times, then the
vertices of the faces it would fold are *frozen* (a face whose three vertices do
not move cannot fold).  Both are the same thing to the optimizer: the set of
free vertices, on which the search direction lives and over which the stopping
rule's gradient is taken.

Why the barrier: from a fold-free start, the discrete harmonic energy itself is
lower with some crowded faces of thin features folded (README, "How the
default differs from the paper", item 5), so an unconstrained Algorithm 1 folds
them again.  The result is then a constrained minimizer.  Under the barrier
Algorithm 1 does not re-center the map (see :mod:`igl_spheremap.gauge`).
"""

import numpy as np

from .metrics import fold_mask


class FreeVertices:
    """Fixed vertices and the fold barrier of one Algorithm 1 run.

    Parameters
    ----------
    F : (m, 3) int64 array
        Faces, oriented outward (for the fold test).
    U0 : (n, 3) float64 array
        The initial map (after any centering): its folded faces are the ones a
        step may keep folded, until they unfold.
    fixed : (n,) bool array, optional
        Vertices that never move.
    fold_barrier : bool
        Whether steps may fold faces.

    Attributes
    ----------
    frozen : (n,) bool array
        Fixed or frozen vertices (the complement of the free set).
    allowed : (m,) bool array or None
        Faces allowed to be folded (folded in every iterate so far); None
        without the barrier.
    last_freeze : int
        Iteration of the latest freeze (0 before any).
    """

    def __init__(self, F, U0, fixed=None, fold_barrier=False):
        n = U0.shape[0]
        self.F = F
        self.fixed = np.zeros(n, dtype=bool) if fixed is None else np.asarray(fixed, dtype=bool)
        self.frozen = self.fixed.copy()
        self.allowed = fold_mask(F, U0) if fold_barrier else None
        self.last_freeze = 0

    @property
    def barrier(self):
        """Whether the fold barrier is on."""
        return self.allowed is not None

    @property
    def free(self):
        """(n,) bool: the vertices that may move."""
        return ~self.frozen

    @property
    def frozen_count(self):
        """Vertices frozen by the barrier (fixed ones not counted)."""
        return int(self.frozen.sum()) - int(self.fixed.sum())

    def check(self, Y):
        """Fold test of a trial map.

        Returns
        -------
        now_folded : (m,) bool array or None
            Folded faces of ``Y`` (None without the barrier).
        flipped : (m,) bool array or None
            Faces ``Y`` folds that the barrier does not allow; None when there
            are none (or no barrier).
        """
        if self.allowed is None:
            return None, None
        now_folded = fold_mask(self.F, Y)
        flipped = now_folded & ~self.allowed
        return now_folded, (flipped if flipped.any() else None)

    def freeze(self, flipped, k):
        """Freeze the vertices of the faces ``flipped`` at iteration ``k``."""
        self.frozen[self.F[flipped].ravel()] = True
        self.last_freeze = k

    def accept(self, now_folded):
        """After an accepted step: faces that unfolded may not fold again."""
        if self.allowed is not None:
            self.allowed &= now_folded
