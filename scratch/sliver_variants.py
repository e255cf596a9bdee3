"""Which split construction reproduces the blow-up?  Each variant in a limited child."""
import json, subprocess, sys, os
HERE = os.path.dirname(os.path.abspath(__file__))
CHILD = r"""
import sys, time, json, resource
sys.path.insert(0, {here!r})
import numpy as np, igl, igl_spheremap
from sliver_mesh import icosphere

def split_edge(V, F, a, b, t, project):
    hit = [(f, c) for f in range(len(F)) for c in range(3) if F[f][(c+1)%3] == a and F[f][(c+2)%3] == b]
    hit2 = [(f, c) for f in range(len(F)) for c in range(3) if F[f][(c+1)%3] == b and F[f][(c+2)%3] == a]
    (f1, c1), (f2, c2) = hit[0], hit2[0]
    x, y = F[f1][c1], F[f2][c2]
    q = V[a] + t * (V[b] - V[a])
    if project: q = q / np.linalg.norm(q)
    p = len(V); V.append(q)
    F[f1] = [x, a, p]; F.append([x, p, b])
    F[f2] = [y, p, a]; F.append([y, b, p])

variant, level, k, t = {variant!r}, {level!r}, {k!r}, {t!r}
V0, F0 = icosphere(level)
V, F = list(V0), F0.tolist()
rng = np.random.default_rng(0)
E = igl.edges(F0)
if variant in ("orig", "orig_proj"):
    for e in rng.choice(len(E), k, replace=False):
        split_edge(V, F, E[e][0], E[e][1], t, variant.endswith("proj"))
elif variant in ("any", "any_proj"):
    for _ in range(k):
        E = igl.edges(np.array(F)); e = E[rng.integers(len(E))]
        split_edge(V, F, e[0], e[1], t, variant.endswith("proj"))
V, F = np.array(V), np.array(F, np.int64)
out = dict(variant=variant, level=level, t=t)
try:
    igl_spheremap.validate_mesh(V, F); out["valid"] = True
except Exception as err:
    out["valid"] = str(err)[:80]
t0 = time.perf_counter()
try:
    L = igl.intrinsic_delaunay_cotmatrix(V, F)[0]; out["idt"] = "ok"
except Exception as err:
    out["idt"] = type(err).__name__
out["s"] = round(time.perf_counter() - t0, 3)
out["mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024
print(json.dumps(out), flush=True)
"""
for level in (2, 3):
    for variant in ("orig", "orig_proj", "any", "any_proj"):
        for t in (1e-7, 1e-11):
            code = CHILD.format(here=HERE, variant=variant, level=level, k=200, t=t)
            p = subprocess.run(["timeout", "30", "prlimit", "--as=2000000000", sys.executable, "-c", code],
                               capture_output=True, text=True)
            print(p.stdout.strip() or f"{variant} L{level} t={t}: killed rc={p.returncode} {p.stderr[-200:]}", flush=True)
