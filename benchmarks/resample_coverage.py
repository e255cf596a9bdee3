"""How much of a surface survives resampling onto an icosphere, and how a sphere survives libigl's writers.

README's "Resampling onto an icosphere" and "Outputs and conventions" quote these numbers.
For each mesh (default: the bundled dinosaur):

* the area of ``resample(V, F, U, *icosphere(k))`` over the area of ``(V, F)``
  (``igl.doublearea``), for the conformal map and the area-balanced sphere and each level
  ``k`` of ``--levels``: an icosphere samples the sphere evenly, so what a map crowds (legs,
  tails) gets few template vertices and is cut off;
* the folds of the conformal map as ``igl.write_triangle_mesh`` stores it in ``.ply``
  (float32) and read back, against ``igl_spheremap.write_mesh`` (float64);
* the faces a hand-written triple product ``U_i . (U_j x U_k) <= 0`` counts as folded on
  the fold-free map, against :func:`igl_spheremap.count_folds` and ``numpy.linalg.det``.

Usage::

    python benchmarks/resample_coverage.py [MESH ...] --levels 6 7 --out DIR
"""

import argparse
import json
import tempfile
import warnings
from pathlib import Path

import igl
import numpy as np

import igl_spheremap as sm

DEFAULT_OUT = Path(__file__).parent / "results"


def coverage(V, F, U, level):
    """Resampled area over the surface's area, on ``icosphere(level)`` (float)."""
    T, TF = sm.icosphere(level)
    res = sm.resample(V, F, U, T, TF)
    return float(igl.doublearea(res.V, res.F).sum() / igl.doublearea(V, F).sum())


def stored_folds(U, F):
    """Folds of ``U`` written by libigl's ``.ply`` writer and by ``write_mesh``, read back."""
    with tempfile.TemporaryDirectory() as d:
        igl.write_triangle_mesh(str(Path(d) / "igl.ply"), U, F)
        sm.write_mesh(Path(d) / "ours.ply", U, F)
        return {name: sm.count_folds(G, W) for name in ("igl", "ours")
                for W, G in [igl.read_triangle_mesh(str(Path(d) / f"{name}.ply"))]}


def triple_product_folds(U, F):
    """Faces with ``U_i . (U_j x U_k) <= 0``, with ``numpy.linalg.det <= 0`` and ``count_folds``."""
    tp = np.einsum("ij,ij->i", U[F[:, 0]], np.cross(U[F[:, 1]], U[F[:, 2]]))
    return {"triple_product": int((tp <= 0).sum()), "det": int((np.linalg.det(U[F]) <= 0).sum()),
            "count_folds": sm.count_folds(F, U)}


def measure(path, levels):
    V, F = igl.read_triangle_mesh(str(path))
    row = {"mesh": Path(path).name, "vertices": int(len(V))}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sm.SphericalMapWarning)
        maps = {"conformal": sm.spherical_conformal_map(V, F),
                "area_balanced": sm.spherical_conformal_map(V, F, kind="area_balanced")}
    for kind, r in maps.items():
        row[f"{kind}_success"] = bool(r.success)
        for k in levels:
            row[f"{kind}_ico{k}"] = coverage(V, r.F, r.U, k)
    conformal = maps["conformal"]
    row["ply_folds"] = stored_folds(conformal.U, conformal.F)
    row["folds_counted"] = triple_product_folds(conformal.U, conformal.F)
    return row


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("meshes", nargs="*", default=[sm.example_mesh()])
    p.add_argument("--levels", nargs="+", type=int, default=[6, 7])
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, metavar="DIR")
    args = p.parse_args(argv)
    rows = [measure(m, args.levels) for m in args.meshes]
    cols = [f"{kind}_ico{k}" for kind in ("conformal", "area_balanced") for k in args.levels]
    lines = ["| mesh | vertices | " + " | ".join(c.replace("_", " ") for c in cols)
             + " | .ply folds: libigl / write_mesh | folds: triple product / det / count_folds |",
             "|---" * (len(cols) + 4) + "|"]
    for r in rows:
        lines.append(f"| {r['mesh']} | {r['vertices']:,} | "
                     + " | ".join(f"{r[c]:.3f}" for c in cols)
                     + f" | {r['ply_folds']['igl']} / {r['ply_folds']['ours']} | "
                     + " / ".join(str(v) for v in r["folds_counted"].values()) + " |")
    text = "\n".join(lines)
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "resample_coverage.md").write_text(
        "Area kept by resampling onto icospheres (resampled area / surface area), and the folds "
        "of the conformal map as libigl's .ply writer stores it (`python benchmarks/"
        "resample_coverage.py`).\n\n" + text + "\n")
    (args.out / "resample_coverage.json").write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
