"""``igl-spheremap batch INPUTS... -o OUTDIR``: map many meshes on Dask."""

import argparse

from .common import (EXIT_CODES, EXIT_ERROR, EXIT_NOT_FOLD_FREE, EXIT_OK, EXIT_PARTIAL,
                     at_least_one, common_arguments, map_options, say, show_progress, warn)


def add_parser(sub):
    p = sub.add_parser(
        "batch", parents=[common_arguments()],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        help="map many meshes in parallel on Dask",
        description="Map many meshes in parallel on a Dask cluster (a local one by default).\n"
                    "Each mesh gets its sphere and a JSON report (and data with --data);\n"
                    "OUTDIR gets summary.csv and summary.md.",
        epilog="Outputs mirror the input folders below their common folder:\n"
               "  subjects/A/surf/lh.white -> OUTDIR/A/surf/lh.white_sphere (+ "
               "lh.white_sphere.json)\n\n" + EXIT_CODES)
    p.add_argument("inputs", nargs="+", metavar="INPUTS",
                   help="mesh files, folders (the mesh files directly in them) or quoted glob "
                        "patterns")
    p.add_argument("-o", "--outdir", required=True, metavar="OUTDIR", help="output folder")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="address of a running Dask scheduler (default: start a LocalCluster)")
    p.add_argument("--workers", type=at_least_one, default=None, metavar="N",
                   help="LocalCluster worker processes (default 2; one thread each)")
    p.add_argument("--resume", action=argparse.BooleanOptionalAction, default=True,
                   help="skip meshes whose complete report exists with the same options and whose "
                        "input and outputs are the files it recorded (default: on)")
    p.set_defaults(func=run)


def batch_exit_code(rows, allow_folds=False):
    """Exit code of a batch: 1 all failed, 4 some failed, 3 folds/not converged, else 0."""
    failed = sum(r["status"] == "failed" for r in rows)
    if rows and failed == len(rows):
        return EXIT_ERROR
    if failed:
        return EXIT_PARTIAL
    if not allow_folds and any(not r["success"] for r in rows):
        return EXIT_NOT_FOLD_FREE
    return EXIT_OK


def run(args):
    from ..app.batch import map_batch, summary_markdown

    def on_result(row):
        if row["status"] == "failed":
            warn(f"failed: {row['mesh']}: {row['message']}")

    if args.scheduler and args.workers is not None:
        warn("warning: --workers is ignored with --scheduler")
    rows = map_batch(args.inputs, args.outdir, options=map_options(args),
                     scheduler=args.scheduler, n_workers=args.workers, resume=args.resume,
                     data=args.data, radius=args.radius, file_precision=args.file_precision,
                     hemisphere=args.hemisphere,
                     progress=show_progress(args),
                     on_result=on_result)
    say(args, summary_markdown(rows).rstrip())
    counts = {s: sum(r["status"] == s for r in rows) for s in ("ok", "warning", "skipped",
                                                                 "failed")}
    say(args, ", ".join(f"{n} {s}" for s, n in counts.items()) +
        f"; summary in {args.outdir.rstrip('/')}/summary.csv and summary.md")
    code = batch_exit_code(rows, args.allow_folds)
    if code == EXIT_NOT_FOLD_FREE:
        warn("warning: some maps have folded faces or did not converge (see the summary); "
             "exit code 3 (--allow-folds exits 0)")
    return code
