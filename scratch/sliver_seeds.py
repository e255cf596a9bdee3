"""Random original-edge splits (faces may be shared) over seeds: valid? degenerate intrinsic triangles? flips?"""
import sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np, igl
import igl_spheremap
from idt_port import idt
from sliver_mesh import icosphere


def split_edge(V, F, a, b, t):
    hit = [(f, c) for f in range(len(F)) for c in range(3) if F[f][(c+1)%3] == a and F[f][(c+2)%3] == b]
    hit2 = [(f, c) for f in range(len(F)) for c in range(3) if F[f][(c+1)%3] == b and F[f][(c+2)%3] == a]
    (f1, c1), (f2, c2) = hit[0], hit2[0]
    x, y = F[f1][c1], F[f2][c2]
    p = len(V); V.append(V[a] + t * (V[b] - V[a]))
    F[f1] = [x, a, p]; F.append([x, p, b]); F[f2] = [y, p, a]; F.append([y, b, p])


def orig_variant(level, k, t, seed):
    V0, F0 = icosphere(level)
    V, F = list(V0), F0.tolist()
    rng = np.random.default_rng(seed)
    E = igl.edges(F0)
    for e in rng.choice(len(E), k, replace=False):
        a, b = E[e] if rng.random() < 2 else E[e][::-1]
        split_edge(V, F, a, b, t)
    return np.array(V), np.array(F, np.int64)


def slack(V, F):
    l = igl.edge_lengths(V, F)
    a, b, c = l[:, 0], l[:, 1], l[:, 2]
    return np.minimum(np.minimum(-a + b + c, a - b + c), a + b - c) / l.max(axis=1)


if __name__ == "__main__":
    level = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    for t in (1e-6, 1e-7, 1e-11):
        for seed in range(6):
            V, F = orig_variant(level, 200, t, seed)
            try:
                igl_spheremap.validate_mesh(V, F); valid = "valid"
            except Exception as err:
                valid = str(err)[14:40]
            s = slack(V, F)
            r = idt(V, F, max_flips=5000)
            print(f"L{level} t={t:g} seed={seed} {valid:28s} faces slack<=0: {int((s <= 0).sum())} "
                  f"min slack {s.min():.2e} idt done={r['done']} flips={r['flips']}", flush=True)
