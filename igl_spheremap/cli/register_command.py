"""``igl-spheremap register A B --landmarks A.txt B.txt [--data X] -o OUT``: surface A onto surface B."""

import argparse

from .common import EXIT_NOT_FOLD_FREE, EXIT_OK, positive_float, say, warn


def add_parser(sub):
    p = sub.add_parser(
        "register", formatter_class=argparse.RawDescriptionHelpFormatter,
        help="map surface A onto surface B through the sphere, with landmarks",
        description="Register surface A onto surface B: B is mapped conformally, A with its "
                    "landmarks\non the images of B's, and every vertex of A is located on B.\n"
                    "Writes OUT.npz (face, bary), OUT.json and, with --data, B's values carried "
                    "to A\n(OUT.func.gii for GIfTI/FreeSurfer surfaces, OUT_data.npz otherwise).",
        epilog="Landmark files: one 0-based vertex index per line, or 'x y z' rows (snapped to "
               "the nearest vertex);\nthe k-th lines of the two files are a pair (at least 3).")
    p.add_argument("mesh1", metavar="A", help="surface to register (gets the correspondence)")
    p.add_argument("mesh2", metavar="B", help="reference surface")
    p.add_argument("--landmarks", nargs=2, required=True, metavar=("A.txt", "B.txt"),
                   help="landmark files of A and of B")
    p.add_argument("--data", metavar="B_VALUES",
                   help="per-vertex data of B to carry to A (.npy .npz .txt .csv .gii, or a "
                        "FreeSurfer curv/thickness file)")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="base path of the outputs")
    p.add_argument("--mode", choices=("hard", "soft"), default="hard",
                   help="hard: landmarks exactly on their partners (default); soft: a penalty")
    p.add_argument("--weight", type=positive_float, default=None,
                   help="penalty weight of --mode soft")
    p.add_argument("-q", "--quiet", action="store_true")
    p.add_argument("--debug", action="store_true")
    p.set_defaults(func=run)


def run(args):
    from ..app.surface_files import register_files

    rep = register_files(args.mesh1, args.mesh2, *args.landmarks, args.output, data=args.data,
                         mode=args.mode, weight=args.weight,
                         on_stage=lambda text: say(args, f"{text} ..."))
    say(args, f"registered: {len(rep['landmark_errors_deg'])} landmark pairs, largest error "
              f"{rep['landmark_error_max_deg']:.3g} deg; folds A {rep['map1']['folds']}, "
              f"B {rep['map2']['folds']}; {rep['timings']['total']:.2f} s -> "
              + ", ".join(rep["outputs"].values()))
    if rep["success"]:
        return EXIT_OK
    warn(f"warning: {rep['map1']['message']}; {rep['map2']['message']}")
    return EXIT_NOT_FOLD_FREE



