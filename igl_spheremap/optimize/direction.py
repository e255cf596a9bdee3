"""The search direction of Algorithm 1: the Riemannian gradient in the L2 or the H1 metric.

The paper's direction is the Riemannian gradient in the lumped L2 product of
Eq. 13 (:class:`L2Metric`): ``G = P(H)`` with ``H = M^{-1} dE/dU`` and ``P`` the
projection onto the tangent planes.  The default preconditions it with the
Sobolev (H1) metric ``K = -L + M`` (:class:`H1Metric`): ``X = P(K^{-1} M G)``.
An energy (:mod:`igl_spheremap.optimize.energy`) chooses its metric.

:class:`SearchDirection` puts the pieces together for the vertices that are
free to move (:class:`igl_spheremap.optimize.barrier.FreeVertices`) and, when the
energy is Möbius invariant, projects off the Möbius dilations
(:class:`igl_spheremap.optimize.gauge.MobiusGauge`).
"""

import numpy as np
import scipy.sparse as sp

from ..mesh.arrays import rowdot
from .preconditioner import h1_preconditioner, resolve_h1_solver


class L2Metric:
    """The lumped L2 product of paper Eq. 13: the direction is the Riemannian gradient."""

    name = "L2"
    newton_decrement = False

    def observe(self, ev):
        """Nothing to record (kept for the interface of a metric that depends on the map)."""

    def setup(self, free, k=0):
        """Nothing to set up (kept for the interface of :class:`H1Metric`)."""

    def due(self, k, constraints, refactor_every):
        """Never: nothing depends on the free set."""
        return False

    def apply(self, MG):
        """None: the direction is the projected gradient itself."""
        return None

    @staticmethod
    def sq_norm(D, MD, new, old):
        """``|D|_M^2 = <D, M D>`` of the step ``D`` between two evaluations."""
        return float(np.vdot(D, MD))


class H1Metric:
    """The Sobolev metric ``K = -L + M``: the direction is ``K^{-1} M G``.

    Parameters
    ----------
    L : (n, n) sparse matrix
        Negative semidefinite Laplacian (the stiffness of the energy).
    area : (n,) float64 array
        Lumped mass ``M = diag(area)`` (mesh scaled to area ``4 pi``).
    solver : {"auto", "direct", "amg", "cholmod", "superlu"}
        How ``K^{-1}`` is applied (:func:`igl_spheremap.optimize.preconditioner.h1_preconditioner`);
        ``"auto"`` is resolved for ``n`` vertices by
        :func:`igl_spheremap.optimize.preconditioner.resolve_h1_solver`.
    """

    name = "H1"
    newton_decrement = False

    def __init__(self, L, area, solver="auto"):
        self.L, self.area = L, area
        self.solver = resolve_h1_solver(solver, area.size)
        self.fact_free = None
        self.last_setup = 0
        self.solve = None

    def observe(self, ev):
        """Nothing to record: ``K`` does not depend on the map."""

    def setup(self, free, k=0):
        """Set the solver up for ``K`` restricted to the ``free`` vertices (iteration ``k``).

        Kept when it was set up for this free set already (a metric reused by
        the Algorithm 1 runs of a continuation with the same fixed vertices).
        """
        self.last_setup = k
        if self.fact_free is not None and np.array_equal(self.fact_free, free):
            return
        self.fact_free = free.copy()
        K = (sp.diags(self.area) - self.L).tocsr()
        if not free.all():
            K = K[free][:, free]
        self.solve = h1_preconditioner(K, self.solver)

    def set_stiffness(self, L):
        """Use the stiffness ``L`` (same pattern of use as the constructor's) from the next
        :meth:`setup` on, whatever the free set (an energy whose stiffness depends on the map)."""
        self.L, self.fact_free = L, None

    def due(self, k, constraints, refactor_every):
        """Whether to set the solver up again on the current free set at iteration ``k``.

        Once the fold barrier froze vertices, the solver is set up again on the
        new free set when freezing has settled (no freeze in the last 2
        iterations), at most every ``refactor_every`` iterations (a count, not
        a clock, so that runs are reproducible bit for bit); in between, newly
        frozen rows are only zeroed in the direction.
        """
        return (k - constraints.last_freeze >= 2 and k - self.last_setup >= refactor_every
                and not np.array_equal(self.fact_free, constraints.free))

    def apply(self, MG):
        """``K^{-1} M G`` on the vertices of the last set-up (0 elsewhere)."""
        if self.fact_free.all():
            return self.solve(MG)
        X = np.zeros_like(MG)
        X[self.fact_free] = self.solve(MG[self.fact_free])
        return X

    def sq_norm(self, D, MD, new, old):
        """``|D|_K^2 = <D, M D> - <D, L D>`` of the step ``D = new.U - old.U``.

        ``L D`` is ``new.LU - old.LU`` when the energy kept ``L U``, else a product.
        """
        LD = new.LU - old.LU if new.LU is not None and old.LU is not None else self.L @ D
        return float(np.vdot(D, MD)) - float(np.vdot(D, LD))


#: What Algorithm 1 uses of a metric object (:class:`L2Metric`, :class:`H1Metric` and the
#: conformal descent's :class:`igl_spheremap.optimize.conformal_distortion.NewtonMetric`).
METRIC_INTERFACE = ("name", "newton_decrement", "observe", "setup", "due", "apply", "sq_norm")


def make_metric(name, L, area, h1_solver="auto"):
    """:class:`L2Metric` or :class:`H1Metric` by name ("L2" or "H1").

    Parameters
    ----------
    name : {"L2", "H1"}
    L : (n, n) sparse matrix
        Negative semidefinite Laplacian, the stiffness of the H1 metric (``"L2"``
        ignores it), e.g. ``igl.cotmatrix(V, F)``.
    area : (n,) float64 array
        Vertex areas of the mesh scaled to total area ``4 pi``.
    h1_solver : {"auto", "direct", "amg", "cholmod", "superlu"}

    Returns
    -------
    L2Metric or H1Metric

    Raises
    ------
    ValueError
        If ``name`` or ``h1_solver`` is unknown.
    """
    if name == "L2":
        return L2Metric()
    if name == "H1":
        return H1Metric(L, area, h1_solver)
    raise ValueError(f"unknown metric {name!r}; expected 'L2' or 'H1'")


class SearchDirection:
    """Projected gradient and search direction on the free vertices.

    Parameters
    ----------
    area : (n,) float64 array
        Vertex areas (mesh scaled to area ``4 pi``).
    metric : L2Metric or H1Metric
    gauge : MobiusGauge or None
        Projects the directions off the Möbius dilations (weights: the areas of
        the free vertices), so the centroid does not move to first order.
    free : (n,) bool array
        Vertices that may move; the metric is set up for them.
    """

    def __init__(self, area, metric, gauge, free):
        self.area, self.metric, self.gauge = area, metric, gauge
        self.set_free(free)
        metric.setup(free)

    def set_free(self, free):
        """Restrict the directions to ``free`` (the metric keeps its last set-up)."""
        self.free = free
        self.all_free = bool(free.all())
        self.free_area = self.area if self.all_free else self.area * free

    def project(self, U, X, S):
        """Tangential part of ``X`` on the free vertices, off the dilations with a gauge."""
        r = rowdot(U, X)
        if self.gauge is not None:
            X = self.gauge.project(U, X, r, S, self.free_area)
        else:
            X = X - r[:, None] * U
        # Second pass on the rounding residue: near a harmonic map H is almost normal, so
        # X - r U keeps a normal part of ~1e-16 |H| that the retraction (which takes X as
        # tangential) would turn into |U_i| != 1, growing with tau over many iterations.
        X -= rowdot(U, X)[:, None] * U
        if not self.all_free:
            X[~self.free] = 0.0
        return X

    def __call__(self, U, H):
        """``(G, X, M G)``: projected gradient, search direction and ``M G``.

        Parameters
        ----------
        U : (n, 3) float64 array
            The map.
        H : (n, 3) float64 array
            The L2 gradient ``M^{-1} dE/dU`` of the energy at ``U``.
        """
        S = self.gauge.gram(U, self.free_area) if self.gauge is not None else None
        G = self.project(U, H, S)
        MG = G * self.area[:, None]
        X = self.metric.apply(MG)
        if X is None:
            return G, G, MG
        return G, self.project(U, X, S), MG
