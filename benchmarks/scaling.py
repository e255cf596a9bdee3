"""Scaling of the default pipeline with mesh size: the same shape at 10k ... 1M vertices.

The shape is refined with libigl subdivision (``igl.loop`` by default: each
pass multiplies the faces by 4 and smooths; ``igl.upsample`` splits without
smoothing) until it has at least the target number of vertices, then
decimated to exactly the target with libigl edge collapses (``igl.decimate``
by default: shortest edge first, collapsed to its midpoint, which keeps the
triangles of the subdivided mesh well shaped: on maxplanck at 10k vertices the
1st percentile of the smallest face angle is 27 deg, against 6 deg with
``igl.qslim``, the quadric-error alternative, which keeps the shape closer but
leaves slivers).  A closed genus-0 mesh with ``n`` vertices has
``2n - 4`` faces, so the face target ``2N - 4`` gives ``N`` vertices.

Default shape: the Max Planck bust (``maxplanck.obj``, 9,002 vertices; also
in the paper's Tables 1 and 2).  It has no thin features and its Gauss map
folds least of the statues (unsigned Gauss-map area 7.0 x 4π against 38.7 x 4π
for ``bimba.obj``, shared/meshes/README.md), and the default pipeline maps it
fold-free straight from the Gauss map, without a folding-removal round, so the
curve measures how Algorithm 1 scales rather than a number of star-map rounds
that changes from size to size (the ``rounds`` column shows if that stops
being true).  Loop subdivision is the default because ``igl.upsample`` leaves
every original triangle flat: from the second pass on, the vertices inside an
original triangle all share its normal, so the Gauss map (the initial map)
sends them to one point (on maxplanck upsampled twice, 178k of its 288k
Gauss-map image triangles have |signed volume| < 1e-15; none with igl.loop).

Each size runs in a fresh child process (benchmarks/_common.py): wall time of
``spherical_conformal_map(V, F)``, peak RSS of that process, folds, rounds,
iterations.  ``--max-seconds`` bounds each size (the child is killed).

Usage::

    python benchmarks/scaling.py                              # maxplanck, 10k..1M
    python benchmarks/scaling.py MESH --sizes 10000 30000 --max-seconds 600 --out DIR

Writes ``DIR/scaling.md``, ``DIR/scaling.json`` and ``DIR/scaling.png``
(log-log plot of seconds and peak memory against N with reference slopes).
"""

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import (DEFAULT_MESH_DIR, DEFAULT_OUT, environment, environment_line,  # noqa: E402
                     fmt, load_mesh, markdown_table, mesh_name, run_case, status_cell,
                     write_outputs)

DEFAULT_SHAPE = DEFAULT_MESH_DIR / "maxplanck.obj"
DEFAULT_SIZES = [10_000, 30_000, 100_000, 300_000, 1_000_000]

COLUMNS = [
    ("target N", "target", ",", "r"),
    ("vertices", "vertices", ",", "r"),
    ("faces", "faces", ",", "r"),
    ("mesh made by", "made_by", "", "l"),
    ("seconds", "seconds", ".2f", "r"),
    ("rounds", "rounds", "", "r"),
    ("iterations", "nit", ",", "r"),
    ("folds", "folds", ",", "r"),
    ("angle mean (°)", "angle_mean", ".3f", "r"),
    ("converged", "converged", "", "l"),
    ("peak RSS (MiB)", "peak_rss_mib", ".0f", "r"),
    ("added RSS (MiB)", lambda r: fmt(_added(r), ".0f"), "", "r"),
    ("status", status_cell, "", "l"),
]


def _added(row):
    if row.get("peak_rss_mib") is None or row.get("base_rss_mib") is None:
        return None
    return row["peak_rss_mib"] - row["base_rss_mib"]


def make_mesh(V, F, n_target, subdivision="loop", decimation="decimate"):
    """The shape ``(V, F)`` refined and decimated to ``n_target`` vertices.

    Subdivide (``igl.loop`` or ``igl.upsample``) the fewest times that reach at
    least ``n_target`` vertices (``n -> 4n - 6`` per pass on a closed genus-0
    mesh), then collapse edges (``igl.decimate`` or ``igl.qslim``) down to
    ``2 n_target - 4`` faces.

    Returns
    -------
    V : (N, 3) float64 array
    F : (2N - 4, 3) int64 array
    made_by : str
        How the mesh was made, e.g. ``"loop x2, decimate"``.

    Raises
    ------
    RuntimeError
        If decimation fails or does not return a closed genus-0 mesh.
    """
    import igl
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    subdivide = {"loop": igl.loop, "upsample": igl.upsample}[subdivision]
    k = 0
    while V.shape[0] < n_target:
        V, F = subdivide(V, F, 1)
        k += 1
    made = [f"{subdivision} x{k}"] if k else []
    if V.shape[0] > n_target:
        collapse = {"qslim": igl.qslim, "decimate": igl.decimate}[decimation]
        out = collapse(np.asfortranarray(V), np.asfortranarray(F.astype(np.int32)),
                       2 * n_target - 4)
        if isinstance(out[0], (bool, np.bool_)):  # older bindings return a success flag first
            if not out[0]:
                raise RuntimeError(f"igl.{decimation} failed at {n_target} vertices")
            out = out[1:]
        V = np.ascontiguousarray(out[0], dtype=np.float64)
        F = np.ascontiguousarray(out[1], dtype=np.int64)
        made.append(decimation)
    E = igl.edges(F)
    if V.shape[0] - E.shape[0] + F.shape[0] != 2 or np.unique(F).size != V.shape[0]:
        raise RuntimeError(f"refined/decimated mesh at {n_target} vertices is not closed "
                           f"genus 0 (V={V.shape[0]}, E={E.shape[0]}, F={F.shape[0]})")
    return V, F, ", ".join(made) or "original"


def fit_slope(rows, key):
    """Least-squares slope of log(key) against log(vertices) over the ok rows."""
    pts = [(r["vertices"], r[key]) for r in rows
           if r.get("status") == "ok" and r.get(key) and r.get(key) > 0]
    if len(pts) < 2:
        return None
    x, y = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    return float(np.polyfit(x, y, 1)[0])


def plot(rows, path, title):
    """Log-log plot of seconds and peak memory against N, with reference slopes."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = [r for r in rows if r.get("status") == "ok"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for r in ok:
        r["added"] = _added(r)
    # (axis, [(label, key, style)], y label, key the reference slopes start from)
    series = [
        (axes[0], [("seconds", "seconds", "o-")], "wall time (s)", "seconds"),
        (axes[1], [("peak RSS", "peak_rss_mib", "o-"), ("added RSS (peak - base)", "added", "s--")],
         "memory (MiB)", "added"),
    ]
    for ax, lines, ylabel, ref_key in series:
        for label, key, style in lines:
            pts = [(r["vertices"], r[key]) for r in ok if r.get(key)]
            if not pts:
                continue
            x, y = zip(*pts)
            ax.loglog(x, y, style, label=label)
        ref = [(r["vertices"], r[ref_key]) for r in ok if r.get(ref_key)]
        if ref:
            n0, y0 = ref[0]
            xs = np.array([n0, max(r["vertices"] for r in ok)], dtype=float)
            if xs[1] > xs[0]:
                ax.loglog(xs, y0 * (xs / n0), ":", color="gray", label="slope 1 (∝ N)")
                if ref_key == "seconds":
                    ax.loglog(xs, y0 * (xs / n0) ** 1.5, "-.", color="darkgray",
                              label="slope 1.5 (∝ N^1.5)")
        failed = [r for r in rows if r.get("status") != "ok"]
        for i, r in enumerate(failed):
            ax.axvline(r.get("vertices") or r["target"], color="red", alpha=0.3,
                       label="failed / timed out" if i == 0 else None)
        ax.set_xlabel("vertices N")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def render(rows, env, args, shape):
    t_slope, m_slope = fit_slope(rows, "seconds"), fit_slope(rows, "peak_rss_mib")
    for r in rows:
        r["added"] = _added(r)
    a_slope = fit_slope(rows, "added")
    limit = f"{args.max_seconds:g} s per size" if args.max_seconds else "no time limit"
    parts = [f"# Scaling of the default pipeline: {shape}", "", environment_line(env), "",
             f"`spherical_conformal_map(V, F)` on `{shape}` refined with igl.{args.subdivision} "
             f"and decimated with igl.{args.decimation} to each size; each size in a fresh "
             f"process ({limit}).", "",
             markdown_table(rows, COLUMNS), "",
             "Fitted log-log slopes over the sizes that finished: seconds ~ N^"
             f"{fmt(t_slope, '.2f')}, peak RSS ~ N^{fmt(m_slope, '.2f')}, added RSS ~ N^"
             f"{fmt(a_slope, '.2f')}.  *peak RSS* = peak resident set size (`VmHWM`) of the "
             "fresh child process that ran the size; *added RSS* = peak RSS minus the "
             "high-water mark just before the call (interpreter, libraries and the mesh), "
             "i.e. what the pipeline itself needed.  Mesh generation is not timed.", "",
             "![scaling](scaling.png)"]
    return "\n".join(parts), dict(seconds=t_slope, peak_rss=m_slope, added_rss=a_slope)


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("mesh", nargs="?", type=Path, default=DEFAULT_SHAPE, metavar="MESH",
                   help="shape to refine (default: %(default)s)")
    p.add_argument("--sizes", type=int, nargs="+", default=DEFAULT_SIZES, metavar="N",
                   help="vertex counts (default: %(default)s)")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, metavar="DIR",
                   help="output folder for scaling.md/.json/.png (default: %(default)s)")
    p.add_argument("--max-seconds", type=float, default=3600.0, metavar="S",
                   help="wall-clock limit per size (child killed after it; default: %(default)s)")
    p.add_argument("--subdivision", choices=["loop", "upsample"], default="loop")
    p.add_argument("--decimation", choices=["decimate", "qslim"], default="decimate")
    return p.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    if any(n < 4 for n in args.sizes):
        raise SystemExit("sizes must be at least 4 vertices")
    shape = mesh_name(args.mesh)
    V0, F0 = load_mesh(args.mesh)
    env = environment()
    rows = []
    t_start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="igl_spheremap_scaling_") as tmp:
        for n in sorted(args.sizes):
            t0 = time.perf_counter()
            try:
                V, F, made_by = make_mesh(V0, F0, n, args.subdivision, args.decimation)
            except Exception as exc:  # recorded, not fatal
                rows.append(dict(target=n, status=f"failed: mesh generation: {exc}"))
                continue
            gen_seconds = time.perf_counter() - t0
            path = Path(tmp) / f"{shape}_{n}.npz"
            np.savez(path, V=V, F=F)
            counts = dict(vertices=int(V.shape[0]), faces=int(F.shape[0]))
            del V, F
            row = run_case(path, "default", {}, timeout=args.max_seconds)
            path.unlink()
            for key, val in counts.items():
                row.setdefault(key, val)
            row.update(target=n, made_by=made_by, generation_seconds=gen_seconds, shape=shape)
            rows.append(row)
            print(f"[{time.perf_counter() - t_start:7.1f} s] N={n:>9,}: {row['status'][:60]}, "
                  f"{fmt(row.get('seconds'), '.2f')} s, peak {fmt(row.get('peak_rss_mib'), '.0f')}"
                  f" MiB, folds {fmt(row.get('folds'))}, iterations {fmt(row.get('nit'))}",
                  file=sys.stderr, flush=True)
            markdown, slopes = render(rows, env, args, shape)
            write_outputs(args.out, "scaling", markdown,
                          dict(environment=env, options=vars(args), rows=rows, slopes=slopes))
            plot(rows, args.out / "scaling.png",
                 f"igl_spheremap default pipeline on {shape} (refined/decimated)")
    markdown, _ = render(rows, env, args, shape)
    print(markdown)
    return 0


if __name__ == "__main__":
    sys.exit(main())
