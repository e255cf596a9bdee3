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
* :func:`restart_round`: after a collapse to degree 0, Algorithm 1 from the
  punctured Tutte map, of degree 1 by construction (not in the paper).

:func:`run_rounds` is Algorithm 2's loop over them; which round runs when is
drawn in :mod:`igl_spheremap.folding`.  Maps are passed between rounds in the
validated mesh's vertex order; the Round objects hold them in the input's order.
"""

import time

from ..errors import plural
from ..mesh.operators import SPHERE_AREA
from ..sphere.folds import count_folds, map_degree
from ..sphere.mobius import mobius_center
from .local_repair import local_repair
from .problem import finite
from .star_map import star_map_of
from .starts import vertex_normals
from .tutte_start import fold_free_tutte_maps
from .untangle import untangle_patches

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


def run_rounds(problem, first=gauss_round, callback=None):
    """Algorithm 2's loop: round 0 by ``first``, then rounds while folds remain.

    The round after round 0 (or after a restart) is a local repair when
    ``options.local_repair`` and it applies, else a star-map round; at most
    ``options.max_rounds`` rounds after round 0.  With ``options.round_guard`` a round
    that collapsed the map to degree 0 (every star map built from it has degree 0
    too) is followed once by :func:`restart_round` (a round too), from a map of degree 1 by
    construction, and the loop stops at a futile round (:func:`futile`): a collapse
    after that, or a round that left no fewer folds than the best round before it;
    the round with the fewest folds that did not collapse is returned.

    Returns
    -------
    rounds : list of Round
        Every round that ran, in order.
    chosen : Round
        The round whose map is the result (the last one unless the loop stopped
        at a futile round).
    note : str or None
        Why ``chosen`` is not the last round, and whether the loop restarted.
    """
    rounds, restarted = [], None
    rnd = first(problem)
    while True:
        rounds.append(rnd)
        if callback is not None:
            callback(rnd)
        k = len(rounds)
        if rnd.folds_after == 0:
            return rounds, rnd, restarted
        if problem.options.round_guard and _collapsed(problem, rnd) and \
                k <= problem.options.max_rounds and not any(r.kind == "restart" for r in rounds):
            restart = restart_round(problem, rnd, k)
            if restart is not None:
                restarted = f"{futile(problem, rounds)}; round {k} restarted from the Tutte map"
                rnd = restart
                continue
        why = futile(problem, rounds) if problem.options.round_guard else None
        if why:
            best = min(rounds, key=lambda r: (_collapsed(problem, r), r.folds_after))
            why = why if restarted is None else f"{restarted}; {why}"
            return rounds, best, (f"{why}; returning round {best.index} "
                                  f"({plural(best.folds_after, 'folded face')})")
        if k > problem.options.max_rounds:
            return rounds, rnd, restarted
        rnd = None
        if rounds[-1].kind in ("gauss", "restart") and problem.options.local_repair:
            rnd = local_round(problem, rounds[-1], k)
        if rnd is None:
            rnd = star_round(problem, rounds[-1], k)


def futile(problem, rounds):
    """Why the last of ``rounds`` ends Algorithm 2's loop (str), or None.

    A round that collapsed the map to degree 0 (half its image folded onto the
    other half: :func:`igl_spheremap.sphere.folds.map_degree`), or one that left
    at least as many folds as the best round before it: the next star map is built
    from a map no less folded, and no round after such a round reached a fold-free
    map on the shared meshes and the corpus (``docs/decisions.md``).  A restart
    (:func:`restart_round`) is a new start, not a step of the loop: the round after it
    is judged, not the restart itself.
    """
    rnd = rounds[-1]
    if _collapsed(problem, rnd):
        return (f"round {rnd.index} collapsed the map to degree 0 (E/4pi = "
                f"{rnd.energy / SPHERE_AREA:.3f}, {rnd.folds_after} folded faces)")
    best = min(rounds[:-1], key=lambda r: r.folds_after, default=None)
    if best is not None and rnd.folds_after >= best.folds_after and rnd.kind != "restart":
        return (f"round {rnd.index} did not lower the fold count (round {best.index}: "
                f"{best.folds_after} -> {rnd.folds_after})")
    return None


def _collapsed(problem, rnd):
    """Whether the round's map has degree 0 (|degree| < 1/2; a mirror image, -1, is not)."""
    return abs(map_degree(problem.F, problem.mesh.from_input(rnd.U))) < 0.5


def restart_round(problem, previous, index):
    """Round ``index`` after a collapse: Algorithm 1 from the punctured Tutte map, or None.

    A map of degree 0 has star maps of degree 0 only; the lifted Tutte embedding (the
    first of :func:`igl_spheremap.folding.tutte_start.fold_free_tutte_maps`) has degree 1
    by construction.  Algorithm 1 runs free from it, as round 0 does from a
    folded Gauss map: under the fold barrier it would hold most vertices near the crowded
    start.  None when every weighting folds (the guaranteed path then untangles one).
    """
    t0 = time.perf_counter()
    U_init = next(fold_free_tutte_maps(problem.mesh.V, problem.F), None)
    if U_init is None:
        return None
    run = problem.minimize(U_init, False, index)
    return problem.round(index, "restart", U_init, run, 0, t0, previous, fold_barrier=False)


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
    folds_star, patched = count_folds(problem.F, U_init), False
    if folds_star and opts.untangle:
        U_init, _, patched = untangle_patches(problem.F, U_init)
    folds_init = count_folds(problem.F, U_init)
    barrier = opts.fold_barrier and folds_init == 0
    run = problem.minimize(U_init, barrier, index)
    return problem.round(index, "star", U_init, run, folds_init, t0, previous, Phi=Phi,
                         eigenvalues=lam, reflected=reflected, folds_star=folds_star,
                         fold_barrier=barrier, patched=patched)


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
    U_init, run, region, patched = repaired
    run.folds = count_folds(problem.F, run.U)
    return problem.round(index, "local", U_init, finite(run, index), 0, t0, previous,
                         region=int(region.sum()), fold_barrier=True, patched=patched)
