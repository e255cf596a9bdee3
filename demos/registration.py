#!/usr/bin/env python
"""Watch an inter-surface map carry one surface's data onto another, stage by stage.

    python demos/registration.py                                 # default pair from the dino
    python demos/registration.py --screenshots out/registration  # headless PNGs
    python demos/registration.py A.obj B.obj --landmarks A.txt B.txt [--data B_curv.npy]
    python demos/registration.py --curvature                     # surface 2's mean curvature

:func:`igl_spheremap.surface_map` maps surface 2 conformally onto the sphere
and surface 1 so that its landmarks land on the images of surface 2's; each
vertex of surface 1 then takes surface 2's data at the same point of the
sphere.  The stages are surface 1's map after each stage of ``surface_map``:
conformal (Möbius-fitted to the targets), deformed until the landmarks sit on
their targets, the distortion between the surfaces lowered on coarse levels,
with the landmark descriptors, and with less of them or none (the map returned).  Each shows, in two rows (surface 1 above, surface
2 below): the surface coloured by part, its spherical map from the front and
from behind (the same turn in both rows), and the surface painted with surface
2's data (by default a checkerboard of surface 2's spherical coordinates; on
surface 1 carried through the map).  The landmark pairs are numbered dots, the
k-th pair in the same colour everywhere; rings on surface 1's sphere mark the
targets.  A slider in the polyscope panel steps through the stages;
``--screenshots DIR`` renders headless instead (one PNG per stage and
``contact_sheet.png``).

Default pair: surface 2 is the bundled dino; surface 1 is the dino decimated to
4,000 faces (``igl.decimate``), Loop-subdivided once (``igl.loop``; a new
triangulation of 8,002 vertices, nowhere aligned with the dino's) and bent
(``y += 0.35 (z - z_c)^2``: head and tail raised).  Landmarks of surface 2:
its extremities (vertices farthest from the centroid within their 2-ring,
farthest first, at least 15% of the size apart: head, tail and the four feet),
then farthest-point sampling up to 8 (a point on the back, one at the hips).
Surface 1's landmarks are its vertices nearest to those points after the same
bend: the known correspondence.

Landmark files: one vertex index per line, or ``x y z`` rows snapped to the
nearest vertex (:func:`igl_spheremap.io.read_landmarks`); the k-th rows of the
two files are a pair.  Exit codes: 0 done, 1 a file cannot be read or the
arguments are wrong, 2 an invalid mesh or no OpenGL (the message names the
Debian packages for headless rendering), 3 shown, but the landmark map failed.
"""

import sys

import numpy as np

import igl_spheremap
from igl_spheremap.cli.common import Parser, at_least_one
from igl_spheremap.cli.register_command import robust_scale
from igl_spheremap.errors import MeshError
from igl_spheremap.io import read_landmarks, read_mesh, read_vertex_data

BEND = 0.35


def extremity_landmarks(V, F, k=8, separation=0.15):
    """Extremities of a surface, then farthest-point samples: ``k`` vertex indices.

    Extremities are the vertices whose distance from the centroid is largest in
    their 2-ring, taken farthest first and at least ``separation`` times the
    largest extent apart; farthest-point sampling (Euclidean) adds vertices
    until there are ``k``.
    """
    import igl

    d = np.linalg.norm(V - V.mean(axis=0), axis=1)
    A = igl.adjacency_matrix(np.asarray(F, dtype=np.int64)).tocsr()
    A = (A + A @ A).tocsr()
    cand = np.flatnonzero(d >= np.maximum.reduceat(d[A.indices], A.indptr[:-1]))
    r = separation * float(np.ptp(V, axis=0).max())
    chosen = []
    for i in cand[np.argsort(-d[cand], kind="stable")]:
        if len(chosen) < k and all(np.linalg.norm(V[i] - V[j]) >= r for j in chosen):
            chosen.append(int(i))
    gap = np.min(np.linalg.norm(V[:, None] - V[chosen][None], axis=2), axis=1)
    while len(chosen) < k:
        i = int(np.argmax(gap))
        chosen.append(i)
        gap = np.minimum(gap, np.linalg.norm(V - V[i], axis=1))
    return np.asarray(chosen, dtype=np.int64)


def bent(X, centre, amount=BEND, along=2, up=1):
    """``X`` bent: ``X[:, up] += amount (X[:, along] - centre[along])^2``."""
    Y = np.array(X, dtype=np.float64)
    Y[:, up] += amount * (Y[:, along] - centre[along]) ** 2
    return Y


def deformed_pair(V2, F2, faces=4000, k=8, amount=BEND):
    """Surface 1 from surface 2: decimated to ``faces``, Loop-subdivided once, bent.

    Returns ``V1, F1, landmarks1, landmarks2``; the landmarks of surface 2 from
    :func:`extremity_landmarks`, surface 1's the vertices nearest to them after
    the bend.
    """
    import igl
    from scipy.spatial import cKDTree

    Vd, Fd, *_ = igl.decimate(np.asfortranarray(V2, dtype=np.float64),
                              np.asfortranarray(F2, dtype=np.int32), faces)
    V1, F1 = igl.loop(Vd, np.asarray(Fd, dtype=np.int64))
    centre = 0.5 * (V2.min(axis=0) + V2.max(axis=0))
    V1 = bent(V1, centre, amount)
    l2 = extremity_landmarks(V2, F2, k)
    l1 = cKDTree(V1).query(bent(V2[l2], centre, amount))[1].astype(np.int64)
    return V1, np.asarray(F1, dtype=np.int64), l1, l2


def _inputs(args):
    """The two surfaces, their landmarks, the data of surface 2 and the axis drawn up."""
    if args.meshes:
        if len(args.meshes) != 2 or not args.landmarks:
            raise ValueError("give two meshes and --landmarks A.txt B.txt (or nothing, for the "
                             "default pair)")
        (V1, F1, fam1), (V2, F2, fam2) = (read_mesh(p) for p in args.meshes)
        l1, l2 = read_landmarks(args.landmarks[0], V1, F1), read_landmarks(args.landmarks[1], V2, F2)
        up = 2 if {fam1, fam2} <= {"gifti", "freesurfer"} else None
        names = args.meshes
    else:
        V2, F2, _ = read_mesh(igl_spheremap.example_mesh())
        V1, F1, l1, l2 = deformed_pair(V2, F2)
        up, names = None, ["dino decimated, Loop-subdivided and bent", "bundled dino"]
    for i, (name, V, F) in enumerate(((names[0], V1, F1), (names[1], V2, F2))):
        print(f"surface {i + 1}: {name}: {len(V)} vertices, {len(F)} faces")
    return V1, F1, V2, F2, l1, l2, up


def _data(args, V2, F2):
    """Surface 2's data and its name, or (None, None) for the default checkerboard."""
    if args.curvature:
        import igl

        _, _, k1, k2, _ = igl.principal_curvature(V2, np.asarray(F2, dtype=np.int64))
        return 0.5 * (k1 + k2), "mean curvature of surface 2 (igl.principal_curvature)"
    if args.data:
        X, names = read_vertex_data(args.data, vertices=len(V2))
        if X.ndim == 2:
            print(f"note: {args.data} has {X.shape[1]} columns; showing the first ({names[0]})")
            X = X[:, 0]
        return X, f"{names[0]} of surface 2 ({args.data})"
    return None, None


def _parser():
    ap = Parser(description=__doc__.split("\n\n")[0])
    ap.add_argument("meshes", nargs="*", metavar="MESH",
                    help="surface 1 and surface 2 (default: the pair built from the dino)")
    ap.add_argument("--landmarks", nargs=2, metavar=("A.txt", "B.txt"),
                    help="landmark files of surface 1 and surface 2 (k-th rows are a pair)")
    ap.add_argument("--data", metavar="FILE",
                    help="per-vertex data of surface 2 (.npy .npz .txt .csv .gii, FreeSurfer "
                         "curv/thickness/sulc); default: a checkerboard of its (theta, phi)")
    ap.add_argument("--curvature", action="store_true",
                    help="show surface 2's mean curvature (igl.principal_curvature) as data")
    ap.add_argument("--mode", choices=("hard", "soft"), default="hard")
    ap.add_argument("--robust-scale", default="auto", metavar="EPS", type=robust_scale,
                    help="surface_map's robust last stage: 'auto' (default), 'off' or a scale "
                         "(e.g. 0.01)")
    ap.add_argument("--screenshots", metavar="DIR",
                    help="render headless into DIR (one PNG per stage + contact_sheet.png)")
    ap.add_argument("--sheet-width", type=at_least_one, default=1800, metavar="PX",
                    help="width of contact_sheet.png in pixels (default 1800)")
    return ap


def compute(args):
    """Read or build the pair, run :func:`igl_spheremap.surface_map`, print the stages.

    Returns
    -------
    result : SurfaceMapResult
    stages : list of dict
        :func:`igl_spheremap.viz.registration.stages.build_registration_stages`.
    up : int or None
        Axis of the surfaces drawn vertical.
    """
    import warnings

    from igl_spheremap.viz.registration.stages import build_registration_stages, stage_line

    V1, F1, V2, F2, l1, l2, up = _inputs(args)
    data2, data_name = _data(args, V2, F2)
    print(f"{len(l1)} landmark pairs: surface 1 {list(map(int, l1))}, "
          f"surface 2 {list(map(int, l2))}", flush=True)
    with warnings.catch_warnings():      # a failure is printed below and shown in red
        warnings.simplefilter("ignore", igl_spheremap.SphericalMapWarning)
        result = igl_spheremap.surface_map(V1, F1, V2, F2, l1, l2, mode=args.mode,
                                           robust_scale=args.robust_scale)
    print(f"surface_map: {result.seconds:.1f} s (" + ", ".join(
        f"{k} {v:.1f} s" for k, v in result.timings.items()) + f"); {result.message}")
    stages = build_registration_stages(result, V1, V2, l1, l2, data2, data_name, args.mode)
    for i, st in enumerate(stages):
        print(stage_line(st, i))
    return result, stages, up


def _opengl_first(args):
    """Headless: open polyscope's EGL context before the maps run, so a machine without it
    fails in a second instead of after the computation."""
    if args.screenshots:
        from igl_spheremap.viz.viewer import init_polyscope

        init_polyscope(None, headless=True, program_name="igl_spheremap: registration",
                        demo="demos/registration.py")


def main(argv=None):
    args = _parser().parse_args(argv)
    try:
        _opengl_first(args)
    except RuntimeError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    try:
        result, stages, up = compute(args)
    except MeshError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except (OSError, ValueError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 1
    from igl_spheremap.viz.registration.view import show_registration

    try:
        view = show_registration(stages, screenshot_dir=args.screenshots,
                                 sheet_width=args.sheet_width, up=up)
    except RuntimeError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    for p in view.screenshots + ([view.contact_sheet] if view.contact_sheet else []):
        print(p)
    return 0 if result.success else 3


if __name__ == "__main__":
    sys.exit(main())
