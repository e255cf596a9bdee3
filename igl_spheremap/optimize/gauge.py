"""The Möbius gauge: keeping the map Möbius-normalized while Algorithm 1 runs (not in the paper).

The continuous harmonic energy is invariant under the Möbius transformations
of the sphere (a conformal map is unique up to them), the discrete one is not:
it decreases along the dilations toward a map collapsed to a point.  An energy
that is Möbius invariant in the continuum (``Energy.mobius_invariant``, true
for :class:`igl_spheremap.optimize.harmonic.HarmonicEnergy`, false once landmarks fix the
map) is minimized with this gauge:

* the initial map is centered (:func:`igl_spheremap.mobius_center`, area-weighted
  centroid at the origin);
* every search direction is projected M-orthogonally off the three
  infinitesimal dilations ``Z_k(U_i) = e_k - (e_k . U_i) U_i``
  (:meth:`MobiusGauge.project`), so the centroid does not move to first order;
* the map is re-centered when the centroid still leaves a ball
  (:meth:`MobiusGauge.needs_recentering`), or when the iteration stalls along the
  Möbius orbit (:meth:`MobiusGauge.stalled_on_orbit`).

Under the fold barrier (:class:`igl_spheremap.optimize.barrier.FreeVertices`) the
projection stays but Algorithm 1 does not re-center: a Möbius transformation can
flip the large flat image triangles, which the barrier must not allow.  With a
float32 rounding margin it re-centers when the centered map keeps the barrier
(a map left off-center crowds one side of the sphere below the margin).
"""

import numpy as np

from ..mesh.arrays import rowdot
from ..sphere.mobius import mobius_center

#: Once the RMS gradient is below ``LATE_GNORM`` the re-centering threshold
#: tightens to ``LATE_TOL``: the centroid left by the fast first iterations
#: (up to ``tol``) is then removed while the gradient is still large compared
#: with the jump a re-centering causes (~ the centroid norm), instead of
#: showing up as a gradient floor ~ the centroid norm near ``gtol`` (see
#: :meth:`MobiusGauge.stalled_on_orbit`; values in ``docs/decisions.md``).
LATE_GNORM = 1.0
LATE_TOL = 1e-4


def _cross_matrix(m):
    """``[m]_x`` with ``[m]_x v = m x v``."""
    return np.array([[0.0, -m[2], m[1]], [m[2], 0.0, -m[0]], [-m[1], m[0], 0.0]])


class MobiusGauge:
    """Möbius normalization of a map during Algorithm 1 (area-weighted centroid at 0).

    Parameters
    ----------
    area : (n,) float64 array
        Vertex areas of the mesh scaled to total area ``4 pi`` (the weights of
        the centroid ``sum_i A_i U_i / sum_i A_i``).
    tol : float
        Re-centering threshold of the centroid norm (``mobius_tol``).
    """

    def __init__(self, area, tol=1e-2):
        self.area = area
        self.total = float(area.sum())
        self.tol = tol
        self.stalls = 0

    def center(self, U):
        """``U`` Möbius-centered (:func:`igl_spheremap.mobius_center`)."""
        return mobius_center(U, self.area)[0]

    def centroid_norm(self, U):
        """``|sum_i A_i U_i| / sum_i A_i`` (float)."""
        return float(np.linalg.norm(self.area @ U)) / self.total

    @staticmethod
    def gram(U, a):
        """``S = sum_i a_i (I - U_i U_i^T)``: the Gram matrix of the dilations
        (and of the rotations) in the product weighted by ``a``."""
        return np.eye(3) * a.sum() - (U * a[:, None]).T @ U

    @staticmethod
    def project(U, X, r, S, a):
        """Tangential part of ``X`` projected ``a``-orthogonally off the dilations.

        One pass: with ``r_i = U_i . X_i`` the tangential part is ``X - r U``, its
        dilation coefficients solve ``S lam = sum_i a_i (X_i - r_i U_i)`` and the
        result is ``X - lam - (r - U lam) U``.

        Parameters
        ----------
        U, X : (n, 3) float64 arrays
        r : (n,) float64 array
            ``rowdot(U, X)``.
        S : (3, 3) float64 array
            :meth:`gram` of ``U`` and ``a``.
        a : (n,) float64 array
            Weights (vertex areas, 0 on vertices that may not move).  When they
            leave ``S`` singular (no vertex free), ``lam`` is its least-squares solution.
        """
        rhs = a @ X - (a * r) @ U
        try:
            lam = np.linalg.solve(S, rhs)
        except np.linalg.LinAlgError:
            # S is singular when the fold barrier froze every vertex (a 1e-11 sliver
            # mesh whose round 0 runs under the barrier): the least-squares solution,
            # which is 0 when no vertex is free.
            lam = np.linalg.lstsq(S, rhs, rcond=None)[0]
        X = X - lam
        X -= (r - U @ lam)[:, None] * U
        return X

    def needs_recentering(self, U, gnorm):
        """Whether the centroid of ``U`` left the ball of radius ``tol``.

        The radius is ``min(tol, LATE_TOL)`` once the RMS gradient ``gnorm`` is
        below :data:`LATE_GNORM`.
        """
        tol = self.tol if gnorm > LATE_GNORM else min(self.tol, LATE_TOL)
        return self.centroid_norm(U) > tol

    def orbit_fraction(self, U, G):
        """Share of ``|G|_M^2`` along the Möbius directions the projection leaves free.

        Off the centered maps (centroid ``m = sum_i A_i U_i != 0``) the
        rotations ``R_k(U_i) = e_k x U_i`` are not M-orthogonal to the
        dilations, and ``W_k = R_k - sum_l (S^{-1} C)_{lk} Z_l`` (rotation minus
        its dilation part; ``C = <Z, R>_M = -[m]_x``) is a Möbius direction
        that the projection allows but along which the energy is nearly flat.
        The component of ``G`` along the ``W_k`` is proportional to ``|m|``;
        Algorithm 1 cannot reduce it efficiently.  With
        ``<G, W_k>_M = <G, R_k>_M = e_k . sum_i A_i U_i x G_i`` and Gram matrix
        ``S - C^T S^{-1} C``.
        """
        aU = U * self.area[:, None]
        S = np.eye(3) * self.area.sum() - aU.T @ U
        C = -_cross_matrix(aU.sum(axis=0))
        T = aU.T @ G  # sum_i A_i U_i G_i^T
        b = np.array([T[1, 2] - T[2, 1], T[2, 0] - T[0, 2], T[0, 1] - T[1, 0]])
        gram = S - C.T @ np.linalg.solve(S, C)
        g2 = float(self.area @ rowdot(G, G))
        return float(b @ np.linalg.solve(gram, b)) / g2 if g2 > 0 else 0.0

    def stalled_on_orbit(self, U, X, slow):
        """Count an iteration that stalled on the Möbius orbit; True after two in a row.

        An iteration stalls when it did not halve the gradient (``slow``) and the
        search direction ``X`` lies mostly (more than half of ``|X|_M^2``) along
        the Möbius directions of :meth:`orbit_fraction`.  Near convergence the
        preconditioned direction amplifies the gradient's small component along
        them, and the iteration can crawl along the nearly flat Möbius orbit
        for hundreds of iterations.  The caller then re-centers the map
        (centroid 0), which removes that component, and the count restarts.
        """
        stalled = (slow and self.centroid_norm(U) > 1e-12
                   and self.orbit_fraction(U, X) > 0.5)
        self.stalls = self.stalls + 1 if stalled else 0
        if self.stalls >= 2:
            self.stalls = 0
            return True
        return False

    def reset_stalls(self):
        """Forget the stall count (after a re-centering for another reason)."""
        self.stalls = 0
