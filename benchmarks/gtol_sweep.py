"""How the stopping tolerance ``gtol`` of Algorithm 1 changes the default map.

For every mesh of a folder, ``spherical_conformal_map(V, F, gtol=g)`` for each
``g`` of ``--gtol`` in one process (CPU time, one BLAS thread): folds, Algorithm 1
iterations, round kinds, mean angle distortion (degrees, over corners, against
the input) and seconds.  The default is 1e-5 (README, "How the default differs
from the paper", item 4).

Usage::

    python benchmarks/gtol_sweep.py                       # ../shared/meshes
    python benchmarks/gtol_sweep.py MESH_OR_DIR ... --gtol 1e-5 1e-4 1e-3 --out DIR
"""

import sys
import time
import warnings

from harness import arguments, load_mesh, mesh_name, mesh_paths, page, parse, run


def measure_mesh(path, args):
    """The default map for every ``--gtol`` on one mesh, in this process (CPU seconds)."""
    import igl_spheremap as sm
    V, F = load_mesh(path)
    rows = []
    for g in args.gtol:
        t = time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", sm.SphericalMapWarning)
            r = sm.spherical_conformal_map(V, F, gtol=g)
        seconds = time.process_time() - t
        rows.append(dict(mesh=mesh_name(path), gtol=g, folds=r.folds, nit=r.nit,
                         rounds=" + ".join(x.kind for x in r.rounds),
                         angle=float(sm.angle_distortion(V, r.F, r.U).mean()),
                         seconds=seconds, success=r.success))
    return rows


def render(rows, env, args):
    lines = ["| mesh | gtol | rounds | iterations | folds | angle mean (°) | CPU s |",
             "|---|---:|---|---:|---:|---:|---:|"]
    lines += [f"| {r['mesh']} | {r['gtol']:g} | {r['rounds']} | {r['nit']} | {r['folds']} | "
              f"{r['angle']:.4f} | {r['seconds']:.2f} |" for r in rows]
    return page("Stopping tolerance: the default map for each gtol", env,
                "`python benchmarks/gtol_sweep.py`; CPU seconds.", "\n".join(lines))


def main(argv=None):
    p = arguments(__doc__)
    p.add_argument("--gtol", type=float, nargs="+", default=[1e-5, 1e-4, 1e-3])
    args = parse(p, argv)
    run("gtol_sweep", args, mesh_paths(args.meshes), lambda path: measure_mesh(path, args),
        render, echo=str)
    return 0


if __name__ == "__main__":
    sys.exit(main())
