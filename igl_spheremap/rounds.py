"""The rounds of Algorithm 2: each builds an initial map and runs Algorithm 1 from it.

Every strategy takes the problem and the previous round and returns a new
:class:`igl_spheremap.result.Round` (or None when it does not apply):

* :func:`gauss_round`: the Gauss map (Definition 1), then Algorithm 1; without
  the fold barrier when the Gauss map folds (it does on thin features), under
  it when it is fold-free (not in the paper; issue #15: an elongated convex
  surface, whose free run folds the crowded tips and whose star rounds then
  collapse the map);
* :func:`star_round`: the star map of the previous map's weighted Laplace-Beltrami
  eigenfunctions (Section 4.2), its few remaining folds untangled (not in the
  paper), then Algorithm 1, under the fold barrier when the start is fold-free;
* :func:`local_round`: the previous map's isolated folds untangled and
  Algorithm 1 rerun only around them (not in the paper,
  :func:`igl_spheremap.local_repair.local_repair`);
* :func:`central_round`: the central projection of a star-shaped surface under
  the barrier (a start of the float32 repairs, :mod:`igl_spheremap.representable`).

:func:`run_rounds` is Algorithm 2's loop over them.  A round that ends with
harmonic energy below :data:`COLLAPSE_ENERGY` times ``4 pi`` has collapsed the
map (a star map of a crowded map can be degenerate, and Algorithm 1 then goes
to a collapsed critical point); the loop stops and returns the best earlier round.

Maps are passed between rounds in the validated mesh's vertex order; the Round
objects hold them in the input's order.
"""

import time
from dataclasses import dataclass

import numpy as np

from .algorithm1 import minimize
from .eigen_projection import star_map_of
from .energies import HarmonicEnergy
from .gauss import vertex_normals
from .local_repair import local_repair
from .metrics import count_folds
from .mobius import mobius_center
from .operators import SPHERE_AREA
from .precision import below_margin
from .result import Round
from .untangle import untangle_folds


@dataclass
class MapProblem:
    """A validated mesh with the operators of Algorithm 1 and the run's options.

    Attributes
    ----------
    mesh : igl_spheremap.ValidatedMesh
    L : (n, n) sparse matrix
        The Laplacian of ``options.laplacian_kind``.
    area : (n,) float64 array
        Vertex areas scaled to total area ``4 pi``.
    options : MapOptions
    on_iteration : callable or None
        ``on_iteration(k, U, energy, grad_norm)`` (a progress bar).
    """

    mesh: object
    L: object
    area: np.ndarray
    options: object
    on_iteration: object = None

    @property
    def F(self):
        return self.mesh.F

    def minimize(self, U0, fold_barrier, index):
        """Algorithm 1 for the harmonic energy from ``U0`` (validated order)."""
        opts = self.options
        energy = HarmonicEnergy(self.L, self.area, opts.metric, opts.h1_solver)
        run = minimize(energy, U0, self.F, opts, fold_barrier=fold_barrier,
                       callback=self.on_iteration)
        return _finite(run, index)

    def round(self, index, kind, U_init, run, folds_init, t0, previous=None, **details):
        """A :class:`Round` in the input's vertex order."""
        to_input = self.mesh.to_input
        run.U = to_input(run.U)
        if details.get("Phi") is not None:
            details["Phi"] = to_input(details["Phi"])
        return Round(index=index, kind=kind, U_init=to_input(U_init), run=run,
                     folds_before=folds_init, seconds=time.perf_counter() - t0,
                     folds_previous=None if previous is None else previous.folds_after,
                     **details)


def _finite(run, index):
    if not np.all(np.isfinite(run.U)):
        raise RuntimeError(f"Algorithm 1 produced non-finite values in round {index}")
    return run


#: A round ending with harmonic energy below this share of ``4 pi`` collapsed the
#: map: a degree-one map has energy about ``4 pi`` or more; the 30:1 ellipsoid's
#: star round without the fold barrier ends at 0.14 with half its faces folded.
COLLAPSE_ENERGY = 0.5


def gauss_round(problem, barrier="float64"):
    """Round 0: Algorithm 1 from the Gauss map.

    Without the fold barrier when the Gauss map folds; with ``options.keep_fold_free``
    and a fold-free Gauss map, under the barrier of ``barrier`` (a precision:
    ``"float64"`` is the plain fold barrier, ``True`` the margin of ``options.precision``).
    """
    t0 = time.perf_counter()
    U_init = vertex_normals(problem.mesh.V, problem.F)
    folds_init = count_folds(problem.F, U_init)
    fold_free = problem.options.keep_fold_free and folds_init == 0
    run = problem.minimize(U_init, fold_barrier=barrier if fold_free else False, index=0)
    return problem.round(0, "gauss", U_init, run, folds_init, t0)


def central_projection(problem):
    """``(V - c) / |V - c|`` (``c`` the area centroid), or None when it folds (not star-shaped about ``c``)."""
    V, w = problem.mesh.V, problem.area
    P = V - (w @ V) / w.sum()
    norm = np.linalg.norm(P, axis=1, keepdims=True)
    if not np.all(norm > 0):
        return None
    U = P / norm
    return None if count_folds(problem.F, U) else U


def central_round(problem):
    """Round 0 from :func:`central_projection` under the margin barrier of ``options.precision``, or None.

    None when the projection folds.  Not in the paper: a start of the float32
    repairs for star-shaped surfaces (a capsule, whose Gauss map is degenerate
    on the cylinder; :mod:`igl_spheremap.representable`).
    """
    t0 = time.perf_counter()
    U_init = central_projection(problem)
    if U_init is None:
        return None
    run = problem.minimize(U_init, fold_barrier=True, index=0)
    return problem.round(0, "central", U_init, run, 0, t0)


def run_rounds(problem, first=gauss_round, callback=None):
    """Algorithm 2's loop: round 0 by ``first``, then rounds while folds remain.

    Round 1 is a local repair when ``options.local_repair`` and it applies,
    else (and from round 2 on) a star-map round; at most ``options.max_rounds``
    rounds after round 0.  A round with energy below :data:`COLLAPSE_ENERGY`
    times ``4 pi`` ends the loop, and the earlier round with the fewest folds
    is returned instead.

    Returns
    -------
    rounds : list of Round
        Every round that ran, in order.
    chosen : Round
        The round whose map is the result (the last one unless a round collapsed).
    note : str or None
        Why ``chosen`` is not the last round.
    """
    rounds = []
    rnd = first(problem)
    while True:
        rounds.append(rnd)
        if callback is not None:
            callback(rnd)
        k = len(rounds)
        if rnd.folds_after == 0:
            return rounds, rnd, None
        if k > 1 and rnd.energy < COLLAPSE_ENERGY * SPHERE_AREA:
            best = min(rounds[:-1], key=lambda r: r.folds_after)
            return rounds, best, _collapse_note(rnd, best)
        if k > problem.options.max_rounds:
            return rounds, rnd, None
        rnd = None
        if k == 1 and problem.options.local_repair:
            rnd = local_round(problem, rounds[-1], k)
        if rnd is None:
            rnd = star_round(problem, rounds[-1], k)


def _collapse_note(rnd, best):
    star = "" if rnd.folds_star is None else f"; the star map had {rnd.folds_star} folded faces"
    return (f"round {rnd.index} collapsed the map (E/4pi = {rnd.energy / SPHERE_AREA:.3f}, "
            f"{rnd.folds_after} folded faces{star}), returning round {best.index} "
            f"({best.folds_after} folded faces)")


def star_round(problem, previous, index):
    """Round ``index``: Algorithm 1 from the star map of the previous map (Algorithm 2).

    The star map's folds, if any, are untangled first (``options.untangle``); the
    fold barrier (``options.keep_fold_free``) applies when the start is fold-free.
    From a start that still folds, the barrier would keep those faces folded
    and, measured on pycortex (2 folds left after untangling), crawl at ~0.5 s
    per iteration, so such rounds run free.
    """
    t0 = time.perf_counter()
    opts = problem.options
    U_prev = problem.mesh.from_input(previous.U)
    U_init, Phi, lam, reflected = star_map_of(problem.F, U_prev, problem.L, problem.area)
    folds_star = count_folds(problem.F, U_init)
    if folds_star and opts.untangle:
        U_init, _ = untangle_folds(problem.F, U_init)
    folds_init = count_folds(problem.F, U_init)
    run = problem.minimize(U_init, opts.keep_fold_free and folds_init == 0, index)
    return problem.round(index, "star", U_init, run, folds_init, t0, previous, Phi=Phi,
                         eigenvalues=lam, reflected=reflected, folds_star=folds_star)


def local_round(problem, previous, index):
    """Round ``index`` as a local repair of the previous map's folds, or None if it does not apply.

    The previous map is Möbius-centered first (with ``options.mobius``), then
    :func:`igl_spheremap.local_repair.local_repair` untangles its folds and
    re-minimizes around them under the fold barrier.
    """
    t0 = time.perf_counter()
    U_prev = problem.mesh.from_input(previous.U)
    if problem.options.mobius:
        U_prev, _ = mobius_center(U_prev, problem.area)
    repaired = local_repair(problem.L, problem.area, problem.F, U_prev, problem.options)
    if repaired is None:
        return None
    U_init, run, region = repaired
    run.folds = count_folds(problem.F, run.U)
    return problem.round(index, "local", U_init, _finite(run, index), 0, t0, previous,
                         region=int(region.sum()))


def final_centering(problem, U, folds):
    """``U`` (input order), Möbius-centered if that folds no more faces (kernel moves for slivers).

    Re-centering can flip a near-degenerate sliver (pycortex: one face of signed
    volume 8e-18); its vertices then get the kernel moves of
    :func:`igl_spheremap.untangle_folds` (with untangling or local repair on).
    With ``options.precision="float32"`` the centered map must also leave no
    more faces below their rounding margin.

    Returns
    -------
    U : (n, 3) float64 array
        In the validated mesh's order.
    folds : int
    """
    opts, F = problem.options, problem.F
    U = problem.mesh.from_input(U)
    if opts.mobius:
        centered, _ = mobius_center(U, problem.area)
        left = count_folds(F, centered)
        if left > folds and (opts.untangle or opts.local_repair):
            centered, left = untangle_folds(F, centered, max_rings=0)
        if left <= folds and (opts.precision == "float64" or
                              below_margin(F, centered, opts.precision).sum()
                              <= below_margin(F, U, opts.precision).sum()):
            U = centered
    return U, count_folds(F, U)
