"""The sliver statistics that route the intrinsic Delaunay Laplacian (issue #15).

``laplacian(V, F)`` (intrinsic Delaunay) uses libigl's flips unless a face's edge ratio
(shortest / longest edge) is below ``operators.NEEDLE_RTOL`` or its relative
triangle-inequality slack below ``operators.CAP_RTOL``; then it uses
``bounded_intrinsic_delaunay_cotmatrix`` (the same flips with bounded work), because
libigl's can loop until memory runs out there.  This script shows where the real meshes
sit and that the routing changes nothing on them:

* per mesh (validated as the pipeline does): smallest edge ratio and slack (from the edge
  lengths libigl starts from), smallest height ratio (2 area / longest edge^2), largest
  angle, the path taken;
* whether ``laplacian(V, F)`` equals ``igl.intrinsic_delaunay_cotmatrix(V, F)`` bit for bit,
  and whether the bounded flips do too;
* the cost of the check, of libigl's Laplacian and of the bounded flips (timed 3 times,
  alternating, best kept; ``--no-bounded`` skips the bounded flips);
* the same statistics on split icospheres (edges split at ``t`` of their length from one
  end, as in the issue; libigl is not run on them here: on such meshes its flips can loop
  until memory runs out, which ``tests/test_slivers.py`` checks the routing avoids).

    python benchmarks/sliver_statistic.py [MESH_OR_FOLDER ...] [--out DIR]

Writes ``DIR/sliver_statistic.md`` and ``.json`` (default ``benchmarks/results/``).
"""

import sys
import time

import igl
import numpy as np

from harness import (arguments, load_mesh, markdown_table, mesh_name, mesh_paths, page, parse,
                     run)
from igl_spheremap import validate_mesh
from igl_spheremap.mesh.intrinsic_delaunay import (CAP_RTOL, NEEDLE_RTOL,
                                                   bounded_intrinsic_delaunay_cotmatrix,
                                                   sliver_statistics)
from igl_spheremap.mesh.operators import laplacian
from igl_spheremap.mesh.shapes import icosphere


def statistics(V, F):
    edge_ratio, slack = sliver_statistics(V, F)
    height = igl.doublearea(V, F) / np.max(igl.edge_lengths(V, F), axis=1) ** 2
    bounded = bool(edge_ratio.min() < NEEDLE_RTOL or slack.min() < CAP_RTOL)
    return dict(faces=int(F.shape[0]), min_edge_ratio=float(edge_ratio.min()),
                min_slack=float(slack.min()), min_height_ratio=float(height.min()),
                max_angle_deg=float(np.degrees(igl.internal_angles(V, F).max())),
                path="bounded" if bounded else "libigl")


def best_of(fns, repeats=3):
    """Best wall time of each function, calling them in turn ``repeats`` times."""
    best = [np.inf] * len(fns)
    for _ in range(repeats):
        for i, fn in enumerate(fns):
            t0 = time.perf_counter()
            fn()
            best[i] = min(best[i], time.perf_counter() - t0)
    return best


def mesh_row(path, bounded=True):
    mesh = validate_mesh(*load_mesh(path))
    V, F = mesh.V, mesh.F
    row = dict(mesh=mesh_name(path), **statistics(V, F))
    L_ref = igl.intrinsic_delaunay_cotmatrix(V, F)[0]
    row["identical"] = bool((laplacian(V, F) != L_ref).nnz == 0)
    fns = [lambda: sliver_statistics(V, F), lambda: igl.intrinsic_delaunay_cotmatrix(V, F)]
    if bounded:
        Lb, skipped = bounded_intrinsic_delaunay_cotmatrix(V, F)
        row.update(bounded_identical=bool((Lb != L_ref).nnz == 0), skipped=skipped)
        fns.append(lambda: bounded_intrinsic_delaunay_cotmatrix(V, F))
    times = best_of(fns)
    row.update(check_s=times[0], laplacian_s=times[1], overhead=times[0] / times[1])
    if bounded:
        row.update(bounded_s=times[2], bounded_ratio=times[2] / times[1])
    return row


def split_icosphere(level, n_edges, t, seed=0):
    """``icosphere(level)`` with ``n_edges`` edges, no two on one face, split at ``t`` of
    their length from one end (as tests/test_slivers.py)."""
    V, F = icosphere(level)
    m = F.shape[0]
    _, uE, _, uEC, uEE = igl.unique_edge_map(F)
    used, V, new = np.zeros(m, bool), list(V), []
    for e in np.random.default_rng(seed).permutation(uE.shape[0]):
        h1, h2 = uEE[uEC[e]], uEE[uEC[e] + 1]
        f1, f2 = h1 % m, h2 % m
        if used[f1] or used[f2]:
            continue
        used[[f1, f2]] = True
        c1, c2 = h1 // m, h2 // m
        a, b, x, y = F[f1, (c1 + 1) % 3], F[f1, (c1 + 2) % 3], F[f1, c1], F[f2, c2]
        V.append(V[a] + t * (V[b] - V[a]))
        q = len(V) - 1
        F[f1], F[f2] = (x, a, q), (y, q, a)
        new += [(x, q, b), (y, b, q)]
        if len(new) == 2 * n_edges:
            break
    return np.array(V), np.vstack([F, np.array(new, np.int64)])


COLUMNS = [("mesh", "mesh", "", "l"), ("faces", "faces", ",", "r"),
           ("min edge ratio", "min_edge_ratio", ".2e", "r"), ("min slack", "min_slack", ".2e", "r"),
           ("min height ratio", "min_height_ratio", ".2e", "r"),
           ("max angle (°)", "max_angle_deg", ".2f", "r"), ("path", "path", "", "l"),
           ("L = libigl", "identical", "", "r"), ("check s", "check_s", ".4f", "r"),
           ("libigl L s", "laplacian_s", ".4f", "r"), ("check / libigl", "overhead", ".3f", "r"),
           ("bounded = libigl", "bounded_identical", "", "r"),
           ("bounded s", "bounded_s", ".3f", "r"),
           ("bounded / libigl", "bounded_ratio", ".1f", "r")]


def split_rows():
    """The statistics of icospheres with 200 edges split at ``t``, for ``t`` from 1e-2 to 1e-11."""
    rows = []
    for t in (1e-2, 1e-4, 1e-5, 1e-6, 1e-7, 1e-9, 1e-11):
        V, F = split_icosphere(3, 200, t, seed=2)
        rows.append(dict(mesh=f"icosphere L3, 200 edges split at t={t:g}", **statistics(V, F)))
    return rows


def render(rows, env, args):
    rho = min((r["min_edge_ratio"] for r in rows), default=float("nan"))
    slack = min((r["min_slack"] for r in rows), default=float("nan"))
    return page(
        "Sliver statistics and the path of the intrinsic Delaunay Laplacian", env,
        f"Bounded flips below edge ratio `NEEDLE_RTOL` = {NEEDLE_RTOL:g} or slack `CAP_RTOL` = "
        f"{CAP_RTOL:g}. Smallest over these meshes: edge ratio {rho:.2e} "
        f"({rho / NEEDLE_RTOL:.1f}x), slack {slack:.2e} ({slack / CAP_RTOL:.0f}x).",
        markdown_table(rows, COLUMNS),
        "Split icospheres (libigl not run here):", markdown_table(args._splits, COLUMNS[:7]))


def main(argv=None):
    p = arguments(__doc__)
    p.add_argument("--no-bounded", action="store_true", help="do not time the bounded flips")
    args = parse(p, argv)
    args._splits = split_rows()
    run("sliver_statistic", args, mesh_paths(args.meshes),
        lambda path: mesh_row(path, bounded=not args.no_bounded), render, echo=str,
        payload=lambda rows: dict(needle_rtol=NEEDLE_RTOL, cap_rtol=CAP_RTOL, meshes=rows,
                                  splits=args._splits))
    return 0


if __name__ == "__main__":
    sys.exit(main())
