"""What the exponent changes: ``p_harmonic_map`` for p = 2, 3, 4 from the conformal map.

For each mesh, in one fresh child process: the default conformal map
``U0 = spherical_conformal_map(V, F).U`` (the first row of the mesh, *conformal*),
then ``p_harmonic_map(V, F, U0, p)`` for each p (default 2, 3, 4; the fold
barrier is on, as ``U0`` is fold-free), the p in turn (2, 3, 4, 2, 3, 4, ...)
``--repeats`` times while one round of all p takes under 30 s, the fastest call
of each p counting; quality from the first call.  ``p = 2`` is the harmonic
energy with the cotangent Laplacian (``igl.grad``), while the conformal map
minimizes it with the intrinsic Delaunay Laplacian, so p = 2 moves the map a
little.  For p != 2 the energy is not Möbius invariant and the minimizer is not
Möbius-normalized (``p_harmonic_map`` docstring).

Area distortion is ``area_distortion`` (per face, ``log`` of the image's area
share over the input's, both normalized to total area 1); its mean absolute
value is given per face (every face counts the same) and weighted by the
input's face areas (every part of the surface counts by its area).

Usage::

    python benchmarks/p_harmonic.py                       # all shared meshes
    python benchmarks/p_harmonic.py MESH ... --p 2 3 4 --repeats 3 --skip pycortex_s1_pia_lh

Writes ``DIR/p_harmonic.md`` and ``DIR/p_harmonic.json`` (default
``benchmarks/results/``).
"""

import sys
import time

import numpy as np

from harness import (arguments, command, load_mesh, markdown_table, mesh_name, mesh_paths, page,
                     parse, run, run_in_child, status_cell)

REPEAT_WHILE_ROUND_BELOW = 30.0

COLUMNS = [
    ("mesh", "mesh", "", "l"),
    ("vertices", "vertices", ",", "r"),
    ("map", lambda r: ("–" if r.get("status") != "ok" and r.get("angle_mean") is None
                       else "conformal" if r.get("p") is None else f"p = {r['p']:g}"), "", "l"),
    ("angle mean (°)", "angle_mean", ".3f", "r"),
    ("angle SD (°)", "angle_sd", ".3f", "r"),
    ("mean \\|log area ratio\\|", "area_mean", ".3f", "r"),
    ("area-weighted mean \\|log area ratio\\|", "area_weighted", ".3f", "r"),
    ("folds", "folds", "", "r"),
    ("iterations", "nit", "", "r"),
    ("frozen", "frozen", "", "r"),
    ("converged", "converged", "", "l"),
    ("seconds", "seconds", ".2f", "r"),
    ("status", status_cell, "", "l"),
]

LEGEND = """\
*map*: *conformal* = the start `U0 = spherical_conformal_map(V, F).U` (its
seconds: that call, once), *p = …* = `p_harmonic_map(V, F, U0, p)`; *angle
mean / SD* = mean and standard deviation of the angle distortion over all
corners (degrees, `angle_distortion`); *mean |log area ratio|* = mean over faces
of |`area_distortion`| (log of the face's share of the image area over its share
of the input area; 0 for an equiareal map); *area-weighted* = the same weighted
by the input's face areas; *folds* = `count_folds`; *iterations* = Algorithm 1
iterations (for *conformal*: all rounds); *frozen* = vertices the fold barrier
froze; *converged* = the stopping rule was met (RMS Riemannian gradient ≤ gtol,
default 1e-5); *seconds* = wall time of the call, fastest of the alternating
calls."""


def _quality(V, F, U, w):
    import igl_spheremap as sm
    ang = sm.angle_distortion(V, F, U)
    area = np.abs(sm.area_distortion(V, F, U))
    return dict(angle_mean=float(ang.mean()), angle_sd=float(ang.std()),
                area_mean=float(area.mean()), area_weighted=float(np.sum(w * area)),
                folds=int(sm.count_folds(F, U)))


def measure(mesh, ps, repeats):
    """Child body: the conformal map, then each p alternating; one row per map."""
    import igl
    import igl_spheremap as sm
    V, F = load_mesh(mesh)
    w = igl.doublearea(V, F)
    w = w / w.sum()
    t = time.perf_counter()
    base = sm.spherical_conformal_map(V, F)
    rows = [dict(p=None, seconds=time.perf_counter() - t, nit=int(base.nit),
                 frozen=int(base.rounds[-1].frozen), converged=bool(base.converged),
                 **_quality(V, F, base.U, w))]
    if base.folds:
        return dict(rows=rows, status=f"skipped: the conformal map has {base.folds} folds")
    first, times = {}, {p: [] for p in ps}
    for i in range(repeats):
        t_round = time.perf_counter()
        for p in ps:
            t = time.perf_counter()
            r = sm.p_harmonic_map(V, F, base.U, p)
            times[p].append(time.perf_counter() - t)
            first.setdefault(p, r)
        if time.perf_counter() - t_round > REPEAT_WHILE_ROUND_BELOW:
            break
    for p in ps:
        r = first[p]
        rows.append(dict(p=p, seconds=min(times[p]), seconds_runs=times[p], nit=int(r.nit),
                         frozen=int(r.frozen), converged=bool(r.converged), message=r.message,
                         energy=float(r.energy), **_quality(V, F, r.U, w)))
    return dict(rows=rows, vertices=int(V.shape[0]))


def render(rows, env, args):
    """The markdown of the results so far."""
    notes = [f"{r['mesh']}: {r['note']}" for r in rows if r.get("note")]
    return page("p-harmonic maps: what the exponent changes", env,
                "`p_harmonic_map(V, F, U0, p)` from the default conformal map `U0` "
                "(protocol: `benchmarks/p_harmonic.py` docstring).",
                markdown_table([r for r in rows if not r.get("skipped")], COLUMNS), LEGEND,
                "Not measured: " + "; ".join(notes) + "." if notes else "",
                command("p_harmonic", args))


def measure_mesh(path, args):
    """The rows of one mesh, measured in a fresh child (:func:`measure`)."""
    name = mesh_name(path)
    if name in args.skip:
        return [dict(mesh=name, skipped=True, note="skipped (--skip)")]
    out = run_in_child(measure, dict(mesh=str(path), ps=list(args.p), repeats=args.repeats),
                       timeout=args.timeout)
    got = out.get("rows") or [dict()]
    for r in got:
        r.update(mesh=name, vertices=out.get("vertices"), status=out.get("status", "ok"))
    if out.get("status") != "ok":
        got[0]["note"] = f"{out.get('status')} (after {out['wall_seconds']:.0f} s)"
    return got


def main(argv=None):
    p = arguments(__doc__, timeout=1200.0, repeats=3)
    p.add_argument("--p", type=float, nargs="+", default=[2.0, 3.0, 4.0], help="exponents")
    p.add_argument("--skip", nargs="*", default=[], help="mesh names to leave out")
    args = parse(p, argv)
    run("p_harmonic", args, mesh_paths(args.meshes), lambda path: measure_mesh(path, args),
        render, echo=lambda r: f"{r['mesh']:>34s} p={r.get('p')}: {r.get('status', 'skipped')}",
        payload=lambda rows: dict(notes=[f"{r['mesh']}: {r['note']}" for r in rows
                                         if r.get("note")]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
