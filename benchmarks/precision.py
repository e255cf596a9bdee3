"""What ``precision="float32"`` costs and buys (issue #15): float64 vs float32 setting.

For each mesh (default: the 14 shared meshes) and each elongated shape of
:mod:`shapes` (ellipsoids 10:1, 30:1, 100:1, 1000:1 and a 50:1 capsule), the
default ``spherical_conformal_map(V, F)`` (``precision="float64"``) and
``spherical_conformal_map(V, F, precision="float32")``, each in a fresh child
process, the two settings in turn (float64, float32, float64, ...) ``--alternate``
times; within a child the call is repeated while it takes under 10 s (at most
``--repeats`` calls) and the fastest call of all counts.  Quality is measured on
the first call's map:

* *angle*: mean angle distortion over all corners, degrees
  (:func:`igl_spheremap.angle_distortion`), after Möbius centering with the
  input's vertex areas (``angle_mean_centered`` of ``_common.quality_row``), so
  both settings are compared at the same Möbius normalization;
* *folds*: :func:`igl_spheremap.count_folds` of the map;
* *stored r=100*: folds of the map stored as ``100 * U`` in float32 (numpy's
  rounding, as the GIfTI and FreeSurfer writers store it) and read back; *rotated*:
  the same after a fixed random rotation (the margin holds in any rotation);
* *below margin*: faces whose signed image volume is at or below their float32
  rounding margin (:func:`igl_spheremap.precision.below_margin`), i.e. that
  float32 storage might fold;
* *repair*: the float32 repair kept (``result.repair["method"]``).

Usage::

    python benchmarks/precision.py                     # 14 meshes + 5 shapes
    python benchmarks/precision.py MESH ... --shapes ellipsoid_30 --alternate 1

Writes ``DIR/precision.md`` and ``DIR/precision.json`` (default ``benchmarks/results/``).
"""

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _child import run_in_child  # noqa: E402
from _common import (DEFAULT_OUT, environment, environment_line, load_mesh,  # noqa: E402
                     markdown_table, mesh_name, mesh_paths, quality_row, status_cell,
                     write_outputs)
from shapes import SHAPES, shape  # noqa: E402

PRECISIONS = ("float64", "float32")
REPEAT_BELOW = 10.0
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

    from igl_spheremap.precision import below_margin

    V, F = shape(case) if case in SHAPES else load_mesh(case)
    times, r = [], None
    for _ in range(repeats):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", sm.SphericalMapWarning)
            t = time.perf_counter()
            out = sm.spherical_conformal_map(V, F, precision=precision)
            times.append(time.perf_counter() - t)
        r = r or out
        if times[-1] > REPEAT_BELOW:
            break
    R = Rotation.random(random_state=ROTATION_SEED).as_matrix()

    def stored_folds(W):
        return sm.count_folds(r.F, (100.0 * W).astype(np.float32).astype(np.float64))

    q = quality_row(V, r.F, r.U)
    return dict(vertices=int(V.shape[0]), faces=int(F.shape[0]), precision=precision,
                seconds=min(times), seconds_all=times, folds=int(r.folds),
                folds_stored_r100=stored_folds(r.U), folds_stored_r100_rotated=stored_folds(r.U @ R.T),
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
    return "\n".join([
        "# Precision: float64 vs float32 setting", "",
        f"`python benchmarks/precision.py` ({', '.join(args.cases_shown)}; alternate "
        f"{args.alternate}, up to {args.repeats} calls per child while under {REPEAT_BELOW:g} s).",
        "", environment_line(env), "",
        "## Cost of the float32 margin", "", markdown_table(cost_rows(rows), COST_COLUMNS), "",
        "*time ratio* = float32 seconds / float64 seconds (fastest calls); *angle* = mean "
        "angle distortion over all corners after Möbius centering with the input's vertex "
        "areas; *folds stored r=100* = folds of `100 * U` rounded to float32 and read back.",
        "", "## All rows", "", markdown_table(rows, COLUMNS), "",
        __doc__.split("\n\n", 1)[1].split("Usage::")[0].strip()])


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("meshes", nargs="*", help="mesh files or folders (default: shared meshes)")
    p.add_argument("--shapes", nargs="*", default=list(SHAPES), choices=list(SHAPES))
    p.add_argument("--alternate", type=int, default=2)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--timeout", type=float, default=900.0)
    p.add_argument("--out", default=str(DEFAULT_OUT))
    return p.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    env = environment()
    cases = [(mesh_name(p), str(p)) for p in mesh_paths(args.meshes)]
    cases += [(s, s) for s in args.shapes]
    args.cases_shown = [f"{len(cases) - len(args.shapes)} meshes", f"{len(args.shapes)} shapes"]
    rows = []
    for name, case in cases:
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
                      f"stored {row.get('folds_stored_r100')} {row.get('status')}", flush=True)
        rows += [best[p] for p in PRECISIONS]
        write_outputs(args.out, "precision", render(rows, env, args),
                      dict(environment=env, rows=rows, cost=cost_rows(rows)))
    print(render(rows, env, args))


if __name__ == "__main__":
    main()
