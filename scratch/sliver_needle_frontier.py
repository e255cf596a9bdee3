"""Needle frontier: the largest edge ratio rho (shortest / longest edge of a face) at which
libigl's flips (exact port, stop at the first NaN length) diverge, vs mesh level and the
number of needles (a quarter of the faces' edges split at t from one end, no two on a face).

    PYTHONPATH=. python scratch/sliver_needle_frontier.py LEVELS SEEDS T_LIST
e.g. ... 3,4,5 10 1e-3,3e-4,1e-4,3e-5,1e-5
"""
import sys, os, time
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
from idt_port import idt
from sliver_mesh import split_icosphere
from sliver_stats import stats

levels = [int(x) for x in sys.argv[1].split(",")]
seeds = range(int(sys.argv[2]))
ts = [float(x) for x in sys.argv[3].split(",")]
for level in levels:
    m = 20 * 4 ** level
    n = m // 4
    for t in ts:
        div, rhos, t0 = 0, [], time.perf_counter()
        for s in seeds:
            V, F = split_icosphere(level, n, t, s)
            rhos.append(stats(V, F)[1].min())
            div += not idt(V, F, max_flips=30 * F.shape[0], stop_on_nan=True)["done"]
        print(f"L{level} needles {n:5d} t={t:7.1e} min rho {min(rhos):8.2e}  diverged {div:2d}/{len(seeds)}"
              f"  ({time.perf_counter() - t0:.0f} s)", flush=True)
