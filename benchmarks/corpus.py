"""Fold-free on every closed genus-0 mesh (issue #21): the default map, float64 and float32.

For every mesh of the shared meshes and of the corpus (robot and CAD parts, CT organs)
and for the constructed shapes (ellipsoids 10:1 to 1000:1, a 50:1 capsule, an
icosphere with every face split at 3% of its edges), ``spherical_conformal_map(V, F)``
runs in a fresh child process with ``precision="float64"`` and ``"float32"``.  The
table lists folds, folds once stored as float32 at radius 100 (float32 runs; numpy's
own rounding), success, degree, E/4π (the run's Laplacian, intrinsic Delaunay), mean
angle distortion after Möbius centering with the input's vertex areas, the vertices
the fold barrier held in the round the map came from, which round that was, and
seconds; then each mesh's time over the median time of the meshes within a factor 2
of its size.

With ``--awkward``, instead, the shapes of :data:`shapes.AWKWARD_SHAPES` (convex hulls of
random points, spiked balls, a hand, a dumbbell and a coiled tube triangulated by marching
cubes: meshes ``../shared`` does not have), with the time ratios among themselves.

Usage::

    python benchmarks/corpus.py                         # ../shared/meshes, ../shared/corpus, shapes
    python benchmarks/corpus.py ../shared/corpus/go2_base_convex.obj --shapes split_ico
    python benchmarks/corpus.py --awkward               # results/awkward_shapes.md

Writes ``results/corpus.md`` and ``.json`` (``awkward_shapes`` with ``--awkward``).
"""

import sys
import time
import warnings

import numpy as np

from harness import (DEFAULT_MESH_DIR, arguments, fmt, load_mesh, markdown_table, mesh_name,
                     mesh_paths, page, parse, quality_row, run, run_in_child, status_cell,
                     timed_calls)
from shapes import AWKWARD_SHAPES, SHAPES, awkward_shape, shape

CORPUS_DIR = DEFAULT_MESH_DIR.parent / "corpus"

COLUMNS = [("mesh", "mesh", "", "l"), ("n", "vertices", ",", "r"), ("precision", "precision", "", "l"),
           ("folds", "folds", ",", "r"), ("stored f32", "stored_folds", ",", "r"),
           ("success", "success", "", "l"), ("degree", "degree", ".3f", "r"),
           ("E/4π", "energy_4pi", ".3f", "r"), ("angle (°)", "angle_mean_centered", ".2f", "r"),
           ("held", "frozen", ",", "r"), ("map from", "path", "", "l"),
           ("s", "seconds", ".2f", "r"), ("time / median", "time_ratio", ".1f", "r")]

LEGEND = """\
*folds* = image faces with signed volume <= 0; *stored f32* = the same once `100 U` is
rounded to float32 (float32 runs only); *success* = the result's own verdict; *degree* =
total signed solid angle / 4π; *E/4π* = harmonic energy with the run's (intrinsic
Delaunay) Laplacian; *angle* = mean corner angle distortion after Möbius centering
with the input's vertex areas; *held* = vertices the fold barrier froze in the round
the map came from; *map from* = that round's kind (gauss, star, local, restart: Algorithm 2;
central, tutte, untangled, polish: the guaranteed path, from that start); *s* = wall time of
the call (best of 3 under 10 s); *time / median* = s over the median s of the same
precision's meshes within a factor 2 in size."""


def case_mesh(case):
    """``(V, F)`` of a mesh file or of a shape of :data:`SHAPES` or :data:`AWKWARD_SHAPES`."""
    if case in SHAPES:
        return shape(case)
    return awkward_shape(case) if case in AWKWARD_SHAPES else load_mesh(case)


def measure(case, precision, repeats):
    """Child body: the default map of one case in one precision, and its quality."""
    import igl_spheremap as sm
    from igl_spheremap.sphere.folds import folds_after_rounding

    V, F = case_mesh(case)

    def call(clock):
        with warnings.catch_warnings(), clock:
            warnings.simplefilter("ignore")
            return sm.spherical_conformal_map(V, F, precision=precision)

    r, _, runs = timed_calls(call, repeats)
    chosen = r.rounds[r.chosen]
    row = quality_row(V, r.F, r.U)  # its energy_4pi (cotangent Laplacian) replaced below
    row.update(vertices=int(V.shape[0]), precision=precision, success=bool(r.success),
               degree=float(r.degree), energy_4pi=float(r.energy_over_4pi),
               frozen=int(chosen.frozen), path=chosen.kind, seconds=min(runs),
               message=r.message, status="ok",
               stored_folds=folds_after_rounding(r.F, r.U, 100.0) if precision == "float32"
               else None)
    return row


def measure_case(case, args):
    """Rows of one case, float64 and float32, each in a fresh child process."""
    rows = []
    for precision in ("float64", "float32"):
        t0 = time.perf_counter()
        row = run_in_child(measure, dict(case=str(case), precision=precision,
                                         repeats=args.repeats), args.timeout)
        if row.get("status") != "ok":
            row.setdefault("seconds", time.perf_counter() - t0)
        named = case in SHAPES or case in AWKWARD_SHAPES
        rows.append(dict(row, precision=precision, mesh=case if named else mesh_name(case)))
    return rows


def time_ratios(rows):
    """Each row's seconds over the median of its precision's rows within a factor 2 in size."""
    for row in rows:
        peers = [r["seconds"] for r in rows if r["precision"] == row["precision"]
                 and r.get("seconds") and r.get("vertices")
                 and 0.5 <= r["vertices"] / row.get("vertices", 1) <= 2.0]
        row["time_ratio"] = row["seconds"] / float(np.median(peers)) if peers else None
    return rows


def render(rows, env, args):
    rows = time_ratios([dict(r) for r in rows])
    columns = COLUMNS + ([("status", status_cell, "", "l")]
                         if any(r.get("status") != "ok" for r in rows) else [])
    ok = [r for r in rows if r.get("status") == "ok"]
    summary = "; ".join(
        f"{p}: {sum(r['folds'] == 0 for r in ok if r['precision'] == p)} of "
        f"{sum(r['precision'] == p for r in rows)} fold-free, "
        f"{sum(r['success'] for r in ok if r['precision'] == p)} successes"
        + (f" ({failed} not mapped: see status)" if (failed := sum(
            r["precision"] == p and r.get("status") != "ok" for r in rows)) else "")
        for p in ("float64", "float32"))
    worst = max((r for r in ok if r.get("time_ratio")), key=lambda r: r["time_ratio"], default=None)
    if worst:
        summary += (f"; slowest for its size: {worst['mesh']} ({worst['precision']}), "
                    f"{fmt(worst['time_ratio'], '.1f')}x the median")
    return page("Fold-free on every closed genus-0 mesh: the default map", env,
                summary + ".", markdown_table(rows, columns), LEGEND)


def main(argv=None):
    p = arguments(__doc__, timeout=900.0, repeats=3,
                  mesh_help=f"mesh files or folders (default: {DEFAULT_MESH_DIR} and {CORPUS_DIR})")
    p.add_argument("--shapes", nargs="*", default=list(SHAPES), choices=list(SHAPES),
                   metavar="NAME", help="constructed shapes (default: all; none: --shapes)")
    p.add_argument("--awkward", action="store_true",
                   help="instead: the awkward shapes of shapes.AWKWARD_SHAPES (results/awkward_shapes)")
    args = parse(p, argv)
    if args.awkward:
        name, cases = "awkward_shapes", list(AWKWARD_SHAPES)
    else:
        meshes = mesh_paths(args.meshes or [DEFAULT_MESH_DIR, CORPUS_DIR])
        name, cases = "corpus", [str(m) for m in meshes] + list(args.shapes)
    run(name, args, cases, lambda c: measure_case(c, args), render,
        echo=lambda r: f"{r['mesh']:>34} {r['precision']}: {r.get('status', '')[:50]}, "
                       f"folds {fmt(r.get('folds'))}, success {fmt(r.get('success'))}, "
                       f"{fmt(r.get('seconds'), '.2f')} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
