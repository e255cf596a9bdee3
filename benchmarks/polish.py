"""What ``polish="always"`` buys and costs: the default map and the polished one, side by side.

For every mesh (default: ../shared/meshes) and precision (``--precisions``, default
float64 and float32), ``spherical_conformal_map(V, F, precision=...)`` and the same with
``polish="always"`` run alternately, each in a fresh child process
(``methods.run_case``, the timing protocol of the other scripts: the best of 3 calls
when one takes under 10 s).  Columns: mean angle distortion (degrees,
``angle_distortion``) of each map as returned, the seconds of each, their ratio, the
folds of the polished map, and the rounds' kinds of the polished run (``polish`` last
when the conformal descent ran from the accepted map).

Usage::

    python benchmarks/polish.py                                   # ../shared/meshes
    python benchmarks/polish.py ../shared/corpus --precisions float32 --out DIR
"""

import sys

from harness import arguments, command, fmt, markdown_table, mesh_paths, page, parse, run
from methods import run_case

COLUMNS = [
    ("mesh", "mesh", "", "l"),
    ("vertices", "vertices", ",", "r"),
    ("precision", "precision", "", "l"),
    ("angle (°)", "angle_default", ".3f", "r"),
    ("polished (°)", "angle_polish", ".3f", "r"),
    ("seconds", "seconds_default", ".2f", "r"),
    ("polished s", "seconds_polish", ".2f", "r"),
    ("ratio", "ratio", ".1f", "r"),
    ("folds", "folds", "", "r"),
    ("rounds (polished run)", "kinds", "", "l"),
    ("status", "status", "", "l"),
]

LEGEND = """\
*angle* = mean |image corner angle - mesh corner angle| over all corners
(`angle_distortion`, flat image triangles) of the map as returned; *polished* = the same
call with `polish="always"`; *seconds* = wall time of the call (best of 3 under 10 s), each
in a fresh process, the two alternating; *ratio* = polished seconds over default
seconds; *folds* = folded faces of the polished map (`count_folds`); *rounds* = kinds of
the polished run's rounds (`polish` last: the conformal descent ran from the accepted
map; the map is the descent's only where it lowered the angle distortion)."""


def parse_args(argv=None):
    p = arguments(__doc__, timeout=900.0)
    p.add_argument("--precisions", nargs="+", choices=("float64", "float32"),
                   default=["float64", "float32"], help="precisions (default: both)")
    return parse(p, argv)


def measure(path, args):
    """One row per precision: the default and the polished call on one mesh."""
    rows = []
    for precision in args.precisions:
        opts = dict(precision=precision)
        d = run_case(path, "default", opts, timeout=args.timeout)
        p = run_case(path, "polish", opts, timeout=args.timeout)
        ok = d["status"] == "ok" and p["status"] == "ok"
        rows.append(dict(
            mesh=d["mesh"], vertices=d.get("vertices"), precision=precision,
            angle_default=d.get("angle_mean"), angle_polish=p.get("angle_mean"),
            seconds_default=d.get("seconds"), seconds_polish=p.get("seconds"),
            ratio=p["seconds"] / d["seconds"] if ok else None, folds=p.get("folds"),
            kinds=" ".join((p.get("extra") or {}).get("round_kinds", [])),
            status="ok" if ok else f"default: {d['status']}; polish: {p['status']}",
            message_polish=p.get("message")))
    return rows


def render(rows, env, args):
    return page("Polish: the conformal descent from the accepted map", env,
                command("polish", args), markdown_table(rows, COLUMNS), LEGEND)


def echo(row):
    return (f"{row['mesh']:>32} {row['precision']}: {fmt(row['angle_default'], '.3f')} -> "
            f"{fmt(row['angle_polish'], '.3f')} deg, {fmt(row['seconds_default'], '.2f')} -> "
            f"{fmt(row['seconds_polish'], '.2f')} s")


def main(argv=None):
    args = parse_args(argv)
    run("polish", args, mesh_paths(args.meshes), lambda path: measure(path, args), render,
        echo=echo)
    return 0


if __name__ == "__main__":
    sys.exit(main())
