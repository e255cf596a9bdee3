"""bounded_intrinsic_delaunay_cotmatrix vs libigl: bit-identical where libigl terminates (libigl is
only run where the exact port says it terminates), bounded where it diverges.

    PYTHONPATH=. python scratch/sliver_bounded_check.py
"""
import sys, os, time
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import igl, numpy as np
import igl_spheremap
from igl_spheremap.bounded_intrinsic_delaunay import bounded_intrinsic_delaunay_cotmatrix
from idt_port import idt
from sliver_mesh import split_icosphere, cap_icosphere, star_icosphere
from sliver_seeds import orig_variant
from sliver_mc import blob


def row(name, V, F):
    port = idt(V, F, max_flips=30 * F.shape[0], stop_on_nan=True)
    t0 = time.perf_counter()
    try:
        L, skipped = bounded_intrinsic_delaunay_cotmatrix(V, F)
        tb = time.perf_counter() - t0
        neg = int(np.count_nonzero(L.tocoo().data[L.tocoo().row != L.tocoo().col] < 0))
        out = f"bounded {tb:6.2f} s skipped {skipped:4d} finite {np.isfinite(L.data).all()} neg.w {neg:4d}"
    except igl_spheremap.MeshError as e:
        L, out = None, f"bounded MeshError {e.problem} ({e.count}) {time.perf_counter() - t0:.2f} s"
    if port["done"]:
        t0 = time.perf_counter(); L0 = igl.intrinsic_delaunay_cotmatrix(V, F)[0]; ti = time.perf_counter() - t0
        same = "n/a" if L is None else (L != L0).nnz == 0
        out += f" | libigl ends, {ti:.3f} s, identical: {same}"
    else:
        out += " | libigl diverges (port: NaN length)"
    print(f"{name:44s} {out}", flush=True)


for p in ("fish_lowres", "dino", "bimba", "horse"):
    V, F = igl.read_triangle_mesh(f"/work/shared/meshes/{p}.obj")
    row(p, V, F)
for t in (1e-2, 1e-4, 1e-7, 1e-11):
    row(f"disjoint L3 t={t:g} seed 2", *split_icosphere(3, 200, t, 2))
for t in (1e-4, 3e-5, 1e-5):
    row(f"disjoint L5 5120 needles t={t:g} seed 0", *split_icosphere(5, 5120, t, 0))
row("shared L3 t=3e-6 seed 0", *orig_variant(3, 200, 3e-6, 0))
row("cap L3 s=1e-9", *cap_icosphere(3, 200, 1e-9, 0))
row("cap L3 s=1e-7", *cap_icosphere(3, 200, 1e-7, 0))
row("star L3 t=1e-7", *star_icosphere(3, 30, 1e-7, 0))
row("marching cubes gauss res 80 seed 2", *blob(80, "gauss", 2))
