"""Point location on a spherical map: locate_on_sphere vs a plain libigl distance query.

The spherical map of a mesh (``spherical_conformal_map``, ~30k vertices by
default: the HCP 32k midthickness surface) is computed once; then the vertices
of ``icosphere(level)`` (level 7: 163,842 points, the fsaverage template size)
are located on it with ``igl_spheremap.locate_on_sphere.locate_on_sphere``
(validation of the map, AABB candidate, cone test, walk) and, in turn, with a
plain ``igl.point_mesh_squared_distance(P, U, F)`` call (nearest face of the
chordal mesh: what locate_on_sphere starts from, without checks or the cone
correction).  ``--repeats`` alternating rounds (locate, libigl, locate, ...);
the fastest of each counts and the ratio is reported.  Also counted: points
whose located face differs from libigl's nearest face.

Usage::

    python benchmarks/locate.py --mesh /work/shared/meshes/hcp_s1200_midthickness_left_32k.obj
    python benchmarks/locate.py --mesh MESH --level 7 --repeats 5 --out DIR

Writes DIR/locate.md and DIR/locate.json (default benchmarks/results/).
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import (DEFAULT_MESH_DIR, DEFAULT_OUT, environment, environment_line,  # noqa: E402
                     load_mesh, markdown_table, mesh_name, write_outputs)

COLUMNS = [
    ("mesh", "mesh", "", "l"),
    ("map vertices", "vertices", ",", "r"),
    ("points", "points", ",", "r"),
    ("locate_on_sphere (s)", "locate_seconds", ".3f", "r"),
    ("igl.point_mesh_squared_distance (s)", "igl_seconds", ".3f", "r"),
    ("ratio", "ratio", ".2f", "r"),
    ("faces differing from libigl's nearest", "differing", ",", "r"),
]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mesh", default=str(DEFAULT_MESH_DIR / "hcp_s1200_midthickness_left_32k.obj"))
    ap.add_argument("--level", type=int, default=7, help="icosphere level of the points")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", default=str(DEFAULT_OUT))
    args = ap.parse_args(argv)

    import igl
    import igl_spheremap
    from igl_spheremap.resampling import icosphere
    from igl_spheremap.point_location import locate_on_sphere

    V, F = load_mesh(args.mesh)
    U = igl_spheremap.spherical_conformal_map(V, F).U
    P, _ = icosphere(args.level)
    times = {"locate": [], "igl": []}
    for _ in range(args.repeats):
        t = time.perf_counter()
        face, _ = locate_on_sphere(U, F, P)
        times["locate"].append(time.perf_counter() - t)
        t = time.perf_counter()
        nearest = igl.point_mesh_squared_distance(P, U, F)[1]
        times["igl"].append(time.perf_counter() - t)
    row = dict(mesh=mesh_name(args.mesh), vertices=V.shape[0], points=P.shape[0],
               locate_seconds=min(times["locate"]), igl_seconds=min(times["igl"]),
               differing=int(np.count_nonzero(face != nearest)), all_seconds=times)
    row["ratio"] = row["locate_seconds"] / row["igl_seconds"]
    env = environment()
    markdown = "\n\n".join([
        "# Point location on a spherical map",
        f"Vertices of `icosphere({args.level})` located on the conformal map of the mesh; fastest of "
        f"{args.repeats} alternating calls each. *ratio* = locate_on_sphere / "
        "igl.point_mesh_squared_distance.",
        markdown_table([row], COLUMNS),
        "Command: `python benchmarks/locate.py" + "".join(f" {a}" for a in (argv or sys.argv[1:])) + "`",
        environment_line(env)])
    md, js = write_outputs(args.out, "locate", markdown, dict(environment=env, level=args.level,
                                                               repeats=args.repeats, row=row))
    print(markdown)
    print(f"wrote {md} and {js}")


if __name__ == "__main__":
    main()
