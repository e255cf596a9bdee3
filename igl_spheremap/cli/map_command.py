"""``igl-spheremap [map] [MESH] [-o OUT]``: map one mesh and print a table of the rounds."""

import argparse
from contextlib import ExitStack
from importlib import resources

from ..errors import plural
from .common import (EXIT_CODES, EXIT_NOT_FOLD_FREE, EXIT_OK, common_arguments, map_options,
                     say, show_progress, warn)

#: ``energy/4pi``: the energy the round lowered: harmonic with the run's Laplacian (intrinsic
#: Delaunay by default) for Algorithm 2's rounds, the conformal distortion for the guaranteed
#: path's.
_ROUND_HEADER = (f"{'round':>5}  {'kind':<13}  {'folds before -> after':>21}  {'iterations':>10}  "
                 f"{'energy/4pi':>10}  {'angle dist. (deg)':>17}  {'seconds':>8}")


def add_parser(sub):
    p = sub.add_parser(
        "map", parents=[common_arguments()], formatter_class=argparse.RawDescriptionHelpFormatter,
        help="map one mesh onto the sphere (default)",
        description="Map one closed genus-0 mesh onto the sphere; print a table of the "
                    "rounds and a summary.\nWith no MESH, maps the bundled dino.obj.",
        epilog="Output names: without -o the sphere is <stem>_sphere.<ext> in the current "
               "directory\n(dino.obj -> dino_sphere.obj, lh.white -> lh.white_sphere, "
               "x.surf.gii -> x_sphere.surf.gii;\n.obj after an .stl, .wrl, .mesh or .msh "
               "input, which cannot store the sphere);\nits format follows the -o name "
               "(.obj/.off/.ply, .surf.gii, ?h.* FreeSurfer) or the input's.\n\n"
               + EXIT_CODES)
    p.add_argument("mesh", nargs="?", metavar="MESH",
                   help="input mesh (default: the bundled dino.obj)")
    p.add_argument("-o", "--output", metavar="OUT", help="sphere to write")
    p.add_argument("--json", metavar="REPORT", help="write a JSON report of the run")
    p.add_argument("--kind", choices=("conformal", "area_balanced"), default="conformal",
                   help="conformal (default): the paper's map; area_balanced: the conformal map "
                        "relaxed toward low area and edge-length distortion, a sphere made for "
                        "registration and resampling (register-sphere's start)")
    p.set_defaults(func=run)


def format_round(row):
    """One line of the per-round table (see :func:`igl_spheremap.app.report.round_row`).

    *folds before* is what the round started from: the previous round's result
    (the Gauss map for round 0).
    """
    before = row["folds_before"] if row.get("folds_previous") is None else row["folds_previous"]
    folds = f"{before:>10} -> {row['folds_after']:<7}"
    return (f"{row['round']:>5}  {row['kind']:<13}  {folds:>21}  {row['nit']:>10}  "
            f"{row['energy_over_4pi']:>10.5f}  {row['angle_distortion_mean_deg']:>17.3f}  "
            f"{row['seconds']:>8.2f}")


def repair_line(rep):
    """The line saying what the float32 repair did to the map the rounds made.

    The rounds' map is the round the map came from (``chosen``), or, where that is the
    polish (which runs after the repair, from the repaired map), the last round before it.
    """
    repair, rounds = rep["repair"], rep["rounds"][:rep.get("chosen", len(rep["rounds"])) + 1]
    made = [row for row in rounds if row["kind"] != "polish"]
    last = f" (the rounds' map: {made[-1]['angle_distortion_mean_deg']:.3f} deg)" if made else ""
    seconds = rep["timings"].get("map_repair", 0.0)
    return (f"{rep['precision']} repair: {repair['summary']}; angle distortion of the map written "
            f"{rep['angle_distortion_mean_deg']:.3f} deg{last}, {seconds:.2f} s")


def run(args):
    from ..app.map_file import map_file

    with ExitStack() as stack:
        mesh = args.mesh
        if mesh is None:
            mesh = stack.enter_context(resources.as_file(
                resources.files("igl_spheremap") / "data" / "dino.obj"))
        header = []

        def on_round(row):
            if not header:
                header.append(True)
                say(args, _ROUND_HEADER)
            say(args, format_round(row))

        rep = map_file(mesh, args.output, options=map_options(args), report=args.json,
                       data=args.data, radius=args.radius, file_precision=args.file_precision,
                       hemisphere=args.hemisphere, on_round=on_round, progress=show_progress(args),
                       kind=args.kind)
    if rep["input_polygons"]:
        say(args, f"note: {rep['validation_notes'][0]}")
    if rep["reorientation"]:
        say(args, f"note: {rep['reorientation']}; the sphere is written with the faces as "
                  "re-oriented")
    if rep["repair"] is not None:
        say(args, repair_line(rep))
    outs = [p for p in (rep["outputs"]["sphere"], rep["outputs"]["data"],
                        rep["outputs"]["report"]) if p]
    say(args, f"{rep['vertices']} vertices, {rep['faces']} faces: folds {rep['folds']} "
              f"(in the file {rep['folds_stored']}), "
              f"converged {'yes' if rep['converged'] else 'no'}, "
              f"angle distortion {rep['angle_distortion_mean_deg']:.3f} deg, "
              f"centroid norm {rep['centroid_norm']:.2e}, {rep['timings']['total']:.2f} s -> "
              + ", ".join(outs))
    if rep["success"]:
        return EXIT_OK
    problems = []
    if rep["folds"]:
        problems.append(plural(rep["folds"], "folded face"))
    elif rep["folds_stored"]:
        problems.append(f"{plural(rep['folds_stored'], 'folded face')} in the file written")
    if not rep["converged"]:
        problems.append("the optimizer did not converge")
    warn(f"warning: {' and '.join(problems)} ({rep['message']}); outputs were written"
         + ("" if args.allow_folds else "; exit code 3 (--allow-folds exits 0)"))
    return EXIT_OK if args.allow_folds else EXIT_NOT_FOLD_FREE
