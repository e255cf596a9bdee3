"""Per-mesh sliver statistics (all from igl.edge_lengths, the lengths libigl's intrinsic Delaunay starts from):

sigma: min over faces of the relative triangle-inequality slack  min_k (l_i + l_j - l_k) / max(l)
rho:   min over faces of shortest / longest edge
theta: largest interior angle in degrees
also the number of faces with sigma below a few candidate thresholds.

    python scratch/sliver_stats.py            # 14 shared meshes + split icospheres
"""
import glob, os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import igl, numpy as np


def stats(V, F):
    l = igl.edge_lengths(V, F)
    a, b, c = l[:, 0], l[:, 1], l[:, 2]
    L = l.max(axis=1)
    sigma = np.minimum(np.minimum(-a + b + c, a - b + c), a + b - c) / L
    rho = l.min(axis=1) / L
    C = igl.internal_angles(V, F)
    theta = np.degrees(C.max(axis=1))
    eta = igl.doublearea(V - 0.5 * (V.min(0) + V.max(0)), F) / L ** 2  # smallest height / longest edge
    return sigma, rho, theta, eta


def row(name, V, F):
    s, r, th, eta = stats(V, F)
    return (f"{name:38s} {len(F):7d} {s.min():10.2e} {r.min():10.2e} {eta.min():10.2e} {th.max():9.4f} "
            f"{int((r < 1e-4).sum()):6d} {int((s < 1e-12).sum()):6d} {int((eta < 1e-5).sum()):6d}")


if __name__ == "__main__":
    print(f"{'mesh':38s} {'faces':>7s} {'min sigma':>10s} {'min rho':>10s} "
          f"{'min eta':>10s} {'max angle':>9s} {'r<1e-4':>6s} {'s<1e-12':>6s} {'e<1e-5':>6s}")
    for p in sorted(glob.glob("/work/shared/meshes/*.obj")):
        V, F = igl.read_triangle_mesh(p)
        print(row(os.path.basename(p), V, F), flush=True)
    for p in ("tests/data/fish_lowres.obj", "tests/data/goathead.obj", "tests/data/hippocampus.obj"):
        if os.path.exists(p):
            V, F = igl.read_triangle_mesh(p); print(row(p, V, F))
    from sliver_mesh import split_icosphere
    from sliver_seeds import orig_variant
    from sliver_mesh import cap_icosphere
    for t in (1e-2, 1e-4, 1e-6, 1e-7, 1e-9, 1e-11):
        print(row(f"split disjoint t={t:g} (seed 2)", *split_icosphere(3, 200, t, 2)))
    for t in (1e-2, 1e-4, 1e-5, 3e-6, 1e-6, 1e-7):
        print(row(f"split shared   t={t:g} (seed 0)", *orig_variant(3, 200, t, 0)))
    for t in (1e-3, 1e-5, 1e-7, 1e-8, 1e-9, 1e-11):
        print(row(f"cap s={t:g} (seed 0)", *cap_icosphere(3, 200, t, 0)))
