"""Accuracy and time of maps between surfaces on real pairs with a known vertex-to-vertex correspondence.

Pairs (``../shared/registration``; vertex ``i`` of surface 1 corresponds to
vertex ``i`` of surface 2): ``cat-ref-07`` (cat reference -> cat pose 07),
``cat-05-08`` (cat pose 05 -> pose 08), near isometric; ``dino-horse``
(``../shared/meshes/dino.obj`` -> the horse with its connectivity), different
species.  Held out (``--pairs``, not in the default run): the other ten ordered
pairs of the four cats (``cat-ref-05``, ``cat-07-ref``, ...), ``horse-dino``, and
``human-posed`` / ``posed-human``: the SMPL woman of ``../shared/meshes`` and the same
mesh in another pose (``benchmarks/posed_human.py``, vendored in ``tests/data``), a body
with fingers; ``human-wide`` / ``posed-wide``: the woman and her posed copy -> the woman
15% wider and 13% shallower (:data:`SCALED`), a body of another shape; ``cat-ref-07-dec`` /
``dino-horse-dec``: the cat reference / the dino decimated to half its faces, two
triangulations (:data:`DECIMATED`); ``cat-ref-07-dec2`` / ``dino-horse-dec2``: cat 07 / the
horse decimated instead (:data:`DECIMATED_2`); ``-kept`` / ``-kept2``: their controls, the pair
in one triangulation with the decimated pair's landmarks and error vertices (:data:`KEPT`).

Landmarks: ``k`` vertices of surface 1 by geodesic farthest-point sampling
(heat-method distances of ``potpourri3d``; the first is the vertex farthest
from vertex 0; the sets for the different ``k`` are nested), paired with the
same indices on surface 2.

Error of vertex ``i`` of surface 1 (Kim, Lipman, Funkhouser 2011; the FAUST
protocol; the README of ``../shared/registration``): the geodesic distance on
surface 2 between the point where the map puts it and vertex ``i`` of surface
2, over ``sqrt(area of surface 2)``.  Distances are heat-method distances
(``potpourri3d.MeshHeatMethodDistanceSolver``) from every vertex of surface 2,
interpolated linearly in the face of the mapped point; the ``n2 x n2`` table
is cached as float32 in ``--cache``.

Methods, each (pair, k, method) in a fresh child process
(``harness.run_in_child``), wall time of the whole call (both spherical maps
included; eigenvectors and descriptors for ZoomOut):

* ``ours``: :func:`igl_spheremap.surface_map` with its defaults (hard landmarks; the
  coarse levels ``uses.coarse_to_fine.LEVELS``; the harmonic landmark descriptors with
  at least 8 landmarks, then a last stage with a tenth of their weight, or without them
  where the map is near-isometric);
* ``ours_plain``: the same without the descriptor term and the coarse levels
  (``descriptor_weight=0, coarse_levels=()``: the defaults before they were on);
* ``ours_no_descriptors``, ``ours_no_coarse``: the defaults with one of the two off;
* ``ours_robust``: the defaults with ``robust_scale=0.01`` (the robust last stage whatever the
  pair; at k >= 8 the maps of ``ours`` at git 9791970, where it was the default there);
* ``ours_no_robust``: the defaults with ``robust_scale=None`` (plain ARAP in every stage, also
  where the default ``"auto"`` finds the pair near-isometric);
* ``mobius``: both conformal maps (``spherical_conformal_map``); surface 1's
  moved by the Möbius transformation that best fits its landmarks (k >= 3,
  ``uses.alignment.landmark_start``), or (k < 3) area-centred and rotated by
  the alignment's best rotation (``uses.alignment.rotation_starts``, first
  hypothesis), located on surface 2's: the conformal maps without a
  deformation;
* ``zoomout``: ZoomOut (Melzi et al. 2019) as shipped in pyfmaps 1.3.1 with
  its README's settings (area-normalized, centred meshes, WKS descriptors,
  ``subsample_step=2``, ``fit(K=30, w_descr=1, w_lap=0.1, w_dcomm=1,
  w_orient=1)``, ``zoomout_refine(nit=16, step=5)``), the landmarks passed as
  descriptors.  Vertex-to-vertex output; no fold count.

Usage::

    python benchmarks/correspondence.py                          # 3 pairs, k = 0 4 8 16 32
    python benchmarks/correspondence.py --pairs cat-ref-07 --ks 16 32 --methods ours zoomout
    python benchmarks/correspondence.py --pairs cat-ref-05 cat-08-07 horse-dino --ks 16 32 \
        --methods ours zoomout --out benchmarks/results/correspondence_held_out
    python benchmarks/correspondence.py --large 50000            # two 50k surfaces: ours, ZoomOut

Writes ``DIR/correspondence.md`` and ``.json`` (``--large``: ``correspondence_large``).
"""

import os
import sys
import time
from pathlib import Path

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import igl  # noqa: E402
import numpy as np  # noqa: E402

from harness import (REPO_ROOT, arguments, command, fmt, markdown_table, page, parse,  # noqa: E402
                     run, run_in_child, status_cell)

SHARED = next((d for d in (REPO_ROOT.parent / "shared", Path("/work/shared")) if d.exists()),
              REPO_ROOT.parent / "shared")  # a worktree's parent has no shared/
REG_DIR = SHARED / "registration"
MESH_DIR = SHARED / "meshes"
#: ``human_woman.obj`` in a second pose, same connectivity (``benchmarks/posed_human.py``).
POSED_HUMAN = REPO_ROOT / "tests" / "data" / "human_woman_posed.obj"
CATS = {"ref": "sumner_cat-reference.obj", "05": "sumner_cat-05.obj", "07": "sumner_cat-07.obj",
        "08": "sumner_cat-08.obj"}
#: The suggested pairs (the default run) first, then every other ordered pair of the same
#: data (``--pairs``): held-out pairs, to check that what was tuned on three generalizes.
PAIRS = {
    "cat-ref-07": (CATS["ref"], CATS["07"]),
    "cat-05-08": (CATS["05"], CATS["08"]),
    "dino-horse": (MESH_DIR / "dino.obj", "isoblend_horse.obj"),
    **{f"cat-{a}-{b}": (CATS[a], CATS[b]) for a in CATS for b in CATS
       if a != b and (a, b) not in (("ref", "07"), ("05", "08"))},
    "horse-dino": ("isoblend_horse.obj", MESH_DIR / "dino.obj"),
    "human-posed": (MESH_DIR / "human_woman.obj", POSED_HUMAN),
    "posed-human": (POSED_HUMAN, MESH_DIR / "human_woman.obj"),
    "human-wide": (MESH_DIR / "human_woman.obj", "human_woman_wide"),
    "posed-wide": (POSED_HUMAN, "human_woman_wide"),
}
#: Pairs of two triangulations (``--pairs``): ``name: (pair, share)``, the pair's surface 1
#: decimated by ``igl.decimate`` to ``share`` of its faces, surface 2 as it is.  A vertex the
#: decimation left where it was (its birth vertex's position to the bit; how many, in the
#: results' ``measured``) corresponds to its birth vertex's partner; the error is the mean over
#: those (:func:`decimated`), whose partners are vertices of surface 2 as in the other pairs; the
#: landmarks are sampled among them too.
DECIMATED = {"cat-ref-07-dec": ("cat-ref-07", 0.5), "dino-horse-dec": ("dino-horse", 0.5)}
#: Pairs with surface 2 in a second triangulation (``--pairs``): ``name: (pair, share)``, the
#: pair's surface 2 decimated by ``igl.decimate`` to ``share`` of its faces.  Vertex ``i`` of
#: surface 1 corresponds to the decimated vertex born of vertex ``i`` where that one stayed in
#: place; the error is the mean over those ``i``, on the decimated surface's geodesics, and the
#: landmarks are sampled among them.
DECIMATED_2 = {"cat-ref-07-dec2": ("cat-ref-07", 0.5), "dino-horse-dec2": ("dino-horse", 0.5)}
#: Controls of :data:`DECIMATED` and :data:`DECIMATED_2` (``--pairs``): ``name: decimated
#: pair``, the pair itself in one triangulation with the decimated pair's landmarks (for
#: :data:`DECIMATED`, the birth vertices of its landmarks) and its error measured at the same
#: vertices of surface 1.  What the second triangulation costs is the decimated pair's error
#: over its control's: the error at the vertices a decimation kept is not the mean over all.
KEPT = {"cat-ref-07-kept": "cat-ref-07-dec", "dino-horse-kept": "dino-horse-dec",
        "cat-ref-07-kept2": "cat-ref-07-dec2", "dino-horse-kept2": "dino-horse-dec2"}
for table in (DECIMATED, DECIMATED_2):
    PAIRS.update({name: PAIRS[pair] for name, (pair, _) in table.items()})
PAIRS.update({name: PAIRS[pair] for name, pair in KEPT.items()})
#: Surfaces made by :func:`load` from a shared mesh: ``name: (mesh, diag(scale) about the
#: centroid)``.  The woman 15% wider and 13% shallower, a body of another shape, stretched
#: everywhere (no part rigid) yet near-isometric by the median stretch.
SCALED = {"human_woman_wide": (MESH_DIR / "human_woman.obj", (1.15, 1.0, 0.87))}
DEFAULT_PAIRS = ["cat-ref-07", "cat-05-08", "dino-horse"]
DEFAULT_KS = [0, 4, 8, 16, 32]
DEFAULT_METHODS = ["ours", "ours_plain", "mobius", "zoomout"]
LARGE_METHODS = ["ours", "zoomout"]

COLUMNS = [
    ("pair", "pair", "", "l"),
    ("k", "k", "", "r"),
    ("method", "method", "", "l"),
    ("mean error", "mean", ".4f", "r"),
    ("< 0.05", "lt05", ".3f", "r"),
    ("< 0.10", "lt10", ".3f", "r"),
    ("folds", "folds", "", "r"),
    ("success", "success", "", "l"),
    ("seconds", "seconds", ".2f", "r"),
    ("status", status_cell, "", "l"),
]

LEGEND = """\
*mean error* = mean over the vertices of surface 1 of the geodesic distance on surface 2 between
the mapped point and the true partner, over sqrt(area of surface 2); *< 0.05*, *< 0.10* = fraction
of vertices with an error below; *folds* = folded faces of both spherical maps (`count_folds`; –
for ZoomOut's vertex-to-vertex map); *success* = `SurfaceMapResult.success` (ours); *seconds* =
wall time of the call, both spherical maps included."""


def pair_paths(name):
    """Paths of surface 1 and surface 2 of a named pair."""
    return tuple(str(p if Path(p).is_absolute() else REG_DIR / p) for p in PAIRS[name])


def load(path):
    """``(V, F)`` as float64 / int64 (a name of :data:`SCALED`: that mesh, scaled)."""
    mesh, scale = SCALED.get(Path(path).stem, (path, None))
    V, F = igl.read_triangle_mesh(str(mesh))
    V, F = np.asarray(V, np.float64), np.asarray(F, np.int64)
    return (V, F) if scale is None else ((V - V.mean(axis=0)) * scale + V.mean(axis=0), F)


def decimated(V, F, share):
    """``(V1, F1, birth, kept)``: ``(V, F)`` decimated by ``igl.decimate`` to ``share`` of its
    faces, each vertex's birth vertex in ``V`` ((n1,) int64) and whether it is still there
    ((n1,) bool: the same position to the bit)."""
    V1, F1, _, birth = igl.decimate(V, F.astype(np.int32), int(share * F.shape[0]))
    V1, birth = np.asarray(V1, np.float64), np.asarray(birth, np.int64)
    return V1, np.asarray(F1, np.int64), birth, np.all(V1 == V[birth], axis=1)


def geodesic_fps(V, F, k, allowed=None):
    """``k`` vertices by geodesic farthest-point sampling (nested in ``k``), among the
    ``allowed`` ones ((n,) bool; default all)."""
    import potpourri3d as pp3d
    if k == 0:
        return np.zeros(0, dtype=np.int64)
    penalty = 0.0 if allowed is None else np.where(allowed, 0.0, -np.inf)
    solver = pp3d.MeshHeatMethodDistanceSolver(V, F)
    picks = [int(np.argmax(solver.compute_distance(0) + penalty))]
    dmin = solver.compute_distance(picks[0])
    for _ in range(k - 1):
        picks.append(int(np.argmax(dmin + penalty)))
        dmin = np.minimum(dmin, solver.compute_distance(picks[-1]))
    return np.array(picks, dtype=np.int64)


def distance_table(surface, V2, F2, cache):
    """Heat-method geodesic distances between all vertices of surface 2 ((n2, n2) float32),
    cached as ``<surface>_D.npy`` (``surface``: its file's stem, shared by the pairs that end
    there; written under a temporary name and renamed, so a parallel run never reads half)."""
    import potpourri3d as pp3d
    path = Path(cache) / f"{surface}_D.npy"
    if path.exists():
        return np.load(path, mmap_mode="r")
    path.parent.mkdir(parents=True, exist_ok=True)
    solver = pp3d.MeshHeatMethodDistanceSolver(V2, F2)
    D = np.empty((V2.shape[0], V2.shape[0]), dtype=np.float32)
    for j in range(V2.shape[0]):
        D[j] = solver.compute_distance(j)
    part = path.with_name(f"{path.stem}.{os.getpid()}.part.npy")
    np.save(part, D)
    os.replace(part, path)
    return D


# --------------------------------------------------------------------------- methods

def m_ours(V1, F1, V2, F2, l1, l2, **kw):
    from igl_spheremap import surface_map
    r = surface_map(V1, F1, V2, F2, l1, l2, reverse=False, **kw)
    return dict(face=r.face, bary=r.bary, folds=r.map1.folds + r.map2.folds, success=r.success,
                message=r.message, timings=r.timings)


def m_ours_plain(V1, F1, V2, F2, l1, l2):
    """Ours without the descriptor term and the coarse levels (the defaults before they were on)."""
    return m_ours(V1, F1, V2, F2, l1, l2, descriptor_weight=0.0, coarse_levels=())


def m_ours_no_descriptors(V1, F1, V2, F2, l1, l2):
    """Ours with the descriptor term off (coarse levels as by default)."""
    return m_ours(V1, F1, V2, F2, l1, l2, descriptor_weight=0.0)


def m_ours_no_coarse(V1, F1, V2, F2, l1, l2):
    """Ours without the coarse levels (descriptor term as by default)."""
    return m_ours(V1, F1, V2, F2, l1, l2, coarse_levels=())


def m_ours_robust(V1, F1, V2, F2, l1, l2):
    """Ours with the robust last stage (``robust_scale=0.01``)."""
    return m_ours(V1, F1, V2, F2, l1, l2, robust_scale=0.01)


def m_ours_no_robust(V1, F1, V2, F2, l1, l2):
    """Ours with plain ARAP in the last stage too (``robust_scale=None``)."""
    return m_ours(V1, F1, V2, F2, l1, l2, robust_scale=None)


def m_mobius(V1, F1, V2, F2, l1, l2):
    from igl_spheremap import count_folds, locate_on_sphere, spherical_conformal_map
    from igl_spheremap.uses.alignment import centred, landmark_start, rotation_starts
    U1 = spherical_conformal_map(V1, F1).U
    U2 = spherical_conformal_map(V2, F2).U
    if l1.size >= 3:
        s = landmark_start(F1, U1, l1, U2[l2])
    else:
        U1, U2 = centred(V1, F1, U1), centred(V2, F2, U2)
        s = rotation_starts(V1, F1, U1, V2, F2, U2, l1, l2, count=1)[0][0]
    face, bary = locate_on_sphere(U2, F2, s.U)
    return dict(face=face, bary=bary, folds=count_folds(F1, s.U) + count_folds(F2, U2),
                message=s.label)


def m_zoomout(V1, F1, V2, F2, l1, l2):
    """pyfmaps' README settings; pyFM's mesh 1 is our surface 2, so that p2p_21 maps ours 1 -> 2."""
    import contextlib
    import io
    from pyFM.functional import FunctionalMapping
    from pyFM.mesh import TriMesh
    model = FunctionalMapping(TriMesh(V2, F2, area_normalize=True, center=True),
                              TriMesh(V1, F1, area_normalize=True, center=True))
    lm = np.stack([l2, l1], axis=1) if l1.size else None
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        model.preprocess(descr_type="WKS", subsample_step=2, landmarks=lm, verbose=False)
        model.fit(K=30, w_descr=1e0, w_lap=1e-1, w_dcomm=1e0, w_orient=1e0, verbose=False)
        p2p = model.get_p2p(model.zoomout_refine(nit=16, step=5, verbose=False))
    return dict(p2p=np.asarray(p2p, dtype=np.int64))


METHODS = {"ours": m_ours, "ours_plain": m_ours_plain, "ours_no_descriptors": m_ours_no_descriptors,
           "ours_no_coarse": m_ours_no_coarse, "ours_robust": m_ours_robust,
           "ours_no_robust": m_ours_no_robust, "mobius": m_mobius,
           "zoomout": m_zoomout}


def second_triangulation(name, V1, F1, V2, F2):
    """``(V1, F1, V2, F2, partner, kept, surface)`` of a pair of :data:`DECIMATED`,
    :data:`DECIMATED_2` or :data:`KEPT` (else as given): the surfaces, the partner on surface 2 of
    each vertex of surface 1, which vertices have one (None: all) and surface 2's cache name."""
    surface = Path(pair_paths(name)[1]).stem
    control = KEPT.get(name)
    if name in DECIMATED or control in DECIMATED:
        Vd, Fd, birth, kept_d = decimated(V1, F1, DECIMATED[control or name][1])
        if control:
            kept = np.zeros(V1.shape[0], dtype=bool)
            kept[birth[kept_d]] = True
            return V1, F1, V2, F2, np.arange(V1.shape[0]), kept, surface
        return Vd, Fd, V2, F2, birth, kept_d, surface
    if name in DECIMATED_2 or control in DECIMATED_2:
        share = DECIMATED_2[control or name][1]
        Vd, Fd, birth, kept_d = decimated(V2, F2, share)
        partner = np.full(V1.shape[0], -1, dtype=np.int64)
        partner[birth[kept_d]] = np.flatnonzero(kept_d)
        kept = partner >= 0
        if control:
            return V1, F1, V2, F2, np.arange(V1.shape[0]), kept, surface
        return V1, F1, Vd, Fd, np.maximum(partner, 0), kept, f"{surface}_decimated_{share:g}"
    return V1, F1, V2, F2, np.arange(V1.shape[0]), None, surface


def child(name, method, k, cache):
    """Child body: one method on one pair with ``k`` landmarks; errors and seconds."""
    import warnings
    V1, F1, V2, F2, partner, kept, surface = second_triangulation(
        name, *load(pair_paths(name)[0]), *load(pair_paths(name)[1]))
    D = distance_table(surface, V2, F2, cache)
    if KEPT.get(name) in DECIMATED:  # the decimated pair's landmarks, by their birth
        Vd, Fd, birth, kept_d = decimated(V1, F1, DECIMATED[KEPT[name]][1])
        l1 = birth[geodesic_fps(Vd, Fd, k, kept_d)]
    else:
        l1 = geodesic_fps(V1, F1, k, kept)
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = METHODS[method](V1, F1, V2, F2, l1, partner[l1])
    seconds = time.perf_counter() - t
    e = mapped_distances(D, partner, r, F2) / np.sqrt(igl.doublearea(V2, F2).sum() / 2.0)
    e = e if kept is None else e[kept]
    for key in ("p2p", "face", "bary"):
        r.pop(key, None)
    return dict(r, seconds=seconds, mean=float(e.mean()), lt05=float((e < 0.05).mean()),
                lt10=float((e < 0.10).mean()), max=float(e.max()), measured=int(e.size))


def mapped_distances(D, partner, r, F2):
    """Distance on surface 2 from vertex ``partner[i]`` to where method result ``r`` maps
    vertex ``i`` of surface 1 (a vertex, or a point in a face: the distances to its corners
    interpolated), (n1,) float64."""
    idx = np.asarray(partner)
    if "p2p" in r:
        return np.asarray(D[idx, r["p2p"]], np.float64)
    return np.einsum("ij,ij->i", np.asarray(D[idx[:, None], F2[r["face"]]], np.float64),
                     r["bary"])


def measure(case, args):
    name, k, method = case
    out = run_in_child(child, dict(name=name, method=method, k=k, cache=str(args.cache)),
                       timeout=args.timeout)
    return dict(out, pair=name, k=k, method=method)


# --------------------------------------------------------------------------- the 50k pair

def large_pair(n, cache):
    """Two ~n-vertex surfaces: cat reference and cat 07, each refined by Loop subdivision and
    decimated (``igl.decimate``) independently; no ground truth, for timing only (cached)."""
    path = Path(cache) / f"large_{n}.npz"
    if path.exists():
        with np.load(path) as z:
            return z["V1"], z["F1"], z["V2"], z["F2"]
    out = []
    for p in pair_paths("cat-ref-07"):
        V, F = load(p)
        while V.shape[0] < 1.5 * n:
            V, F = igl.loop(V, F)
        V, F = igl.decimate(V, F.astype(np.int32), 2 * n - 4)[:2]
        out += [np.asarray(V, float), np.asarray(F, np.int64)]
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez(path, V1=out[0], F1=out[1], V2=out[2], F2=out[3])
    return tuple(out)


def large_child(n, k, method, cache):
    """Child body: seconds of ``method`` on the ``n``-vertex pair with ``k`` landmarks (partners:
    the vertex of surface 2 nearest to the coarse partner of the coarse vertex nearest)."""
    from scipy.spatial import cKDTree
    V1, F1, V2, F2 = large_pair(n, cache)
    Vc1, _ = load(pair_paths("cat-ref-07")[0])
    Vc2, _ = load(pair_paths("cat-ref-07")[1])
    l1 = geodesic_fps(V1, F1, k)
    l2 = cKDTree(V2).query(Vc2[cKDTree(Vc1).query(V1[l1])[1]])[1].astype(np.int64)
    t = time.perf_counter()
    r = METHODS[method](V1, F1, V2, F2, l1, l2)
    return dict(n1=V1.shape[0], n2=V2.shape[0], seconds=time.perf_counter() - t,
                folds=r.get("folds"), success=r.get("success"), timings=r.get("timings"))


def render(rows, env, args):
    order = {name: i for i, name in enumerate(PAIRS)}
    rows = sorted(rows, key=lambda r: (order[r["pair"]], r["k"], list(METHODS).index(r["method"])))
    return page("Maps between surfaces: accuracy on pairs with known correspondence", env,
                command("correspondence", args), markdown_table(rows, COLUMNS), LEGEND)


def main(argv=None):
    p = arguments(__doc__, meshes=None, timeout=900.0)
    p.add_argument("--pairs", nargs="+", default=DEFAULT_PAIRS, choices=list(PAIRS))
    p.add_argument("--ks", nargs="+", type=int, default=DEFAULT_KS)
    p.add_argument("--methods", nargs="+", choices=list(METHODS),
                   help=f"default: {' '.join(DEFAULT_METHODS)}; with --large: "
                        f"{' '.join(LARGE_METHODS)}")
    p.add_argument("--cache", type=Path, default=Path("/tmp/surf19_cache"),
                   help="folder of the distance tables and the large pair (default: %(default)s)")
    p.add_argument("--large", type=int, default=0, metavar="N",
                   help="instead: seconds of the methods on two surfaces of about N vertices, k = 16")
    args = parse(p, argv)
    echo = lambda r: (f"{r['pair']} k={r['k']} {r['method']}: mean {fmt(r.get('mean'), '.4f')} "  # noqa: E731
                      f"folds {fmt(r.get('folds'))} {fmt(r.get('seconds'), '.2f')} s "
                      f"{r.get('status')}")
    if args.large:
        cols = [("method", "method", "", "l"), ("n1", "n1", ",", "r"), ("n2", "n2", ",", "r"),
                ("seconds", "seconds", ".2f", "r"), ("folds", "folds", "", "r"),
                ("success", "success", "", "l"), ("status", status_cell, "", "l")]
        run("correspondence_large", args, args.methods or LARGE_METHODS,
            lambda m: dict(run_in_child(large_child, dict(n=args.large, k=16, method=m,
                                                          cache=str(args.cache)),
                                        timeout=args.timeout), method=m),
            lambda rows, env, a: page(f"Maps between surfaces: two {a.large:,}-vertex surfaces, "
                                      "16 landmarks", env, command("correspondence", a),
                                      markdown_table(rows, cols)),
            echo=lambda r: f"{r['method']}: {fmt(r.get('seconds'), '.2f')} s {r.get('status')}")
        return
    cases = [(name, k, m) for name in args.pairs for k in args.ks
             for m in args.methods or DEFAULT_METHODS]
    run("correspondence", args, cases, lambda c: measure(c, args), render, echo=echo)


if __name__ == "__main__":
    sys.exit(main())
