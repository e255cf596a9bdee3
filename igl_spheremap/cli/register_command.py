"""``igl-spheremap register A B [--landmarks A.txt B.txt] [--data X] -o OUT``: surface A onto surface B."""

import argparse

from ..errors import plural
from ..uses.correspondence import SPRING
from ..uses.side_by_side import DEFAULT_WORKERS
from .common import (EXIT_NOT_FOLD_FREE, EXIT_OK, at_least_one, non_negative_float, positive_float,
                     say, warn)


def robust_scale(text):
    """``--robust-scale``: ``auto``, ``off`` (None) or a number above 0."""
    if text in ("auto", "off"):
        return None if text == "off" else text
    return positive_float(text)


def add_parser(sub):
    p = sub.add_parser(
        "register", formatter_class=argparse.RawDescriptionHelpFormatter,
        help="map surface A onto surface B through the sphere (landmarks optional)",
        description="Register surface A onto surface B: both are mapped to the sphere, A's map is "
                    "aligned to B's\n(by the landmarks or, with fewer than 3, a rotation search; "
                    "and by a functional map), "
                    "bent onto the landmarks and\nmoved until the map between the surfaces is as "
                    "rigid as possible, fold-free; every\nvertex of A is then located on B.\n"
                    "Writes OUT.npz (face, bary), OUT.json and, with --data, B's values carried "
                    "to A\n(OUT.func.gii for GIfTI/FreeSurfer surfaces, OUT_data.npz otherwise).",
        epilog="Landmark files: one 0-based vertex index per line, or 'x y z' rows (snapped to "
               "the nearest vertex);\nthe k-th lines of the two files are a pair.\n"
               "Exit status 3 (outputs written) when a landmark is not met or a map folds.")
    p.add_argument("mesh1", metavar="A", help="surface to register (gets the correspondence)")
    p.add_argument("mesh2", metavar="B", help="reference surface")
    p.add_argument("--landmarks", nargs=2, default=None, metavar=("A.txt", "B.txt"),
                   help="landmark files of A and of B (optional)")
    p.add_argument("--data", metavar="B_VALUES",
                   help="per-vertex data of B to carry to A (.npy .npz .txt .csv .gii, or a "
                        "FreeSurfer curv/thickness or .mgh/.mgz file)")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="base path of the outputs")
    p.add_argument("--mode", choices=("hard", "soft"), default="hard",
                   help="hard: landmarks exactly on their partners (default); soft: a penalty")
    p.add_argument("--weight", type=positive_float, default=None,
                   help="spring stiffness of --mode soft, surfaces scaled to area 4 pi (default "
                        f"{SPRING:g}); refused with --mode hard")
    p.add_argument("--descriptor-weight", type=non_negative_float, default=None, metavar="W",
                   help="weight of the harmonic landmark descriptors in the distortion stage, "
                        "built from the --landmarks pairs alone (not from pairs found by the "
                        "alignment), so refused above 0 without --landmarks "
                        "(default: 300 with at least 8 landmark pairs, else 0; 0: off; README "
                        "'Maps between surfaces')")
    p.add_argument("--robust-scale", type=robust_scale, default="auto", metavar="EPS",
                   help="for poses of one body: the last distortion stage charges stretches "
                        "beyond EPS (e.g. 0.01) linearly, so limbs stay rigid and joints bend; "
                        "'auto' (default): 0.01 where the map is near-isometric; 'off': plain "
                        "(README 'Maps between surfaces')")
    levels = p.add_mutually_exclusive_group()
    levels.add_argument("--coarse-levels", nargs="+", type=at_least_one, default=None,
                        metavar="N",
                        help="vertex counts of coarse versions of A on which the distortion "
                             "stage runs first, coarsest first, each from 4 to half of A's "
                             "vertices (refused otherwise; the default's larger levels are "
                             "skipped on small surfaces) (default: 300 1000)")
    levels.add_argument("--no-coarse-levels", dest="coarse_levels", action="store_const",
                        const=(), help="no coarse levels")
    p.add_argument("--workers", type=at_least_one, default=DEFAULT_WORKERS, metavar="N",
                   help="processes working side by side on the stages that do not depend on "
                        f"each other, e.g. the two conformal maps (default {DEFAULT_WORKERS}; "
                        "1: one process)")
    p.add_argument("-q", "--quiet", action="store_true")
    p.add_argument("--debug", action="store_true")
    p.set_defaults(func=run)


def run(args):
    from ..app.surface_files import register_files

    if args.weight is not None and args.mode != "soft":
        raise ValueError("--weight is the spring stiffness of --mode soft; with --mode hard (the "
                         "default) the landmarks are met exactly: add --mode soft or drop --weight")
    if args.descriptor_weight and args.landmarks is None:
        raise ValueError("--descriptor-weight weighs descriptors built from the landmark pairs of "
                         "--landmarks; without landmarks there are none and the weight would "
                         "have no effect: add --landmarks A.txt B.txt or drop --descriptor-weight")
    l1, l2 = args.landmarks or (None, None)
    rep = register_files(args.mesh1, args.mesh2, l1, l2, args.output, data=args.data,
                         mode=args.mode, weight=args.weight,
                         descriptor_weight=args.descriptor_weight, workers=args.workers,
                         robust_scale=args.robust_scale,
                         **({} if args.coarse_levels is None else
                            dict(coarse_levels=tuple(args.coarse_levels))),
                         on_stage=lambda text: say(args, f"{text} ..."))
    k = len(rep["landmark_errors_deg"])
    lm = (f"{plural(k, 'landmark pair')}, largest error {rep['landmark_error_max_deg']:.3g} deg"
          if k else "no landmarks")
    say(args, f"registered: {lm}; distortion (1: isometric) median {rep['distortion_median']:.3g}, "
              f"90th percentile {rep['distortion_p90']:.3g}; folds A "
              f"{rep['map1']['folds']}, B {rep['map2']['folds']}; "
              f"{rep['timings']['total']:.2f} s -> " + ", ".join(rep["outputs"].values()))
    if rep["success"]:
        return EXIT_OK
    warn(f"warning: {rep['message']}")
    return EXIT_NOT_FOLD_FREE



