"""Flat regions: needles on exactly opposite edges of a grid vertex (grid_cube).  Does libigl's
flip loop (exact port, stop at first NaN) diverge, and at which edge ratio?"""
import sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
import igl_spheremap
from idt_port import idt
from sliver_mesh import flat_opposite_splits, grid_cube
from sliver_stats import stats

V, F = grid_cube(8)
igl_spheremap.validate_mesh(V, F)
print("grid cube alone: flips", idt(V, F, stop_on_nan=True)["flips"], "done", idt(V, F, stop_on_nan=True)["done"])
for t in (0.3, 0.1, 1e-2, 1e-3, 1e-4, 1e-6):
    div, rhos = 0, []
    for s in range(10):
        V, F = flat_opposite_splits(8, t, s)
        igl_spheremap.validate_mesh(V, F)
        rhos.append(stats(V, F)[1].min())
        div += not idt(V, F, max_flips=30 * F.shape[0], stop_on_nan=True)["done"]
    print(f"flat opposite splits t={t:g} faces {F.shape[0]} min rho {min(rhos):.2e} diverged {div}/10", flush=True)
