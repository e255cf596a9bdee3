"""Does the port agree with libigl where libigl terminates, and what does it log where it does not?"""
import sys, os, json
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np, igl, scipy.sparse as sp
from idt_port import idt
from sliver_mesh import split_icosphere, icosphere

def lap(r, n):
    return igl.cotmatrix_intrinsic(r["l"], r["F"].astype(np.int64))

for t in (1e-2, 1e-7, 1e-11):
    V, F = split_icosphere(3, 200, t)
    r = idt(V, F)
    L0 = igl.intrinsic_delaunay_cotmatrix(V, F)[0]
    L1 = lap(r, len(V))
    print("face-disjoint", t, r["done"], r["flips"], r["maxQ"], "max|L-Llibigl|", abs(L0 - L1).max())

# the invalid 'orig' variant of sliver_variants.py, level 3 t=1e-7
def split_edge(V, F, a, b, t):
    hit = [(f, c) for f in range(len(F)) for c in range(3) if F[f][(c+1)%3] == a and F[f][(c+2)%3] == b]
    hit2 = [(f, c) for f in range(len(F)) for c in range(3) if F[f][(c+1)%3] == b and F[f][(c+2)%3] == a]
    (f1, c1), (f2, c2) = hit[0], hit2[0]
    x, y = F[f1][c1], F[f2][c2]
    p = len(V); V.append(V[a] + t * (V[b] - V[a]))
    F[f1] = [x, a, p]; F.append([x, p, b]); F[f2] = [y, p, a]; F.append([y, b, p])
V0, F0 = icosphere(3)
V, F = list(V0), F0.tolist()
rng = np.random.default_rng(0)
E = igl.edges(F0)
for e in rng.choice(len(E), 200, replace=False):
    split_edge(V, F, E[e][0], E[e][1], 1e-7)
V, F = np.array(V), np.array(F, np.int64)
log = []
r = idt(V, F, max_flips=20000, log=log)
print("orig variant", r["done"], r["flips"], "Q", r["Q"], "nan lengths", int(np.isnan(r["l"]).sum()))
for row in log[:12]:
    print({k: (f"{v:.3e}" if isinstance(v, float) else v) for k, v in row.items()})
from collections import Counter
print(Counter(row["ue"] for row in log).most_common(5))
