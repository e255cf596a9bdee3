"""``igl-spheremap register-sphere SUBJECT --target SPHERE -o OUT``: a subject's ``?h.sphere.reg``."""

import argparse

from .common import EXIT_NOT_FOLD_FREE, EXIT_OK, say, warn


def add_parser(sub):
    p = sub.add_parser(
        "register-sphere", formatter_class=argparse.RawDescriptionHelpFormatter,
        help="register a subject's sphere to a target sphere by features (?h.sphere.reg)",
        description="Register SUBJECT to the target sphere by per-vertex features (atlas "
                    "registration, as FreeSurfer's\nmris_register): a rigid search, then a "
                    "fold-free deformation coarse to fine.  SUBJECT is the\nsubject's surface "
                    "(its area-balanced sphere is computed) or, with --sphere, its sphere.\n"
                    "Writes OUT, the registered sphere: the subject's vertices in its order on "
                    "the target\nsphere (its radius and frame), FreeSurfer (lh.sphere.reg) or "
                    "GIfTI (.surf.gii) by name, and\nOUT.json (correlations before/after, "
                    "folds as stored, distortion, seconds).",
        epilog="Features: FreeSurfer curv format (lh.sulc, lh.curv) or .mgh/.mgz, GIfTI "
               "(.func.gii, .shape.gii;\n.gii.gz) or .npy, one column per file, several = coarse to fine "
               "(the first at every level,\nthe next ones added at finer levels); the same "
               "kinds in the same order on both sides.\nDefault: ?h.sulc then ?h.curv next to "
               "SUBJECT and next to the target (a FreeSurfer\nsubject's surf/ folder).\n\n"
               "exit codes: 0 success; 1 usage or I/O error; 2 invalid mesh; 3 written, but "
               "folded as\nstored, no better match, or a doubtful (poor) start: see the warning")
    p.add_argument("subject", metavar="SUBJECT", help="subject surface (or sphere with --sphere)")
    p.add_argument("--features", nargs="+", metavar="FILE", help="subject features, coarse to fine")
    p.add_argument("--target", required=True, metavar="TARGET_SPHERE",
                   help="target sphere (fsaverage's lh.sphere, an fs_LR sphere, another subject's)")
    p.add_argument("--target-features", nargs="+", metavar="FILE",
                   help="the target's features, the same kinds in the same order")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="registered sphere")
    p.add_argument("--sphere", action="store_true", help="SUBJECT is the subject's sphere")
    p.add_argument("--surface", metavar="FILE",
                   help="with --sphere: the subject's surface (e.g. lh.white), to flag a poor "
                        "start sphere")
    p.add_argument("--kind", choices=("area_balanced", "conformal"), default="area_balanced",
                   help="the subject's computed sphere (default area_balanced: the conformal map "
                        "is a poor start for registration)")
    p.add_argument("--precision", choices=("float32", "float64"), default=None,
                   help="storage precision the registered sphere stays fold-free in (default "
                        "float32: FreeSurfer and GIfTI store float32)")
    p.add_argument("--hemisphere", choices=("left", "right"), default=None,
                   help="hemisphere named in a GIfTI output (default: the subject's, or its name's)")
    p.add_argument("--json", metavar="REPORT", help="report path (default OUT.json)")
    p.add_argument("--allow-doubtful", action="store_true",
                   help="exit 0 when the output is fold-free as stored even if not a success")
    p.add_argument("-q", "--quiet", action="store_true")
    p.add_argument("--debug", action="store_true")
    p.set_defaults(func=run)


def run(args):
    from ..app.sphere_registration import register_sphere_file

    rep = register_sphere_file(args.subject, args.target, args.output, features=args.features,
                               target_features=args.target_features, sphere=args.sphere,
                               surface=args.surface,
                               kind=args.kind, hemisphere=args.hemisphere,
                               report=args.json or True,
                               options={"precision": args.precision} if args.precision else None,
                               on_stage=lambda text: say(args, f"{text} ..."))
    corr = ", ".join(f"{a:.3f} -> {b:.3f}" for a, b in
                     zip(rep["correlation_before"], rep["correlation_after"]))
    say(args, f"registered {rep['vertices']:,} vertices: feature correlation {corr}; folds "
              f"{rep['folds']} (in the file {rep['folds_stored']}); radius {rep['radius']:.4g}; "
              f"{rep['timings']['total']:.1f} s -> " + ", ".join(
                  v for v in rep["outputs"].values() if v))
    for note in rep.get("notes", []):
        say(args, f"note: {note}")
    if rep["success"]:
        return EXIT_OK
    warn(f"warning: {rep['message']}")
    fold_free = rep["folds"] == 0 and rep["folds_stored"] == 0
    return EXIT_OK if (args.allow_doubtful and fold_free) else EXIT_NOT_FOLD_FREE
