"""Largest needle ratio / cap slack at which libigl's flip loop diverges (exact port, flip cap).

For each construction and parameter, 10 seeds; prints the number of seeds whose flips
diverge (port capped at 20 x #edges flips, NaN lengths), with min rho / sigma of the input.

    PYTHONPATH=. python scratch/sliver_threshold_scan.py [level]
"""
import sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
import igl_spheremap
from idt_port import idt
from sliver_mesh import split_icosphere, cap_icosphere
from sliver_seeds import orig_variant
from sliver_stats import stats

level = int(sys.argv[1]) if len(sys.argv) > 1 else 3
seeds = range(int(sys.argv[2]) if len(sys.argv) > 2 else 10)
families = [
    ("needle disjoint", lambda p, s: split_icosphere(level, 200, p, s), [10 ** -k for k in np.arange(2, 8.01, 0.5)]),
    ("needle shared", lambda p, s: orig_variant(level, 200, p, s), [10 ** -k for k in np.arange(2, 7.01, 0.5)]),
    ("cap", lambda p, s: cap_icosphere(level, 200, p, s), [10 ** -k for k in np.arange(3, 13.01, 1.0)]),
]
for name, make, params in families:
    for p in params:
        diverged, valid, rho, sig = 0, 0, [], []
        for s in seeds:
            V, F = make(p, s)
            try:
                igl_spheremap.validate_mesh(V, F); valid += 1
            except igl_spheremap.MeshError:
                pass
            sg, r, _, _ = stats(V, F)[:3]
            rho.append(r.min()); sig.append(sg.min())
            res = idt(V, F, max_flips=20 * 3 * F.shape[0] // 2)
            diverged += not res["done"]
        print(f"L{level} {name:16s} param={p:8.1e} valid {valid:2d}/{len(seeds)} diverged {diverged:2d}/{len(seeds)} "
              f"min rho {min(rho):9.2e}  min sigma {min(sig):9.2e}", flush=True)
