"""Point location on a spherical map: locate_on_sphere vs a plain libigl distance query.

The spherical map of a mesh (``spherical_conformal_map``, ~30k vertices by
default: the HCP 32k midthickness surface) is computed once; then the vertices
of ``icosphere(level)`` (level 7: 163,842 points, the fsaverage template size)
are located on it with ``igl_spheremap.sphere.locate.locate_on_sphere``
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

import sys
import time

import numpy as np

from harness import (DEFAULT_MESH_DIR, arguments, command, load_mesh, markdown_table, mesh_name,
                     page, parse, run)

COLUMNS = [
    ("mesh", "mesh", "", "l"),
    ("map vertices", "vertices", ",", "r"),
    ("points", "points", ",", "r"),
    ("locate_on_sphere (s)", "locate_seconds", ".3f", "r"),
    ("igl.point_mesh_squared_distance (s)", "igl_seconds", ".3f", "r"),
    ("ratio", "ratio", ".2f", "r"),
    ("faces differing from libigl's nearest", "differing", ",", "r"),
]


def measure(mesh, args):
    """The map of ``mesh``, then both locators alternating on the icosphere's vertices."""
    import igl

    import igl_spheremap
    from igl_spheremap.mesh.shapes import icosphere
    from igl_spheremap.sphere.locate import locate_on_sphere

    V, F = load_mesh(mesh)
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
    row = dict(mesh=mesh_name(mesh), vertices=V.shape[0], points=P.shape[0],
               locate_seconds=min(times["locate"]), igl_seconds=min(times["igl"]),
               differing=int(np.count_nonzero(face != nearest)), all_seconds=times)
    row["ratio"] = row["locate_seconds"] / row["igl_seconds"]
    return row


def render(rows, env, args):
    return page("Point location on a spherical map", env,
                f"Vertices of `icosphere({args.level})` located on the conformal map of the mesh; "
                f"fastest of {args.repeats} alternating calls each. *ratio* = locate_on_sphere / "
                "igl.point_mesh_squared_distance.",
                markdown_table(rows, COLUMNS), command("locate", args))


def main(argv=None):
    p = arguments(__doc__, meshes=None, repeats=5)
    p.add_argument("--mesh", default=str(DEFAULT_MESH_DIR / "hcp_s1200_midthickness_left_32k.obj"))
    p.add_argument("--level", type=int, default=7, help="icosphere level of the points")
    args = parse(p, argv)
    run("locate", args, [args.mesh], lambda mesh: measure(mesh, args), render,
        payload=lambda rows: dict(level=args.level, repeats=args.repeats, row=rows[-1]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
