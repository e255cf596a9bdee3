"""The area-balanced sphere on each mesh: how far the relaxation gets from the conformal map, and why it stops.

For every mesh, ``igl_spheremap.spherical_conformal_map(V, F, kind="area_balanced",
precision=...)`` (float32 by default, as ``register_surface`` makes it): the conformal map,
then the relaxation of the symmetric Dirichlet energy under the fold barrier
(``igl_spheremap.optimize.area_balanced``).  Columns: *success*; the relaxation's
iterations and why it stopped (*gradient*: the RMS Riemannian gradient at most ``GTOL``;
*stall*: the energy fell by less than ``FTOL`` over two chunks; *max_iter*; *not
area-balanced*: stopped by one of the first two with more than ``CRUSHED_SHARE`` of the area
crushed); the mean |log area ratio| per face (``igl_spheremap.area_distortion``, both sides
normalized to area 1) of the conformal map (the relaxation's start, ``rounds[-1].U_init``)
and of the area-balanced one; *crushed*: the share of the surface's area on faces below
``CRUSHED_RATIO`` of their share of the sphere (``area_balanced.crushed_share``); ``E / 8 pi``
of the symmetric Dirichlet energy (1 for an isometry) at the end; the vertices the barrier
froze; folds; seconds of the whole call.

Usage::

    python benchmarks/area_balanced.py               # the shared meshes up to 40,000 vertices
    python benchmarks/area_balanced.py MESH_OR_DIR ... --precision float64 --out DIR

Writes DIR/area_balanced.md and DIR/area_balanced.json (default benchmarks/results/).
"""

import sys
import time
import warnings

import numpy as np

from harness import (arguments, command, load_mesh, markdown_table, mesh_name, mesh_paths, page,
                     parse, run)

COLUMNS = [
    ("mesh", "mesh", "", "l"),
    ("vertices", "vertices", ",", "r"),
    ("success", "success", "", "l"),
    ("iterations", "iterations", ",", "r"),
    ("stopped by", "stop", "", "l"),
    ("mean abs log area ratio, conformal", "area_conformal", ".3f", "r"),
    ("area-balanced", "area_balanced", ".3f", "r"),
    ("crushed", "crushed", ".3f", "r"),
    ("E / 8π", "energy", ".4g", "r"),
    ("frozen", "frozen", ",", "r"),
    ("folds", "folds", ",", "r"),
    ("seconds", "seconds", ".2f", "r"),
]


def stop_reason(run):
    """Why the relaxation stopped, in the words of the module docstring."""
    for start, reason in (("RMS Riemannian gradient", "gradient"),
                          ("energy decreased by less than", "stall"),
                          ("not area-balanced", "not area-balanced"),
                          ("reached max_iter", "max_iter")):
        if run.message.startswith(start):
            return reason
    return run.message.split(":")[0][:40]


def run_mesh(path, precision, max_vertices):
    """The row of one mesh (none for a mesh above ``max_vertices``)."""
    import igl_spheremap as sm
    from igl_spheremap.optimize.area_balanced import crushed_share

    V, F = load_mesh(path)
    if V.shape[0] > max_vertices:
        return []
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sm.SphericalMapWarning)
        result = sm.spherical_conformal_map(V, F, kind="area_balanced", precision=precision)
    seconds = time.perf_counter() - t
    row = dict(mesh=mesh_name(path), vertices=V.shape[0], success=result.success,
               folds=result.folds, seconds=seconds)
    last = result.rounds[-1]
    if last.kind != "area_balanced":  # the conformal map folded: no relaxation
        return dict(row, stop=f"no relaxation: {result.message[:60]}")
    run = last.run
    return dict(row, iterations=run.nit, stop=stop_reason(run),
                area_conformal=float(np.abs(sm.area_distortion(V, F, last.U_init)).mean()),
                area_balanced=float(np.abs(sm.area_distortion(V, F, result.U)).mean()),
                crushed=crushed_share(V, result.F, result.U), energy=run.energy / (8 * np.pi),
                frozen=run.frozen)


def render(rows, env, args):
    return page(
        "The area-balanced sphere: from the conformal map, and why the relaxation stops", env,
        f"`spherical_conformal_map(V, F, kind=\"area_balanced\", precision=\"{args.precision}\")` "
        "on each mesh (meshes above "
        f"{args.max_vertices:,} vertices skipped). Area distortion: mean |log area ratio| per "
        "face, both sides normalized to total area 1, of the conformal map the relaxation starts "
        "from and of the area-balanced sphere; *crushed*: the share of the surface's area on "
        "faces below 1% of their share of the sphere (above 0.1 the relaxation has not "
        "converged); *E / 8π*: the symmetric Dirichlet energy at the end (1 for an isometry); "
        "*frozen*: the most vertices the fold barrier froze in one chunk of 25 iterations.",
        markdown_table(rows, COLUMNS), command("area_balanced", args))


def main(argv=None):
    p = arguments(__doc__)
    p.add_argument("--precision", default="float32", choices=("float32", "float64"),
                   help="the map's precision (default: %(default)s, as register_surface)")
    p.add_argument("--max-vertices", type=int, default=40_000, metavar="N",
                   help="skip meshes with more vertices (default: %(default)s)")
    args = parse(p, argv)
    run("area_balanced", args, mesh_paths(args.meshes),
        lambda path: run_mesh(path, args.precision, args.max_vertices), render,
        echo=lambda r: f"{r['mesh']}: {r['stop']}, {r['seconds']:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
