"""``igl-spheremap resample MESH (--ico L | --template SPHERE) [--sphere REG] [--data X] -o OUT``:
a surface and its data on a template sphere, or (``--from-template``) a template's data on a subject."""

import argparse

from .common import EXIT_NOT_FOLD_FREE, EXIT_OK, non_negative_int, say, warn


def add_parser(sub):
    p = sub.add_parser(
        "resample", formatter_class=argparse.RawDescriptionHelpFormatter,
        help="resample a surface and its data onto a template sphere (or a template's data onto it)",
        description="Re-triangulate MESH with the connectivity of a template sphere (the "
                    "icosphere of level ICO,\n10 * 4^ICO + 2 vertices, or --template SPHERE such "
                    "as fsaverage's lh.sphere) through MESH's\nsphere in the template's frame: "
                    "--sphere (its registered sphere, lh.sphere.reg) or its conformal\nmap.  "
                    "Writes OUT, OUT's base .json and, with --data/--labels, the values resampled."
                    "\nWith --from-template: the template's --data/--labels carried to MESH's "
                    "vertices through\n--sphere (mri_surf2surf from the atlas to a subject); OUT "
                    "is then the data file.",
        epilog="Data: .npy .npz .txt .csv .gii, FreeSurfer curv/thickness or .mgh/.mgz files; "
               "labels: one integer per\nvertex in any of these, or a FreeSurfer .annot; mask: "
               "per-vertex values, > 0 where the source's\ndata is used, or a FreeSurfer .label "
               "(e.g. cortex.label: cortex without the medial wall).\nLabels are written as "
               "int32 GIfTI labels with the input's label table, or int64 in .npz.")
    p.add_argument("mesh", metavar="MESH")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--ico", type=non_negative_int, default=6, metavar="LEVEL",
                       help="icosphere level (default 6)")
    where.add_argument("--template", metavar="SPHERE", help="template sphere file")
    p.add_argument("--order", choices=("igl", "freesurfer"), default="igl",
                   help="vertex order of --ico: igl (default, libigl's) or freesurfer "
                        "(fsaverage's order and frame: output is fsaverage-ordered, in its "
                        "correspondence only with --sphere ?h.sphere.reg)")
    p.add_argument("--sphere", metavar="SPHERE",
                   help="MESH's sphere in the template's frame (e.g. lh.sphere.reg); default: "
                        "its conformal map")
    p.add_argument("--data", metavar="VALUES", help="per-vertex data to resample")
    p.add_argument("--labels", metavar="LABELS", help="per-vertex integer labels to resample")
    p.add_argument("--mask", metavar="MASK", help="vertices of the source whose values are used")
    p.add_argument("--method", choices=("barycentric", "adap_bary_area"), default="barycentric",
                   help="barycentric (default) or Workbench's area-corrected adaptive "
                        "barycentric ADAP_BARY_AREA")
    p.add_argument("--label-method", choices=("majority", "nearest"), default="majority",
                   help="label of the largest summed weight (default) or of the nearest vertex")
    p.add_argument("--from-template", action="store_true",
                   help="carry the template's --data/--labels to MESH (needs --sphere, --template)")
    p.add_argument("--template-surface", metavar="SURFACE",
                   help="with --from-template and adap_bary_area: the template's anatomical "
                        "surface for its vertex areas (default: the template sphere)")
    p.add_argument("-o", "--output", required=True, metavar="OUT",
                   help="the resampled surface (its format from the name); with "
                        "--from-template the data file (.func.gii or .npz)")
    p.add_argument("-q", "--quiet", action="store_true")
    p.add_argument("--debug", action="store_true")
    p.set_defaults(func=run)


def run(args):
    from ..app.resampling import from_template_file, resample_file

    if args.template_surface and not args.from_template:
        raise ValueError("--template-surface is used only with --from-template (the template's "
                         "vertex areas for adap_bary_area); drop it or add --from-template")
    if args.template and args.order != "igl":
        raise ValueError(f"--order {args.order} orders the vertices of --ico; a --template "
                         "sphere keeps its own vertex order: drop --order")
    if args.from_template:
        if not (args.sphere and args.template):
            raise ValueError("--from-template needs --sphere (MESH's registered sphere) and "
                             "--template")
        rep = from_template_file(args.mesh, args.sphere, args.template, args.output,
                                 data=args.data, labels=args.labels, mask=args.mask,
                                 method=args.method, label_method=args.label_method,
                                 template_surface=args.template_surface)
        say(args, f"carried to {rep['vertices']:,} vertices; {rep['seconds']:.2f} s -> "
                  + ", ".join(rep["outputs"].values()))
        return EXIT_OK
    rep = resample_file(args.mesh, args.ico, args.output, data=args.data, labels=args.labels,
                        mask=args.mask, method=args.method, label_method=args.label_method,
                        template=args.template, sphere=args.sphere, order=args.order)
    say(args, f"resampled onto {rep['template']} ({rep['vertices']:,} vertices); "
              f"{rep['seconds']:.2f} s -> " + ", ".join(rep["outputs"].values()))
    for note in rep["notes"]:
        say(args, f"note: {note}")
    if rep["map_success"]:
        return EXIT_OK
    warn(f"warning: the spherical map is not fold-free or did not converge: "
         f"{rep['map_message']}")
    return EXIT_NOT_FOLD_FREE
