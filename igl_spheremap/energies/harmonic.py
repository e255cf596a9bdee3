"""The harmonic (Dirichlet) energy of paper Eq. 6, discretized as in Eq. 13."""

from ..operators import dirichlet_energy
from ..search_direction import make_metric
from .base import Energy, Evaluation


class HarmonicEnergy(Energy):
    """``E(U) = -1/2 tr(U^T L U)`` (paper Eqs. 6 and 13) with ``dE/dU = -L U``.

    For a conformal bijection onto the unit sphere ``E = 4 pi``; every conformal
    map of a genus-0 surface is a critical point, and the continuous energy is
    Möbius invariant (the discrete one is not: Algorithm 1 keeps the map
    normalized, :mod:`igl_spheremap.gauge`).

    Parameters
    ----------
    L : (n, n) sparse matrix
        Negative semidefinite Laplacian (:func:`igl_spheremap.operators.laplacian`;
        the paper's is the cotangent Laplacian).
    area : (n,) float64 array
        Vertex areas, mesh scaled to total area ``4 pi``.
    metric : {"H1", "L2"}
        ``"L2"``: the paper's Riemannian gradient; ``"H1"``: preconditioned by the
        Sobolev metric ``-L + M`` (README, "How the default differs", item 3).
    h1_solver : {"auto", "direct", "amg", "cholmod", "superlu"}
        How the H1 metric is inverted.

    Raises
    ------
    ValueError
        Unknown ``metric`` or ``h1_solver``.
    """

    mobius_invariant = True

    def __init__(self, L, area, metric="H1", h1_solver="auto"):
        super().__init__(area, make_metric(metric, L, area, h1_solver))
        self.L = L

    def evaluate(self, U):
        """One product ``L U``; the value and :meth:`euclidean_gradient` reuse it."""
        LU = self.L @ U
        return Evaluation(U=U, value=dirichlet_energy(self.L, U, LU), LU=LU)

    def euclidean_gradient(self, ev):
        """``-L U`` (n, 3)."""
        return -ev.LU
