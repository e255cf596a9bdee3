"""The README results table: the default pipeline on every mesh of a folder.

For every mesh, ``igl_spheremap.spherical_conformal_map(V, F)`` (default
method) runs in a fresh child process (benchmarks/_common.py) and the table
lists vertices, folding-removal rounds, folds, mean/SD angle distortion
(degrees), harmonic energy / 4π (cotangent Laplacian), image centroid norm,
whether Algorithm 1 converged, and seconds.

Usage::

    python benchmarks/results_table.py                     # ../shared/meshes
    python benchmarks/results_table.py MESH_DIR --out FILE.md --timeout 900

Writes FILE (markdown, default benchmarks/results/results_table.md) and the
same rows as JSON next to it (FILE with suffix .json), and prints the markdown.
"""

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import (DEFAULT_MESH_DIR, DEFAULT_OUT, environment, environment_line,  # noqa: E402
                     fmt, markdown_table, mesh_paths, run_case, status_cell, write_outputs)

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
Algorithm 1 over the rings around them); *folds* = image
triangles with signed volume <= 0 (`count_folds`); *angle* = |image corner
angle - mesh corner angle| over all corners (`angle_distortion`, flat image
triangles); *energy/4π* = harmonic energy with the cotangent Laplacian of the
input over 4π (1 for a conformal bijection); *centroid norm* = |area-weighted
image centroid| (0 after Möbius normalization); *converged* = the last
Algorithm 1 run met its stopping rule; *seconds* = wall time of the call, the
best of 3 calls when one takes under 10 s (each mesh in a fresh process;
loading not timed)."""


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("mesh_dir", nargs="*", metavar="MESH_DIR",
                   help=f"folder(s) or files of meshes (default: {DEFAULT_MESH_DIR})")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT / "results_table.md", metavar="FILE",
                   help="markdown output; JSON goes next to it (default: %(default)s)")
    p.add_argument("--timeout", type=float, default=900.0, metavar="S",
                   help="wall-clock limit per mesh, in seconds (default: %(default)s)")
    return p.parse_args(argv)


def render(rows, env):
    columns = list(COLUMNS)
    if any(r.get("status") != "ok" for r in rows):
        columns.append(("status", status_cell, "", "l"))
    parts = ["# Results: default pipeline on the test meshes", "", environment_line(env), "",
             markdown_table(rows, columns), "", LEGEND]
    return "\n".join(parts)


def main(argv=None):
    args = parse_args(argv)
    paths = mesh_paths(args.mesh_dir)
    env = environment()
    rows = []
    t_start = time.perf_counter()
    out = args.out.with_suffix("")
    for path in paths:
        row = run_case(path, "default", {}, timeout=args.timeout)
        rows.append(row)
        print(f"[{time.perf_counter() - t_start:7.1f} s] {row['mesh']:>36}: {row['status'][:60]}, "
              f"{fmt(row.get('seconds'), '.2f')} s, rounds {fmt(row.get('rounds'))}, "
              f"folds {fmt(row.get('folds'))}", file=sys.stderr, flush=True)
        markdown = render(rows, env)
        write_outputs(out.parent, out.name, markdown, dict(environment=env, rows=rows))
    print(markdown)
    return 0


if __name__ == "__main__":
    sys.exit(main())
