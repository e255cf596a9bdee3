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
    frozen : int
        Vertices frozen by the fold barrier (``keep_fold_free``); the gradient
        of the stopping rule is taken over the other vertices.
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

    def set_free(self, free, refactor=True):
        """Restrict the direction to the ``free`` vertices.

        The H1 factorization is of ``K`` restricted to the free set it was
        built for; without ``refactor`` the newly frozen rows are only zeroed
        (cheap, slightly worse preconditioning) until :meth:`refactor`.
        """
        self.free = free
        self.all_free = bool(free.all())
        if refactor:
            self.refactor()

    def refactor(self):
        self.fact_free = self.free.copy()
        if self.metric == "H1":
            K = (-self.L + sp.diags(self.area)).tocsc()
            if not self.all_free:
                K = K[self.fact_free][:, self.fact_free]
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
        if self.fact_free.all():
            X = self.solve(rhs)
        else:
            X = np.zeros_like(G)
            X[self.fact_free] = self.solve(rhs[self.fact_free])
        return G, self._project(U, X)


def minimize_harmonic_energy(L, area, F, U0, *, gtol=1e-5, max_iter=20000, rho=1e-4,
                             delta=0.1, xi=0.85, tau_max=1e6, metric="L2", mobius=False,
                             mobius_tol=1e-2, keep_fold_free=False, max_backtracks=60,
                             max_fold_shrinks=2, refactor_every=25, callback=None):
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
    refactor_every : int
        With the H1 metric and frozen vertices: refactor the metric on the free
        set at most every ``refactor_every`` iterations (in between, newly
        frozen rows are only zeroed in the direction).
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
    # Faces allowed to be folded: those folded at the start, until they unfold.
    allowed = folded_faces(F, U) if keep_fold_free else None
    frozen = np.zeros(U.shape[0], dtype=bool)
    last_freeze = last_refactor = 0
    tau = 1.0
    U_prev = G_prev = X_prev = None
    converged, message, k = False, f"reached max_iter={max_iter}", 0
    while k < max_iter:
        if gnorm <= gtol:
            converged, message = True, f"RMS Riemannian gradient {gnorm:.3g} <= gtol={gtol:g}"
            break
        if (metric == "H1" and k - last_freeze >= 2 and k - last_refactor >= refactor_every
                and not np.array_equal(direction.fact_free, ~frozen)):
            # Refactor the H1 metric on the current free set once freezing
            # settles, at most every refactor_every iterations (a count, not a
            # clock, so that runs are reproducible bit for bit).
            direction.refactor()
            last_refactor = k
            E, G, X = evaluate(U)
            g2, gx = norms(G, X)
            U_prev = None
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
        shrinks, backtracks, accepted = 0, 0, False
        while backtracks < max_backtracks:
            Y = cayley_step(U, X, tau)
            if allowed is not None:
                now_folded = folded_faces(F, Y)
                flipped = now_folded & ~allowed
                if flipped.any():
                    if shrinks < max_fold_shrinks:
                        shrinks += 1
                        backtracks += 1
                        tau *= delta
                        continue
                    # The step folds faces even when much shorter: freeze their
                    # vertices (a face whose three vertices do not move cannot
                    # fold) and retry this step size.  Each freeze adds
                    # vertices, so this ends.
                    frozen[F[flipped].ravel()] = True
                    direction.set_free(~frozen, refactor=False)
                    last_freeze = k
                    E, G, X = evaluate(U)
                    g2, gx = norms(G, X)
                    if not gx > 0:  # masked H1 direction is no descent: use L2
                        X, gx = G, g2
                    continue
            E_new, G_new, X_new = evaluate(Y)
            if E_new <= C - rho * tau * gx:
                accepted = True
                break
            backtracks += 1
            tau *= delta
        if not accepted:
            message = f"line search failed after {max_backtracks} backtracks (tau={tau:.3g})"
            break
        U_prev, G_prev, X_prev = U, G, X
        U, E, G, X = Y, E_new, G_new, X_new
        if allowed is not None:
            allowed &= now_folded
        k += 1
        if mobius and allowed is None and np.linalg.norm(area @ U) / total > mobius_tol:
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


def harmonic_map(V, F, U0, *, laplacian_kind="intrinsic_delaunay", metric="H1", mobius=True,
                 keep_fold_free=False, gtol=1e-5, max_iter=5000, rho=1e-4, delta=0.1, xi=0.85,
                 tau_max=1e6, mobius_tol=1e-2, callback=None):
    """Paper Algorithm 1: minimize the discrete harmonic energy from an initial map.

    Minimizes ``E(U) = -1/2 tr(U^T L U)`` (paper Eq. 6 discretised by Eq. 13)
    subject to ``|U_i| = 1`` with the closed-form Cayley update of Theorem 1
    (Eqs. 10-11), alternating Barzilai-Borwein steps (Eq. 12) and the
    Zhang-Hager nonmonotone curvilinear search (Algorithm 1, lines 3-5).
    Inner products are the lumped L2 products ``sum_i A_i x_i . y_i`` of Eq. 13
    on the mesh scaled to total area ``4 pi``, so one tolerance means the same
    on every mesh.  Stopping rule: the RMS Riemannian gradient
    ``sqrt(sum_i A_i |G_i|^2 / 4 pi) <= gtol``, where ``G_i`` is the tangential
    part of ``H_i = -(M^{-1} L U)_i`` (after the Möbius projection when
    ``mobius`` is on, and over the free vertices when the fold barrier froze
    some).  ``laplacian_kind="cotan", metric="L2", mobius=False`` is Algorithm 1
    exactly as published.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
        Closed genus-0 triangle mesh, outward oriented (not validated here).
    U0 : (n, 3) float64 array
        Initial map (e.g. :func:`gauss_map` or :func:`star_map`); rows are normalized.
    laplacian_kind : {"intrinsic_delaunay", "cotan"}
        See :func:`igl_spheremap.operators.laplacian`; the paper uses ``"cotan"``.
    metric : {"H1", "L2"}
        Gradient metric.  ``"L2"`` is the paper's; ``"H1"`` preconditions the
        gradient by ``(-L + M)^{-1} M`` (one sparse factorization per run).
    mobius : bool
        Möbius normalization: center the initial map by a Möbius transformation
        (:func:`igl_spheremap.mobius_center`), project every search direction
        off the infinitesimal Möbius dilations (the centroid stays fixed to
        first order), and re-center if the centroid still leaves a ball of
        radius ``mobius_tol``.  Off in the paper.
    keep_fold_free : bool
        Fold barrier: a step may not fold a face that is not folded (faces
        folded in ``U0`` may unfold and then stay unfolded).  A step that would
        is shortened twice, then the vertices of the faces it folds are frozen.
    gtol : float
        Stopping tolerance (dimensionless, see above).
    max_iter : int
        Iteration cap; reaching it leaves ``converged=False``.
    rho, delta, xi : float
        Curvilinear search parameters (paper defaults 1e-4, 0.1, 0.85).
    tau_max : float
        Upper clip of the Barzilai-Borwein step.
    mobius_tol : float
        Re-centering threshold on the centroid norm.
    callback : callable, optional
        ``callback(k, U, energy, grad_norm)`` after each accepted iteration.

    Returns
    -------
    HarmonicMapResult

    Raises
    ------
    ValueError
        If ``U0`` does not have the shape of ``V``, or ``metric`` / ``laplacian_kind``
        is unknown.
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
        tau_max=tau_max, metric=metric, mobius=mobius, mobius_tol=mobius_tol,
        keep_fold_free=keep_fold_free, callback=callback)
