"""Time and peak memory of libigl's Laplacians and the pipeline on split icospheres.

Every (operation, t) runs in its own child under ``timeout 120 prlimit --as=4e9``
(the parent only launches children and reads one JSON line from each).

    PYTHONPATH=. python scratch/sliver_measure.py [--ops idt,cot,map_cot,map] [--ts 1e-2,...]
        [--family disjoint|shared|cap] [--seed 2]

ops: validate (igl_spheremap.validate_mesh), cot (igl.cotmatrix), idt (igl.intrinsic_delaunay_cotmatrix),
ours (igl_spheremap.operators.laplacian default), map / map_cot (spherical_conformal_map, default /
laplacian_kind="cotan").  A child that exceeds the limits prints no JSON: "killed (timeout)" after
--timeout s, or MemoryError inside the 4 GB address-space limit.
"""

import argparse
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
CHILD = r"""
import json, resource, sys, time
sys.path.insert(0, {here!r})
import igl, numpy as np
import igl_spheremap
from sliver_mesh import split_icosphere, cap_icosphere
from sliver_seeds import orig_variant
op, t, level, k, fam, seed = {op!r}, {t!r}, {level!r}, {k!r}, {fam!r}, {seed!r}
make = dict(disjoint=split_icosphere, shared=orig_variant, cap=cap_icosphere)[fam]
V, F = make(level, k, t, seed)
out = dict(fam=fam, seed=seed, op=op, t=t)
t0 = time.perf_counter()
try:
    if op == "validate":
        igl_spheremap.validate_mesh(V, F); out["status"] = "ok"
    elif op == "idt":
        L = igl.intrinsic_delaunay_cotmatrix(V, F)[0]; out["status"] = "ok"
        out["finite"] = bool(np.isfinite(L.data).all())
    elif op == "cot":
        L = igl.cotmatrix(V, F); out["status"] = "ok"
        out["finite"] = bool(np.isfinite(L.data).all())
        out["max_abs_w"] = float(np.abs(L.data).max())
    elif op == "ours":  # igl_spheremap.operators.laplacian, default kind (intrinsic Delaunay)
        from igl_spheremap.operators import laplacian
        L = laplacian(V, F); out["status"] = "ok"
        out["finite"] = bool(np.isfinite(L.data).all())
    elif op in ("map", "map_cot"):
        kw = dict(laplacian_kind="cotan") if op == "map_cot" else dict()
        import warnings
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = igl_spheremap.spherical_conformal_map(V, F, **kw)
        out.update(status="ok", folds=int(r.folds), success=bool(r.success), message=r.message[:120])
except Exception as err:
    out["status"] = f"{{type(err).__name__}}: {{str(err)[:70]}}"
out["seconds"] = time.perf_counter() - t0
# peak RSS of this child's own address space (VmHWM; ru_maxrss carries over fork + exec)
out["peak_rss_mb"] = [int(ln.split()[1]) / 1024 for ln in open("/proc/self/status")
                      if ln.startswith("VmHWM")][0]
print(json.dumps(out), flush=True)
"""


def run(op, t, level, k, fam, seed, timeout, limit):
    code = CHILD.format(here=HERE, op=op, t=t, level=level, k=k, fam=fam, seed=seed)
    t0 = time.perf_counter()
    p = subprocess.run(["timeout", str(timeout), "prlimit", f"--as={limit}", sys.executable, "-c",
                        code], capture_output=True, text=True)
    wall = time.perf_counter() - t0
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith("{")]
    if lines:
        return json.loads(lines[-1])
    why = "timeout" if p.returncode == 124 else f"rc={p.returncode}"
    return dict(fam=fam, seed=seed, op=op, t=t, status=f"killed ({why}) {p.stderr.strip().splitlines()[-1:]}",
                seconds=wall)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ops", default="validate,cot,idt")
    ap.add_argument("--ts", default="1e-2,1e-4,1e-6,1e-7,1e-9,1e-11")
    ap.add_argument("--level", type=int, default=3)
    ap.add_argument("--edges", type=int, default=200)
    ap.add_argument("--family", default="disjoint", choices=("disjoint", "shared", "cap"))
    ap.add_argument("--seed", type=int, default=2)
    ap.add_argument("--timeout", type=int, default=120)
    ap.add_argument("--limit", type=int, default=4_000_000_000)
    a = ap.parse_args()
    for t in map(float, a.ts.split(",")):
        for op in a.ops.split(","):
            print(json.dumps(run(op, t, a.level, a.edges, a.family, a.seed, a.timeout, a.limit)), flush=True)


if __name__ == "__main__":
    main()
