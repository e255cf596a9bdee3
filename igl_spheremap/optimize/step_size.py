"""Initial step size of each Algorithm 1 iteration: alternating Barzilai-Borwein steps (Eq. 12).

With the step ``D = U_k - U_{k-1}`` and the change ``W`` of the gradient, paper
Eq. 12 gives ``tau_1 = <D, D> / |<D, W>|`` and ``tau_2 = |<D, W>| / <W, W>``;
Algorithm 1 alternates them (odd iterations ``tau_1``, even ``tau_2``).  In a
metric ``K`` (:mod:`igl_spheremap.optimize.direction`) the products become
``<D, K D>``, ``<D, W_g>_M`` and ``<W_x, W_g>_M`` with ``W_g`` the change of the
projected gradient and ``W_x`` the change of the search direction (for the L2
metric ``W_x = W_g`` and these are the paper's formulas).  The step is clipped to
``[TAU_MIN, tau_max]``; with the H1 metric it is also capped so that no vertex
turns by more than 90 degrees (:func:`turn_cap`).  At the first iteration, and
after a re-centering or a new set-up of the metric, the previous iteration's
final step is kept (1 at the start, the paper's unit initial step).
"""

import numpy as np

from ..mesh.arrays import rowdot

#: Lower clip of the Barzilai-Borwein step.
TAU_MIN = 1e-20

#: Largest ``tau |X_i|`` of one step: ``2 tan(pi / 4)``, a 90 degree turn.
MAX_TURN = 2.0


def bb_step(k, dkd, dw, wkw, tau):
    """Paper Eq. 12, alternating: ``dkd / dw`` for odd ``k``, ``dw / wkw`` for even ``k``.

    Parameters
    ----------
    k : int
        Iteration number.
    dkd : float
        ``<D, K D>``, the squared length of the last step in the metric.
    dw : float
        ``|<D, W_g>_M|``.
    wkw : float
        ``|<W_x, W_g>_M|``.
    tau : float
        The previous step, kept when ``dw`` or ``wkw`` is not positive.

    Returns
    -------
    float
    """
    if dw > 0 and wkw > 0:
        return dkd / dw if k % 2 else dw / wkw
    return tau


def turn_cap(tau, X):
    """``tau`` capped so that no vertex turns by more than 90 degrees.

    The Cayley step turns ``U_i`` by ``2 atan(tau |X_i| / 2)``.  Far from
    harmonic, a long Barzilai-Borwein step that the nonmonotone search accepts
    can otherwise turn the map inside out (then Algorithm 1 converges to the
    mirror image).
    """
    return min(tau, MAX_TURN / max(float(np.sqrt(rowdot(X, X).max())), 1e-300))


class BarzilaiBorwein:
    """Initial step sizes of Algorithm 1 (paper Eq. 12, alternating, clipped).

    Parameters
    ----------
    metric : L2Metric or H1Metric
        Gives ``<D, K D>`` (:meth:`~igl_spheremap.optimize.direction.H1Metric.sq_norm`).
    area : (n,) float64 array
        Lumped mass.
    tau_max : float
        Upper clip.
    cap_turns : bool
        Apply :func:`turn_cap`.
    """

    def __init__(self, metric, area, tau_max, cap_turns):
        self.metric, self.area = metric, area
        self.tau_max, self.cap_turns = tau_max, cap_turns
        self.tau = 1.0

    def initial(self, k, it, prev):
        """The first trial step of iteration ``k`` from iterate ``it`` (``prev``: the one
        before, or None after a restart)."""
        tau = self.tau
        if prev is not None:
            D = it.U - prev.U
            MD = D * self.area[:, None]
            dkd = self.metric.sq_norm(D, MD, it.ev, prev.ev)
            dw = abs(float(np.vdot(MD, it.G - prev.G)))
            wkw = abs(float(np.vdot(it.X - prev.X, it.MG - prev.MG)))
            tau = min(max(bb_step(k, dkd, dw, wkw, tau), TAU_MIN), self.tau_max)
        if self.cap_turns:
            tau = turn_cap(tau, it.X)
        return tau
