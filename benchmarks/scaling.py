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
fold-free at every size.  Up to 30k vertices that takes Algorithm 1 from the
Gauss map alone; from 100k on the Gauss-map round leaves a few folded faces
(1 at 100k, 3 at 300k) and one star-map round follows (the ``rounds``
column), so the larger sizes also pay for the eigensolver and a second run
of Algorithm 1.  Loop subdivision is the default because ``igl.upsample`` leaves
every original triangle flat: from the second pass on, the vertices inside an
original triangle all share its normal, so the Gauss map (the initial map)
sends them to one point (on maxplanck upsampled twice, 178k of its 288k
Gauss-map image triangles have |signed volume| < 1e-15; none with igl.loop).

Generated meshes are kept in ``--cache`` (default: ``igl_spheremap_scaling_cache``
in the system's temporary folder) as ``.npz`` files named by the shape, the
SHA-1 of its file, the size and the two methods, so reruns skip the
generation (the 1M mesh takes ~30 s and ~2 GB).

Each size runs in a fresh child process (``methods.run_case``): wall time of
``spherical_conformal_map(V, F)``, peak RSS of that process, folds, rounds,
iterations.  ``--max-seconds`` bounds each size (the child is killed).  With
``--stages N ...`` those sizes run a second time, in another fresh process,
with timers around the pipeline's stages (validation, Laplacian, Gauss map,
Algorithm 1 and its H1 solves, Cayley steps and fold tests, star map, final
metrics); the table of where the time goes is added to the markdown.

Usage::

    python benchmarks/scaling.py                              # maxplanck, 10k..1M
    python benchmarks/scaling.py MESH --sizes 10000 30000 --max-seconds 600 --out DIR
    python benchmarks/scaling.py --stages 1000000              # + stage profile at 1M

Writes ``DIR/scaling.md``, ``DIR/scaling.json`` and ``DIR/scaling.png``
(log-log plot of seconds and peak memory against N with reference slopes).
"""

import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from harness import (DEFAULT_MESH_DIR, Stop, arguments, environment, fmt, load_mesh,
                     markdown_table, mesh_name, page, parse, peak_rss_mib, run, run_in_child,
                     status_cell)
from methods import run_case
from remesh import DEFAULT_CACHE, cached_mesh

DEFAULT_SHAPE = DEFAULT_MESH_DIR / "maxplanck.obj"
DEFAULT_SIZES = [10_000, 30_000, 100_000, 300_000, 1_000_000]
TARGET = dict(vertices=1_000_000, seconds=120.0, peak_rss_mib=4096.0)
"""Issue #4: 1M vertices mapped fold-free in at most 120 s with at most 4 GB peak RSS."""

COLUMNS = [
    ("target N", "target", ",", "r"),
    ("vertices", "vertices", ",", "r"),
    ("faces", "faces", ",", "r"),
    ("mesh made by", "made_by", "", "l"),
    ("seconds", "seconds", ".2f", "r"),
    ("rounds", "rounds", "", "r"),
    ("iterations", "nit", ",", "r"),
    ("per round", lambda r: " + ".join(str(k) for k in (r.get("extra") or {}).get("round_nit", []))
     or "–", "", "r"),
    ("Gauss-round folds", lambda r: fmt(((r.get("extra") or {}).get("round_folds") or [None])[0],
                                        ","), "", "r"),
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
        if ref_key == "seconds":  # which sizes needed folding-removal (star-map) rounds
            for r in ok:
                if r.get("rounds"):
                    ax.annotate(f"+{r['rounds']} star round{'s' if r['rounds'] > 1 else ''}",
                                (r["vertices"], r["seconds"]), textcoords="offset points",
                                xytext=(-8, 8), ha="right", fontsize=7, color="C0")
            lo, hi = ax.get_ylim()
            ax.set_ylim(lo, hi * 2.5)  # room for the labels
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


def slopes(rows):
    """Fitted log-log slopes of seconds, peak RSS and added RSS against N."""
    for r in rows:
        r["added"] = _added(r)
    return dict(seconds=fit_slope(rows, "seconds"), peak_rss=fit_slope(rows, "peak_rss_mib"),
                added_rss=fit_slope(rows, "added"))


def render(rows, env, args):
    """The markdown page of the sizes so far (those kept by ``--merge`` too); also draws
    ``scaling.png`` next to it."""
    rows = merged(rows, args)
    shape = mesh_name(args.mesh)
    plot(rows, args.out / "scaling.png",
         f"igl_spheremap default pipeline on {shape} (refined/decimated)")
    s = slopes(rows)
    limit = f"{args.max_seconds:g} s per size" if args.max_seconds else "no time limit"
    parts = [f"`spherical_conformal_map(V, F)` on `{shape}` refined with igl.{args.subdivision} "
             f"and decimated with igl.{args.decimation} to each size; each size in a fresh "
             f"process ({limit}).",
             markdown_table(rows, COLUMNS), _target_line(rows), *_merged_note(rows, env),
             "Fitted log-log slopes over the sizes that finished: seconds ~ N^"
             f"{fmt(s['seconds'], '.2f')}, peak RSS ~ N^{fmt(s['peak_rss'], '.2f')}, added RSS ~ N^"
             f"{fmt(s['added_rss'], '.2f')}.  *peak RSS* = peak resident set size (`VmHWM`) of the "
             "fresh child process that ran the size; *added RSS* = peak RSS minus the "
             "high-water mark just before the call (interpreter, libraries and the mesh), "
             "i.e. what the pipeline itself needed.  Mesh generation is not timed.",
             "![scaling](scaling.png)"]
    for r in rows:
        parts += _profile_blocks(r)
    return page(f"Scaling of the default pipeline: {shape}", env, *parts)


def _profile_blocks(row):
    """The section of one size's stage profile (``--stages``), if it has one."""
    prof = row.get("profile")
    if not prof:
        return []
    blocks = [f"## Where the time goes at N = {row.get('vertices') or row['target']:,}"]
    if "stages" not in prof:
        return blocks + [f"Stage profile: {prof.get('status')}."]
    how = ("" if prof["status"] == "ok" else f" **{prof['status']}** (times up to then).")
    return blocks + [
        f"A second run of the same size in another fresh process, under cProfile "
        f"(`--stages`; cumulative seconds per function).{how}  Finished rounds: "
        f"{_rounds_text(prof.get('rounds_done', []))}.  Rows marked ↳ run inside "
        "Algorithm 1 (also the one inside `local_repair`) and are part of its "
        "time; the local repair's untangling and Algorithm 1 also appear in their "
        "own rows, and `mobius_center` runs inside and outside Algorithm 1, so "
        "the rows overlap and do not add up to the total.", render_stages(prof)]


# --------------------------------------------------------------------------- stage profile

#: (label, file of the package, function name) of the functions whose cumulative
#: time ``--stages`` reports, from a cProfile run of the whole call (the library
#: is not changed for it).  Labels starting with two spaces run inside Algorithm 1
#: (their time is part of it; ``local_repair`` runs Algorithm 1 on its region too).
STAGES = [
    ("validate_mesh", "mesh/validate.py", "validate_mesh"),
    ("laplacian", "mesh/operators.py", "laplacian"),
    ("Gauss map", "folding/starts.py", "vertex_normals"),
    ("Algorithm 1 (optimize.minimize)", "optimize/minimize.py", "minimize"),
    ("  H1 metric set-up (H1Metric.setup)", "optimize/direction.py", "setup"),
    ("  search direction (SearchDirection.__call__)", "optimize/direction.py", "__call__"),
    ("  energy evaluations (HarmonicEnergy.evaluate)", "optimize/harmonic.py", "evaluate"),
    ("  Cayley step", "optimize/manifold.py", "cayley_step"),
    ("  fold test of the barrier (FreeVertices.check)", "optimize/barrier.py", "check"),
    ("local_repair (untangling, Algorithm 1 on the region)", "folding/local_repair.py",
     "local_repair"),
    ("star map", "folding/star_map.py", "star_map_of"),
    ("untangle_folds", "folding/untangle.py", "untangle_folds"),
    ("mobius_center (all calls)", "sphere/mobius.py", "mobius_center"),
    ("final centering", "folding/centering.py", "final_centering"),
    ("result (final energy, centroid, areas)", "folding/result.py", "build_result"),
]


def _stage_times(profile):
    """``{label: dict(calls, seconds)}`` of :data:`STAGES` from a cProfile.Profile."""
    import pstats

    stats = pstats.Stats(profile).stats
    out = {}
    for label, filename, func in STAGES:
        calls, seconds = 0, 0.0
        for (path, _, name), (_, ncalls, _, cumtime, _) in stats.items():
            if name == func and Path(path).as_posix().endswith(f"igl_spheremap/{filename}"):
                calls += ncalls
                seconds += cumtime
        out[label] = dict(calls=calls, seconds=seconds)
    return out


def stage_profile(mesh):
    """Child body of :func:`run_stages`: the pipeline under cProfile.

    Stopped by the parent's time limit (:class:`harness.Stop`), it returns what it has
    measured so far.
    """
    import cProfile

    import igl_spheremap as sm
    V, F = load_mesh(mesh)
    rounds, profile, out = [], cProfile.Profile(), dict(status="ok")
    t0 = time.perf_counter()
    profile.enable()
    try:
        r = sm.spherical_conformal_map(V, F, callback=lambda rnd: rounds.append(
            dict(kind=rnd.kind, nit=rnd.nit, folds_before=rnd.folds_before,
                 folds_after=rnd.folds_after, seconds=rnd.seconds)))
        out.update(folds=int(r.folds), nit=int(r.nit), library_timings=dict(r.timings))
    except Stop:
        out["status"] = f"timeout: stopped after {time.perf_counter() - t0:.0f} s"
    finally:
        profile.disable()
    return dict(out, seconds=time.perf_counter() - t0, stages=_stage_times(profile),
                peak_rss_mib=peak_rss_mib(), vertices=int(V.shape[0]), rounds_done=rounds)


def run_stages(mesh, timeout, grace=120.0):
    """Time the stages of ``spherical_conformal_map`` on one mesh in a fresh child process.

    After ``timeout`` seconds the child is asked (SIGTERM) for the times so far; it
    answers when the running library call returns to Python, within ``grace`` seconds,
    or is killed.

    Returns
    -------
    dict
        ``status`` (``"ok"``, ``"timeout..."``, ``"failed: ..."``), ``seconds`` (whole
        call, or until stopped), ``peak_rss_mib``, ``rounds_done`` (kind, iterations,
        folds before/after, seconds of each finished round) and ``stages``: label ->
        ``calls``, ``seconds``.
    """
    return run_in_child(stage_profile, dict(mesh=str(mesh)), timeout, grace=grace)


def render_stages(prof):
    """Markdown table of one :func:`run_stages` result (complete or stopped).

    Cumulative times from cProfile (a function's own time and everything it
    calls); its overhead is per Python call, small at these sizes.
    """
    total = prof["seconds"]
    lines = ["| stage | calls | seconds | share |", "|---|---:|---:|---:|"]
    for label, _, _ in STAGES:
        row = prof["stages"].get(label)
        if row is None or not row["calls"]:
            continue
        name = label.replace("  ", "&nbsp;&nbsp;↳ ", 1) if label.startswith(" ") else label
        lines.append(f"| {name} | {row['calls']:,} | {row['seconds']:.2f} | "
                     f"{100 * row['seconds'] / total:.1f}% |")
    lines.append(f"| **total** (peak RSS {prof['peak_rss_mib']:.0f} MiB) | | **{total:.2f}** | "
                 "100% |")
    return "\n".join(lines)


def _rounds_text(rounds):
    return "; ".join(f"{r['kind']} round: {r['nit']} iterations, folds {r['folds_before']:,} → "
                     f"{r['folds_after']:,}, {r['seconds']:.1f} s" for r in rounds) or "none"


def _merged_note(rows, env):
    """A line naming the sizes kept from earlier runs (``--merge``), if any."""
    older = [r for r in rows if r.get("run_date") and r["run_date"] != env.get("date")]
    if not older:
        return []
    return ["Rows kept from earlier runs (`--merge`): " + ", ".join(
        f"N = {r['target']:,} ({r['run_date']}, git {r.get('git_commit')})" for r in older)
        + ".", ""]


def _target_line(rows):
    """Whether the largest size reached :data:`TARGET`."""
    want = (f"Target (issue #4): {TARGET['vertices']:,} vertices fold-free in ≤ "
            f"{TARGET['seconds']:g} s with ≤ {TARGET['peak_rss_mib'] / 1024:g} GiB peak RSS")
    big = [r for r in rows if (r.get("vertices") or r["target"]) >= TARGET["vertices"]]
    if not big:
        return want + f": not measured (largest size {max(r['target'] for r in rows):,})."
    r = big[0]
    if r.get("status") != "ok":
        return want + f": **not met** ({r.get('status')})."
    ok = (r["folds"] == 0 and r["seconds"] <= TARGET["seconds"]
          and r["peak_rss_mib"] <= TARGET["peak_rss_mib"])
    return want + (f": **{'met' if ok else 'not met'}** ({r['seconds']:.1f} s, "
                   f"{r['peak_rss_mib']:,.0f} MiB, {r['folds']} folds).")



def merged(rows, args):
    """The rows measured now and those kept from an earlier run (``--merge``), by size."""
    return sorted(args._kept + rows, key=lambda r: r["target"])


def parse_args(argv=None):
    p = arguments(__doc__, meshes=None)
    p.add_argument("mesh", nargs="?", type=Path, default=DEFAULT_SHAPE, metavar="MESH",
                   help="shape to refine (default: %(default)s)")
    p.add_argument("--sizes", type=int, nargs="+", default=DEFAULT_SIZES, metavar="N",
                   help="vertex counts (default: %(default)s)")
    p.add_argument("--max-seconds", type=float, default=600.0, metavar="S",
                   help="wall-clock limit per size (child killed after it; default: %(default)s)")
    p.add_argument("--subdivision", choices=["loop", "upsample"], default="loop")
    p.add_argument("--decimation", choices=["decimate", "qslim"], default="decimate")
    p.add_argument("--cache", type=Path, default=DEFAULT_CACHE, metavar="DIR",
                   help="folder of generated meshes reused by later runs (default: %(default)s)")
    p.add_argument("--no-cache", action="store_true", help="regenerate every mesh, keep none")
    p.add_argument("--merge", action="store_true",
                   help="keep the rows of other sizes from an existing DIR/scaling.json of the "
                        "same shape (to run the sizes one at a time)")
    p.add_argument("--stages", type=int, nargs="*", default=[], metavar="N",
                   help="sizes (among --sizes) to run a second time with timers on each stage "
                        "of the pipeline (the timed run stays unpatched)")
    args = parse(p, argv)
    if any(n < 4 for n in args.sizes):
        raise SystemExit("sizes must be at least 4 vertices")
    old = args.out / "scaling.json"
    args._kept = [r for r in (json.loads(old.read_text()).get("rows", []) if args.merge and
                             old.is_file() else [])
                 if r.get("shape") == mesh_name(args.mesh) and r.get("target") not in args.sizes]
    return args


def measure_size(n, args, V0, F0, tmp):
    """One size: the mesh generated (or read from the cache), then mapped in a child."""
    cache = None if args.no_cache else args.cache
    try:
        path, V, F, made_by, gen_seconds = cached_mesh(
            args.mesh, V0, F0, n, args.subdivision, args.decimation, cache)
    except Exception as exc:  # recorded, not fatal
        return dict(target=n, status=f"failed: mesh generation: {exc}")
    if path is None:
        path = Path(tmp) / f"{mesh_name(args.mesh)}_{n}.npz"
        np.savez(path, V=V, F=F)
    counts = dict(vertices=int(V.shape[0]), faces=int(F.shape[0]))
    del V, F
    row = run_case(path, "default", {}, timeout=args.max_seconds)
    for key, val in counts.items():
        row.setdefault(key, val)
    row.update(target=n, made_by=made_by, generation_seconds=gen_seconds,
               shape=mesh_name(args.mesh), run_date=args._date, git_commit=args._git_commit)
    if n in args.stages:
        row["profile"] = run_stages(path, args.max_seconds)
    if cache is None:
        path.unlink()
    return row


def echo(row):
    return (f"N={row['target']:>9,}: {row['status'][:60]}, {fmt(row.get('seconds'), '.2f')} s, "
            f"peak {fmt(row.get('peak_rss_mib'), '.0f')} MiB, folds {fmt(row.get('folds'))}, "
            f"iterations {fmt(row.get('nit'))}")


def main(argv=None):
    args = parse_args(argv)
    env = environment()
    args._date, args._git_commit = env.get("date"), env.get("git_commit")
    V0, F0 = load_mesh(args.mesh)
    with tempfile.TemporaryDirectory(prefix="igl_spheremap_scaling_") as tmp:
        run("scaling", args, sorted(args.sizes), lambda n: measure_size(n, args, V0, F0, tmp),
            render, echo=echo, env=env,
            payload=lambda rows: dict(rows=merged(rows, args), slopes=slopes(merged(rows, args))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
