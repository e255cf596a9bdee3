"""Algorithm 1 of the paper: harmonic energy minimization on the product of spheres."""

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .cayley import cayley_step
from .metrics import count_folds, folded_faces
from .mobius import mobius_center
from .operators import laplacian, vertex_areas
from .preconditioner import H1_SOLVERS, h1_preconditioner, one_blas_thread


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


#: ``h1_solver="auto"`` factorizes the H1 metric up to this many vertices and
#: uses the AMG V-cycle above.  Measured with the default pipeline (seconds,
#: direct / AMG, best of 3, one BLAS thread): maxplanck 9k 0.12 / 0.14, bimba
#: 25k 0.37 / 0.39, hcp_s1200_midthickness_left_32k 0.61 / 0.42, armadillo 43k
#: 0.77 / 0.83, horse 48k (fold barrier) 22 / 24; Algorithm 1 from the Gauss
#: map on a 100k remesh of maxplanck 2.0 / 1.2.  With CHOLMOD instead of
#: SuperLU (best of 3, default pipeline): bimba 0.34 / 0.45, hcp 0.54 / 0.47,
#: armadillo 0.74 / 0.93, the 100k remesh 2.8 / 2.1.  The factorization's time and
#: memory grow faster than ``n`` (300k: 9-30 s for one), the V-cycle's like
#: ``n`` (1M vertices: Algorithm 1 in 16 s, 1.4 GB peak); with the fold barrier
#: the exact direction also froze fewer vertices on the test meshes.
AUTO_DIRECT_MAX_SIZE = 50_000

#: Once the RMS gradient is below ``_LATE_GNORM`` the re-centering threshold
#: tightens to ``_LATE_MOBIUS_TOL``: the centroid left by the fast first
#: iterations (up to ``mobius_tol``) is then removed while the gradient is
#: still large compared with the jump a re-centering causes (~ the centroid
#: norm), instead of showing up as a gradient floor ~ the centroid norm near
#: ``gtol`` (see :func:`_stalled_on_orbit`).  Iterations over 8 test meshes:
#: 129 -> 128 with the factorized metric, 178 -> 153 with the AMG V-cycle.
_LATE_GNORM = 1.0
_LATE_MOBIUS_TOL = 1e-4

#: Largest ``tau |X_i|`` of one H1 step: ``2 tan(pi / 4)``, a 90 degree turn.
_MAX_TURN = 2.0


def _resolve_h1_solver(h1_solver, n):
    """``"auto"`` -> ``"direct"`` up to :data:`AUTO_DIRECT_MAX_SIZE` vertices, else ``"amg"``."""
    if h1_solver == "auto":
        return "direct" if n <= AUTO_DIRECT_MAX_SIZE else "amg"
    if h1_solver not in H1_SOLVERS:
        raise ValueError(f"unknown h1_solver {h1_solver!r}; expected 'auto' or one of "
                         f"{H1_SOLVERS}")
    return h1_solver


def _unit(U):
    return U / np.linalg.norm(U, axis=1, keepdims=True)


_ONES3 = np.ones(3)


def _rowdot(X, Y):
    """Row-wise dot products of two (n, 3) arrays (faster than einsum for n x 3)."""
    return (X * Y) @ _ONES3


def _cross_matrix(m):
    """``[m]_x`` with ``[m]_x v = m x v``."""
    return np.array([[0.0, -m[2], m[1]], [m[2], 0.0, -m[0]], [-m[1], m[0], 0.0]])


class _Direction:
    """Search direction of Algorithm 1 on the vertices that are free to move.

    ``metric="L2"`` is the paper's: the Riemannian gradient ``P(H)``, ``H = -M^{-1} L U``.
    ``metric="H1"`` preconditions it with the Sobolev metric ``K = -L + M``:
    ``X = P(K^{-1} M G)``, with ``K^{-1}`` applied by
    :func:`igl_spheremap.preconditioner.h1_preconditioner` (set up once and
    reused while the free set does not change).

    With ``gauge=True`` both are projected M-orthogonally off the fields
    ``Z_k(U_i) = e_k - (e_k . U_i) U_i`` (infinitesimal Möbius dilations): then
    ``sum_i A_i X_i = 0`` and the area-weighted centroid does not move to first
    order, which keeps the map Möbius-normalized (the 3x3 matrix is the one of
    Baden-Crane-Kazhdan's centering Newton step).
    """

    def __init__(self, L, area, metric, gauge, h1_solver="auto", fixed=None):
        if metric not in ("L2", "H1"):
            raise ValueError(f"unknown metric {metric!r}; expected 'L2' or 'H1'")
        self.L, self.area, self.metric, self.gauge = L, area, metric, gauge
        self.h1_solver = _resolve_h1_solver(h1_solver, area.size)
        self.free = None
        self.set_free(np.ones(area.size, dtype=bool) if fixed is None else ~fixed)

    def set_free(self, free, refactor=True):
        """Restrict the direction to the ``free`` vertices.

        The H1 solver is set up for ``K`` restricted to the free set it was
        built for; without ``refactor`` the newly frozen rows are only zeroed
        (cheap, slightly worse preconditioning) until :meth:`refactor`.
        """
        self.free = free
        self.all_free = bool(free.all())
        self.free_area = self.area if self.all_free else self.area * free
        if refactor:
            self.refactor()

    def refactor(self):
        self.fact_free = self.free.copy()
        if self.metric == "H1":
            K = (sp.diags(self.area) - self.L).tocsr()
            if not self.fact_free.all():
                K = K[self.fact_free][:, self.fact_free]
            self.solve = h1_preconditioner(K, self.h1_solver)

    def _gauge_matrix(self, U):
        """``S = sum_i a_i (I - U_i U_i^T)`` over the free vertices: the Gram
        matrix of the dilations (and of the rotations) in the M product."""
        a = self.free_area
        return np.eye(3) * a.sum() - (U * a[:, None]).T @ U

    def _project(self, U, X, S):
        """Tangential part of ``X`` on the free vertices, off the dilations if ``gauge``.

        One pass: with ``r_i = U_i . X_i`` the tangential part is ``X - r U``,
        its dilation coefficients solve ``S lam = sum_i a_i (X_i - r_i U_i)``
        and the result is ``X - lam - (r - U lam) U``.
        """
        r = _rowdot(U, X)
        if self.gauge:
            a = self.free_area
            lam = np.linalg.solve(S, a @ X - (a * r) @ U)
            X = X - lam
            X -= (r - U @ lam)[:, None] * U
        else:
            X = X - r[:, None] * U
        if not self.all_free:
            X[~self.free] = 0.0
        return X

    def __call__(self, U, H):
        """Return ``(G, X, M G)``: projected gradient, search direction and ``M G``."""
        S = self._gauge_matrix(U) if self.gauge else None
        G = self._project(U, H, S)
        MG = G * self.area[:, None]
        if self.metric == "L2":
            return G, G, MG
        if self.fact_free.all():
            X = self.solve(MG)
        else:
            X = np.zeros_like(G)
            X[self.fact_free] = self.solve(MG[self.fact_free])
        return G, self._project(U, X, S), MG

    def orbit_fraction(self, U, G):
        """Share of ``|G|_M^2`` along the Möbius directions the gauge leaves free.

        Off the centered maps (centroid ``m = sum_i A_i U_i != 0``) the
        rotations ``R_k(U_i) = e_k x U_i`` are not M-orthogonal to the
        dilations, and ``W_k = R_k - sum_l (S^{-1} C)_{lk} Z_l`` (rotation minus
        its dilation part; ``C = <Z, R>_M = -[m]_x``) is a Möbius direction
        that the gauge allows but along which the energy is nearly flat.  The
        component of ``G`` along the ``W_k`` is proportional to ``|m|``;
        Algorithm 1 cannot reduce it efficiently, so when it dominates ``G``
        the map is re-centered (which makes ``m = 0``).  With
        ``<G, W_k>_M = <G, R_k>_M = e_k . sum_i A_i U_i x G_i`` and Gram matrix
        ``S - C^T S^{-1} C``.
        """
        if not (self.gauge and self.all_free):
            return 0.0
        aU = U * self.area[:, None]
        S = np.eye(3) * self.area.sum() - aU.T @ U
        C = -_cross_matrix(aU.sum(axis=0))
        T = aU.T @ G  # sum_i A_i U_i G_i^T
        b = np.array([T[1, 2] - T[2, 1], T[2, 0] - T[0, 2], T[0, 1] - T[1, 0]])
        gram = S - C.T @ np.linalg.solve(S, C)
        g2 = float(self.area @ _rowdot(G, G))
        return float(b @ np.linalg.solve(gram, b)) / g2 if g2 > 0 else 0.0


def _stalled_on_orbit(direction, U, X, area, total, stalled):
    """Whether an iteration stalled on the Möbius orbit.

    True when the last step did not halve the gradient (``stalled``) and the
    search direction ``X`` lies mostly (more than half of ``|X|_M^2``) along
    the Möbius directions that the gauge lets through off-center (see
    :meth:`_Direction.orbit_fraction`).  Near convergence the preconditioned
    direction amplifies the gradient's small component along them, and the
    iteration can crawl along the nearly flat Möbius orbit (bimba with one
    AMG V-cycle and centroid 3e-3: an RMS gradient stuck at 1.3e-5 for
    hundreds of iterations).  After two such iterations in a row the map is
    Möbius-centered (centroid 0), which removes that component.
    """
    return (stalled and float(np.linalg.norm(area @ U)) / total > 1e-12
            and direction.orbit_fraction(U, X) > 0.5)


def minimize_harmonic_energy(L, area, F, U0, *, gtol=1e-5, max_iter=20000, rho=1e-4,
                             delta=0.1, xi=0.85, tau_max=1e6, metric="L2", mobius=False,
                             mobius_tol=1e-2, keep_fold_free=False, max_backtracks=60,
                             max_fold_shrinks=2, refactor_every=25, h1_solver="auto",
                             fixed=None, callback=None):
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
        With the H1 metric and frozen vertices: set the H1 solver up again on the
        free set at most every ``refactor_every`` iterations (in between, newly
        frozen rows are only zeroed in the direction).
    max_fold_shrinks : int
        With ``keep_fold_free``: how many times a step that folds a face is
        shortened (by ``delta``) before the vertices of the faces it folds are
        frozen instead.
    fixed : (n,) bool array, optional
        Vertices that never move (a Dirichlet boundary, as in
        :func:`igl_spheremap.local_repair.local_repair`); the stopping rule
        is over the others.  Use with ``mobius=False``.
    Other parameters
        See :func:`harmonic_map`.

    Returns
    -------
    HarmonicMapResult

    Raises
    ------
    ValueError
        If ``metric`` or ``h1_solver`` is unknown.
    """
    _resolve_h1_solver(h1_solver, area.size)  # fail before any work
    with one_blas_thread():  # the loop's BLAS calls are all small
        return _minimize(L, area, F, U0, gtol=gtol, max_iter=max_iter, rho=rho, delta=delta,
                         xi=xi, tau_max=tau_max, metric=metric, mobius=mobius,
                         mobius_tol=mobius_tol, keep_fold_free=keep_fold_free,
                         max_backtracks=max_backtracks, max_fold_shrinks=max_fold_shrinks,
                         refactor_every=refactor_every, h1_solver=h1_solver, fixed=fixed,
                         callback=callback)


def _minimize(L, area, F, U0, *, gtol, max_iter, rho, delta, xi, tau_max, metric, mobius,
              mobius_tol, keep_fold_free, max_backtracks, max_fold_shrinks, refactor_every,
              h1_solver, fixed, callback):
    t0 = time.perf_counter()
    U = _unit(np.asarray(U0, dtype=np.float64))
    inv_area = 1.0 / area
    total = float(area.sum())
    mobius_steps = 0
    direction = _Direction(L, area, metric, mobius, h1_solver, fixed)
    if mobius:
        U, _ = mobius_center(U, area)

    def energy(U):
        LU = L @ U
        return -0.5 * float(np.vdot(U, LU)), LU

    def evaluate(U, LU=None):
        """Energy, gradient G, search direction X (one H1 solve), M G and L U."""
        if LU is None:
            LU = L @ U
        G, X, MG = direction(U, -LU * inv_area[:, None])
        return -0.5 * float(np.vdot(U, LU)), G, X, MG, LU

    def norms(G, X, MG):
        """``|G|_M^2`` and ``<G, X>_M``."""
        return float(np.vdot(MG, G)), float(np.vdot(MG, X))

    E, G, X, MG, LU = evaluate(U)
    g2, gx = norms(G, X, MG)
    C, Q = E, 1.0
    gnorm = np.sqrt(g2 / total)
    e_hist, g_hist = [E], [gnorm]
    # Faces allowed to be folded: those folded at the start, until they unfold.
    allowed = folded_faces(F, U) if keep_fold_free else None
    frozen = np.zeros(U.shape[0], dtype=bool) if fixed is None else fixed.copy()
    last_freeze = last_refactor = 0
    tau = 1.0
    U_prev = G_prev = X_prev = MG_prev = LU_prev = None
    orbit_stalls = 0
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
            E, G, X, MG, LU = evaluate(U, LU)
            g2, gx = norms(G, X, MG)
            U_prev = None
        if U_prev is not None:
            D = U - U_prev
            MD = D * area[:, None]
            # <D, K D> with K D = M D - L D and L D = L U - L U_prev.
            dkd = float(np.vdot(D, MD))
            if metric == "H1":
                dkd -= float(np.vdot(D, LU - LU_prev))
            dw = abs(float(np.vdot(MD, G - G_prev)))  # <D, W_g>_M
            wkw = abs(float(np.vdot(X - X_prev, MG - MG_prev)))  # <W_x, W_g>_M
            if dw > 0 and wkw > 0:
                tau = dkd / dw if k % 2 else dw / wkw
            tau = min(max(tau, 1e-20), tau_max)
        if metric == "H1":
            # Trust region: no vertex turns by more than 90 degrees in one step
            # (the Cayley step turns U_i by 2 atan(tau |X_i| / 2)).  Far from
            # harmonic, a long Barzilai-Borwein step that the nonmonotone
            # search accepts can otherwise turn the map inside out (seen on
            # fsaverage5_pial_left: tau max|X_i| = 122, then convergence to
            # the mirror image); it also replaces the first step's tau = 1.
            tau = min(tau, _MAX_TURN / max(float(np.sqrt(_rowdot(X, X).max())), 1e-300))
        # Curvilinear search: a trial costs the energy only (one product
        # with L); the direction at the accepted point is computed once.
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
                    E, G, X, MG, LU = evaluate(U, LU)
                    g2, gx = norms(G, X, MG)
                    if not gx > 0:  # masked H1 direction is no descent: use L2
                        X, gx = G, g2
                    continue
            E_new, LU_new = energy(Y)
            if E_new <= C - rho * tau * gx:
                accepted = True
                break
            backtracks += 1
            tau *= delta
        if not accepted:
            message = f"line search failed after {max_backtracks} backtracks (tau={tau:.3g})"
            break
        k += 1
        if allowed is not None:
            allowed &= now_folded
        # Möbius re-centering (not under the fold barrier): when the centroid
        # left the ball of radius mobius_tol (the gauge keeps it only to first
        # order), before the direction is computed at the new point.
        tol_now = mobius_tol if gnorm > _LATE_GNORM else min(mobius_tol, _LATE_MOBIUS_TOL)
        recentered = (mobius and allowed is None
                      and float(np.linalg.norm(area @ Y)) / total > tol_now)
        if recentered:
            Y, _ = mobius_center(Y, area)
            LU_new = None
        U_prev, G_prev, X_prev, MG_prev, LU_prev = U, G, X, MG, LU
        U = Y
        E, G, X, MG, LU = evaluate(U, LU_new)
        g2_prev = g2
        g2, gx = norms(G, X, MG)
        orbit_stalls = (orbit_stalls + 1 if mobius and allowed is None and not recentered
                        and _stalled_on_orbit(direction, U, X, area, total,
                                              g2 > 0.25 * g2_prev) else 0)
        if orbit_stalls >= 2:
            orbit_stalls = 0
            U, _ = mobius_center(U, area)
            E, G, X, MG, LU = evaluate(U)
            g2, gx = norms(G, X, MG)
            recentered = True
        if recentered:
            mobius_steps += 1
            C, Q = E, 1.0
            U_prev = None
        else:
            Qn = xi * Q + 1.0
            C = (xi * Q * C + E) / Qn
            Q = Qn
        gnorm = np.sqrt(g2 / total)
        e_hist.append(E)
        g_hist.append(gnorm)
        if callback is not None:
            callback(k, U, E, gnorm)
    return HarmonicMapResult(
        U=U, converged=converged, message=message, nit=k, energy=E, grad_norm=gnorm,
        energy_history=e_hist, grad_norm_history=g_hist, folds=count_folds(F, U),
        mobius_steps=mobius_steps, seconds=time.perf_counter() - t0,
        frozen=int(frozen.sum()) - (0 if fixed is None else int(fixed.sum())))


def harmonic_map(V, F, U0, *, laplacian_kind="intrinsic_delaunay", metric="H1", mobius=True,
                 keep_fold_free=False, gtol=1e-5, max_iter=5000, rho=1e-4, delta=0.1, xi=0.85,
                 tau_max=1e6, mobius_tol=1e-2, h1_solver="auto", callback=None):
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
        gradient by ``(-L + M)^{-1} M``, applied as ``h1_solver`` says, and
        caps each step so that no vertex turns by more than 90 degrees.
    h1_solver : {"auto", "amg", "direct", "cholmod", "superlu"}
        How ``(-L + M)^{-1}`` is applied with ``metric="H1"``
        (:func:`igl_spheremap.preconditioner.h1_preconditioner`): ``"direct"``
        by a sparse factorization (exact; CHOLMOD's ``L D L^T`` when
        scikit-sparse is installed, SuperLU otherwise; ``"cholmod"`` and
        ``"superlu"`` name one), ``"amg"`` by one algebraic multigrid V-cycle
        (a fixed SPD approximation; O(n) time and memory, for large meshes),
        ``"auto"`` direct up to :data:`AUTO_DIRECT_MAX_SIZE` vertices and AMG
        above.  The fixed point and the stopping rule are the same for all.
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
        Re-centering threshold on the centroid norm while the RMS gradient is
        above 1 (then 1e-4; the map is also re-centered when the search
        direction stalls along the Möbius orbit).
    callback : callable, optional
        ``callback(k, U, energy, grad_norm)`` after each accepted iteration.

    Returns
    -------
    HarmonicMapResult

    Raises
    ------
    ValueError
        If ``U0`` does not have the shape of ``V``, or ``metric`` / ``laplacian_kind``
        / ``h1_solver`` is unknown.
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
        keep_fold_free=keep_fold_free, h1_solver=h1_solver, callback=callback)
