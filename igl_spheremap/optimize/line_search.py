"""The Zhang-Hager nonmonotone curvilinear search of Algorithm 1 (lines 3-5).

A trial step ``tau`` is accepted when the energy of the Cayley point
``Y(tau)`` satisfies ``E(Y(tau)) <= C_k - rho tau <G, X>_M`` (line 3; the slope of
``E`` along the curve at 0 is ``-<G, X>_M``), else ``tau`` is multiplied by
``delta``.  ``C_k`` is a weighted average of the energies of all iterates so
far (line 5: ``Q_{k+1} = xi Q_k + 1``, ``C_{k+1} = (xi Q_k C_k + E_{k+1}) / Q_{k+1}``,
``C_0 = E_0``, ``Q_0 = 1``), so single steps may go up while the trend goes down.
Zhang, Hager, "A nonmonotone line search technique and its application to
unconstrained optimization", SIAM J Optim 2004 (the paper's ref. [25]).
"""


class ZhangHager:
    """The reference value ``C_k`` of the nonmonotone search and its acceptance test.

    Parameters
    ----------
    rho : float
        Sufficient-decrease constant in (0, 1) (paper: 1e-4).
    delta : float
        Backtracking factor in (0, 1) (paper: 0.1).
    xi : float
        Averaging weight in [0, 1] (paper: 0.85; 0 gives the monotone Armijo search).
    energy : float
        ``E_0``.

    Attributes
    ----------
    C, Q : float
        The current ``C_k`` and ``Q_k``.
    """

    def __init__(self, rho, delta, xi, energy):
        self.rho, self.delta, self.xi = rho, delta, xi
        self.reset(energy)

    def accepts(self, energy, tau, slope):
        """Line 3: whether ``energy <= C_k - rho * tau * slope`` (``slope = <G, X>_M``)."""
        return energy <= self.C - self.rho * tau * slope

    def update(self, energy):
        """Line 5 after an accepted step with energy ``E_{k+1}``."""
        Qn = self.xi * self.Q + 1.0
        self.C = (self.xi * self.Q * self.C + energy) / Qn
        self.Q = Qn

    def reset(self, energy):
        """Start the average again at ``energy`` (``C = energy``, ``Q = 1``)."""
        self.C, self.Q = energy, 1.0


def curvilinear_search(it, tau, search, space, energy, constraints, freeze, max_backtracks,
                       max_fold_shrinks):
    """Backtracking along the Cayley curve from iterate ``it`` (Algorithm 1, lines 3-4).

    A trial point ``Y = space.retract(it.U, it.X, tau)`` that the fold barrier
    rejects (:meth:`igl_spheremap.optimize.barrier.FreeVertices.check`) is shortened
    by ``delta`` up to ``max_fold_shrinks`` times; after that ``freeze`` is
    called, which freezes the vertices of the faces the step would fold and
    returns a new iterate (same point, new direction) tried with the same
    ``tau``.  Each freeze adds vertices, so this ends (and ``it`` is the same point
    with a new direction).  With a feasible barrier (``constraints.feasible``) the
    first trial is capped by ``constraints.max_step`` (the per-face maximal step along
    the curve) and a rejected trial is only ever shortened, never frozen; a trial
    whose energy is infinite (a barrier energy on a folded face) fails the test and is
    shortened too.  A trial costs one energy evaluation; the gradient at the accepted
    point is the caller's.

    Parameters
    ----------
    it : Iterate
        Current point ``it.U`` with direction ``it.X`` and slope ``it.gx = <G, X>_M``.
    tau : float
        Initial trial step (:class:`igl_spheremap.optimize.step_size.BarzilaiBorwein`).
    search : ZhangHager
    space : igl_spheremap.optimize.manifold.SphereProduct
    energy : igl_spheremap.optimize.energy.Energy
    constraints : igl_spheremap.optimize.barrier.FreeVertices
    freeze : callable
        ``freeze(it, flipped) -> Iterate``.
    max_backtracks : int
        Shortenings allowed in all.
    max_fold_shrinks : int
        Shortenings because of the barrier before it freezes vertices instead
        (unlimited with a feasible barrier).

    Returns
    -------
    it : Iterate
        The iterate the step starts from (a new one after a freeze).
    step : tuple or None
        ``(evaluation, now_folded)`` of the accepted point (``now_folded``: its
        folded faces under the barrier, else None), or None when no step was
        accepted after ``max_backtracks`` shortenings.
    tau : float
        The accepted step, or the last one tried.
    """
    shrinks = backtracks = 0
    if constraints.feasible:
        tau = constraints.max_step(it.U, it.X, tau)
    while backtracks < max_backtracks:
        Y = space.retract(it.U, it.X, tau)
        now_folded, flipped = constraints.check(Y)
        if flipped is not None:
            if constraints.feasible or shrinks < max_fold_shrinks:
                shrinks += 1
                backtracks += 1
                tau *= search.delta
            else:
                it = freeze(it, flipped)
            continue
        ev = energy.evaluate(Y)
        if search.accepts(ev.value, tau, it.gx):
            return it, (ev, now_folded), tau
        backtracks += 1
        tau *= search.delta
    return it, None, tau
