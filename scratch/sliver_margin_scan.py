"""Does libigl's flip loop (exact port, capped at 20 flips per edge) diverge on any mesh just above
the proposed threshold (min eta = smallest height / longest edge >= 1e-5), and where below it?

    PYTHONPATH=. python scratch/sliver_margin_scan.py LEVEL SEEDS
prints per family/parameter: seeds whose input has min eta >= 1e-5 ("kept") and how many of those
and of the refused ones diverge.
"""
import sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
from idt_port import idt
from sliver_mesh import split_icosphere, cap_icosphere, star_icosphere
from sliver_seeds import orig_variant
from sliver_stats import stats

ETA = 1e-5
level = int(sys.argv[1]) if len(sys.argv) > 1 else 3
seeds = range(int(sys.argv[2]) if len(sys.argv) > 2 else 20)
only = sys.argv[3].split(",") if len(sys.argv) > 3 else None  # family names, e.g. "needle disjoint"
nsplit = 200 * 4 ** (level - 3)
families = [
    ("needle disjoint", lambda p, s: split_icosphere(level, nsplit, p, s), (1e-4, 3e-5, 1.5e-5, 1e-5, 3e-6, 1e-6, 1e-7)),
    ("needle shared", lambda p, s: orig_variant(level, nsplit, p, s), (1e-2, 4e-3, 1e-3, 1e-5, 3e-6)),
    ("cap", lambda p, s: cap_icosphere(level, nsplit, p, s), (1e-4, 3e-5, 1.5e-5, 1e-7, 1e-8)),
    ("star", lambda p, s: star_icosphere(level, 30 * 4 ** (level - 3), p, s), (1e-4, 3e-5, 1.5e-5, 1e-5, 1e-6, 1e-7)),
]
for name, make, params in families:
    if only and name not in only:
        continue
    for p in params:
        kept = kept_div = refused = refused_div = 0
        etas = []
        for s in seeds:
            V, F = make(p, s)
            eta = stats(V, F)[3].min()
            etas.append(eta)
            div = not idt(V, F, max_flips=30 * F.shape[0], stop_on_nan=True)["done"]
            if eta >= ETA:
                kept += 1; kept_div += div
            else:
                refused += 1; refused_div += div
        print(f"L{level} {name:16s} param={p:8.1e} min eta {min(etas):9.2e}..{max(etas):9.2e}  "
              f"kept {kept:3d} (diverged {kept_div:3d})  refused {refused:3d} (diverged {refused_div:3d})",
              flush=True)
