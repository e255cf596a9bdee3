#!/usr/bin/env python
"""Watch Algorithm 2 remove the folds of a spherical conformal map, stage by stage.

    python demos/folding_removal.py                       # bundled dino, interactive window
    python demos/folding_removal.py my_mesh.obj --method paper --max-rounds 4
    python demos/folding_removal.py --screenshots out/demo --save-result out/dino.npz
    python demos/folding_removal.py --load-result out/dino.npz --screenshots out/demo

Stages: the Gauss map, the map after Algorithm 1, then for each folding-removal
round k the star map and the map after Algorithm 1.  A slider in the polyscope
panel steps through them; see :mod:`igl_spheremap.viz` for what is drawn.
``--screenshots DIR`` renders headless (Mesa EGL) instead: one PNG per stage
and ``contact_sheet.png``.  Any mesh libigl reads (OBJ, OFF, PLY, STL, ...) works
if it is a closed genus-0 triangle mesh.
"""

import argparse
import dataclasses
import json
import os
import sys
from importlib import resources
from pathlib import Path

import igl
import numpy as np

import igl_spheremap
from igl_spheremap.result import Round, SphericalMapResult

DEFAULT_MESH = os.fspath(resources.files("igl_spheremap") / "data" / "dino.obj")

def read_mesh(path):
    """Read a triangle mesh with libigl; ``(V float64 (n, 3), F int64 (m, 3))``.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        If libigl reads no triangles from it.
    """
    if not os.path.isfile(path):
        raise FileNotFoundError(f"mesh file not found: {path}")
    V, F = igl.read_triangle_mesh(os.fspath(path))
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    if F.ndim != 2 or F.shape[0] == 0 or F.shape[1] != 3:
        raise ValueError(f"{path}: libigl read no triangle faces (got F of shape {F.shape})")
    return V, F


def print_rounds(result):
    """One line per round of a result: folds before -> after, iterations, energy, time."""
    for rnd in result.rounds:
        print(f"  round {rnd.index} ({rnd.kind}): folded faces {rnd.folds_before} -> "
              f"{rnd.folds_after}, {rnd.nit} iterations, E/4pi = {rnd.energy / (4 * np.pi):.4f}, "
              f"{rnd.seconds:.1f} s")


def compute(V, F, method="folding_free", max_rounds=6, max_iter=None, progress=None):
    """Run :func:`igl_spheremap.spherical_conformal_map` (tqdm progress when stderr is a terminal)."""
    kw = dict(method=method, max_rounds=max_rounds,
              progress=sys.stderr.isatty() if progress is None else progress)
    if max_iter is not None:
        kw["max_iter"] = max_iter
    return igl_spheremap.spherical_conformal_map(V, F, **kw)


def _split(obj, prefix, arrays):
    """Dataclass fields of ``obj``: arrays/lists into ``arrays``, the rest as a JSON dict."""
    meta = {}
    for f in dataclasses.fields(obj):
        val = getattr(obj, f.name)
        if f.name == "rounds":
            continue
        if isinstance(val, np.ndarray):
            arrays[prefix + f.name] = val
            meta[f.name] = {"array": "ndarray"}
        elif isinstance(val, (list, tuple)) and all(np.isscalar(v) for v in val):
            arrays[prefix + f.name] = np.asarray(val, dtype=np.float64)
            meta[f.name] = {"array": "list"}
        else:
            meta[f.name] = val
    return meta


def _join(cls, meta, prefix, z):
    known = {f.name for f in dataclasses.fields(cls)}
    kw = {}
    for name, val in meta.items():
        if name not in known:
            continue
        if isinstance(val, dict) and set(val) == {"array"}:
            arr = z[prefix + name]
            val = arr.tolist() if val["array"] == "list" else arr
        kw[name] = val
    return kw


def save_result(path, V, F, result):
    """Write the mesh and a :class:`SphericalMapResult` to one ``.npz`` (no pickles).

    Every dataclass field of the result and of its rounds is stored (arrays in
    the archive, the rest as JSON), so new fields survive without changes here.

    Parameters
    ----------
    path : str
    V : (n, 3) float64 array
    F : (m, 3) int array
    result : SphericalMapResult
    """
    arrays = dict(V=np.asarray(V, np.float64), F=np.asarray(F, np.int64))
    meta = _split(result, "result_", arrays)
    meta["rounds"] = [_split(rnd, f"round{i}_", arrays) for i, rnd in enumerate(result.rounds)]
    arrays["meta"] = np.array(json.dumps(meta, default=_json_default))
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, **arrays)


def _json_default(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"cannot store {type(obj).__name__} in the result file")


def load_result(path):
    """Read what :func:`save_result` wrote: ``(V, F, SphericalMapResult)``.

    Fields that the installed :class:`Round` / :class:`SphericalMapResult` do
    not have are ignored; fields missing from the file take their defaults.
    """
    with np.load(path, allow_pickle=False) as z:
        meta = json.loads(str(z["meta"]))
        rounds = [Round(**_join(Round, rm, f"round{i}_", z))
                  for i, rm in enumerate(meta.pop("rounds"))]
        result = SphericalMapResult(rounds=rounds, **_join(SphericalMapResult, meta, "result_", z))
        return z["V"], z["F"], result


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mesh", nargs="?", default=None,
                    help="closed genus-0 triangle mesh (default: the bundled dino.obj)")
    ap.add_argument("--method", choices=("folding_free", "paper"), default="folding_free")
    ap.add_argument("--max-iter", type=int, default=None,
                    help="cap on Algorithm 1 iterations per round (default: the method's)")
    ap.add_argument("--max-rounds", type=int, default=6, help="folding-removal rounds at most")
    ap.add_argument("--screenshots", metavar="DIR",
                    help="render headless into DIR (one PNG per stage + contact_sheet.png)")
    ap.add_argument("--sheet-width", type=int, default=2000, metavar="PX",
                    help="width of contact_sheet.png in pixels (default 2000)")
    ap.add_argument("--save-result", metavar="FILE.npz", help="store mesh + result for re-rendering")
    ap.add_argument("--load-result", metavar="FILE.npz",
                    help="skip the computation; use a file written by --save-result")
    args = ap.parse_args(argv)

    if args.load_result:
        if args.mesh:
            print(f"note: --load-result given, ignoring {args.mesh}")
        V, F, result = load_result(args.load_result)
        print(f"loaded {args.load_result}: {V.shape[0]} vertices, {len(result.rounds)} rounds")
    else:
        path = args.mesh or DEFAULT_MESH
        V, F = read_mesh(path)
        print(f"{path}: {V.shape[0]} vertices, {F.shape[0]} faces; method={args.method}",
              flush=True)
        result = compute(V, F, args.method, args.max_rounds, args.max_iter)
    print_rounds(result)
    print(result.message)
    if args.save_result:
        save_result(args.save_result, V, F, result)
        print(f"saved {args.save_result}")

    from igl_spheremap import viz

    stages = viz.build_stages(V, F, result)
    for i, st in enumerate(stages):
        print(f"stage {i}: {st['name']}: {st['folds']} folded faces")
    try:
        view = viz.show(V, F, result, screenshot_dir=args.screenshots, stages=stages,
                        sheet_width=args.sheet_width)
    except RuntimeError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    for p in view.screenshots:
        print(p)
    if view.contact_sheet:
        print(view.contact_sheet)
    return 0


if __name__ == "__main__":
    sys.exit(main())
