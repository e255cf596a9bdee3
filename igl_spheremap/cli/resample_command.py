"""``igl-spheremap resample MESH --ico 6 [--data X] -o OUT``: a surface on a standard icosphere."""

import argparse

from .common import EXIT_NOT_FOLD_FREE, EXIT_OK, non_negative_int, say, warn


def add_parser(sub):
    p = sub.add_parser(
        "resample", formatter_class=argparse.RawDescriptionHelpFormatter,
        help="resample a surface (and its data) onto an icosphere through its spherical map",
        description="Map MESH onto the sphere and re-triangulate it with the connectivity of "
                    "the icosphere\nof level ICO (10 * 4^ICO + 2 vertices, e.g. 6: 40,962), "
                    "as fsaverage-style resampling does.\nWrites OUT, OUT's base .json and, "
                    "with --data, the values resampled.")
    p.add_argument("mesh", metavar="MESH")
    p.add_argument("--ico", type=non_negative_int, default=6, metavar="LEVEL",
                   help="icosphere level (default 6)")
    p.add_argument("--data", metavar="VALUES", help="per-vertex data of MESH to resample")
    p.add_argument("-o", "--output", required=True, metavar="OUT",
                   help="the resampled surface (its format from the name)")
    p.add_argument("-q", "--quiet", action="store_true")
    p.add_argument("--debug", action="store_true")
    p.set_defaults(func=run)


def run(args):
    from ..app.surface_files import resample_file

    rep = resample_file(args.mesh, args.ico, args.output, data=args.data)
    say(args, f"resampled onto icosphere {args.ico} ({rep['vertices']:,} vertices); "
              f"{rep['seconds']:.2f} s -> " + ", ".join(rep["outputs"].values()))
    if rep["map_success"]:
        return EXIT_OK
    warn(f"warning: the spherical map is not fold-free or did not converge: "
         f"{rep['map_message']}")
    return EXIT_NOT_FOLD_FREE
