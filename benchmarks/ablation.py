"""Which deviation from the paper does what: the default pipeline with one piece switched off.

Usage: ``python benchmarks/ablation.py [MESH ...] [--out DIR] [--variants LABEL ...]`` (default: dino,
fish_lowres and maxplanck from ../shared/meshes, every variant).  For each mesh it also reports the number of negative cotangent weights of
``igl.cotmatrix`` and of ``igl.intrinsic_delaunay_cotmatrix``.  Runs in-process (a diagnostic, not a
timing benchmark); the numbers quoted in README.md ("How the default differs from the paper") come
from this script.
"""

import argparse
import time
import warnings

import igl

import igl_spheremap as sm
from igl_spheremap.operators import count_negative_weights, laplacian

from _common import DEFAULT_MESH_DIR, DEFAULT_OUT, load_mesh, markdown_table, mesh_name, \
    mesh_paths, quality_row, write_outputs

VARIANTS = {
    "default": {},
    "cotan Laplacian (paper Eq. 13)": dict(laplacian_kind="cotan"),
    "no fold barrier": dict(keep_fold_free=False),
    "no untangling": dict(untangle=False),
    "no local repair (star round instead)": dict(local_repair=False),
    "no Möbius normalization": dict(mobius=False),
    "L2 gradient (paper)": dict(metric="L2"),
    "paper as published": "paper",
}
DEFAULT_MESHES = ("dino", "fish_lowres", "maxplanck")


def run_variant(V, F, change, max_rounds):
    """Run the pipeline with the default options changed by ``change``; returns (result, seconds)."""
    kwargs = dict(method="paper") if change == "paper" else dict(change)
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sm.SphericalMapWarning)
        result = sm.spherical_conformal_map(V, F, max_rounds=max_rounds, **kwargs)
    return result, time.perf_counter() - t


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("meshes", nargs="*", metavar="MESH")
    ap.add_argument("--out", default=str(DEFAULT_OUT))
    ap.add_argument("--max-rounds", type=int, default=3)
    ap.add_argument("--variants", nargs="+", metavar="LABEL", choices=list(VARIANTS),
                    default=list(VARIANTS), help="variants to run (labels of VARIANTS)")
    args = ap.parse_args(argv)
    paths = mesh_paths(args.meshes or [DEFAULT_MESH_DIR / f"{m}.obj" for m in DEFAULT_MESHES])
    rows = []
    for path in paths:
        V, F = load_mesh(path)
        n_edges = igl.edges(F).shape[0]
        neg = {k: count_negative_weights(laplacian(V, F, k)) for k in ("cotan", "intrinsic_delaunay")}
        print(f"{mesh_name(path)}: negative weights cotan {neg['cotan']:,} / {n_edges:,} edges, "
              f"intrinsic Delaunay {neg['intrinsic_delaunay']:,}", flush=True)
        for label in args.variants:
            change = VARIANTS[label]
            result, seconds = run_variant(V, F, change, args.max_rounds)
            q = quality_row(V, F, result.U)
            row = dict(mesh=mesh_name(path), variant=label, rounds=len(result.rounds) - 1,
                       folds_per_round=" → ".join(str(r.folds_after) for r in result.rounds),
                       iterations=result.nit, converged=result.converged, seconds=seconds,
                       neg_cotan=neg["cotan"], edges=n_edges, **q)
            rows.append(row)
            print(f"  {label:32s} folds {row['folds_per_round']:>24s}  it {result.nit:6d} "
                  f"conv {result.converged!s:5s} angle {q['angle_mean']:.3f}° "
                  f"E/4π {q['energy_4pi']:.4f} centroid {q['centroid_norm']:.1e} {seconds:.1f} s",
                  flush=True)
    columns = [("mesh", "mesh", "", "l"), ("variant", "variant", "", "l"),
               ("folds after each round", "folds_per_round", "", "l"),
               ("iterations", "iterations", ",", "r"), ("converged", "converged", "", "l"),
               ("angle mean (°)", "angle_mean", ".3f", "r"), ("energy/4π", "energy_4pi", ".4f", "r"),
               ("centroid", "centroid_norm", ".1e", "r"), ("seconds", "seconds", ".1f", "r")]
    md = markdown_table(rows, columns)
    print(md)
    write_outputs(args.out, "ablation", md, dict(rows=rows))


if __name__ == "__main__":
    main()
