"""A second pose of the SMPL woman, with the same connectivity: a pair with a known
correspondence (vertex ``i`` to vertex ``i``) whose surfaces have fingers.

The shared meshes' ``human_woman.obj`` (T-pose) is posed by linear blend skinning with smooth
(logistic) weights: both arms lowered 55 degrees at the shoulders and bent 40 degrees at
the elbows, one leg kicked forward 35 degrees at the hip, the other knee bent 45 degrees.
The joints' skinning artefacts are then relaxed as-rigid-as-possibly (``igl.arap_solve``,
50 iterations), with every vertex whose weights are all within 0.01 of 0 or 1 held where the
skinning put it.  Deterministic; the edge length ratios to the rest pose end in 0.62-1.34
(1st-99th percentile 0.83-1.10).

Usage::

    python benchmarks/posed_human.py                       # writes tests/data/human_woman_posed.obj
    python benchmarks/posed_human.py --mesh M.obj --out P.obj

``benchmarks/correspondence.py`` measures the pair (``--pairs human-posed posed-human``), and
``tests/test_surface_maps.py`` maps it.
"""

import argparse
import sys
from pathlib import Path

import igl
import numpy as np

from harness import REPO_ROOT

SHARED_MESH = REPO_ROOT.parent / "shared" / "meshes" / "human_woman.obj"
OUT = REPO_ROOT / "tests" / "data" / "human_woman_posed.obj"
HEADER = ("# SMPL female body (odedstein/meshes @ 835213277571d625722d25880c9c3010c6f45a5a : "
          "objects/human/human_woman.obj, CC BY 4.0, SMPL by the Max Planck Society e.V.)\n"
          "# re-posed by benchmarks/posed_human.py of igl_spheremap (same vertices and faces, "
          "moved); CC BY 4.0\n")


def rotation(axis, degrees):
    """The 3 x 3 rotation by ``degrees`` about ``axis`` (Rodrigues)."""
    a = np.radians(degrees)
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K


def logistic(t, width):
    return 1.0 / (1.0 + np.exp(-t / width))


def joints(V):
    """``(weights (n,), rotation, centre)`` of each joint, children first (rest coordinates:
    y up, arms along x)."""
    x, y = V[:, 0], V[:, 1]
    arm, leg = y > 1.15, y < 0.95
    out = []
    for side in (1, -1):
        out.append((logistic(side * x - 0.45, 0.02) * arm, rotation([0, 1, 0], side * 40),
                    np.array([side * 0.45, 1.35, 0.0])))  # elbow
        out.append((logistic(side * x - 0.19, 0.025) * arm, rotation([0, 0, 1], -side * 55),
                    np.array([side * 0.19, 1.38, 0.0])))  # shoulder
    out.append((logistic(0.50 - y, 0.02) * (x > 0) * leg, rotation([1, 0, 0], 45),
                np.array([0.09, 0.50, 0.0])))  # knee
    out.append((logistic(0.90 - y, 0.03) * logistic(-x, 0.015) * leg, rotation([1, 0, 0], -35),
                np.array([-0.09, 0.90, 0.0])))  # hip
    return out


def posed(V, F):
    """The posed vertices ((n, 3) float64) of the rest pose ``(V, F)``."""
    P = np.array(V, dtype=np.float64)
    js = joints(V)
    for w, R, c in js:
        P += w[:, None] * ((P - c) @ R.T + c - P)
    W = np.column_stack([w for w, _, _ in js])
    held = np.flatnonzero(np.all((W < 0.01) | (W > 0.99), axis=1)).astype(np.int64)
    data = igl.ARAPData()
    data.max_iter = 50
    igl.arap_precomputation(np.ascontiguousarray(V, dtype=np.float64),
                            np.ascontiguousarray(F, dtype=np.int64), 3, held, data)
    out = igl.arap_solve(np.ascontiguousarray(P[held]), data, np.ascontiguousarray(P))
    return out[0] if isinstance(out, tuple) else out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--mesh", type=Path, default=SHARED_MESH)
    p.add_argument("--out", type=Path, default=OUT)
    args = p.parse_args(argv)
    V, F = igl.read_triangle_mesh(str(args.mesh))[:2]
    P = posed(V, F)
    E = igl.edges(np.asarray(F, dtype=np.int64))
    ratio = (np.linalg.norm(P[E[:, 0]] - P[E[:, 1]], axis=1)
             / np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1))
    lines = [HEADER] + [f"v {a:.9g} {b:.9g} {c:.9g}\n" for a, b, c in P]
    lines += [f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in np.asarray(F)]
    args.out.write_text("".join(lines))
    print(f"{args.out}: {len(V)} vertices; edge length ratios {ratio.min():.2f}-{ratio.max():.2f}, "
          f"1st-99th percentile {np.percentile(ratio, 1):.2f}-{np.percentile(ratio, 99):.2f}")


if __name__ == "__main__":
    sys.exit(main())
