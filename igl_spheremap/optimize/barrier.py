"""Which vertices Algorithm 1 may move: fixed vertices and the fold barrier, one mechanism.

*Fixed* vertices never move (a Dirichlet boundary: the outside of a local
repair's region, or landmarks held on their targets).  The *fold barrier*
(not in the paper) keeps a fold-free map fold-free: a step may not fold a face
that is not folded; a step that would is shortened a few times, then the
vertices of the faces it would fold are *frozen* (a face whose three vertices do
not move cannot fold).  Both are the same thing to the optimizer: the set of
free vertices, on which the search direction lives and over which the stopping
rule's gradient is taken.

With a storage precision whose rounding can fold small faces (``"float32"``,
:func:`igl_spheremap.sphere.folds.rounding_margin`) the barrier keeps a *margin*: a face whose
signed image volume is above its rounding margin may not go to or below it, a
face below its margin but not folded may not fold, and a folded face may stay
folded until it unfolds.  With ``"float64"`` the margin is 0 and the
test is the plain fold test, operation for operation.

A *feasible* barrier (``feasible=True``, for an energy that is itself a barrier:
:class:`igl_spheremap.optimize.conformal_distortion.ConformalDistortionEnergy`) never
freezes: every step is capped by :meth:`FreeVertices.max_step`, the largest step along
the Cayley curve before a face breaks the barrier or loses more than
:data:`FEASIBLE_SHARE` of its signed volume (per face in closed form,
:mod:`igl_spheremap.optimize.feasible_step`), and a trial the barrier still rejects
is shortened.

Why the barrier: from a fold-free start, the discrete harmonic energy itself is
lower with some crowded faces of thin features folded (README, "How the
default differs from the paper", item 5), so an unconstrained Algorithm 1 folds
them again.  The result is then a constrained minimizer.  Under the barrier
Algorithm 1 re-centers the map only with a margin, and only when the centered map
breaks no margin (see :mod:`igl_spheremap.optimize.gauge`).
"""

import numpy as np

from ..sphere.folds import fold_mask, unit_roundoff, volumes_and_margins
from .feasible_step import max_step

#: A feasible step lets no face lose more than this share of its signed volume
#: (:meth:`FreeVertices.max_step`; ``docs/decisions.md``).
FEASIBLE_SHARE = 0.5


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
    precision : {"float64", "float32"}
        Storage precision the barrier protects: the margin of
        :func:`igl_spheremap.sphere.folds.rounding_margin` (0 for ``"float64"``).
    feasible : bool
        With ``fold_barrier``: steps are capped by :meth:`max_step` and no vertex is
        ever frozen (the line search only shortens).

    Attributes
    ----------
    frozen : (n,) bool array
        Fixed or frozen vertices (the complement of the free set).
    allowed : (m,) bool array or None
        Faces allowed at or below their margin (at or below it in every iterate
        so far); with margin 0 the folded faces.  None without the barrier.
    may_fold : (m,) bool array or None
        With a margin: faces allowed to be folded (folded in every iterate so
        far); None otherwise.
    last_freeze : int
        Iteration of the latest freeze (0 before any).
    feasible : bool
    """

    def __init__(self, F, U0, fixed=None, fold_barrier=False, precision="float64",
                 feasible=False):
        n = U0.shape[0]
        self.feasible = bool(feasible and fold_barrier)
        self.F = F
        self.fixed = np.zeros(n, dtype=bool) if fixed is None else np.asarray(fixed, dtype=bool)
        self.frozen = self.fixed.copy()
        self.u = unit_roundoff(precision) if fold_barrier else 0.0
        self.allowed = self.may_fold = None
        if fold_barrier and self.u:
            self.allowed, self.may_fold = self._state(U0)
        elif fold_barrier:
            self.allowed = fold_mask(F, U0)
        self.last_freeze = 0

    def _state(self, Y):
        """``(below, folded)`` masks of ``Y`` for a margin barrier."""
        s, margin = volumes_and_margins(self.F, Y, self.u)
        return s <= margin, s <= 0.0

    @property
    def fold_barrier(self):
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

    @property
    def margin(self):
        """Whether the barrier keeps a rounding margin (precision other than float64)."""
        return self.may_fold is not None

    def check(self, Y):
        """Barrier test of a trial map.

        Returns
        -------
        now : (m,) bool array, tuple or None
            What :meth:`accept` needs of ``Y``: its folded faces (margin 0), or
            its ``(below margin, folded)`` masks; None without the barrier.
        flipped : (m,) bool array or None
            Faces where ``Y`` breaks the barrier (folded, or below the margin
            when they were above it); None when there are none (or no barrier).
        """
        if self.allowed is None:
            return None, None
        if self.may_fold is not None:
            below, folded = now = self._state(Y)
            flipped = (below & ~self.allowed) | (folded & ~self.may_fold)
        else:
            now = fold_mask(self.F, Y)
            flipped = now & ~self.allowed
        return now, (flipped if flipped.any() else None)

    def max_step(self, U, X, tau):
        """``tau`` capped so that along the Cayley curve from ``U`` (direction ``-X``) no face
        breaks the barrier, nor loses more than :data:`FEASIBLE_SHARE` of its signed volume.

        The threshold of a face is the larger of ``(1 - FEASIBLE_SHARE) s_f`` and its
        rounding margin (0 for a face allowed at or below it); faces allowed to be folded
        are free (:func:`igl_spheremap.optimize.feasible_step.max_step`).
        """
        s, margin = volumes_and_margins(self.F, U, self.u)
        if self.may_fold is not None:
            faces = ~self.may_fold
            margin = np.where(self.allowed, 0.0, margin)
        else:
            faces = ~self.allowed
        threshold = np.maximum(margin, (1.0 - FEASIBLE_SHARE) * s)
        return max_step(self.F[faces], U, X, tau, s[faces], threshold[faces])

    def freeze(self, flipped, k):
        """Freeze the vertices of the faces ``flipped`` at iteration ``k``."""
        self.frozen[self.F[flipped].ravel()] = True
        self.last_freeze = k

    def accept(self, now):
        """After an accepted step (``now`` from :meth:`check`): faces that unfolded
        (or rose above their margin) may not fold (or go below it) again.

        A feasible barrier keeps the margin of the faces above it at the start only: the
        energy that is itself the barrier guards exactly those
        (:class:`igl_spheremap.optimize.conformal_distortion.ConformalDistortionEnergy`),
        and a margin the energy does not know would hold a face that rose above it
        against the energy's pull: the step goes to 0 and the descent stalls
        (``docs/decisions.md``).
        """
        if self.may_fold is not None:
            if not self.feasible:
                self.allowed &= now[0]
            self.may_fold &= now[1]
        elif self.allowed is not None:
            self.allowed &= now
