"""The landmark-matching harmonic energy of Lui, Wang, Chan, Thompson 2007 (the paper's ref. [19])."""

import numpy as np

from ..operators import dirichlet_energy
from ..search_direction import make_metric
from .base import Energy, Evaluation


class LandmarkEnergy(Energy):
    """``E(U) = -1/2 tr(U^T L U) + lambda/2 sum_i |U_{p_i} - q_i|^2``.

    The harmonic energy (Eqs. 6, 13) plus a quadratic penalty pulling each
    landmark vertex ``p_i`` toward its target ``q_i`` on the unit sphere (Lui,
    Wang, Chan, Thompson, "Landmark constrained genus zero surface conformal
    mapping and its application to brain mapping research", Applied Numerical
    Mathematics 2007; the paper names this use of its optimizer in Section 1).
    ``dE/dU = -L U + lambda S^T (S U - q)`` with ``S`` the selection of the landmark
    rows.  The landmarks fix the Möbius freedom, so no gauge applies
    (``mobius_invariant`` is False).

    Parameters
    ----------
    L : (n, n) sparse matrix
        Negative semidefinite Laplacian.
    area : (n,) float64 array
        Vertex areas, mesh scaled to total area ``4 pi``.
    landmarks : (k,) int array
        Distinct vertex indices.
    targets : (k, 3) float64 array
        Unit vectors.
    weight : float
        ``lambda`` (> 0, dimensionless: the harmonic energy of a conformal map is
        ``4 pi``, a landmark 1 radian off adds about ``lambda / 2``).
    metric : {"H1", "L2"}
    h1_solver : str
    """

    mobius_invariant = False

    def __init__(self, L, area, landmarks, targets, weight, metric="H1", h1_solver="auto"):
        super().__init__(area, make_metric(metric, L, area, h1_solver))
        self.L = L
        self.landmarks = np.asarray(landmarks, dtype=np.int64)
        self.targets = np.asarray(targets, dtype=np.float64)
        self.weight = float(weight)

    def evaluate(self, U):
        LU = self.L @ U
        D = U[self.landmarks] - self.targets
        value = dirichlet_energy(self.L, U, LU) + 0.5 * self.weight * float(np.vdot(D, D))
        return Evaluation(U=U, value=value, LU=LU, cache=D)

    def euclidean_gradient(self, ev):
        g = -ev.LU
        g[self.landmarks] += self.weight * ev.cache
        return g
