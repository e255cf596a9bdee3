"""Disjoint split, seed 2, t=1e-7: the flip that first makes a NaN length, and the triangles around it."""
import sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
import idt_port
from sliver_mesh import split_icosphere

V, F = split_icosphere(3, 200, float(sys.argv[1]) if len(sys.argv) > 1 else 1e-7, 2)
log = []
idt_port.idt.__globals__  # same module
r = idt_port.idt(V, F, max_flips=400, log=log)
first = next(i for i, row in enumerate(log) if not np.isfinite(row["new"]) or not np.isfinite(row["w"]))
for row in log[max(0, first - 3): first + 3]:
    print({k: (f"{v:.17g}" if isinstance(v, (float, np.floating)) else v) for k, v in row.items()})
