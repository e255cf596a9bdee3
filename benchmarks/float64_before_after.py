"""The default (float64) map with two checkouts of the library: did a change alter it?

For each mesh, the default ``spherical_conformal_map(V, F)`` runs with the
library of ``--before`` and of ``--after`` (each a repository root put first on
``PYTHONPATH`` of a fresh ``python`` process), the two in turn ``--alternate``
times; in a process the call is repeated while it takes under 10 s (at most 3
calls) and the fastest call of all counts.  Reported: seconds, ratio after /
before, folds, mean angle distortion after Möbius centering with the input's
vertex areas (``_common.quality_row``), and whether the two maps are identical
bit for bit.

Usage::

    python benchmarks/float64_before_after.py --before /path/to/main --after . \\
        [--mesh-dir ../shared/meshes] dino horse pycortex_s1_pia_lh human_woman scorpion_lowres

Writes ``DIR/float64_before_after.md`` and ``.json`` (default ``benchmarks/results/``).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import (DEFAULT_MESH_DIR, DEFAULT_OUT, environment_line, environment,  # noqa: E402
                     markdown_table, write_outputs)

CHILD = r"""
import json, sys, time, warnings
import numpy as np
sys.path.insert(0, {bench!r})
from _common import load_mesh, quality_row
import igl_spheremap as sm
V, F = load_mesh({mesh!r})
times, r = [], None
for _ in range(3):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = time.perf_counter()
        out = sm.spherical_conformal_map(V, F)
        times.append(time.perf_counter() - t)
    r = r or out
    if times[-1] > 10.0:
        break
np.save({npy!r}, r.U)
q = quality_row(V, r.F, r.U)
print(json.dumps(dict(seconds=min(times), folds=int(r.folds), success=bool(r.success),
                      angle=q["angle_mean_centered"], library=sm.__file__)))
"""

COLUMNS = [("mesh", "mesh", "", "l"), ("before s", "seconds_before", ".2f", "r"),
           ("after s", "seconds_after", ".2f", "r"), ("after / before", "ratio", ".2f", "r"),
           ("folds before", "folds_before", "", "r"), ("folds after", "folds_after", "", "r"),
           ("angle before (°)", "angle_before", ".3f", "r"),
           ("angle after (°)", "angle_after", ".3f", "r"),
           ("identical map", "identical", "", "l")]


def run(root, mesh, npy):
    code = CHILD.format(bench=str(Path(root) / "benchmarks"), mesh=str(mesh), npy=npy)
    env = dict(os.environ, PYTHONPATH=str(root))
    # cwd=root: "python -c" puts the current folder first on sys.path, before PYTHONPATH
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=str(root), capture_output=True,
                         text=True, check=True, timeout=1800)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("meshes", nargs="+", help="names in the shared mesh folder, or paths")
    p.add_argument("--before", required=True)
    p.add_argument("--after", required=True)
    p.add_argument("--alternate", type=int, default=2)
    p.add_argument("--mesh-dir", default=str(DEFAULT_MESH_DIR))
    p.add_argument("--out", default=str(DEFAULT_OUT))
    args = p.parse_args(argv)
    env, rows = environment(), []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.meshes:
            mesh = Path(name) if Path(name).is_file() else Path(args.mesh_dir) / f"{name}.obj"
            res = {}
            for k in range(args.alternate):
                for side, root in (("before", args.before), ("after", args.after)):
                    r = run(Path(root).resolve(), mesh, f"{tmp}/{side}.npy")
                    if side in res:
                        r["seconds"] = min(r["seconds"], res[side]["seconds"])
                    res[side] = r
                    print(name, side, k, f"{r['seconds']:.2f} s", r["library"], flush=True)
            same = np.array_equal(np.load(f"{tmp}/before.npy"), np.load(f"{tmp}/after.npy"))
            b, a = res["before"], res["after"]
            rows.append(dict(mesh=Path(mesh).stem, seconds_before=b["seconds"],
                             seconds_after=a["seconds"], ratio=a["seconds"] / b["seconds"],
                             folds_before=b["folds"], folds_after=a["folds"],
                             angle_before=b["angle"], angle_after=a["angle"], identical=same,
                             library_before=b["library"], library_after=a["library"]))
    md = "\n".join(["# Default float64 map: before and after", "",
                    f"before = `{args.before}`, after = `{args.after}`; alternate {args.alternate}.",
                    "", environment_line(env), "", markdown_table(rows, COLUMNS), "",
                    __doc__.split("\n\n", 1)[1].split("Usage::")[0].strip()])
    write_outputs(args.out, "float64_before_after", md, dict(environment=env, rows=rows,
                                                            before=args.before, after=args.after))
    print(md)
    if any(r["library_before"] == r["library_after"] for r in rows):
        sys.exit("both sides imported the same library: check --before and --after")


if __name__ == "__main__":
    main()
