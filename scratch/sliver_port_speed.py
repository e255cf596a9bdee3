"""Could the exact port (idt_port.py) with a flip cap serve as a bounded fallback? Its speed and
agreement with libigl on shared meshes.

    PYTHONPATH=. python scratch/sliver_port_speed.py MESH ...
"""
import sys, os, time
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import igl, numpy as np
from idt_port import idt

for path in sys.argv[1:]:
    V, F = igl.read_triangle_mesh(path)
    t0 = time.perf_counter(); L0 = igl.intrinsic_delaunay_cotmatrix(V, F)[0]; t_igl = time.perf_counter() - t0
    t0 = time.perf_counter(); r = idt(V, F, max_flips=10 ** 7); t_port = time.perf_counter() - t0
    L1 = igl.cotmatrix_intrinsic(r["l"], r["F"].astype(np.int64))
    print(f"{os.path.basename(path):24s} faces {len(F):7d} flips {r['flips']:6d} libigl {t_igl:.3f} s  "
          f"port {t_port:.2f} s ({t_port / t_igl:.0f}x)  (L_port != L_libigl).nnz = {(L0 != L1).nnz}", flush=True)
