"""What the subcommands of ``igl-spheremap`` share: exit codes, argument types, options, printing."""

import argparse
import math
import sys

PROG = "igl-spheremap"

EXIT_OK = 0            #: success
EXIT_ERROR = 1         #: usage or I/O error, unexpected error; batch: every mesh failed
EXIT_INVALID_MESH = 2  #: the input is not a closed genus-0 triangle mesh (MeshError)
EXIT_NOT_FOLD_FREE = 3  #: outputs written but the map has folds or did not converge
EXIT_PARTIAL = 4       #: batch: some meshes failed, the others finished

EXIT_CODES = """\
exit codes:
  0  success (batch: every mesh mapped fold-free and converged, or skipped as done)
  1  usage or I/O error, unexpected error (batch: every mesh failed)
  2  invalid mesh: not a closed, manifold, genus-0 triangle mesh
  3  outputs written, but the map has folded faces or did not converge
     (--allow-folds exits 0 instead)
  4  batch only: some meshes failed, the others finished
"""


class Parser(argparse.ArgumentParser):
    """ArgumentParser whose usage errors exit with 1 (2 means 'invalid mesh' here)."""

    def error(self, message):
        self.print_usage(sys.stderr)
        self.exit(EXIT_ERROR, f"{self.prog}: error: {message}\n")


def _number(text, kind, low, strict=False):
    try:
        value = kind(text)
    except ValueError:
        try:
            float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text}") from None
    if kind is float and not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite, got {text}")
    if value < low or (strict and value == low):
        raise argparse.ArgumentTypeError(f"must be {'>' if strict else '>='} {low}, got {text}")
    return value


def non_negative_int(text):
    return _number(text, int, 0)


def at_least_one(text):
    return _number(text, int, 1)


def positive_float(text):
    return _number(text, float, 0.0, strict=True)


def non_negative_float(text):
    return _number(text, float, 0.0)


def common_arguments():
    """The options every mapping subcommand takes (an argparse parent parser)."""
    common = argparse.ArgumentParser(add_help=False)
    g = common.add_argument_group("mapping options")
    g.add_argument("--method", choices=("folding_free", "paper"), default=None,
                   help="folding_free (default): the fold-free variant documented in the "
                        "README; paper: Algorithms 1 and 2 as published")
    g.add_argument("--max-rounds", type=non_negative_int, default=None, metavar="N",
                   help="cap on folding-removal (star map) rounds after the Gauss-map stage "
                        "(default: the method's)")
    g.add_argument("--max-iter", type=non_negative_int, default=None, metavar="N",
                   help="cap on Algorithm 1 iterations per round (default: the method's)")
    g.add_argument("--gtol", type=positive_float, default=None, metavar="X",
                   help="stop Algorithm 1 when the RMS Riemannian gradient is below X "
                        "(default: the method's)")
    g.add_argument("--radius", type=positive_float, default=None, metavar="R",
                   help="radius of the written sphere (default 100 for GIfTI and FreeSurfer "
                        "output, like FreeSurfer's ?h.sphere and the HCP's spheres; 1 for "
                        ".obj/.off/.ply)")
    g.add_argument("--precision", choices=("float32", "float64"), default=None,
                   help="storage precision the map must stay fold-free in: float32 keeps "
                        "every image triangle above its float32 rounding margin, at some "
                        "angle distortion on thin features (default: float32 when the sphere "
                        "is written as float32, i.e. GIfTI and FreeSurfer, else float64)")
    g.add_argument("--polish", choices=("auto", "always", "never"), default=None,
                   help="when the conformal descent also runs from the rounds' map: auto "
                        "(default) where the fold barrier froze more than a tenth of the "
                        "vertices, more than a tenth of the area is on faces distorted over "
                        "twice a conformal map's, or the round started from untangled patches, "
                        "always for the most conformal map (several "
                        "times the seconds), never for the rounds' speed (README: Polish)")
    g = common.add_argument_group("output and behaviour")
    g.add_argument("--file-precision", choices=("float32", "float64"), default=None,
                   help="numbers in the written sphere: the format's own by default (float64 "
                        "for .obj/.off/.ply, float32 for GIfTI and FreeSurfer); float64 GIfTI "
                        "is exact but outside the GIfTI standard")
    g.add_argument("--hemisphere", choices=("left", "right"), default=None,
                   help="hemisphere named in GIfTI outputs (default: the input's, else its "
                        "name's: lh./rh., BIDS hemi-L/hemi-R, HCP .L./.R.)")
    g.add_argument("--data", action="store_true",
                   help="also write per-vertex data: log conformal factor, theta, phi, "
                        "equirectangular tex_u/tex_v, folded (.npz for mesh files, "
                        ".func.gii for GIfTI/FreeSurfer)")
    g.add_argument("--allow-folds", action="store_true",
                   help="exit 0 even if the map has folds or did not converge")
    g.add_argument("-q", "--quiet", action="store_true",
                   help="print nothing on stdout (warnings and errors still go to stderr)")
    g.add_argument("--no-progress", action="store_true",
                   help="no progress bar (it is shown only when stderr is a terminal)")
    g.add_argument("--debug", action="store_true",
                   help="show full tracebacks of unexpected errors")
    return common


def map_options(args):
    """The :class:`igl_spheremap.MapOptions` the command line asks for."""
    from ..options import MapOptions

    return MapOptions(method=args.method, max_rounds=args.max_rounds, max_iter=args.max_iter,
                      gtol=args.gtol, precision=args.precision, polish=args.polish)


def say(args, text=""):
    """Print on stdout unless --quiet, without breaking a tqdm bar shown on stderr."""
    if args.quiet:
        return
    if show_progress(args):
        from tqdm import tqdm

        tqdm.write(text, file=sys.stdout)
    else:
        print(text, file=sys.stdout)
    sys.stdout.flush()


def warn(text):
    print(f"{PROG}: {text}", file=sys.stderr, flush=True)


def show_progress(args):
    """A progress bar only on a terminal, and not with --quiet or --no-progress."""
    return (not (getattr(args, "no_progress", True) or args.quiet)
            and sys.stderr.isatty())
