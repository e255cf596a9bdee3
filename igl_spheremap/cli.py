"""Command-line interface ``igl-spheremap``.

``igl-spheremap [map] [MESH] [-o OUT] ...`` maps one mesh (the default
subcommand: ``map`` is inserted when the first argument is not a subcommand);
``igl-spheremap batch INPUTS... -o OUTDIR`` maps many on Dask.  This module
only parses arguments and prints; the work is in
:func:`igl_spheremap.map_file.map_file` and :func:`igl_spheremap.batch.map_batch`.
"""

import argparse
import math
import re
import sys
from contextlib import ExitStack
from importlib import resources

PROG = "igl-spheremap"
SUBCOMMANDS = ("map", "batch")

EXIT_OK = 0            #: success
EXIT_ERROR = 1         #: usage or I/O error, unexpected error; batch: every mesh failed
EXIT_INVALID_MESH = 2  #: the input is not a closed genus-0 triangle mesh (MeshError)
EXIT_NOT_FOLD_FREE = 3  #: outputs written but the map has folds or did not converge
EXIT_PARTIAL = 4       #: batch: some meshes failed, the others finished

_EXIT_CODES = """\
exit codes:
  0  success (batch: every mesh mapped fold-free and converged, or skipped as done)
  1  usage or I/O error, unexpected error (batch: every mesh failed)
  2  invalid mesh: not a closed, manifold, genus-0 triangle mesh
  3  outputs written, but the map has folded faces or did not converge
     (--allow-folds exits 0 instead)
  4  batch only: some meshes failed, the others finished
"""


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose usage errors exit with 1 (2 means 'invalid mesh' here)."""

    def error(self, message):
        self.print_usage(sys.stderr)
        self.exit(EXIT_ERROR, f"{self.prog}: error: {message}\n")


def _number(text, kind, low, strict=False):
    try:
        value = kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if kind is float and not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite, got {text}")
    if value < low or (strict and value == low):
        raise argparse.ArgumentTypeError(f"must be {'>' if strict else '>='} {low}, got {text}")
    return value


def _non_negative_int(text):
    return _number(text, int, 0)


def _at_least_one(text):
    return _number(text, int, 1)


def _positive_float(text):
    return _number(text, float, 0.0, strict=True)


def build_parser():
    """The argparse parser of ``igl-spheremap`` (subcommands ``map`` and ``batch``)."""
    from . import __version__

    common = argparse.ArgumentParser(add_help=False)
    g = common.add_argument_group("mapping options")
    g.add_argument("--method", choices=("folding_free", "paper"), default=None,
                   help="folding_free (default): the fold-free variant documented in the "
                        "README; paper: Algorithms 1 and 2 as published")
    g.add_argument("--max-rounds", type=_non_negative_int, default=None, metavar="N",
                   help="cap on folding-removal (star map) rounds after the Gauss-map stage "
                        "(default: the method's)")
    g.add_argument("--max-iter", type=_non_negative_int, default=None, metavar="N",
                   help="cap on Algorithm 1 iterations per round (default: the method's)")
    g.add_argument("--gtol", type=_positive_float, default=None, metavar="X",
                   help="stop Algorithm 1 when the RMS Riemannian gradient is below X "
                        "(default: the method's)")
    g.add_argument("--radius", type=_positive_float, default=None, metavar="R",
                   help="radius of the written sphere (default 100 for FreeSurfer output, "
                        "like ?h.sphere; 1 otherwise)")
    g = common.add_argument_group("output and behaviour")
    g.add_argument("--data", action="store_true",
                   help="also write per-vertex data: log conformal factor, theta, phi, "
                        "equirectangular tex_u/tex_v, folded (.npz for mesh files, "
                        ".func.gii for GIfTI/FreeSurfer)")
    g.add_argument("--allow-folds", action="store_true",
                   help="exit 0 even if the map has folds or did not converge")
    g.add_argument("-q", "--quiet", action="store_true",
                   help="print nothing on stdout (warnings and errors still go to stderr)")
    g.add_argument("--no-progress", action="store_true",
                   help="no progress bar (it is shown only when stderr is a terminal)")
    g.add_argument("--debug", action="store_true",
                   help="show full tracebacks of unexpected errors")

    parser = _Parser(
        prog=PROG, formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Folding-free spherical conformal maps of closed genus-0 triangle meshes "
                    "(Lai, Wen, Yin, Gu, Lui 2014) on libigl.\n\n"
                    f"  {PROG} [map] [MESH] [-o OUT] ...     map one mesh (default subcommand)\n"
                    f"  {PROG} batch INPUTS... -o OUTDIR    map many meshes on Dask\n\n"
                    "Formats: anything igl.read_triangle_mesh reads (.obj .off .ply .stl .wrl "
                    ".mesh),\nGIfTI surfaces (.surf.gii) and FreeSurfer surfaces (lh.white, "
                    "rh.pial, ...).",
        epilog=_EXIT_CODES)
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="{map,batch}")

    p = sub.add_parser(
        "map", parents=[common], formatter_class=argparse.RawDescriptionHelpFormatter,
        help="map one mesh onto the sphere (default)",
        description="Map one closed genus-0 mesh onto the sphere; print a table of the "
                    "rounds and a summary.\nWith no MESH, maps the bundled dino.obj.",
        epilog="Output names: without -o the sphere is <stem>_sphere.<ext> in the current "
               "directory\n(dino.obj -> dino_sphere.obj, lh.white -> lh.white_sphere, "
               "x.surf.gii -> x_sphere.surf.gii);\nits format follows the -o name "
               "(.obj/.off/.ply/.stl/.wrl, .surf.gii, ?h.* FreeSurfer) or the input's.\n\n"
               + _EXIT_CODES)
    p.add_argument("mesh", nargs="?", metavar="MESH",
                   help="input mesh (default: the bundled dino.obj)")
    p.add_argument("-o", "--output", metavar="OUT", help="sphere to write")
    p.add_argument("--json", metavar="REPORT", help="write a JSON report of the run")
    p.set_defaults(func=_cmd_map)

    p = sub.add_parser(
        "batch", parents=[common], formatter_class=argparse.RawDescriptionHelpFormatter,
        help="map many meshes in parallel on Dask",
        description="Map many meshes in parallel on a Dask cluster (a local one by default).\n"
                    "Each mesh gets its sphere and a JSON report (and data with --data);\n"
                    "OUTDIR gets summary.csv and summary.md.",
        epilog="Outputs mirror the input folders below their common folder:\n"
               "  subjects/A/surf/lh.white -> OUTDIR/A/surf/lh.white_sphere (+ "
               "lh.white_sphere.json)\n\n" + _EXIT_CODES)
    p.add_argument("inputs", nargs="+", metavar="INPUTS", help="mesh files")
    p.add_argument("-o", "--outdir", required=True, metavar="OUTDIR", help="output folder")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="address of a running Dask scheduler (default: start a LocalCluster)")
    p.add_argument("--workers", type=_at_least_one, default=None, metavar="N",
                   help="LocalCluster worker processes (default 2; one thread each)")
    p.add_argument("--resume", action=argparse.BooleanOptionalAction, default=True,
                   help="skip meshes whose outputs and complete report exist (default: on)")
    p.set_defaults(func=_cmd_batch)
    return parser


def _say(args, text=""):
    """Print on stdout unless --quiet, without breaking a tqdm bar shown on stderr."""
    if not args.quiet:
        from tqdm import tqdm

        tqdm.write(text, file=sys.stdout)
        sys.stdout.flush()


def _warn(text):
    print(f"{PROG}: {text}", file=sys.stderr, flush=True)


def _show_progress(args):
    return not (args.no_progress or args.quiet) and sys.stderr.isatty()


def _map_options(args):
    return dict(method=args.method, max_rounds=args.max_rounds, max_iter=args.max_iter,
                gtol=args.gtol, radius=args.radius)


_ROUND_HEADER = (f"{'round':>5}  {'kind':<5}  {'folds before -> after':>21}  {'iterations':>10}  "
                 f"{'energy/4pi':>10}  {'angle dist. (deg)':>17}  {'seconds':>8}")


def format_round(row):
    """One line of the per-round table (see :func:`igl_spheremap.map_file.round_row`)."""
    folds = f"{row['folds_before']:>10} -> {row['folds_after']:<7}"
    return (f"{row['round']:>5}  {row['kind']:<5}  {folds:>21}  {row['nit']:>10}  "
            f"{row['energy_over_4pi']:>10.5f}  {row['angle_distortion_mean_deg']:>17.3f}  "
            f"{row['seconds']:>8.2f}")


def _cmd_map(args):
    from .map_file import map_file

    with ExitStack() as stack:
        mesh = args.mesh
        if mesh is None:
            mesh = stack.enter_context(resources.as_file(
                resources.files("igl_spheremap") / "data" / "dino.obj"))
        header = []

        def on_round(row):
            if not header:
                header.append(True)
                _say(args, _ROUND_HEADER)
            _say(args, format_round(row))

        rep = map_file(mesh, args.output, report=args.json, data=args.data,
                       on_round=on_round, progress=_show_progress(args), **_map_options(args))
    outs = [p for p in (rep["outputs"]["sphere"], rep["outputs"]["data"],
                        rep["outputs"]["report"]) if p]
    _say(args, f"{rep['vertices']} vertices, {rep['faces']} faces: folds {rep['folds']}, "
               f"converged {'yes' if rep['converged'] else 'no'}, "
               f"centroid norm {rep['centroid_norm']:.2e}, {rep['timings']['total']:.2f} s -> "
               + ", ".join(outs))
    if rep["success"]:
        return EXIT_OK
    problems = []
    if rep["folds"]:
        problems.append(f"{rep['folds']} folded faces")
    if not rep["converged"]:
        problems.append("the optimizer did not converge")
    _warn(f"warning: {' and '.join(problems)} ({rep['message']}); outputs were written"
          + ("" if args.allow_folds else "; exit code 3 (--allow-folds exits 0)"))
    return EXIT_OK if args.allow_folds else EXIT_NOT_FOLD_FREE


def mesh_error_text(exc):
    """One-line text of a MeshError without a leading 'invalid mesh (problem):' of its own."""
    from .io._stderr import one_line

    return re.sub(r"^invalid mesh(\s*\([^)]*\))?:\s*", "", one_line(str(exc)), flags=re.I)


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


def _cmd_batch(args):
    from .batch import map_batch, summary_markdown

    def on_result(row):
        if row["status"] == "failed":
            _warn(f"failed: {row['mesh']}: {row['message']}")

    if args.scheduler and args.workers is not None:
        _warn("warning: --workers is ignored with --scheduler")
    rows = map_batch(args.inputs, args.outdir, scheduler=args.scheduler, n_workers=args.workers,
                     resume=args.resume, data=args.data, progress=_show_progress(args),
                     on_result=on_result, **_map_options(args))
    _say(args, summary_markdown(rows).rstrip())
    counts = {s: sum(r["status"] == s for r in rows) for s in ("ok", "warning", "skipped",
                                                                 "failed")}
    _say(args, ", ".join(f"{n} {s}" for s, n in counts.items()) +
         f"; summary in {args.outdir.rstrip('/')}/summary.csv and summary.md")
    code = batch_exit_code(rows, args.allow_folds)
    if code == EXIT_NOT_FOLD_FREE:
        _warn("warning: some maps have folded faces or did not converge (see the summary); "
              "exit code 3 (--allow-folds exits 0)")
    return code


def main(argv=None):
    """Entry point of ``igl-spheremap``; returns the exit code.

    Parameters
    ----------
    argv : list of str, optional
        Arguments without the program name (default ``sys.argv[1:]``).  ``map``
        is inserted when the first one is not a subcommand or a top-level flag.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] not in SUBCOMMANDS + ("-h", "--help", "--version"):
        argv.insert(0, "map")
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else EXIT_ERROR
    from .errors import MeshError
    from .io._stderr import one_line

    try:
        return args.func(args)
    except MeshError as exc:
        if args.debug:
            raise
        _warn(f"invalid mesh: {mesh_error_text(exc)}")
        return EXIT_INVALID_MESH
    except KeyboardInterrupt:
        _warn("interrupted")
        return 130
    except Exception as exc:
        if args.debug:
            raise
        msg = one_line(str(exc))
        if not isinstance(exc, (OSError, ValueError)) or not msg:
            msg = f"{type(exc).__name__}: {msg}" if msg else type(exc).__name__
        _warn(f"error: {msg}")
        return EXIT_ERROR


if __name__ == "__main__":
    sys.exit(main())
