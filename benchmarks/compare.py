"""Side-by-side benchmark: our spherical conformal maps vs LaPy and a Gu-Yau baseline.

For every mesh, each method runs in its own fresh child process
(``methods.run_case``), and the same quality measures are computed on every
resulting map:

* ``default``  ours, default pipeline: ``igl_spheremap.spherical_conformal_map(V, F)``;
* ``default_superlu``  the same as installed without the ``cholmod`` extra
               (the H1 metric factorized by SuperLU instead of CHOLMOD);
* ``alg1``     ours, Algorithm 1 alone from the Gauss map with the paper's
               settings (cotangent Laplacian, L2 gradient, no Möbius
               normalization; the paper's Table 2 setting), capped at
               ``--alg1-max-iter`` iterations;
* ``paper``    the paper's Algorithm 2 as published:
               ``spherical_conformal_map(V, F, method="paper")``;
* ``lapy``     ``lapy.conformal.spherical_conformal_map(lapy.TriaMesh(V, F))``
               (LaPy 1.7, the linear method of Choi, Lam and Lui);
* ``lapy_arrays``  the same with the ``TriaMesh(V, F)`` construction timed too
               (from arrays to a map, as ours is timed);
* ``gu_yau``   the Gu-Yau-style gradient descent of benchmarks/gu_yau.py (the
               paper's comparator), capped at ``--gu-yau-seconds``.

Usage::

    python benchmarks/compare.py                       # all meshes of ../shared/meshes
    python benchmarks/compare.py MESH.obj [MESH ...] --out DIR --timeout 600
    python benchmarks/compare.py --methods default lapy   # a subset of the methods
    python benchmarks/compare.py --repeats 1              # time one call only
    python benchmarks/compare.py --alternate 3            # methods in turn, 3 times

Writes ``DIR/compare.md`` and ``DIR/compare.json`` (default DIR:
benchmarks/results), rewritten after every mesh so an interrupted run keeps
what it has, and prints the markdown to stdout.  A method that raises, dies or
times out is recorded in its row's status; it never stops the run.
"""

import sys

from harness import (REPEAT_BELOW_SECONDS, REPEATS, arguments, fmt, markdown_table, mesh_paths,
                     page, parse, run, status_cell)
from methods import METHODS, run_case

COLUMNS = [
    ("mesh", "mesh", "", "l"),
    ("method", "label", "", "l"),
    ("vertices", "vertices", ",", "r"),
    ("rounds", "rounds", "", "r"),
    ("iterations", "nit", ",", "r"),
    ("seconds", "seconds", ".2f", "r"),
    ("folds", "folds", ",", "r"),
    ("angle mean (°)", "angle_mean", ".3f", "r"),
    ("angle SD (°)", "angle_sd", ".3f", "r"),
    ("energy/4π", "energy_4pi", ".5f", "r"),
    ("centroid norm", "centroid_norm", ".1e", "r"),
    ("converged", "converged", "", "l"),
    ("peak RSS (MiB)", "peak_rss_mib", ".0f", "r"),
    ("status", status_cell, "", "l"),
]

RATIO_COLUMNS = [
    ("mesh", "mesh", "", "l"),
    ("vertices", "vertices", ",", "r"),
    ("ours s", "ours_seconds", ".2f", "r"),
    ("LaPy s", "lapy_seconds", ".2f", "r"),
    ("time ours/LaPy", "time_ratio", ".2f", "r"),
    ("LaPy s, TriaMesh too", "lapy_arrays_seconds", ".2f", "r"),
    ("time ours/LaPy, TriaMesh too", "time_ratio_arrays", ".2f", "r"),
    ("ours s, SuperLU", "superlu_seconds", ".2f", "r"),
    ("time ours SuperLU/LaPy", "time_ratio_superlu", ".2f", "r"),
    ("ours angle (°)", "ours_angle", ".3f", "r"),
    ("LaPy angle (°)", "lapy_angle", ".3f", "r"),
    ("angle ours/LaPy", "angle_ratio", ".2f", "r"),
    ("LaPy angle, Möbius-centered (°)", "lapy_angle_centered", ".3f", "r"),
    ("angle ours/LaPy centered", "angle_ratio_centered", ".2f", "r"),
    ("ours folds", "ours_folds", ",", "r"),
    ("LaPy folds", "lapy_folds", ",", "r"),
    ("LaPy status", "lapy_status", "", "l"),
]

LEGEND = """\
Columns: *rounds* = folding-removal (star-map) rounds after the Gauss-map stage
(0: Algorithm 1 from the Gauss map was enough; – for methods without rounds);
*iterations* = Algorithm 1 (or gradient-descent) iterations over all rounds;
*seconds* = wall time of the method's call only (mesh loading, LaPy's
`TriaMesh` construction and the metrics are not timed; ours includes input
validation, the Gauss map and operator assembly), the best of 3 calls in the
same child process when the first call takes less than 10 s (the machine is
shared and timings are noisy), else the one call; every method, LaPy
included, is timed this way (`--repeats`); *folds* =
`igl_spheremap.count_folds` (image triangles with signed volume <= 0);
*angle* = `igl_spheremap.angle_distortion`, |corner angle on the flat image
triangle - corner angle on the mesh| in degrees, mean and SD over all corners;
*energy/4π* = `igl_spheremap.harmonic_energy` with the cotangent Laplacian
(`igl.cotmatrix`) of the input, over 4π (1 for a conformal bijection; ~0 for a
map collapsed to a point); *centroid norm* = |area-weighted image centroid|
(`igl_spheremap.image_centroid`; 0 for a Möbius-normalized map); *peak RSS* =
peak resident set size of the fresh child process that ran the method
(`VmHWM` of `/proc/self/status` read in the child right after the call;
includes Python, numpy/scipy/libigl, LaPy for the LaPy rows, and the mesh).
"""


def ratio_rows(rows):
    """Per mesh: ours (default) vs LaPy, time and mean angle distortion."""
    out = []
    for mesh in dict.fromkeys(r["mesh"] for r in rows):
        by = {r["method"]: r for r in rows if r["mesh"] == mesh}
        ours, lapy = by.get("default"), by.get("lapy")
        if ours is None or lapy is None:
            continue
        row = dict(mesh=mesh, vertices=ours.get("vertices") or lapy.get("vertices"),
                   ours_seconds=ours.get("seconds"), lapy_seconds=lapy.get("seconds"),
                   ours_angle=ours.get("angle_mean"), lapy_angle=lapy.get("angle_mean"),
                   lapy_angle_centered=lapy.get("angle_mean_centered"),
                   ours_folds=ours.get("folds"), lapy_folds=lapy.get("folds"),
                   ours_status=ours.get("status"), lapy_status=status_cell(lapy, 50))
        ok = ours.get("status") == "ok" and lapy.get("status") == "ok"
        row["time_ratio"] = (ours["seconds"] / lapy["seconds"]
                             if ok and lapy["seconds"] else None)
        arrays = by.get("lapy_arrays")
        if ok and arrays is not None and arrays.get("status") == "ok" and arrays["seconds"]:
            row["lapy_arrays_seconds"] = arrays["seconds"]
            row["time_ratio_arrays"] = ours["seconds"] / arrays["seconds"]
        superlu = by.get("default_superlu")
        if superlu is not None and superlu.get("status") == "ok":
            row["superlu_seconds"] = superlu["seconds"]
            row["time_ratio_superlu"] = (superlu["seconds"] / lapy["seconds"]
                                         if ok and lapy["seconds"] else None)
        row["angle_ratio"] = (ours["angle_mean"] / lapy["angle_mean"]
                              if ok and lapy["angle_mean"] else None)
        row["angle_ratio_centered"] = (
            ours["angle_mean_centered"] / lapy["angle_mean_centered"]
            if ok and lapy.get("angle_mean_centered") and ours.get("angle_mean_centered")
            else None)
        out.append(row)
    return out


def notes_lines(rows):
    """Bullet list of failures, timeouts, LaPy warnings and stopping messages worth reading."""
    lines = []
    for r in rows:
        head = f"- {r['mesh']}, {r['label']}:"
        if r.get("status") != "ok":
            lines.append(f"{head} {r.get('status')}")
        for note in r.get("notes") or []:
            lines.append(f"{head} {note}")
        if r.get("status") == "ok" and r.get("converged") is False:
            lines.append(f"{head} not converged: {r.get('message')}")
        if r["method"] == "gu_yau" and r.get("extra"):
            lines.append(f"{head} fixed step {r['extra'].get('step'):.3g} "
                         f"(1/lambda_max, mesh scaled to area 4π)")
    return lines


def render(rows, env, args):
    """The markdown report."""
    gtol = f"{args.gtol:g}" if args.gtol else "library default (1e-5)"
    parts = [f"Per-method child-process timeout {args.timeout:g} s; seconds are the best of "
             f"{args.repeats} calls per child for calls under {REPEAT_BELOW_SECONDS:g} s"
             + (f", and the best of {args.alternate} such children per method, the methods' "
                "children run in turn" if args.alternate > 1 else "") + "; "
             f"Algorithm 1 alone capped at "
             f"{args.alg1_max_iter:,} iterations; Gu-Yau baseline capped at "
             f"{args.gu_yau_seconds:g} s; gtol {gtol}.",
             markdown_table(rows, COLUMNS), LEGEND]
    ratios = ratio_rows(rows)
    if ratios:
        parts += ["## Ours (default) / LaPy",
                  "Ratios below 1 mean ours is faster / less angle-distorting; computed "
                  "only where both methods returned a map.  LaPy does not Möbius-normalize "
                  "its map and flat-triangle angles depend on the normalization, so the "
                  "*centered* columns measure both maps after Möbius centering "
                  "(`igl_spheremap.mobius_center`, input vertex areas).",
                  markdown_table(ratios, RATIO_COLUMNS)]
    notes = notes_lines(rows)
    if notes:
        parts += ["## Notes", "\n".join(notes)]
    return page("Spherical conformal maps: ours vs LaPy vs Gu-Yau baseline", env, *parts)


def method_options(method, args):
    """Options passed to one method's child process."""
    opts = dict(repeats=args.repeats)
    if method == "alg1":
        opts.update(gtol=args.gtol, max_iter=args.alg1_max_iter)
    elif method == "gu_yau":
        opts.update(gtol=args.gtol, gu_yau_seconds=args.gu_yau_seconds,
                    gu_yau_max_iter=args.gu_yau_max_iter)
    elif method in ("default", "default_superlu", "paper"):
        opts.update(gtol=args.gtol)
    return opts


def _faster(kept, row):
    """Of two runs of one method on one mesh, the faster ``ok`` one (else the
    first), with every call's time of both in ``seconds_runs``."""
    if kept is None:
        return row
    runs = kept.get("seconds_runs", []) + row.get("seconds_runs", [])
    if row.get("status") == "ok" and (kept.get("status") != "ok"
                                      or row["seconds"] < kept["seconds"]):
        kept = row
    return dict(kept, seconds_runs=runs)


def parse_args(argv=None):
    p = arguments(__doc__, timeout=600.0, repeats=REPEATS)
    p.add_argument("--methods", nargs="+", choices=list(METHODS), default=list(METHODS),
                   help="methods to run (default: all)")
    p.add_argument("--alternate", type=int, default=1, metavar="K",
                   help="run the methods' child processes K times in turn (method A, B, ..., "
                        "A, B, ...) and keep each method's fastest: this machine's speed drifts "
                        "by 10-20%% over seconds, which biases methods timed one after the other "
                        "(default: %(default)s)")
    p.add_argument("--gtol", type=float, default=None,
                   help="stopping tolerance on the RMS Riemannian gradient for ours and the "
                        "Gu-Yau baseline (default: the library's, 1e-5)")
    p.add_argument("--alg1-max-iter", type=int, default=20000,
                   help="iteration cap of Algorithm 1 alone (default: %(default)s)")
    p.add_argument("--gu-yau-seconds", type=float, default=60.0,
                   help="time cap of the Gu-Yau baseline (default: %(default)s)")
    p.add_argument("--gu-yau-max-iter", type=int, default=1_000_000,
                   help="iteration cap of the Gu-Yau baseline (default: %(default)s)")
    return parse(p, argv)


def measure_mesh(path, args):
    """Every method on one mesh (``--alternate`` rounds of the methods in turn); one row each."""
    best = {}
    for _ in range(max(args.alternate, 1)):
        for method in args.methods:
            row = run_case(path, method, method_options(method, args), timeout=args.timeout)
            print(f"{row['mesh']:>36} {method:>8}: {row['status'][:60]}, "
                  f"{fmt(row.get('seconds'), '.2f')} s, folds {fmt(row.get('folds'))}, "
                  f"angle {fmt(row.get('angle_mean'), '.3f')}°", file=sys.stderr, flush=True)
            best[method] = _faster(best.get(method), row)
    return [best[m] for m in args.methods]


def main(argv=None):
    args = parse_args(argv)
    run("compare", args, mesh_paths(args.meshes), lambda path: measure_mesh(path, args), render,
        payload=lambda rows: dict(ratios_ours_over_lapy=ratio_rows(rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
