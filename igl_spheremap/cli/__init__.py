"""Command-line interface ``igl-spheremap``.

``igl-spheremap [map] [MESH] [-o OUT] ...`` maps one mesh (the default
subcommand: ``map`` is inserted when the first argument is not a subcommand);
``igl-spheremap batch INPUTS... -o OUTDIR`` maps many on Dask; ``register`` maps one
surface onto another with landmarks, ``register-sphere`` registers a subject's sphere to an
atlas sphere by features (``?h.sphere.reg``), ``resample`` puts a surface or data on a template
sphere.  One module per
subcommand; they only parse arguments and print, the work is in
:func:`igl_spheremap.app.map_file.map_file` and :func:`igl_spheremap.app.batch.map_batch`.
"""

import argparse
import sys

from . import (batch_command, map_command, register_command, register_sphere_command,
               resample_command)
from .batch_command import batch_exit_code
from .common import EXIT_CODES, EXIT_ERROR, EXIT_INVALID_MESH, PROG, Parser, warn
from .map_command import format_round

SUBCOMMANDS = {"map": map_command, "batch": batch_command, "register": register_command,
               "register-sphere": register_sphere_command, "resample": resample_command}

__all__ = ["main", "build_parser", "batch_exit_code", "format_round", "version_text"]


def version_text():
    """What ``igl-spheremap --version`` prints: our, libigl's, numpy's and scipy's versions
    and the H1 solver backend a run would use."""
    from importlib import metadata

    from .. import __version__
    from ..optimize.preconditioner import backend_description

    def version(dist):
        try:
            return metadata.version(dist)
        except metadata.PackageNotFoundError:
            return "not installed"

    return (f"{PROG} {__version__}\n"
            + ", ".join(f"{d} {version(d)}" for d in ("libigl", "numpy", "scipy")) + "\n"
            + f"H1 solver: {backend_description()}")


class _Version(argparse.Action):
    def __init__(self, option_strings, dest=argparse.SUPPRESS, **kwargs):
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        print(version_text())
        parser.exit()


def build_parser():
    """The argparse parser of ``igl-spheremap`` (one subparser per subcommand)."""
    parser = Parser(
        prog=PROG, formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Folding-free spherical conformal maps of closed genus-0 triangle meshes "
                    "(Lai, Wen, Yin, Gu, Lui 2014) on libigl.\n\n"
                    f"  {PROG} [map] [MESH] [-o OUT] ...     map one mesh (default subcommand)\n"
                    f"  {PROG} batch INPUTS... -o OUTDIR    map many meshes on Dask\n"
                    f"  {PROG} register A B --landmarks A.txt B.txt -o OUT   A onto B\n"
                    f"  {PROG} register-sphere lh.white --target fsaverage/lh.sphere -o "
                    "lh.sphere.reg\n"
                    f"  {PROG} resample MESH --ico 6 -o OUT   onto a standard icosphere\n\n"
                    "Formats: .obj .off .ply .stl .wrl .mesh .msh (read by libigl, plyfile "
                    "and meshio),\nGIfTI surfaces (.surf.gii; .gii.gz, as nilearn ships fsaverage) "
                    "and FreeSurfer\nsurfaces (lh.white, rh.pial, ...).",
        epilog=EXIT_CODES)
    parser.add_argument("--version", action=_Version,
                        help="print the versions of igl-spheremap, libigl, numpy and scipy and "
                             "the H1 solver backend, then exit")
    sub = parser.add_subparsers(dest="command", metavar="{" + ",".join(SUBCOMMANDS) + "}")
    for module in SUBCOMMANDS.values():
        module.add_parser(sub)
    return parser


def main(argv=None):
    """Entry point of ``igl-spheremap``; returns the exit code.

    Parameters
    ----------
    argv : list of str, optional
        Arguments without the program name (default ``sys.argv[1:]``).  ``map``
        is inserted when the first one is not a subcommand or a top-level flag.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] not in (*SUBCOMMANDS, "-h", "--help", "--version"):
        argv.insert(0, "map")
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else EXIT_ERROR
    from ..errors import MeshError, describe

    try:
        return args.func(args)
    except KeyboardInterrupt:
        warn("interrupted")
        return 130
    except Exception as exc:
        if args.debug:
            raise
        if isinstance(exc, MeshError):
            warn(describe(exc))
            return EXIT_INVALID_MESH
        warn(f"error: {describe(exc)}")
        return EXIT_ERROR
