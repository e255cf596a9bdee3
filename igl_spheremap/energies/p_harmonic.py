"""The p-harmonic energy of paper Remark 1 (Eq. 8), discretized per face with libigl's gradient."""

import igl
import numpy as np

from ..search_direction import make_metric
from .base import Energy, Evaluation


class PHarmonicEnergy(Energy):
    """``E_p(U) = 1/p sum_f A_f |grad U|_f^p`` (paper Remark 1, Eq. 8, for maps into S^2).

    ``grad U`` is constant on each face (``igl.grad``, piecewise linear ``U``) and
    ``|grad U|_f^2 = sum_k |grad f_k|^2`` over the three coordinates; ``A_f`` is
    the face area of the mesh scaled to total area ``4 pi`` (for ``p != 2`` the
    energy depends on scale).  For ``p = 2`` this is the harmonic energy with the
    cotangent Laplacian, ``-1/2 tr(U^T L U)`` (``igl.cotmatrix = -G^T diag(A) G``).
    ``dE/dU = G^T diag(A_f |grad U|_f^{p-2}) G U``.  For ``p > 2`` the energy
    penalizes large stretch more than the harmonic energy does, trading angle
    distortion for more even areas; it is not Möbius invariant (no gauge) unless
    ``p = 2``.  The search direction's H1 metric uses the cotangent Laplacian of
    the mesh.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
        A validated mesh.
    p : float
        Exponent, >= 2 (for ``p < 2`` the energy is not differentiable where
        ``grad U`` vanishes).
    metric : {"H1", "L2"}
    h1_solver : str

    Raises
    ------
    ValueError
        If ``p < 2`` or not finite.
    """

    def __init__(self, V, F, p, metric="H1", h1_solver="auto"):
        p = float(p)
        if not (np.isfinite(p) and p >= 2.0):
            raise ValueError(f"p must be a finite number >= 2, got {p}")
        V = np.asarray(V, dtype=np.float64)
        A = igl.doublearea(V, F) / 2.0
        scale = np.sqrt(4.0 * np.pi / A.sum())
        self.G = igl.grad(V * scale, F).tocsr()
        self.face_area = A * scale ** 2
        self.p = p
        weights = np.tile(self.face_area, 3)
        L = -(self.G.T @ self.G.multiply(weights[:, None])).tocsr()
        area = np.bincount(F.ravel(), weights=np.repeat(self.face_area / 3.0, 3),
                           minlength=V.shape[0])
        super().__init__(area, make_metric(metric, L, area, h1_solver))
        self.mobius_invariant = p == 2.0

    def _squared_gradient(self, J):
        m = self.face_area.size
        return (J * J).sum(axis=1).reshape(3, m).sum(axis=0)

    def evaluate(self, U):
        J = self.G @ U
        s = self._squared_gradient(J)
        value = float(self.face_area @ s ** (0.5 * self.p)) / self.p
        return Evaluation(U=U, value=value, cache=(J, s))

    def euclidean_gradient(self, ev):
        J, s = ev.cache
        w = self.face_area * s ** (0.5 * self.p - 1.0)
        return self.G.T @ (J * np.tile(w, 3)[:, None])
