"""The float32 repairs: lift the faces a fold-free map leaves below their rounding margin.

After Algorithm 2 under the margin barrier, faces can still be below their
float32 rounding margin: those crowded before the barrier applied (round 0 from
a Gauss map that folds runs free, and the star map of a crowded map is crowded
too).  Three repairs trade some conformality for room there, tried in turn
until one leaves no face below the margin:

* ``"cluster inflation"`` (:func:`igl_spheremap.precision.inflation.inflate_crowding`): local
  re-embedding of each crowded cluster (limbs, fingers, horns); cheap, and the
  map stays as it was elsewhere;
* ``"compressed metric"`` (:func:`igl_spheremap.precision.compressed_metric.compressed_metric_map`):
  Algorithm 2 rerun on a metric shortened along the crowding direction
  (elongated convex shapes, whose whole length crowds);
* ``"central projection"`` (:func:`igl_spheremap.folding.guaranteed.start_round`):
  Algorithm 2 from the central projection under the margin barrier (star-shaped
  surfaces such as a capsule, whose Gauss map is degenerate).

The order follows the cause: when round 0 ran under the barrier from a fold-free
Gauss map (an elongated convex shape), the compressed metric comes first; when
the surface is star-shaped (a point of its kernel sees every face), the central projection; else
cluster inflation.  When none leaves 0, the fold-free candidate with the fewest
faces below the margin is returned.
"""

import time

import numpy as np

from ..errors import plural
from ..folding.centering import final_centering
from ..folding.guaranteed import start_round
from ..folding.rounds import run_rounds
from ..folding.starts import central_projection
from ..sphere.folds import count_below_margin, count_folds, unit_roundoff
from ..sphere.mobius import mobius_center
from .compressed_metric import compressed_metric_map
from .inflation import inflate_crowding


#: Cluster inflation is repeated, aiming this far past the margin in turn, while
#: faces stay below it (deep nested crowding, as on fingers, needs the last).
INFLATION_OVERSHOOTS = (2.0, 4.0, 8.0)


def make_representable(problem, U, chosen):
    """Raise the faces of a fold-free map above their ``options.precision`` rounding margin.

    Parameters
    ----------
    problem : igl_spheremap.folding.problem.MapProblem
        The mesh, its operators and options (``precision``).
    U : (n, 3) float64 array
        Fold-free map in the validated mesh's order, some faces below the margin.
    chosen : igl_spheremap.Round
        The round ``U`` came from (its kind and start decide the order of the repairs).

    Returns
    -------
    U : (n, 3) float64 array
        The best map (validated order): the first repair's that leaves no face
        below the margin, else the fold-free candidate with the fewest (``U``
        itself when no repair lowered the count).
    info : dict
        ``method`` (the repair kept, or None), ``below_before``, ``below_margin``
        (after), ``tried`` (per repair: ``method``, ``below_margin``, ``folds``,
        ``seconds`` and its details, or ``skipped`` and why), ``summary`` (str).
    converged : bool
        Whether the Algorithm 1 run behind the returned map converged (a rerun's
        last round for the reruns; ``chosen``'s otherwise).
    """
    u = unit_roundoff(problem.options.precision)
    before = count_below_margin(problem.F, U, u)
    best = dict(U=U, below=before, method=None, converged=chosen.converged)
    tried = []
    for name in _order(problem, chosen):
        t = time.perf_counter()
        out = REPAIRS[name](problem, U, chosen)
        rec = dict(method=name, seconds=time.perf_counter() - t)
        tried.append(rec)
        if isinstance(out, str):
            rec["skipped"] = out
            continue
        U_new, converged, details = out
        rec.update(folds=count_folds(problem.F, U_new), below_margin=count_below_margin(problem.F, U_new, u),
                   **details)
        if rec["folds"] == 0 and rec["below_margin"] < best["below"]:
            best = dict(U=U_new, below=rec["below_margin"], method=name, converged=converged)
        if best["below"] == 0:
            break
    info = dict(method=best["method"], below_before=before, below_margin=best["below"],
                tried=tried, summary=_summary(problem.options.precision, before, best, tried))
    return best["U"], info, best["converged"]


def _order(problem, chosen):
    if chosen.kind == "gauss" and chosen.folds_before == 0:
        return ["compressed metric", "cluster inflation", "central projection"]
    if central_projection(problem.mesh.V, problem.F) is not None:
        return ["central projection", "cluster inflation", "compressed metric"]
    return ["cluster inflation", "compressed metric", "central projection"]


def _inflation(problem, U, chosen):
    V, F, precision = problem.mesh.V, problem.F, problem.options.precision
    u = unit_roundoff(precision)
    clusters = []
    for overshoot in INFLATION_OVERSHOOTS:
        # deeper nested crowding (human_woman's hands): aim further past the floor
        U, more = inflate_crowding(V, F, U, precision, overshoot=overshoot)
        clusters += more
        if not count_below_margin(F, U, u):
            break
    if problem.options.mobius:
        Uc, _ = mobius_center(U, problem.area)
        if count_folds(F, Uc) == 0 and count_below_margin(F, Uc, u) <= count_below_margin(F, U, u):
            U = Uc
    kept = sum(rec["result"].startswith("kept") for rec in clusters)
    return U, chosen.converged, dict(clusters=len(clusters), kept=int(kept))


def _compressed(problem, U, chosen):
    U, info = compressed_metric_map(problem, U)
    if info["converged"] is None:
        return "no rerun kept: " + "; ".join(
            s.get("error", f"the rerun folded {plural(s.get('rerun_folds'), 'face')}")
            for s in info["steps"] if "error" in s or "rerun_folds" in s)
    return U, info["converged"], dict(reruns=sum("seconds" in s for s in info["steps"]),
                                      K_max=info["K_max"], K_faces=info["K_faces"])


def _central(problem, U, chosen):
    U0 = central_projection(problem.mesh.V, problem.F)
    if U0 is None:
        return "the central projection folds (the surface is not star-shaped)"
    rounds, last, _ = run_rounds(problem, first=lambda p: start_round(p, "central", U0, 0))
    U, folds = final_centering(problem, last.U, last.folds_after)
    return U, last.converged, dict(rounds=len(rounds) - 1)


REPAIRS = {"cluster inflation": _inflation, "compressed metric": _compressed,
           "central projection": _central}


def _summary(precision, before, best, tried):
    done = ", ".join(f"{rec['method']} {rec['below_margin']}" if "skipped" not in rec
                     else f"{rec['method']} skipped" for rec in tried)
    head = (f"{plural(before, 'face was', 'faces were')} below their {precision} rounding margin "
            "after the rounds")
    if best["method"] is None:
        return f"{head}; no repair lowered that ({done})"
    return f"{head}; {best['method']} left {best['below']} (tried: {done})"
