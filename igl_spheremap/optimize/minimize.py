"""Algorithm 1 of the paper: minimizing an energy of a map on the product of spheres.

:func:`minimize` is the solver loop, line by line the paper's Algorithm 1 with
the pieces of this package:

* the energy and its gradient (:mod:`igl_spheremap.optimize.energy`) and the
  metric of the search direction (:mod:`igl_spheremap.optimize.direction`);
* the product of spheres and the Cayley retraction of Theorem 1
  (:mod:`igl_spheremap.optimize.manifold`);
* alternating Barzilai-Borwein steps of Eq. 12 (:mod:`igl_spheremap.optimize.step_size`);
* the Zhang-Hager nonmonotone curvilinear search (:mod:`igl_spheremap.optimize.line_search`);
* the free vertices: fixed ones and the fold barrier (:mod:`igl_spheremap.optimize.barrier`);
* the Möbius gauge, when the energy is Möbius invariant (:mod:`igl_spheremap.optimize.gauge`).

:func:`igl_spheremap.optimize.harmonic.harmonic_map` runs it for the harmonic energy of a mesh.
"""

import time
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import SphericalMapWarning, plural
from ..mesh.arrays import as_points, unit_rows
from ..mesh.validate import validate_mesh
from ..options import map_options
from ..sphere.folds import count_below_margin, count_folds, unit_roundoff
from .barrier import FreeVertices
from .direction import SearchDirection
from .energy import Evaluation
from .gauge import MobiusGauge
from .line_search import ZhangHager, curvilinear_search
from .manifold import SphereProduct
from .result import Algorithm1Result
from .step_size import BarzilaiBorwein


@dataclass
class Iterate:
    """A point of Algorithm 1 with its gradient and search direction.

    ``ev`` (:class:`igl_spheremap.optimize.energy.Evaluation`), ``G`` the projected L2
    gradient, ``X`` the search direction, ``MG = M G``, ``g2 = <G, G>_M``,
    ``gx = <G, X>_M`` (minus the slope along the Cayley curve), ``gnorm`` the RMS
    gradient ``sqrt(g2 / 4 pi)``.
    """

    ev: Evaluation
    G: np.ndarray
    X: np.ndarray
    MG: np.ndarray
    g2: float
    gx: float
    gnorm: float

    U = property(lambda self: self.ev.U)
    E = property(lambda self: self.ev.value)


#: A feasible descent (``feasible=True``), or a run the gauge re-centered after each of these
#: iterations, stops, not converged, when its energy fell by at most ``STALL_RTOL`` of itself
#: over the last ``STALL_WINDOW`` iterations (``docs/decisions.md``).
STALL_WINDOW = 50
STALL_RTOL = 1e-6


class _Run:
    """The state of one call of :func:`minimize` that the loop's steps share."""

    def __init__(self, energy, U, F, fixed, fold_barrier, options, gauge, feasible=False):
        self.energy, self.options = energy, options
        area = energy.area
        self.space = SphereProduct(area)
        self.inv_area = 1.0 / area
        self.total = float(area.sum())
        if gauge is None:
            gauge = options.mobius and energy.mobius_invariant and fixed is None
        self.gauge = MobiusGauge(area, options.mobius_tol) if gauge else None
        free = np.ones(area.size, dtype=bool) if fixed is None else ~np.asarray(fixed, bool)
        self.direction = SearchDirection(area, energy.metric, self.gauge, free)
        if self.gauge is not None and fixed is None:
            U = self._centered_start(U, F, fold_barrier, options.precision)
        self.constraints = FreeVertices(F, U, fixed, fold_barrier, options.precision, feasible)
        self.steps = BarzilaiBorwein(energy.metric, area, options.tau_max,
                                     cap_turns=energy.metric.name != "L2")
        self.mobius_steps = self.recentered_streak = 0
        self.start = U

    def _centered_start(self, U, F, fold_barrier, precision):
        """``U`` Möbius-centred, unless that brings faces to their margin under the fold barrier.

        Centring can flip a large flat image triangle; the barrier would then
        hold it folded, so a fold-free start stays uncentred rather than fold.  Nor is it
        centred where an energy that is itself a barrier would be infinite there.
        """
        Uc = self.gauge.center(U)
        if not fold_barrier:
            return Uc
        if not np.isfinite(self.energy.evaluate(Uc).value):
            return U
        u = unit_roundoff(precision)
        return Uc if count_below_margin(F, Uc, u) <= count_below_margin(F, U, u) else U

    def iterate(self, U, ev=None):
        """Evaluate the energy (unless ``ev`` is given), the gradient and the direction at ``U``."""
        ev = self.energy.evaluate(U) if ev is None else ev
        self.energy.metric.observe(ev)
        H = self.energy.euclidean_gradient(ev) * self.inv_area[:, None]
        G, X, MG = self.direction(U, H)
        g2, gx = float(np.vdot(MG, G)), float(np.vdot(MG, X))
        if self.energy.metric.newton_decrement and not gx > 0:  # no descent direction: L2
            X, gx = G, g2
        gnorm = np.sqrt((gx if self.energy.metric.newton_decrement else g2) / self.total)
        return Iterate(ev, G, X, MG, g2, gx, float(gnorm))

    def freeze(self, it, flipped, k):
        """Freeze the vertices of ``flipped`` (the fold barrier's last resort); new direction."""
        self.constraints.freeze(flipped, k)
        self.direction.set_free(self.constraints.free)
        it = self.iterate(it.U, it.ev)
        if not it.gx > 0:  # the masked H1 direction is no descent direction: use L2
            it.X, it.gx = it.G, it.g2
        return it

    def may_recenter(self):
        """Re-centering is off with fixed vertices, and under the fold barrier
        unless it keeps a rounding margin (then :meth:`centered` checks the map)."""
        return (self.gauge is not None and not self.constraints.fixed.any()
                and (not self.constraints.fold_barrier or self.constraints.margin))

    def recentered(self, Y, it_gnorm):
        """``Y`` Möbius-centered when that is due and allowed, else None."""
        if not (self.may_recenter() and self.gauge.needs_recentering(Y, it_gnorm)):
            return None
        return self.centered(Y)

    def centered(self, Y):
        """``Y`` Möbius-centered, or None when the centered map breaks the margin barrier."""
        Yc = self.gauge.center(Y)
        if self.constraints.fold_barrier:
            now, flipped = self.constraints.check(Yc)
            if flipped is not None:
                return None
            self.constraints.accept(now)
        return Yc

    def stall_message(self, k, e_hist):
        """Why the run stops at iteration ``k``, not converged, or None.

        It stalls when its energy fell by at most :data:`STALL_RTOL` of itself over the last
        :data:`STALL_WINDOW` iterations and either it is a feasible descent or the gauge
        re-centered the map after each of those iterations: then the re-centering undoes every
        step, as on a map collapsing toward a point, which the gauge holds off step after step
        until ``max_iter``.  A harmonic run that converges changes its energy by less than
        that late on too, but is seldom re-centered.
        """
        if k < STALL_WINDOW or e_hist[-STALL_WINDOW] - e_hist[-1] > STALL_RTOL * abs(e_hist[-1]):
            return None
        drop = f"energy down by at most {STALL_RTOL:g} of itself in {STALL_WINDOW} iterations"
        if self.constraints.feasible:
            return f"stalled: {drop}"
        if self.recentered_streak >= STALL_WINDOW:
            return f"stalled on the Möbius orbit: re-centered after each step, {drop}"
        return None

    def orbit_stall(self, it, prev, recentered):
        """Whether the iteration stalled on the Möbius orbit (then the caller re-centers)."""
        if not self.may_recenter():
            return False
        if recentered:
            self.gauge.reset_stalls()
            return False
        return self.gauge.stalled_on_orbit(it.U, it.X, it.g2 > 0.25 * prev.g2)


def minimize(energy, U0, F, options=None, *, fixed=None, fold_barrier=False, feasible=False,
             gauge=None, callback=None):
    """Paper Algorithm 1: minimize ``energy`` over maps ``U`` with ``|U_i| = 1``.

    From ``U0`` (Möbius-centered first when the gauge applies), each iteration
    takes the alternating Barzilai-Borwein step of Eq. 12 (clipped, and capped
    to 90-degree turns with the H1 metric), shortens it by ``delta`` until the
    Cayley point of Theorem 1 passes the Zhang-Hager test (line 3), and updates
    the reference value (line 5).  It stops when the RMS Riemannian gradient
    ``sqrt(sum_i A_i |G_i|^2 / 4 pi)`` over the free vertices is at most ``gtol``
    (with a metric whose ``newton_decrement`` is set, the Newton decrement
    ``sqrt(<G, X>_M / 4 pi)`` instead: scale invariant, like such an energy).

    The Möbius gauge (:mod:`igl_spheremap.optimize.gauge`) applies when ``options.mobius``
    is on, the energy is Möbius invariant and no vertex is fixed: directions are
    projected off the dilations and the map is re-centered when its centroid
    leaves a ball or the iteration stalls on the Möbius orbit, except under the
    fold barrier, which a re-centering could break (with a rounding margin the
    map is re-centered when the centered map keeps the barrier).  A run the gauge
    re-centered after each of the last :data:`STALL_WINDOW` iterations, while its
    energy fell by at most :data:`STALL_RTOL` of itself, stops, not converged: the
    re-centering undoes its steps.  With
    ``fold_barrier`` no step folds a face that is not folded in the (centered)
    ``U0``, and with ``options.precision="float32"`` no face goes below its
    rounding margin once above it (:mod:`igl_spheremap.optimize.barrier`).  The
    barrier freezes the vertices of faces that keep blocking the step, unless
    ``feasible``: then the first trial of every step is capped by the per-face
    maximal step (:meth:`igl_spheremap.optimize.barrier.FreeVertices.max_step`), no
    vertex is ever frozen, and a run whose energy stalls (:data:`STALL_RTOL` over
    :data:`STALL_WINDOW` iterations) stops, not converged.

    Parameters
    ----------
    energy : igl_spheremap.optimize.energy.Energy
        With ``area`` (n,) the vertex areas of the mesh scaled to ``4 pi``.
    U0 : (n, 3) float64 array
        Initial map (rows are normalized).
    F : (m, 3) int64 array
        Faces, outward oriented (fold counts, fold barrier).
    options : MapOptions or dict, optional
        Uses ``gtol``, ``max_iter``, ``mobius``, ``mobius_tol``, ``rho``, ``delta``,
        ``xi``, ``tau_max``, ``max_backtracks``, ``max_fold_shrinks``, ``refactor_every``,
        ``precision`` (the rounding margin the fold barrier keeps).
    fixed : (n,) bool array, optional
        Vertices that never move (a Dirichlet boundary).
    fold_barrier : bool
        The fold barrier, keeping the rounding margin of ``options.precision``
        (none for ``"float64"``: the plain fold test).
    feasible : bool
        With ``fold_barrier``: cap each step before any face breaks the barrier
        instead of freezing vertices (for an energy that is itself a barrier, such as
        :class:`igl_spheremap.optimize.conformal_distortion.ConformalDistortionEnergy`).
    gauge : bool, optional
        Force the Möbius gauge on or off.  With fixed vertices it only projects
        the directions off the dilations of the free vertices (the start is not
        centered and the map never re-centered: that would move the fixed
        vertices).  Default: as described above.
    callback : callable, optional
        ``callback(k, U, energy, grad_norm)`` after each accepted iteration.

    Returns
    -------
    Algorithm1Result
    """
    opts = map_options(options)
    t0 = time.perf_counter()
    run = _Run(energy, unit_rows(U0), F, fixed, fold_barrier, opts, gauge, feasible)
    it = run.iterate(run.start)
    search = ZhangHager(opts.rho, opts.delta, opts.xi, it.E)
    e_hist, g_hist = [it.E], [it.gnorm]
    converged, message, k, prev = False, f"reached max_iter={opts.max_iter}", 0, None
    while True:
        if not run.constraints.free.any():  # a zero gradient, but no minimizer: say so
            message = f"the fold barrier froze every vertex by iteration {k}"
            break
        if it.gnorm <= opts.gtol:
            converged, message = True, f"RMS Riemannian gradient {it.gnorm:.3g} <= gtol={opts.gtol:g}"
            break
        if k >= opts.max_iter:
            break
        stall = run.stall_message(k, e_hist)
        if stall is not None:
            message = stall
            break
        if energy.metric.due(k, run.constraints, opts.refactor_every):
            energy.metric.setup(run.constraints.free, k)
            it, prev = run.iterate(it.U, it.ev), None
        tau = run.steps.initial(k, it, prev)
        it, step, tau = curvilinear_search(
            it, tau, search, run.space, energy, run.constraints,
            lambda it, flipped: run.freeze(it, flipped, k), opts.max_backtracks,
            opts.max_fold_shrinks)
        run.steps.tau = tau
        if step is None:
            message = (f"line search failed after {plural(opts.max_backtracks, 'backtrack')} "
                       f"(tau={tau:.3g})")
            break
        k += 1
        ev, now_folded = step
        run.constraints.accept(now_folded)
        Yc = run.recentered(ev.U, it.gnorm)
        recentered = Yc is not None
        prev, it = it, run.iterate(Yc) if recentered else run.iterate(ev.U, ev)
        if run.orbit_stall(it, prev, recentered):
            Yc = run.centered(it.U)
            if Yc is not None:
                it, recentered = run.iterate(Yc), True
        run.recentered_streak = run.recentered_streak + 1 if recentered else 0
        if recentered:
            run.mobius_steps += 1
            search.reset(it.E)
            prev = None
        else:
            search.update(it.E)
        e_hist.append(it.E)
        g_hist.append(it.gnorm)
        if callback is not None:
            callback(k, it.U, it.E, it.gnorm)
    return Algorithm1Result(
        U=it.U, converged=converged, message=message, nit=k, energy=it.E, grad_norm=it.gnorm,
        energy_history=e_hist, grad_norm_history=g_hist, folds=count_folds(F, it.U),
        mobius_steps=run.mobius_steps, seconds=time.perf_counter() - t0,
        frozen=run.constraints.frozen_count)


def minimize_map(make_energy, V, F, U0, options, *, fold_barrier=False, callback=None,
                 caller="minimize_map"):
    """Algorithm 1 on a mesh ``(V, F)`` from ``U0``, both in the input's vertex order.

    The body the public wrappers share (:func:`igl_spheremap.harmonic_map`,
    :func:`igl_spheremap.p_harmonic_map`): validate the mesh, minimize
    ``make_energy(mesh)`` with :func:`minimize`, return the map in the input's order,
    and warn unless the result is a success (fold-free and converged).

    Parameters
    ----------
    make_energy : callable
        ``make_energy(mesh) -> Energy`` for the :class:`igl_spheremap.ValidatedMesh`.
    V, F : array_like
        The mesh (validated by :func:`igl_spheremap.validate_mesh`).
    U0 : (n, 3) array_like of float
        Initial map, indexed like ``V``.
    options : MapOptions
    fold_barrier : bool or None
        None: on when ``U0`` is fold-free.
    callback : callable, optional
    caller : str
        Name used in the warning.

    Returns
    -------
    Algorithm1Result
        ``U`` indexed like ``V``; where it has folded faces, ``message`` begins with
        their count, and where validation flipped faces it ends saying so
        (:attr:`igl_spheremap.ValidatedMesh.reorientation`).
    """
    mesh = validate_mesh(V, F)
    U0 = mesh.from_input(as_points(U0, "U0", rows=mesh.n_input))
    zero = int(np.count_nonzero(~np.any(U0, axis=1)))
    if zero:  # a direction is needed to put a vertex on the sphere
        raise ValueError(f"U0 has {plural(zero, 'zero row')}: a start map's rows are directions")
    if fold_barrier is None:
        fold_barrier = count_folds(mesh.F, U0) == 0
    with options.blas_limit():
        result = minimize(make_energy(mesh), U0, mesh.F, options, fold_barrier=fold_barrier,
                          callback=callback)
    result.U = mesh.to_input(result.U)
    if result.folds:  # the stopping rule alone reads like a success
        result.message = f"{plural(result.folds, 'folded face')} in the map; {result.message}"
    if mesh.reorientation:  # the folds are counted on the re-oriented faces
        result.message += (f"; {mesh.reorientation}, use validate_mesh(V, F).F_input with this "
                           "map")
    if not result.success:
        warnings.warn(f"{caller}: {result.message}", SphericalMapWarning, stacklevel=3)
    return result
