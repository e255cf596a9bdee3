"""Which deviation from the paper does what: the default pipeline with one piece switched off.

For each mesh (default: dino, fish_lowres and maxplanck from ../shared/meshes) and each
variant of :data:`VARIANTS` (default: all), ``spherical_conformal_map`` with the default
options changed by the variant, in this process (a diagnostic, not a timing benchmark).
For each mesh it also reports the number of negative cotangent weights of
``igl.cotmatrix`` and of ``igl.intrinsic_delaunay_cotmatrix``.  The numbers quoted in
README.md ("How the default differs from the paper") come from this script.

Usage::

    python benchmarks/ablation.py [MESH ...] [--out DIR] [--max-rounds N] [--variants LABEL ...]
"""

import sys
import time
import warnings

import igl

import igl_spheremap as sm
from harness import (DEFAULT_MESH_DIR, arguments, command, load_mesh, markdown_table, mesh_name,
                     mesh_paths, page, parse, quality_row, run)
from igl_spheremap.mesh.operators import count_negative_weights, laplacian

VARIANTS = {
    "default": {},
    "cotan Laplacian (paper Eq. 13)": dict(laplacian_kind="cotan"),
    "no fold barrier": dict(fold_barrier=False),
    "no untangling": dict(untangle=False),
    "no local repair (star round instead)": dict(local_repair=False),
    "no Möbius normalization": dict(mobius=False),
    "L2 gradient (paper)": dict(metric="L2"),
    "paper as published": "paper",
}
DEFAULT_MESHES = ("dino", "fish_lowres", "maxplanck")
COLUMNS = [("mesh", "mesh", "", "l"), ("variant", "variant", "", "l"),
           ("folds after each round", "folds_per_round", "", "l"),
           ("iterations", "iterations", ",", "r"), ("converged", "converged", "", "l"),
           ("angle mean (°)", "angle_mean", ".3f", "r"), ("energy/4π", "energy_4pi", ".4f", "r"),
           ("centroid", "centroid_norm", ".1e", "r"), ("seconds", "seconds", ".1f", "r")]


def run_variant(V, F, change, max_rounds):
    """The pipeline with the default options changed by ``change``: (result, seconds)."""
    kwargs = dict(method="paper") if change == "paper" else dict(change)
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sm.SphericalMapWarning)
        result = sm.spherical_conformal_map(V, F, max_rounds=max_rounds, **kwargs)
    return result, time.perf_counter() - t


def measure_mesh(path, args):
    """Every variant on one mesh, in this process; one row each."""
    V, F = load_mesh(path)
    n_edges = igl.edges(F).shape[0]
    neg = {k: count_negative_weights(laplacian(V, F, k)) for k in ("cotan", "intrinsic_delaunay")}
    print(f"{mesh_name(path)}: negative weights cotan {neg['cotan']:,} / {n_edges:,} edges, "
          f"intrinsic Delaunay {neg['intrinsic_delaunay']:,}", file=sys.stderr, flush=True)
    rows = []
    for label in args.variants:
        result, seconds = run_variant(V, F, VARIANTS[label], args.max_rounds)
        rows.append(dict(mesh=mesh_name(path), variant=label, rounds=len(result.rounds) - 1,
                         folds_per_round=" → ".join(str(r.folds_after) for r in result.rounds),
                         iterations=result.nit, converged=result.converged, seconds=seconds,
                         neg_cotan=neg["cotan"], neg_intrinsic_delaunay=neg["intrinsic_delaunay"],
                         edges=n_edges, **quality_row(V, F, result.U)))
    return rows


def echo(row):
    return (f"{row['mesh']} {row['variant']:32s} folds {row['folds_per_round']:>24s}  "
            f"it {row['iterations']:6d} conv {row['converged']!s:5s} "
            f"angle {row['angle_mean']:.3f}° E/4π {row['energy_4pi']:.4f} "
            f"centroid {row['centroid_norm']:.1e} {row['seconds']:.1f} s")


def render(rows, env, args):
    return page("Ablation: the default with one change switched off", env,
                markdown_table(rows, COLUMNS), command("ablation", args))


def main(argv=None):
    p = arguments(__doc__, mesh_help="mesh files or folders (default: "
                  f"{', '.join(DEFAULT_MESHES)} in {DEFAULT_MESH_DIR})")
    p.add_argument("--max-rounds", type=int, default=3)
    p.add_argument("--variants", nargs="+", metavar="LABEL", choices=list(VARIANTS),
                   default=list(VARIANTS), help="variants to run (labels of VARIANTS)")
    args = parse(p, argv)
    paths = mesh_paths(args.meshes or [DEFAULT_MESH_DIR / f"{m}.obj" for m in DEFAULT_MESHES])
    run("ablation", args, paths, lambda path: measure_mesh(path, args), render, echo=echo)
    return 0


if __name__ == "__main__":
    sys.exit(main())
