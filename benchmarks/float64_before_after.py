"""The default (float64) map with two checkouts of the library: did a change alter it?

For each mesh, the default ``spherical_conformal_map(V, F)`` runs with the
library of ``--before`` and of ``--after`` (each a repository root: a fresh
``python`` process started in that folder with it first on ``PYTHONPATH``), the
two in turn ``--alternate`` times, on the same input arrays (read once, here); in
a process the call is repeated while it takes under 10 s (at most 3 calls) and
the fastest call of all counts.  Reported: seconds, ratio after / before, folds,
mean angle distortion after Möbius centering with the input's vertex areas
(``harness.quality_row``, this checkout's measure for both maps), and whether the
two maps are identical bit for bit.  ``tests/test_slow_acceptance.py`` runs the
same comparison as a test (``IGL_SPHEREMAP_BEFORE=ROOT python -m pytest -m slow``).

Usage::

    python benchmarks/float64_before_after.py --before /path/to/main --after . \\
        [--mesh-dir ../shared/meshes] dino horse pycortex_s1_pia_lh human_woman scorpion_lowres

Writes ``DIR/float64_before_after.md`` and ``.json`` (default ``benchmarks/results/``).
"""

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from harness import (DEFAULT_MESH_DIR, arguments, load_mesh, markdown_table, page, parse,
                     quality_row, run)

#: The child: argv = mesh .npz (V, F), output .npz (U, F), calls at most; prints a JSON line.
CHILD = r"""
import json, sys, time, warnings
import numpy as np
import igl_spheremap as sm
with np.load(sys.argv[1]) as d:
    V, F = d["V"], d["F"]
times, r = [], None
for _ in range(int(sys.argv[3])):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = time.perf_counter()
        out = sm.spherical_conformal_map(V, F)
        times.append(time.perf_counter() - t)
    r = r or out
    if times[-1] > 10.0:
        break
np.savez(sys.argv[2], U=r.U, F=r.F)
print(json.dumps(dict(seconds=min(times), folds=int(r.folds), success=bool(r.success),
                      library=sm.__file__)))
"""

COLUMNS = [("mesh", "mesh", "", "l"), ("before s", "seconds_before", ".2f", "r"),
           ("after s", "seconds_after", ".2f", "r"), ("after / before", "ratio", ".2f", "r"),
           ("folds before", "folds_before", "", "r"), ("folds after", "folds_after", "", "r"),
           ("angle before (°)", "angle_before", ".3f", "r"),
           ("angle after (°)", "angle_after", ".3f", "r"),
           ("identical map", "identical", "", "l")]


def map_with(root, mesh_npz, out_npz, calls=3, timeout=1800):
    """The default map of the mesh in ``mesh_npz`` by the library of the checkout ``root``.

    Runs :data:`CHILD` in a fresh ``python -c`` process in ``root`` (``python -c`` puts
    the current folder first on the module search path, before ``PYTHONPATH`` and
    installed packages).  Writes the map to ``out_npz`` (``U``, ``F``) and returns the child's
    ``seconds`` (fastest call), ``folds``, ``success`` and ``library`` (the imported
    ``__init__.py``, to check which checkout ran).
    """
    env = dict(os.environ, PYTHONPATH=str(root))
    out = subprocess.run([sys.executable, "-c", CHILD, str(mesh_npz), str(out_npz), str(calls)],
                         env=env, cwd=str(root), capture_output=True, text=True, check=True,
                         timeout=timeout)
    return json.loads(out.stdout.strip().splitlines()[-1])


def compare(mesh, before, after, tmp, alternate=1, calls=3):
    """One row: the mesh mapped by both checkouts, in turn ``alternate`` times."""
    V, F = load_mesh(mesh)
    np.savez(Path(tmp) / "mesh.npz", V=V, F=F)
    res = {}
    for k in range(alternate):
        for side, root in (("before", before), ("after", after)):
            r = map_with(Path(root).resolve(), Path(tmp) / "mesh.npz", Path(tmp) / f"{side}.npz",
                         calls)
            if side in res:
                r["seconds"] = min(r["seconds"], res[side]["seconds"])
            res[side] = r
            print(Path(mesh).stem, side, k, f"{r['seconds']:.2f} s", r["library"],
                  file=sys.stderr, flush=True)
    maps = {side: dict(np.load(Path(tmp) / f"{side}.npz")) for side in res}
    b, a = res["before"], res["after"]
    angle = {side: quality_row(V, m["F"], m["U"])["angle_mean_centered"]
             for side, m in maps.items()}
    return dict(mesh=Path(mesh).stem, seconds_before=b["seconds"], seconds_after=a["seconds"],
                ratio=a["seconds"] / b["seconds"], folds_before=b["folds"],
                folds_after=a["folds"], angle_before=angle["before"], angle_after=angle["after"],
                identical=all(np.array_equal(maps["before"][k], maps["after"][k])
                              for k in ("U", "F")),
                library_before=b["library"], library_after=a["library"])


def render(rows, env, args):
    return page("Default float64 map: before and after", env,
                f"before = `{args.before}`, after = `{args.after}`; alternate {args.alternate}.",
                markdown_table(rows, COLUMNS),
                __doc__.split("\n\n", 1)[1].split("Usage::")[0].strip())


def main(argv=None):
    p = arguments(__doc__, meshes="+", mesh_help="names in the shared mesh folder, or paths")
    p.add_argument("--before", required=True)
    p.add_argument("--after", required=True)
    p.add_argument("--alternate", type=int, default=2)
    p.add_argument("--mesh-dir", default=str(DEFAULT_MESH_DIR))
    args = parse(p, argv)
    meshes = [Path(m) if Path(m).is_file() else Path(args.mesh_dir) / f"{m}.obj"
              for m in args.meshes]
    with tempfile.TemporaryDirectory() as tmp:
        rows = run("float64_before_after", args, meshes,
                   lambda mesh: compare(mesh, args.before, args.after, tmp, args.alternate),
                   render, payload=lambda rows: dict(before=args.before, after=args.after))
    if any(r["library_before"] == r["library_after"] for r in rows):
        sys.exit("both sides imported the same library: check --before and --after")
    return 0


if __name__ == "__main__":
    sys.exit(main())
