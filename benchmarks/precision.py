"""What ``precision="float32"`` costs and buys (issue #15): float64 vs float32 setting.

For each mesh (default: the 14 shared meshes) and each elongated shape of
:mod:`shapes` (ellipsoids 10:1, 30:1, 100:1, 1000:1 and a 50:1 capsule), the
default ``spherical_conformal_map(V, F)`` (``precision="float64"``) and
``spherical_conformal_map(V, F, precision="float32")``, each in a fresh child
process, the two settings in turn (float64, float32, float64, ...) ``--alternate``
times; within a child the call is repeated while the first takes under 10 s (at most
``--repeats`` calls) and the fastest call of all counts.  Quality is measured on
the first call's map:

* *angle*: mean angle distortion over all corners, degrees
  (:func:`igl_spheremap.angle_distortion`), after Möbius centering with the
  input's vertex areas (``angle_mean_centered`` of ``harness.quality_row``), so
  both settings are compared at the same Möbius normalization;
* *folds*: :func:`igl_spheremap.count_folds` of the map;
* *stored r=100*: folds of the map stored as ``100 * U`` in float32 (numpy's
  rounding, as the GIfTI and FreeSurfer writers store it) and read back; *rotated*:
  the same after a fixed random rotation (the margin holds in any rotation);
* *below margin*: faces whose signed image volume is at or below their float32
  rounding margin (:func:`igl_spheremap.sphere.folds.below_margin`), i.e. that
  float32 storage might fold;
* *repair*: the float32 repair kept (``result.repair["method"]``).

Usage::

    python benchmarks/precision.py                     # 14 meshes + 5 shapes
    python benchmarks/precision.py MESH ... --shapes ellipsoid_30 --alternate 1

Writes ``DIR/precision.md`` and ``DIR/precision.json`` (default ``benchmarks/results/``).
"""

import sys
import warnings

import numpy as np

from harness import (REPEAT_BELOW_SECONDS, arguments, load_mesh, markdown_table, mesh_name,
                     mesh_paths, page, parse, quality_row, run, run_in_child, status_cell,
                     timed_calls)
from shapes import PRECISION_SHAPES, SHAPES, shape

PRECISIONS = ("float64", "float32")
ROTATION_SEED = 11

COLUMNS = [
    ("mesh", "mesh", "", "l"),
    ("vertices", "vertices", ",", "r"),
    ("setting", "precision", "", "l"),
    ("seconds", "seconds", ".2f", "r"),
    ("angle mean (°)", "angle_mean_centered", ".3f", "r"),
    ("folds", "folds", "", "r"),
    ("stored r=100", "folds_stored_r100", "", "r"),
    ("rotated", "folds_stored_r100_rotated", "", "r"),
    ("below float32 margin", "below_f32_margin", "", "r"),
    ("min image area", "min_image_area", ".1e", "r"),
    ("repair", lambda r: r.get("repair") or "–", "", "l"),
    ("success", "success", "", "l"),
    ("status", status_cell, "", "l"),
]

COST_COLUMNS = [
    ("mesh", "mesh", "", "l"),
    ("vertices", "vertices", ",", "r"),
    ("float64 s", "seconds_64", ".2f", "r"),
    ("float32 s", "seconds_32", ".2f", "r"),
    ("time ratio", "time_ratio", ".2f", "r"),
    ("float64 angle (°)", "angle_64", ".3f", "r"),
    ("float32 angle (°)", "angle_32", ".3f", "r"),
    ("float64 folds stored r=100", "stored_64", "", "r"),
    ("float32 folds stored r=100", "stored_32", "", "r"),
    ("float32 repair", lambda r: r.get("repair") or "–", "", "l"),
]


def measure(case, precision, repeats):
    """Child process: map ``case`` (a mesh path or a shape name) with ``precision``; one dict."""
    import igl_spheremap as sm
    from scipy.spatial.transform import Rotation

    from igl_spheremap.sphere.folds import below_margin

    V, F = shape(case) if case in SHAPES else load_mesh(case)

    def once(clock):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", sm.SphericalMapWarning)
            with clock:
                return sm.spherical_conformal_map(V, F, precision=precision)
    r, _, times = timed_calls(once, repeats)
    R = Rotation.random(random_state=ROTATION_SEED).as_matrix()

    def stored_folds(W):
        return sm.count_folds(r.F, (100.0 * W).astype(np.float32).astype(np.float64))

    q = quality_row(V, r.F, r.U)
    return dict(vertices=int(V.shape[0]), faces=int(F.shape[0]), precision=precision,
                seconds=min(times), seconds_all=times, folds=int(r.folds),
                folds_stored_r100=stored_folds(r.U),
                folds_stored_r100_rotated=stored_folds(r.U @ R.T),
                below_f32_margin=int(below_margin(r.F, r.U, "float32").sum()),
                below_margin_reported=int(r.below_margin), min_image_area=r.min_image_area,
                angle_mean_centered=q["angle_mean_centered"], angle_mean=q["angle_mean"],
                energy_4pi=q["energy_4pi"], success=bool(r.success), converged=bool(r.converged),
                rounds=[(rnd.kind, int(rnd.folds_after)) for rnd in r.rounds],
                repair=(r.repair or {}).get("method"),
                repair_tried=[{k: v for k, v in t.items() if k != "steps"}
                              for t in (r.repair or {}).get("tried", [])],
                message=r.message, library=sm.__file__)


def cost_rows(rows):
    """One row per case: float32 against float64 (time ratio, angles, stored folds)."""
    out = []
    for name in dict.fromkeys(r["mesh"] for r in rows):
        by = {r["precision"]: r for r in rows if r["mesh"] == name and r.get("status") == "ok"}
        if set(by) != set(PRECISIONS):
            continue
        a, b = by["float64"], by["float32"]
        out.append(dict(mesh=name, vertices=a["vertices"], seconds_64=a["seconds"],
                        seconds_32=b["seconds"], time_ratio=b["seconds"] / a["seconds"],
                        angle_64=a["angle_mean_centered"], angle_32=b["angle_mean_centered"],
                        stored_64=a["folds_stored_r100"], stored_32=b["folds_stored_r100"],
                        repair=b.get("repair")))
    return out


def render(rows, env, args):
    n_shapes = len(args.shapes)
    return page(
        "Precision: float64 vs float32 setting", env,
        f"`python benchmarks/precision.py` ({args._n_meshes} meshes, {n_shapes} shapes; alternate "
        f"{args.alternate}, up to {args.repeats} calls per child while the first takes under "
        f"{REPEAT_BELOW_SECONDS:g} s).",
        "## Cost of the float32 margin", markdown_table(cost_rows(rows), COST_COLUMNS),
        "*time ratio* = float32 seconds / float64 seconds (fastest calls); *angle* = mean "
        "angle distortion over all corners after Möbius centering with the input's vertex "
        "areas; *folds stored r=100* = folds of `100 * U` rounded to float32 and read back.",
        "## All rows", markdown_table(rows, COLUMNS),
        __doc__.split("\n\n", 1)[1].split("Usage::")[0].strip())


def measure_case(name, case, args):
    """Both settings on one case, in turn ``--alternate`` times, each in a fresh child."""
    best = {}
    for k in range(args.alternate):
        for precision in PRECISIONS:
            row = run_in_child(measure, dict(case=case, precision=precision,
                                             repeats=args.repeats), timeout=args.timeout)
            row.update(mesh=name, precision=precision)
            old = best.get(precision)
            if old is None or old.get("status") != "ok":
                best[precision] = row
            elif row.get("status") == "ok":
                old["seconds_all"] = old["seconds_all"] + row["seconds_all"]
                old["seconds"] = min(old["seconds_all"])
            print(f"{name} {precision} pass {k}: {row.get('seconds', float('nan')):.2f} s "
                  f"stored {row.get('folds_stored_r100')} {row.get('status')}",
                  file=sys.stderr, flush=True)
    return [best[p] for p in PRECISIONS]


def main(argv=None):
    p = arguments(__doc__, timeout=900.0, repeats=3,
                  mesh_help="mesh files or folders (default: shared meshes)")
    p.add_argument("--shapes", nargs="*", default=list(PRECISION_SHAPES), choices=list(SHAPES))
    p.add_argument("--alternate", type=int, default=2)
    args = parse(p, argv)
    cases = [(mesh_name(p), str(p)) for p in mesh_paths(args.meshes)]
    args._n_meshes = len(cases)
    cases += [(s, s) for s in args.shapes]
    run("precision", args, cases, lambda case: measure_case(*case, args), render,
        payload=lambda rows: dict(cost=cost_rows(rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
