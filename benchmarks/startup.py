"""Start-up cost of the command line: import time of the package and wall time of ``igl-spheremap``.

Every measurement is a fresh interpreter (``subprocess``), repeated ``--repeats``
times, the variants taking turns (the machine's speed drifts); the table gives
the best and the median.  Variants:

* ``python -c pass``: the interpreter alone;
* ``import numpy, scipy.sparse, igl``: the floor every run pays (libigl's
  bindings import scipy.sparse);
* ``import igl_spheremap``;
* ``igl-spheremap MESH -o OUT --no-progress -q``: the whole command on the
  945-vertex fish (read, validate, map, write, read back, report).

Then one ``python -X importtime -c "import igl_spheremap"`` run lists the
modules with the largest cumulative import time, and the optional
dependencies a plain ``import igl_spheremap`` must not load.

Usage::

    python benchmarks/startup.py                      # tests/data/fish_lowres.obj
    python benchmarks/startup.py MESH --repeats 15 --out DIR
"""

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from harness import REPO_ROOT, arguments, page, parse, run

DEFAULT_MESH = REPO_ROOT / "tests" / "data" / "fish_lowres.obj"
OPTIONAL = ("pyamg", "nibabel", "tqdm", "dask", "distributed", "matplotlib", "polyscope",
            "plyfile", "threadpoolctl", "scipy.optimize", "scipy.spatial")
#: The goal of issue #13 for the command on the fish.
GOAL_SECONDS = 0.3


def _variants(mesh, out):
    exe = sys.executable
    cli = [exe, "-m", "igl_spheremap", str(mesh), "-o", str(out), "--no-progress", "-q"]
    return {"python -c pass": [exe, "-c", "pass"],
            "import numpy, scipy.sparse, igl": [exe, "-c", "import numpy, scipy.sparse, igl"],
            "import igl_spheremap": [exe, "-c", "import igl_spheremap"],
            "igl-spheremap (fish)": cli}


def _time(cmd, cwd):
    t = time.perf_counter()
    subprocess.run(cmd, cwd=cwd, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    return time.perf_counter() - t


def import_profile(top=12):
    """(module, cumulative seconds) of the slowest imports, and the optional modules loaded."""
    code = ("import sys, igl_spheremap; print('LOADED', *[m for m in " + repr(OPTIONAL)
            + " if m in sys.modules])")
    r = subprocess.run([sys.executable, "-X", "importtime", "-c", code], capture_output=True,
                       text=True, check=True)
    rows = []
    for line in r.stderr.splitlines():
        if line.startswith("import time:") and "|" in line:
            _, cum, name = line[len("import time:"):].split("|")
            depth = len(name) - len(name.lstrip(" "))
            if cum.strip().isdigit() and depth <= 3:  # the package and what it imports directly
                rows.append(((depth - 1) // 2, name.strip(), int(cum) / 1e6))
    top_level = [(("  " * d) + n, s) for d, n, s in sorted(rows, key=lambda r: -r[2])[:top]]
    loaded = r.stdout.split("LOADED", 1)[1].split()
    return top_level, loaded


def measure(mesh, args):
    """The variants in turn, ``--repeats`` rounds; one row per variant (best and median)."""
    with tempfile.TemporaryDirectory() as tmp:
        variants = _variants(Path(mesh).resolve(), Path(tmp) / "out_sphere.obj")
        times = {k: [] for k in variants}
        for _ in range(args.repeats):
            for name, cmd in variants.items():
                times[name].append(_time(cmd, tmp))
    args._imports = import_profile()
    return [dict(variant=k, best=min(v), median=statistics.median(v), runs=v)
            for k, v in times.items()]


def render(rows, env, args):
    top, loaded = args._imports
    lines = [f"Fresh interpreters, the {len(rows)} variants in turn, {args.repeats} rounds "
             "(`python benchmarks/startup.py`).", "",
             "| variant | best (s) | median (s) |", "|---|---:|---:|"]
    lines += [f"| {r['variant']} | {r['best']:.3f} | {r['median']:.3f} |" for r in rows]
    cli = rows[-1]
    lines += ["", f"Goal (issue #13): the command on the fish in <= {GOAL_SECONDS} s wall: "
                  f"**{'met' if cli['median'] <= GOAL_SECONDS else 'not met'}** "
                  f"(median {cli['median']:.3f} s, best {cli['best']:.3f} s).", "",
              "Slowest top-level imports of `import igl_spheremap` (`python -X importtime`, "
              "cumulative):", "", "| module | seconds |", "|---|---:|"]
    lines += [f"| {name} | {sec:.3f} |" for name, sec in top]
    lines += ["", "Optional modules loaded by `import igl_spheremap`: "
              + (", ".join(loaded) if loaded else "none") + "."]
    return page("Start-up cost of the command line", env, "\n".join(lines))


def main(argv=None):
    p = arguments(__doc__, meshes=None, repeats=11)
    p.add_argument("mesh", nargs="?", default=str(DEFAULT_MESH))
    args = parse(p, argv)
    run("startup", args, [args.mesh], lambda mesh: measure(mesh, args), render,
        payload=lambda rows: dict(imports=args._imports[0], loaded=args._imports[1]))
    return 0


if __name__ == "__main__":
    os.environ.setdefault("PYTHONWARNINGS", "ignore")
    sys.exit(main())
