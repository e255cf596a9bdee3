"""Registration accuracy and time of ``surface_map`` on pairs with a known correspondence.

A pair is built from one mesh ``S`` (surface 2, used as it is):

1. *Another triangulation of S.*  ``S`` is refined once by Loop subdivision
   (``igl.loop``), then decimated back to ``S``'s vertex count by edge
   collapses (``igl.decimate``: shortest edge first, collapsed to its midpoint;
   ``benchmarks/remesh.py``'s ``make_mesh``).  Subdivision smooths and the
   collapses move vertices, so they leave ``S``'s surface slightly (*off S*
   under the table: largest distance, in % of ``S``'s bounding-box diagonal).
2. *Ground truth.*  For each vertex ``a`` of that mesh, ``p_a`` is the closest
   point of ``S``'s surface (``igl.point_mesh_squared_distance``): the true
   correspondent of ``a``.
3. *A smooth non-conformal deformation* gives surface 1, so that the two
   conformal structures differ.  In coordinates centred at ``S``'s vertex
   centroid, divided by ``S``'s bounding-box diagonal ``d`` and expressed in
   ``S``'s principal axes (``u1`` the longest): ``u1 -> 1.4 u1``, ``u3 -> 0.7 u3``
   (anisotropic scaling, a factor 2 between the two), then the parabolic bend
   ``u3 -> u3 + 0.6 u1^2``; then back to the original frame and scale.
4. *Landmarks.*  ``k`` vertices of surface 1 spread by farthest-point sampling
   (Euclidean, over the points ``p_a``, starting from the point farthest from
   their centroid; the sets for the different ``k`` are nested), each paired
   with the vertex of ``S`` nearest to its ``p_a`` (*landmark pairing offset*
   under the table: the largest such offset, % of ``d``; the landmark pairs
   themselves are only that exact).

Then ``surface_map(V1, F1, V_S, F_S, landmarks1, landmarks2)`` (hard landmarks)
runs for each ``k``; the error of vertex ``a`` is ``|transfer(V_S)_a - p_a| / d``
(``transfer(V_S) = P @ V_S``: where the map puts ``a`` on ``S``).  Reference
rows, method *Möbius fit*: both surfaces mapped conformally
(``spherical_conformal_map``), surface 1's map moved by the Möbius
transformation that best fits its landmarks to surface 2's
(``igl_spheremap.sphere.mobius.mobius_fit``, least squares), and located on surface
2's map the same way: what the conformal maps give without the landmark
deformation.  With ``k = 3`` the fit is exact, so hard ``k = 3`` and the fit
should agree.

Default pairs: hippocampus, maxplanck, bimba (``/work/shared/meshes``) and a
50k-vertex pair from maxplanck (``scaling.py``'s cached 50,000-vertex remesh as
``S``, surface 1 built from it as above) for the goal of issue #12:
``surface_map`` of two 50k-vertex surfaces in at most 5 s on this machine.

Every (pair, method, k) runs in a fresh child process (``harness.run_in_child``):
seconds = wall time of the call, best of up to 3 calls when the first takes
under 10 s (``harness.REPEATS``, ``REPEAT_BELOW_SECONDS``); peak RSS = the
child's ``VmHWM`` after its first call; errors and folds from the first call.

Usage::

    python benchmarks/registration.py                           # 3 meshes + 50k pair
    python benchmarks/registration.py --mesh-dir /work/shared/meshes
    python benchmarks/registration.py MESH ... --ks 4 8 --large 0 --out DIR
    python benchmarks/registration.py --large 50000 --large-shape MESH --timeout 900

Writes ``DIR/registration.md`` and ``DIR/registration.json`` (default
``benchmarks/results/``); pairs are cached as ``.npz`` in ``--cache``.
"""

import hashlib
import sys
import time
from pathlib import Path

import numpy as np

from harness import (DEFAULT_MESH_DIR, REPEATS, arguments, command, fmt, load_mesh,
                     markdown_table, mesh_name, page, parse, run, run_in_child, status_cell,
                     timed_calls)
from remesh import DEFAULT_CACHE, cached_mesh, make_mesh, save_npz

DEFAULT_MESHES = ["hippocampus", "maxplanck", "bimba"]
DEFAULT_KS = [4, 8, 16, 32]
REFERENCE_K = 3
#: Deformation of step 3 (principal-axis scales and bend), recorded in the JSON.
SCALES = (1.4, 1.0, 0.7)
BEND = 0.6
GOAL = dict(vertices=50_000, seconds=5.0)
"""Issue #12: surface_map of two 50k-vertex surfaces in at most 5 s on this machine."""
PAIR_VERSION = 1  # bump when the construction changes (cache key)

COLUMNS = [
    ("pair", "pair", "", "l"),
    ("n1 / n2", lambda r: f"{fmt(r.get('n1'), ',')} / {fmt(r.get('n2'), ',')}", "", "r"),
    ("method", "method", "", "l"),
    ("k", "k", "", "r"),
    ("mean err (% diag)", "err_mean", ".2f", "r"),
    ("p90 err (% diag)", "err_p90", ".2f", "r"),
    ("max err (% diag)", "err_max", ".2f", "r"),
    ("max landmark err (°)", "landmark_err_max", ".2g", "r"),
    ("folds map1 / map2", lambda r: f"{fmt(r.get('folds1'))} / {fmt(r.get('folds2'))}", "", "r"),
    ("success", "success", "", "l"),
    ("landmark round it. / frozen",
     lambda r: (f"{r['landmark_nit']} / {r['landmark_frozen']}"
                if r.get("landmark_nit") is not None else "–"), "", "r"),
    ("seconds", "seconds", ".2f", "r"),
    ("map2 / map1 / locate (s)", lambda r: " / ".join(
        fmt((r.get("timings") or {}).get(x), ".2f") for x in ("map2", "map1", "locate")), "", "r"),
    ("peak RSS (MiB)", "peak_rss_mib", ".0f", "r"),
    ("status", status_cell, "", "l"),
]

LEGEND = """\
*pair* = the mesh S the pair was built from (surface 2 = S, surface 1 = S
re-triangulated and deformed, see the construction above); *n1 / n2* = vertices
of surface 1 / surface 2; *method*: *hard* = `surface_map(V1, F1, V_S, F_S, l1,
l2)` (hard landmarks), *Möbius fit* = both conformal maps and the least-squares
Möbius fit of the landmarks, no landmark deformation (reference); *k* = landmark
pairs; *err* = |transfer(V_S)_a - p_a| over the vertices a of surface 1, in % of
S's bounding-box diagonal: *mean*, *p90* (90th percentile) and *max*; *max
landmark err* = largest angle between a landmark's image and its partner's on
surface 2's map (degrees; 0 to rounding for hard landmarks); *folds map1 /
map2* = folded faces of surface 1's (landmark or Möbius-moved) map / surface 2's
conformal map (`count_folds`); *success* = `SurfaceMapResult.success` (both maps
fold-free and converged, landmarks reached; for the fit: both conformal maps
successful and the moved map fold-free); *landmark round it. / frozen* =
Algorithm 1 iterations of surface 1's landmark round / vertices the fold barrier
froze in it; *seconds* = wall time of the call (for the fit: both conformal
maps, the fit and the location), best of up to 3 calls when one takes under
10 s; *map2 / map1 / locate* = the result's `timings` (first call): surface 2's
conformal map, surface 1's landmark map (for the fit: its conformal map and the
fit), point location and interpolation matrix; *peak RSS* = the child process's
peak resident set size (`VmHWM`) after its first call (interpreter, libraries,
both meshes included)."""


# --------------------------------------------------------------------------- the pair

def principal_frame(V):
    """Centroid and principal axes (columns, longest first) of the points ``V``."""
    c = V.mean(axis=0)
    w, E = np.linalg.eigh(np.cov((V - c).T))
    return c, E[:, ::-1]


def deform(X, center, axes, diag):
    """The deformation of step 3 applied to points ``X`` ((n, 3) -> (n, 3))."""
    u = (X - center) @ axes / diag
    u = u * np.asarray(SCALES)
    u[:, 2] = u[:, 2] + BEND * u[:, 0] ** 2
    return (u * diag) @ axes.T + center


def farthest_points(X, k):
    """Indices of ``k`` points of ``X`` by farthest-point sampling (Euclidean).

    Starts from the point farthest from the centroid; deterministic, and the
    first ``j`` of the result are the sampling with ``j`` points.
    """
    first = int(np.argmax(np.linalg.norm(X - X.mean(axis=0), axis=1)))
    chosen = [first]
    d = np.linalg.norm(X - X[first], axis=1)
    for _ in range(k - 1):
        j = int(np.argmax(d))
        chosen.append(j)
        d = np.minimum(d, np.linalg.norm(X - X[j], axis=1))
    return np.array(chosen, dtype=np.int64)


def build_pair(VS, FS, k_max):
    """Surface 1, the ground truth and the landmark sequence for the mesh ``(VS, FS)``.

    Returns
    -------
    dict of arrays
        ``VS, FS`` (surface 2), ``V1, F1`` (surface 1), ``Pa`` ((n1, 3): true
        correspondent of each vertex of surface 1 on S), ``diag`` (S's
        bounding-box diagonal), ``off_s`` (largest |vertex - p_a| before the
        deformation / diag), ``l1, l2`` (``k_max`` landmark pairs in
        farthest-point order), ``made_by``.
    """
    import igl
    from scipy.spatial import cKDTree

    VL, FL = igl.loop(VS, FS, 1)
    V0, F1, made = make_mesh(VL, FL, VS.shape[0])
    _, _, Pa = igl.point_mesh_squared_distance(V0, VS, FS)
    diag = float(np.linalg.norm(VS.max(axis=0) - VS.min(axis=0)))
    center, axes = principal_frame(VS)
    V1 = deform(V0, center, axes, diag)
    l1 = farthest_points(Pa, k_max)
    l2 = cKDTree(VS).query(Pa[l1])[1].astype(np.int64)
    return dict(VS=VS, FS=FS, V1=V1, F1=F1, Pa=Pa, diag=np.array(diag),
                off_s=np.array(np.linalg.norm(V0 - Pa, axis=1).max() / diag), l1=l1, l2=l2,
                made_by=np.array(f"loop x1, then {made}"))


def cached_pair(name, source_bytes, VS, FS, k_max, cache_dir):
    """:func:`build_pair` through a ``.npz`` cache keyed by the source's SHA-1 and ``k_max``."""
    digest = hashlib.sha1(source_bytes).hexdigest()[:12]
    path = Path(cache_dir) / f"registration_pair_v{PAIR_VERSION}_{name}_{digest}_k{k_max}.npz"
    if not path.exists():
        t = time.perf_counter()
        pair = build_pair(VS, FS, k_max)
        pair["seconds"] = np.array(time.perf_counter() - t)
        save_npz(path, **pair)
    return path


# --------------------------------------------------------------------------- the child

def _errors(X, Pa, diag):
    e = 100.0 * np.linalg.norm(X - Pa, axis=1) / diag
    return dict(err_mean=float(e.mean()), err_p90=float(np.percentile(e, 90)),
                err_max=float(e.max()))


def _hard(VS, FS, V1, F1, l1, l2):
    import igl_spheremap as sm
    r = sm.surface_map(V1, F1, VS, FS, l1, l2, mode="hard")
    last = r.map1.rounds[-1]  # no landmark round when the landmarks could not be reached
    landmark = last.kind == "landmark"
    return r.transfer(VS), dict(
        landmark_err_max=float(np.max(r.landmark_errors)), folds1=int(r.map1.folds),
        folds2=int(r.map2.folds), success=bool(r.success), timings=dict(r.timings),
        landmark_nit=int(last.nit) if landmark else None,
        landmark_frozen=int(last.frozen) if landmark else None,
        round_kinds=[x.kind for x in r.map1.rounds], message=r.message)


def _mobius_fit(VS, FS, V1, F1, l1, l2):
    import igl_spheremap as sm
    from igl_spheremap.sphere.mobius import mobius_fit, mobius_transform
    t0 = time.perf_counter()
    map2 = sm.spherical_conformal_map(VS, FS)
    t1 = time.perf_counter()
    map1 = sm.spherical_conformal_map(V1, F1)
    c, R, _ = mobius_fit(map1.U[l1], map2.U[l2])
    U1 = mobius_transform(map1.U, c) @ R.T
    t2 = time.perf_counter()
    face, bary = sm.locate_on_sphere(map2.U, map2.F, U1)
    P = sm.barycentric_matrix(face, bary, map2.F, map2.U.shape[0])
    t3 = time.perf_counter()
    err = np.degrees(np.arctan2(np.linalg.norm(np.cross(U1[l1], map2.U[l2]), axis=1),
                                np.sum(U1[l1] * map2.U[l2], axis=1)))
    folds1 = sm.count_folds(map1.F, U1)
    return P @ VS, dict(landmark_err_max=float(err.max()), folds1=int(folds1),
                        folds2=int(map2.folds),
                        success=bool(map1.success and map2.success and folds1 == 0),
                        timings=dict(map2=t1 - t0, map1=t2 - t1, locate=t3 - t2),
                        landmark_nit=None, landmark_frozen=None)


RUNNERS = {"hard": _hard, "Möbius fit": _mobius_fit}


def measure(pair_path, method, k, repeats=REPEATS):
    """Child body: one method with ``k`` landmarks on the cached pair; errors, time, memory."""
    import igl_spheremap  # noqa: F401  (imported before the base RSS reading)
    with np.load(pair_path) as d:
        data = {key: d[key] for key in d.files}
    VS, FS, V1, F1 = data["VS"], data["FS"], data["V1"], data["F1"]
    l1, l2 = data["l1"][:k], data["l2"][:k]
    fn = RUNNERS[method]

    def once(clock):
        with clock:
            return fn(VS, FS, V1, F1, l1, l2)
    (X, row), clock, runs = timed_calls(once, repeats)
    peak, base = clock.peak_rss, clock.base_rss
    row.update(_errors(X, data["Pa"], float(data["diag"])))
    pairing = np.linalg.norm(VS[l2] - data["Pa"][l1], axis=1).max() / float(data["diag"])
    row.update(seconds=min(runs), seconds_runs=runs, peak_rss_mib=peak, base_rss_mib=base,
               n1=int(V1.shape[0]), n2=int(VS.shape[0]), pairing_pct=100.0 * float(pairing))
    return row


# --------------------------------------------------------------------------- driver

def parse_args(argv=None):
    p = arguments(__doc__, timeout=600.0, repeats=REPEATS,
                  mesh_help="mesh files S (default: hippocampus, maxplanck, bimba in --mesh-dir)")
    p.add_argument("--mesh-dir", type=Path, default=DEFAULT_MESH_DIR,
                   help="folder of the default meshes (default: ../shared/meshes)")
    p.add_argument("--ks", type=int, nargs="+", default=DEFAULT_KS, help="landmark counts")
    p.add_argument("--reference-k", type=int, default=REFERENCE_K,
                   help="extra landmark count for the reference rows (0: none)")
    p.add_argument("--no-mobius", action="store_true", help="skip the Möbius-fit reference rows")
    p.add_argument("--large", type=int, default=GOAL["vertices"],
                   help="vertex count of the large pair (0: no large pair)")
    p.add_argument("--large-shape", help="shape of the large pair (default: maxplanck.obj in "
                   "--mesh-dir)")
    p.add_argument("--cache", type=Path, default=DEFAULT_CACHE)
    args = parse(p, argv)
    args._ks = sorted(set(([args.reference_k] if args.reference_k else []) + list(args.ks)))
    args._pairs = []
    return args


def pairs(args, k_max):
    """(name, pair .npz path, notes) of every pair, built or read from the cache."""
    meshes = args.meshes or [str(args.mesh_dir / f"{m}.obj") for m in DEFAULT_MESHES]
    for m in meshes:
        VS, FS = load_mesh(m)
        yield mesh_name(m), cached_pair(mesh_name(m), Path(m).read_bytes(), VS, FS, k_max,
                                        args.cache)
    if args.large:
        args.large_shape = args.large_shape or str(args.mesh_dir / "maxplanck.obj")
        V0, F0 = load_mesh(args.large_shape)
        src, VS, FS, made, _ = cached_mesh(args.large_shape, V0, F0, args.large, "loop",
                                           "decimate", args.cache)
        name = f"{mesh_name(args.large_shape)} {args.large // 1000}k ({made})"
        key = Path(src).read_bytes() if src else VS.tobytes() + FS.tobytes()
        yield name, cached_pair(f"{mesh_name(args.large_shape)}_{args.large}", key, VS, FS,
                                k_max, args.cache)


def render(rows, env, args):
    ks = args._ks
    lines = [(__doc__.split("\n\n", 1)[1].split("Default pairs")[0]).strip().replace("``", "`"),
             f"Landmark counts: {', '.join(map(str, ks))}.",
             markdown_table(rows, COLUMNS), LEGEND]
    info = [f"{p['pair']}: surface 1 made by {p['made_by']}, off S ≤ {p['off_s_pct']:.2f} % of "
            f"the diagonal, landmark pairing offset ≤ {p['pairing_pct']:.2f} % (k = {max(ks)})"
            for p in args._pairs]
    if info:
        lines.append("Pairs: " + "; ".join(info) + ".")
    lines.append(_goal_line(rows))
    lines.append(command("registration", args))
    return page("Registration through the sphere: `surface_map` on pairs with known "
                "correspondence", env, *lines)


def _goal_line(rows):
    """Whether the 50k pair met issue #12's goal, if it was measured."""
    goal = [r for r in rows if r.get("method") == "hard" and r.get("status") == "ok"
            and min(r.get("n1", 0), r.get("n2", 0)) >= 0.95 * GOAL["vertices"]]
    if not goal:
        return ""
    met = [r for r in goal if r["seconds"] <= GOAL["seconds"] and r["success"]]
    met_ks = ", ".join(str(r["k"]) for r in met) or "none"
    return (f"Goal (issue #12): `surface_map` of two {GOAL['vertices']:,}-vertex surfaces in "
            f"≤ {GOAL['seconds']:g} s: met for k = {met_ks}"
            f" of k = {', '.join(str(r['k']) for r in goal)} (seconds "
            f"{', '.join(format(r['seconds'], '.2f') for r in goal)}; peak RSS "
            f"{', '.join(format(r['peak_rss_mib'], '.0f') for r in goal)} MiB).")


def measure_pair(pair, args):
    """Every method and landmark count on one pair, each in a fresh child; one row each."""
    name, path = pair
    with np.load(path) as d:
        info = dict(pair=name, made_by=str(d["made_by"]), off_s_pct=100.0 * float(d["off_s"]),
                    seconds_to_build=float(d["seconds"]), cache=str(path))
    args._pairs.append(info)
    rows = []
    for k in args._ks:
        for method in ["hard"] + ([] if args.no_mobius else ["Möbius fit"]):
            row = run_in_child(measure, dict(pair_path=str(path), method=method, k=k,
                                             repeats=args.repeats), timeout=args.timeout)
            row.update(pair=name, method=method, k=k)
            rows.append(row)
            info["pairing_pct"] = row.get("pairing_pct", float("nan"))
    return rows


def echo(row):
    return (f"{row['pair']:>40s} {row['method']:>10s} k={row['k']:2d}: {row.get('status')}, "
            f"{fmt(row.get('seconds'), '.2f')} s, mean err {fmt(row.get('err_mean'), '.2f')} %")


def main(argv=None):
    args = parse_args(argv)
    run("registration", args, pairs(args, max(args._ks)), lambda pair: measure_pair(pair, args),
        render, echo=echo, payload=lambda rows: dict(scales=SCALES, bend=BEND, goal=GOAL,
                                                     pairs=args._pairs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
