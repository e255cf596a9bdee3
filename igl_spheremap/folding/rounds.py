"""The rounds of Algorithm 2: each builds an initial map and runs Algorithm 1 from it.

Every strategy takes the problem (:class:`igl_spheremap.folding.problem.MapProblem`)
and the previous round and returns a new :class:`igl_spheremap.folding.result.Round`
(or None when it does not apply):

* :func:`gauss_round`: the Gauss map (Definition 1), then Algorithm 1;
* :func:`star_round`: the star map of the previous map's weighted Laplace-Beltrami
  eigenfunctions (Section 4.2), its few remaining folds untangled (not in the
  paper), then Algorithm 1;
* :func:`local_round`: the previous map's isolated folds untangled and
  Algorithm 1 rerun only around them (not in the paper);
* :func:`central_round`: the central projection of a star-shaped surface under
  the fold barrier (a start of the float32 repairs).

:func:`run_rounds` is Algorithm 2's loop over them; which round runs when is
drawn in :mod:`igl_spheremap.folding`.  Maps are passed between rounds in the
validated mesh's vertex order; the Round objects hold them in the input's order.
"""

import time

from ..mesh.operators import SPHERE_AREA
from ..sphere.folds import count_folds
from ..sphere.mobius import mobius_center
from .local_repair import local_repair
from .problem import finite
from .star_map import star_map_of
from .starts import central_projection, vertex_normals
from .untangle import untangle_folds

#: A round ending with harmonic energy below this share of ``4 pi`` collapsed the
#: map: a fold-free map of degree one has energy ``4 pi`` or more.
COLLAPSE_ENERGY = 0.5


def gauss_round(problem, precision="float64"):
    """Round 0: Algorithm 1 from the Gauss map.

    Without the fold barrier when the Gauss map folds; with ``options.fold_barrier``
    and a fold-free Gauss map, under the fold barrier keeping the rounding margin
    of ``precision`` (``"float64"``: the plain fold barrier).
    """
    t0 = time.perf_counter()
    U_init = vertex_normals(problem.mesh.V, problem.F)
    folds_init = count_folds(problem.F, U_init)
    barrier = problem.options.fold_barrier and folds_init == 0
    run = problem.minimize(U_init, barrier, 0, precision=precision)
    return problem.round(0, "gauss", U_init, run, folds_init, t0, fold_barrier=barrier)


def central_round(problem):
    """Round 0 from the central projection under the fold barrier of ``options.precision``, or None.

    None when the projection folds (:func:`igl_spheremap.folding.starts.central_projection`).
    Not in the paper: a start of the float32 repairs for star-shaped surfaces
    (a capsule, whose Gauss map is degenerate on the cylinder;
    :mod:`igl_spheremap.precision.repair`).
    """
    t0 = time.perf_counter()
    U_init = central_projection(problem.mesh.V, problem.F, problem.area)
    if U_init is None:
        return None
    run = problem.minimize(U_init, True, 0)
    return problem.round(0, "central", U_init, run, 0, t0, fold_barrier=True)


def run_rounds(problem, first=gauss_round, callback=None):
    """Algorithm 2's loop: round 0 by ``first``, then rounds while folds remain.

    Round 1 is a local repair when ``options.local_repair`` and it applies,
    else (and from round 2 on) a star-map round; at most ``options.max_rounds``
    rounds after round 0.  With ``options.collapse_guard``, a round with energy
    below :data:`COLLAPSE_ENERGY` times ``4 pi`` ends the loop, and the earlier
    round with the fewest folds is returned instead.

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
        if k > 1 and problem.options.collapse_guard and rnd.energy < COLLAPSE_ENERGY * SPHERE_AREA:
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
    fold barrier (``options.fold_barrier``) applies when the start is fold-free.
    From a start that still folds the barrier would hold those faces folded
    (and crawl: ``docs/decisions.md``), so such rounds run free.
    """
    t0 = time.perf_counter()
    opts = problem.options
    U_prev = problem.mesh.from_input(previous.U)
    U_init, Phi, lam, reflected = star_map_of(problem.F, U_prev, problem.L, problem.area)
    folds_star = count_folds(problem.F, U_init)
    if folds_star and opts.untangle:
        U_init, _ = untangle_folds(problem.F, U_init)
    folds_init = count_folds(problem.F, U_init)
    barrier = opts.fold_barrier and folds_init == 0
    run = problem.minimize(U_init, barrier, index)
    return problem.round(index, "star", U_init, run, folds_init, t0, previous, Phi=Phi,
                         eigenvalues=lam, reflected=reflected, folds_star=folds_star,
                         fold_barrier=barrier)


def local_round(problem, previous, index):
    """Round ``index`` as a local repair of the previous map's folds, or None if it does not apply.

    The previous map is Möbius-centered first (with ``options.mobius``), then
    :func:`igl_spheremap.folding.local_repair.local_repair` untangles its folds and
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
    return problem.round(index, "local", U_init, finite(run, index), 0, t0, previous,
                         region=int(region.sum()), fold_barrier=True)
