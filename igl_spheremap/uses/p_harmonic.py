"""p-harmonic maps onto the sphere (paper Remark 1, Eq. 8): the energy, discretized per face
with libigl's gradient, and Algorithm 1 for it."""

import igl
import numpy as np

from ..optimize.direction import make_metric
from ..optimize.energy import Energy, Evaluation
from ..optimize.minimize import minimize_map
from ..options import map_options


def p_harmonic_map(V, F, U0, p, options=None, *, fold_barrier=None, callback=None,
                   **option_values):
    """Minimize the p-harmonic energy ``1/p sum_f A_f |grad U|_f^p`` from an initial map.

    Paper Remark 1: the optimizer of Algorithm 1 minimizes Eq. 8 as well
    (:class:`PHarmonicEnergy`, per-face gradients from
    ``igl.grad``, mesh scaled to area ``4 pi``).  ``p = 2`` is the harmonic energy
    with the cotangent Laplacian; larger ``p`` weighs large stretch more: the
    map spreads area more evenly (less area distortion) at the cost of angle
    distortion (README, "p-harmonic maps and area correction", has the measured trade-off).  For
    ``p != 2`` the energy is not Möbius invariant, so no Möbius normalization
    is applied: the minimizer picks its own placement.

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
        A closed, connected, genus-0 triangle mesh.
    U0 : (n, 3) array_like of float
        Initial map, indexed like ``V`` (e.g. ``spherical_conformal_map(V, F).U``).
    p : float
        Exponent, >= 2.
    options : MapOptions or dict, optional
        Algorithm 1's options (``gtol``, ``max_iter``, ``metric``, ``h1_solver``, ...).
    fold_barrier : bool, optional
        The fold barrier (default: on when ``U0`` is fold-free).
    callback : callable, optional
        ``callback(k, U, energy, grad_norm)`` after each iteration.
    **option_values
        Fields of :class:`igl_spheremap.MapOptions`.

    Returns
    -------
    Algorithm1Result
        ``U`` indexed like ``V``; ``energy`` is the p-harmonic energy; ``success``
        needs a converged and fold-free map.

    Raises
    ------
    MeshError
        Invalid mesh.
    ValueError
        ``p < 2``, a bad ``U0`` or bad options.

    Warns
    -----
    SphericalMapWarning
        If the map has folded faces (e.g. from a folded ``U0``, where the fold
        barrier cannot apply) or Algorithm 1 did not converge.
    """
    opts = map_options(options, **option_values)
    return minimize_map(lambda mesh: PHarmonicEnergy(mesh.V, mesh.F, p, opts.metric,
                                                     opts.h1_solver),
                        V, F, U0, opts, fold_barrier=fold_barrier, callback=callback,
                        caller="p_harmonic_map")


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
