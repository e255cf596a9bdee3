"""Algorithm 1 of the paper: harmonic energy minimization on the product of spheres."""

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .cayley import cayley_step
from .metrics import count_folds, folded_faces
from .mobius import mobius_center
from .operators import laplacian, vertex_areas


@dataclass
class HarmonicMapResult:
    """Outcome of :func:`harmonic_map` (scipy.optimize style).

    Attributes
    ----------
    U : (n, 3) float64 array
        Final map, unit rows.
    converged : bool
        True when the stopping rule was met before ``max_iter``.
    message : str
        Why the iteration stopped.
    nit : int
        Accepted iterations.
    energy : float
        Final harmonic energy (of the Laplacian used), dimensionless.
    grad_norm : float
        Final RMS Riemannian gradient (see :func:`harmonic_map`).
    energy_history, grad_norm_history : list of float
        One value per iterate, starting with the initial map.
    folds : int
        Folded faces of ``U``.
    mobius_steps : int
        How many times the map was re-centered during the run.
    seconds : float
        Wall time.
    """

    U: np.ndarray
    converged: bool
    message: str
    nit: int
    energy: float
    grad_norm: float
    energy_history: list = field(default_factory=list)
    grad_norm_history: list = field(default_factory=list)
    folds: int = 0
    mobius_steps: int = 0
    seconds: float = 0.0
    frozen: int = 0

    @property
    def success(self):
        return self.converged


def _unit(U):
    return U / np.linalg.norm(U, axis=1, keepdims=True)


def _rowdot(X, Y):
    return np.einsum("ij,ij->i", X, Y)


class _Direction:
    """Search direction of Algorithm 1 on the vertices that are free to move.

    ``metric="L2"`` is the paper's: the Riemannian gradient ``P(H)``, ``H = -M^{-1} L U``.
    ``metric="H1"`` preconditions it with the Sobolev metric ``K = -L + M`` (one
    sparse factorization, reused while the free set does not change).

    With ``gauge=True`` both are projected M-orthogonally off the fields
    ``Z_k(U_i) = e_k - (e_k . U_i) U_i`` (infinitesimal Möbius dilations): then
    ``sum_i A_i X_i = 0`` and the area-weighted centroid does not move to first
    order, which keeps the map Möbius-normalized (the 3x3 matrix is the one of
    Baden-Crane-Kazhdan's centering Newton step).
    """

    def __init__(self, L, area, metric, gauge):
        if metric not in ("L2", "H1"):
            raise ValueError(f"unknown metric {metric!r}; expected 'L2' or 'H1'")
        self.L, self.area, self.metric, self.gauge = L, area, metric, gauge
        self.free = None
        self.set_free(np.ones(area.size, dtype=bool))

    def set_free(self, free):
        self.free = free
        self.all_free = bool(free.all())
        if self.metric == "H1":
            K = (-self.L + sp.diags(self.area)).tocsc()
            if not self.all_free:
                K = K[free][:, free]
            self.solve = spla.factorized(K.tocsc())

    def _project(self, U, X):
        X = X - _rowdot(U, X)[:, None] * U
        if not self.all_free:
            X[~self.free] = 0.0
        if self.gauge:
            a = self.area * self.free
            S = np.eye(3) * a.sum() - (U * a[:, None]).T @ U
            lam = np.linalg.solve(S, a @ X)
            X -= (lam[None, :] - (U @ lam)[:, None] * U) * self.free[:, None]
        return X

    def __call__(self, U, H):
        """Return ``(G, X)``: projected gradient and search direction."""
        G = self._project(U, H)
        if self.metric == "L2":
            return G, G
        rhs = G * self.area[:, None]
        if self.all_free:
            X = self.solve(rhs)
        else:
            X = np.zeros_like(G)
            X[self.free] = self.solve(rhs[self.free])
        return G, self._project(U, X)


def minimize_harmonic_energy(L, area, F, U0, *, gtol=1e-5, max_iter=20000, rho=1e-4,
                             delta=0.1, xi=0.85, tau_max=1e6, metric="L2", mobius=False,
                             mobius_tol=1e-2, keep_fold_free=False, max_backtracks=60,
                             max_fold_shrinks=2, callback=None):
    """Algorithm 1 on prepared operators (the engine behind :func:`harmonic_map`).

    Parameters
    ----------
    L : (n, n) sparse matrix
        Laplacian (negative semidefinite).
    area : (n,) float64 array
        Vertex areas of the mesh scaled to total area ``4 pi``.
    F : (m, 3) int array
        Faces (used for the fold test of ``keep_fold_free``).
    U0 : (n, 3) float64 array
        Initial map (rows are normalized).
    max_backtracks : int
        Line-search trials per iteration before giving up.
    max_fold_shrinks : int
        With ``keep_fold_free``: how many times a step that folds a face is
        shortened (by ``delta``) before the vertices of the faces it folds are
        frozen instead.
    Other parameters
        See :func:`harmonic_map`.

    Returns
    -------
    HarmonicMapResult
    """
    t0 = time.perf_counter()
    U = _unit(np.asarray(U0, dtype=np.float64))
    inv_area = 1.0 / area
    total = float(area.sum())
    mobius_steps = 0
    direction = _Direction(L, area, metric, mobius)
    if mobius:
        U, _ = mobius_center(U, area)

    def evaluate(U):
        LU = L @ U
        G, X = direction(U, -LU * inv_area[:, None])
        return -0.5 * float(np.sum(U * LU)), G, X

    def norms(G, X):
        return float(area @ _rowdot(G, G)), float(area @ _rowdot(G, X))

    E, G, X = evaluate(U)
    g2, gx = norms(G, X)
    C, Q = E, 1.0
    gnorm = np.sqrt(g2 / total)
    e_hist, g_hist = [E], [gnorm]
    fold_free = keep_fold_free and count_folds(F, U) == 0
    frozen = np.zeros(U.shape[0], dtype=bool)
    tau = 1.0
    U_prev = None
    converged, message, k = False, f"reached max_iter={max_iter}", 0
    while k < max_iter:
        if gnorm <= gtol:
            converged, message = True, f"RMS Riemannian gradient {gnorm:.3g} <= gtol={gtol:g}"
            break
        if U_prev is not None:
            D = U - U_prev
            Wg, Wx = G - G_prev, X - X_prev
            KD = D * area[:, None] if metric == "L2" else D * area[:, None] - L @ D
            dkd = float(np.sum(D * KD))
            dw = abs(float(area @ _rowdot(D, Wg)))
            wkw = abs(float(area @ _rowdot(Wx, Wg)))
            if dw > 0 and wkw > 0:
                tau = dkd / dw if k % 2 else dw / wkw
            tau = min(max(tau, 1e-20), tau_max)
        tau0, shrinks = tau, 0
        for _ in range(max_backtracks):
            Y = cayley_step(U, X, tau)
            if fold_free:
                flipped = folded_faces(F, Y)
                if flipped.any():
                    if shrinks < max_fold_shrinks:
                        shrinks += 1
                        tau *= delta
                        continue
                    # The step folds faces even when much shorter: freeze their
                    # vertices (a face whose three vertices do not move cannot
                    # fold) and retry from the original step size.
                    frozen[F[flipped].ravel()] = True
                    direction.set_free(~frozen)
                    E, G, X = evaluate(U)
                    g2, gx = norms(G, X)
                    tau, shrinks = tau0, 0
                    continue
            E_new, G_new, X_new = evaluate(Y)
            if E_new <= C - rho * tau * gx:
                break
            tau *= delta
        else:
            message = f"line search failed after {max_backtracks} backtracks (tau={tau:.3g})"
            break
        U_prev, G_prev, X_prev = U, G, X
        U, E, G, X = Y, E_new, G_new, X_new
        k += 1
        if mobius and np.linalg.norm(area @ U) / total > mobius_tol and not frozen.any():
            U, _ = mobius_center(U, area)
            mobius_steps += 1
            E, G, X = evaluate(U)
            C, Q = E, 1.0
            U_prev = None
        else:
            Qn = xi * Q + 1.0
            C = (xi * Q * C + E) / Qn
            Q = Qn
        g2, gx = norms(G, X)
        gnorm = np.sqrt(g2 / total)
        e_hist.append(E)
        g_hist.append(gnorm)
        if callback is not None:
            callback(k, U, E, gnorm)
    return HarmonicMapResult(
        U=U, converged=converged, message=message, nit=k, energy=E, grad_norm=gnorm,
        energy_history=e_hist, grad_norm_history=g_hist, folds=count_folds(F, U),
        mobius_steps=mobius_steps, seconds=time.perf_counter() - t0, frozen=int(frozen.sum()))


def harmonic_map(V, F, U0, *, laplacian_kind="intrinsic_delaunay", gtol=1e-5, max_iter=20000,
                 rho=1e-4, delta=0.1, xi=0.85, tau_max=1e6, mobius_tol=1e-3,
                 keep_fold_free=False, callback=None):
    """Paper Algorithm 1: minimize the discrete harmonic energy from an initial map.

    Minimizes ``E(U) = -1/2 tr(U^T L U)`` (paper Eq. 6 discretised by Eq. 13)
    subject to ``|U_i| = 1`` with the Cayley update of Theorem 1, alternating
    Barzilai-Borwein steps (Eq. 12) and the Zhang-Hager nonmonotone curvilinear
    search (Algorithm 1, lines 3-5).  Inner products are the lumped L2
    products ``sum_i A_i x_i . y_i`` of Eq. 13 on the mesh scaled to total area
    ``4 pi``, so the stopping rule means the same on every mesh: stop when the
    RMS Riemannian gradient ``sqrt(sum_i A_i |P_i H_i|^2 / 4 pi) <= gtol`` with
    ``H = -M^{-1} L U`` and ``P_i`` the projection onto the tangent plane at ``U_i``.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
        Closed genus-0 triangle mesh, outward oriented (not validated here).
    U0 : (n, 3) float64 array
        Initial map (e.g. :func:`gauss_map` or :func:`star_map`); rows are normalized.
    laplacian_kind : {"intrinsic_delaunay", "cotan"}
        See :func:`igl_spheremap.operators.laplacian`; the paper uses ``"cotan"``.
    gtol : float
        Stopping tolerance on the RMS Riemannian gradient (dimensionless).
    max_iter : int
        Iteration cap; reaching it leaves ``converged=False``.
    rho, delta, xi : float
        Curvilinear search parameters (paper defaults 1e-4, 0.1, 0.85).
    tau_max : float
        Upper clip of the Barzilai-Borwein step.
    mobius_tol : float or None
        Möbius normalization: whenever the area-weighted image centroid leaves
        a ball of this radius the map is re-centered by a Möbius transformation
        (:func:`igl_spheremap.mobius.mobius_center`), and the returned map is
        centered to 1e-12.  ``None`` disables it (the paper as published).
    keep_fold_free : bool
        Once the map has no folded face, refuse line-search steps that create one.
    callback : callable, optional
        ``callback(k, U, energy, grad_norm)`` after each accepted iteration.

    Returns
    -------
    HarmonicMapResult

    Raises
    ------
    ValueError
        If shapes of ``V``, ``F``, ``U0`` disagree.
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    U0 = np.asarray(U0, dtype=np.float64)
    if U0.shape != V.shape:
        raise ValueError(f"U0 has shape {U0.shape}, expected {V.shape}")
    L = laplacian(V, F, laplacian_kind)
    area = vertex_areas(V, F)
    area *= 4.0 * np.pi / area.sum()
    return minimize_harmonic_energy(
        L, area, F, U0, gtol=gtol, max_iter=max_iter, rho=rho, delta=delta, xi=xi,
        tau_max=tau_max, mobius_tol=mobius_tol, keep_fold_free=keep_fold_free,
        callback=callback)
