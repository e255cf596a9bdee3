"""Raw marching-cubes meshes (igl.marching_cubes) of smooth blobs: their edge / height ratios,
whether they pass validate_mesh, and whether libigl's flips diverge (exact port, stop at NaN).
How common are needles below the candidate thresholds in a realistic unprocessed input?"""
import sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np, igl
import igl_spheremap
from idt_port import idt
from sliver_stats import stats


def blob(res, kind, seed):
    g = np.linspace(-1.6, 1.6, res)
    X, Y, Z = np.meshgrid(g, g, g, indexing="ij")
    GV = np.stack([X.ravel(order="F"), Y.ravel(order="F"), Z.ravel(order="F")], 1)
    x, y, z = GV.T
    if kind == "sphere":
        S = np.sqrt(x * x + y * y + z * z) - 1.0 - 0.013 * seed
    else:  # sum of Gaussians
        rng = np.random.default_rng(seed)
        C = rng.uniform(-0.5, 0.5, (4, 3))
        S = 0.5 - sum(np.exp(-np.sum((GV - c) ** 2, 1) / 0.25) for c in C)
    V, F, _ = igl.marching_cubes(S, GV, res, res, res, 0.0)
    return V, F


for kind in ("sphere", "gauss"):
    for res in (20, 40, 80):
        for seed in range(3):
            V, F = blob(res, kind, seed)
            try:
                m = igl_spheremap.validate_mesh(V, F); V, F = m.V, m.F; valid = "valid"
            except igl_spheremap.MeshError as e:
                print(f"{kind} res={res} seed={seed}: {e.problem} ({e.count})"); continue
            s, r, th, eta = stats(V, F)
            res_ = idt(V, F, max_flips=30 * F.shape[0], stop_on_nan=True)
            print(f"{kind:6s} res={res:3d} seed={seed} faces {F.shape[0]:6d} min rho {r.min():8.1e} "
                  f"(faces rho<1e-3: {int((r < 1e-3).sum()):4d}, <1e-5: {int((r < 1e-5).sum()):3d}) "
                  f"min eta {eta.min():8.1e} (eta<1e-5: {int((eta < 1e-5).sum()):3d}) max angle {th.max():7.3f} "
                  f"idt {'done' if res_['done'] else 'DIVERGED'} flips {res_['flips']}", flush=True)
