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

import argparse
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import (DEFAULT_OUT, environment, environment_line, load_mesh,  # noqa: E402
                     mesh_name, mesh_paths, write_outputs)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("meshes", nargs="*")
    ap.add_argument("--gtol", type=float, nargs="+", default=[1e-5, 1e-4, 1e-3])
    ap.add_argument("--out", default=str(DEFAULT_OUT))
    args = ap.parse_args(argv)
    import igl_spheremap as sm

    env = environment()
    rows = []
    for path in mesh_paths(args.meshes):
        V, F = load_mesh(path)
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
            print(rows[-1], flush=True)
    lines = [environment_line(env), "", "`python benchmarks/gtol_sweep.py`; CPU seconds.", "",
             "| mesh | gtol | rounds | iterations | folds | angle mean (°) | CPU s |",
             "|---|---:|---|---:|---:|---:|---:|"]
    lines += [f"| {r['mesh']} | {r['gtol']:g} | {r['rounds']} | {r['nit']} | {r['folds']} | "
              f"{r['angle']:.4f} | {r['seconds']:.2f} |" for r in rows]
    write_outputs(args.out, "gtol_sweep", "\n".join(lines), dict(environment=env, rows=rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
