"""The README results table: the default pipeline on every mesh of a folder.

For every mesh, ``igl_spheremap.spherical_conformal_map(V, F)`` (default
method) runs in a fresh child process (``methods.run_case``) and the table
lists vertices, folding-removal rounds, folds, mean/SD angle distortion
(degrees), harmonic energy / 4π (cotangent Laplacian), image centroid norm,
whether Algorithm 1 converged, and seconds.

Usage::

    python benchmarks/results_table.py                     # ../shared/meshes
    python benchmarks/results_table.py MESH_DIR --out FILE.md --timeout 900

Writes FILE (markdown, default benchmarks/results/results_table.md) and the
same rows as JSON next to it (FILE with suffix .json), and prints the markdown.
"""

import sys
from pathlib import Path

from harness import (DEFAULT_MESH_DIR, DEFAULT_OUT, arguments, fmt, markdown_table, mesh_paths,
                     page, parse, run, status_cell)
from methods import run_case


def rounds_cell(row):
    """Folding-removal rounds and their kinds, e.g. ``1 (local)``."""
    if row.get("rounds") is None:
        return "–"
    kinds = (row.get("extra") or {}).get("round_kinds", [])[1:]
    return f"{row['rounds']} ({', '.join(kinds)})" if kinds else str(row["rounds"])


COLUMNS = [
    ("mesh", "mesh", "", "l"),
    ("vertices", "vertices", ",", "r"),
    ("rounds", rounds_cell, "", "r"),
    ("folds", "folds", ",", "r"),
    ("angle mean (°)", "angle_mean", ".3f", "r"),
    ("angle SD (°)", "angle_sd", ".3f", "r"),
    ("energy/4π", "energy_4pi", ".5f", "r"),
    ("centroid norm", "centroid_norm", ".1e", "r"),
    ("converged", "converged", "", "l"),
    ("seconds", "seconds", ".2f", "r"),
]

LEGEND = """\
Default pipeline, `igl_spheremap.spherical_conformal_map(V, F)`.  *rounds* =
folding-removal rounds after the Gauss-map stage and their kind: *star* (star
map, then Algorithm 1) or *local* (the few isolated folds untangled, then
Algorithm 1 over the rings around them), and *polish* (the conformal descent
from a map the fold barrier partly held); *folds* = image
triangles with signed volume <= 0 (`count_folds`); *angle* = |image corner
angle - mesh corner angle| over all corners (`angle_distortion`, flat image
triangles); *energy/4π* = harmonic energy with the cotangent Laplacian of the
input over 4π (1 for a conformal bijection); *centroid norm* = |area-weighted
image centroid| (0 after Möbius normalization); *converged* = the last
Algorithm 1 run met its stopping rule; *seconds* = wall time of the call, the
best of 3 calls when one takes under 10 s (each mesh in a fresh process;
loading not timed)."""


def parse_args(argv=None):
    p = arguments(__doc__, out=None, timeout=900.0,
                  mesh_help=f"folder(s) or files of meshes (default: {DEFAULT_MESH_DIR})")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT / "results_table.md", metavar="FILE",
                   help="markdown output; JSON goes next to it (default: %(default)s)")
    return parse(p, argv)


def render(rows, env, args):
    columns = list(COLUMNS)
    if any(r.get("status") != "ok" for r in rows):
        columns.append(("status", status_cell, "", "l"))
    return page("Results: default pipeline on the test meshes", env,
                markdown_table(rows, columns), LEGEND)


def echo(row):
    return (f"{row['mesh']:>36}: {row['status'][:60]}, {fmt(row.get('seconds'), '.2f')} s, "
            f"rounds {fmt(row.get('rounds'))}, folds {fmt(row.get('folds'))}")


def main(argv=None):
    args = parse_args(argv)
    run(args.out.with_suffix("").name, args, mesh_paths(args.meshes),
        lambda path: run_case(path, "default", {}, timeout=args.timeout), render, echo=echo,
        out=args.out.parent)
    return 0


if __name__ == "__main__":
    sys.exit(main())
