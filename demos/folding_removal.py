#!/usr/bin/env python
"""Watch Algorithm 2 remove the folds of a spherical conformal map, stage by stage.

    python demos/folding_removal.py                       # bundled dino, interactive window
    python demos/folding_removal.py my_mesh.obj --method paper --max-rounds 4
    python demos/folding_removal.py --screenshots out/demo --save-result out/dino.npz
    python demos/folding_removal.py --load-result out/dino.npz --screenshots out/demo
    python demos/folding_removal.py subj/surf/lh.pial                # FreeSurfer surface
    python demos/folding_removal.py lh.pial.surf.gii --screenshots out/brain    # GIfTI

Stages: the Gauss map, the map after Algorithm 1, then for each folding-removal
round k the star map and the map after Algorithm 1.  A slider in the polyscope
panel steps through them; see :mod:`igl_spheremap.viz` for what is drawn.
``--screenshots DIR`` renders headless (Mesa EGL) instead: one annotated PNG
per stage and ``contact_sheet.png``.  Any mesh :func:`igl_spheremap.io.read_mesh`
reads (OBJ, OFF, PLY, STL, ..., GIfTI ``.gii``, FreeSurfer ``lh.white``/``rh.pial``)
works if it is a closed genus-0 triangle mesh.

Exit codes: 0 done, 1 the mesh or result file cannot be read or an option is
wrong, 2 the mesh is not a closed genus-0 manifold triangle mesh or polyscope
cannot open OpenGL (the message names the Debian packages for headless
rendering); one line on stderr, no traceback.
"""

import os
import sys
from importlib import resources

import numpy as np

import igl_spheremap
from igl_spheremap.cli.common import Parser, at_least_one, non_negative_int
from igl_spheremap.errors import MeshError
from igl_spheremap.io import read_mesh
from igl_spheremap.io.result_file import load_result, save_result
from igl_spheremap.viz.stages import STARTS

DEFAULT_MESH = os.fspath(resources.files("igl_spheremap") / "data" / "dino.obj")


def print_rounds(result):
    """One line per round of a result: folds before -> after, iterations, energy, time.

    The energy is the harmonic energy, or for the polish and the guaranteed path's
    rounds the conformal distortion they minimize (``Econf/4pi``).
    """
    for rnd in result.rounds:
        name = "Econf" if rnd.kind in STARTS and rnd.kind != "restart" else "E"
        print(f"  round {rnd.index} ({rnd.kind}): folded faces {rnd.folds_before} -> "
              f"{rnd.folds_after}, {rnd.nit} iterations, {name}/4pi = "
              f"{rnd.energy / (4 * np.pi):.4f}, {rnd.seconds:.1f} s")


def _result(args):
    """Load ``--load-result`` or read the mesh and run :func:`spherical_conformal_map`.

    Returns the result and the axis to draw vertical (None: the viewer's default).
    """
    if args.load_result:
        if args.mesh:
            print(f"note: --load-result given, ignoring {args.mesh}")
        result = load_result(args.load_result)
        print(f"loaded {args.load_result}: {result.U.shape[0]} vertices, "
              f"{len(result.rounds)} rounds")
        return result, None
    path = args.mesh or DEFAULT_MESH
    V, F, family = read_mesh(path)  # OBJ, OFF, PLY, ..., GIfTI, FreeSurfer
    print(f"{path} ({family}): {V.shape[0]} vertices, {F.shape[0]} faces; "
          f"method={args.method}", flush=True)
    result = igl_spheremap.spherical_conformal_map(
        V, F, method=args.method, max_rounds=args.max_rounds, max_iter=args.max_iter,
        progress=sys.stderr.isatty())
    # neuroimaging surfaces are RAS (z superior): draw them upright
    return result, (2 if family in ("gifti", "freesurfer") else None)


def main(argv=None):
    ap = Parser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mesh", nargs="?", default=None,
                    help="closed genus-0 triangle mesh (default: the bundled dino.obj)")
    ap.add_argument("--method", choices=("folding_free", "paper"), default="folding_free")
    ap.add_argument("--max-iter", type=non_negative_int, default=None,
                    help="cap on Algorithm 1 iterations per round (default: the method's)")
    ap.add_argument("--max-rounds", type=non_negative_int, default=6, help="folding-removal rounds at most")
    ap.add_argument("--screenshots", metavar="DIR",
                    help="render headless into DIR (one PNG per stage + contact_sheet.png)")
    ap.add_argument("--sheet-width", type=at_least_one, default=2000, metavar="PX",
                    help="width of contact_sheet.png in pixels (default 2000)")
    ap.add_argument("--save-result", metavar="FILE.npz", help="store mesh + result for re-rendering")
    ap.add_argument("--load-result", metavar="FILE.npz",
                    help="skip the computation; use a file written by --save-result")
    args = ap.parse_args(argv)

    try:
        result, up = _result(args)
    except MeshError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except (OSError, ValueError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 1
    print_rounds(result)
    print(result.message)
    if args.save_result:
        save_result(args.save_result, result)
        print(f"saved {args.save_result}")

    from igl_spheremap import viz

    stages = viz.build_stages(result)
    for i, st in enumerate(stages):    # numbered from 1, as the PNG titles ("k/n.") and README
        print(f"stage {i + 1}: {st['name']}: {st['folds']} folded faces")
    try:
        view = viz.show(result, screenshot_dir=args.screenshots, stages=stages,
                        sheet_width=args.sheet_width, up=up)
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
