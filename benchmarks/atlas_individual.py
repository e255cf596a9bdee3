"""An individual cortex registered to fsaverage5: pycortex's S1 left pial surface (issue #20).

The subject is ``pycortex_s1_pia_lh.obj`` (152,893 vertices, ``../shared/meshes``); the
target is fsaverage5's left sphere, its surface fsaverage5's left pial (nilearn's wheel,
:mod:`atlas_cases`).  The feature, computed the same way on both surfaces with libigl:
mean curvature (``-L x / 2A`` along the vertex normal, cotangent Laplacian) smoothed by
heat diffusion on the surface to FWHM 20, 10 and 4 mm, used coarse to fine (20 mm at the
first two levels, 10 mm at the third, 10 and 4 mm at the fourth, 4 mm at the last).

Rows: the area-balanced sphere rigidly aligned only; ours from the surface alone
(``register_surface``: the area-balanced sphere, then, above 30,000 vertices, through a
level-5 icosphere with 300 iterations per level and membrane weight 0.3, lifted and
polished at full resolution); CAT-Surface's Spherical Demons (``cat_surf.spherical_demon``,
defaults, its own depth-potential features from the same two surfaces) from the same
area-balanced sphere and from CAT's metric-relaxed sphere.  Columns: the correlation
(area-weighted over the subject) of each feature with the target's at the registered
points (also for maps with folds), and of CAT's ``sulcus_depth`` (optimized by neither); folds and folds as stored
(float32, radius 100); seconds; and the label round trip: a 75-parcel Voronoi labelling of
fsaverage5's sphere carried to the subject (barycentric, nearest) and back
(``adap_bary_area`` with both pial surfaces' vertex areas, majority): the share of
fsaverage5's vertices that keep their label (not computed for a map with folds).

Usage::

    python benchmarks/atlas_individual.py [--mesh ../shared/meshes/pycortex_s1_pia_lh.obj]
"""

import sys
import time
from pathlib import Path

import numpy as np

from atlas_cases import cat_sphere, fsaverage5, spherical_demons
from harness import (DEFAULT_MESH_DIR, arguments, command, load_mesh, markdown_table, page,
                     parse, run, run_in_child, status_cell)

FWHM_MM = (20.0, 10.0, 4.0)
WEIGHTS = [(1, 0, 0), (1, 0, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1)]


def smoothed_mean_curvature(V, F, fwhms=FWHM_MM):
    """Mean curvature of a surface smoothed to each FWHM (mm): (n, len(fwhms)) float64."""
    import igl

    from igl_spheremap.mesh.operators import vertex_areas
    from igl_spheremap.uses.features import heat_smooth

    a = vertex_areas(V, F)
    HN = -(igl.cotmatrix(V, F) @ V) / (2.0 * a[:, None])
    H0 = np.sign((HN * igl.per_vertex_normals(V, F)).sum(1)) * np.linalg.norm(HN, axis=1)
    return np.stack([heat_smooth(V, F, H0, fw) for fw in fwhms], axis=1)


def levels():
    from dataclasses import replace

    from igl_spheremap.uses.atlas import DEFAULT_LEVELS

    return [replace(lv, max_iter=300, reg_weight=0.3, feature_weights=w)
            for lv, w in zip(DEFAULT_LEVELS, WEIGHTS)]


def label_round_trip(U, V, F, T, TF, target_surface, parcels=75):
    """Share of fsaverage5's vertices whose label survives the trip to the subject and back."""
    from igl_spheremap import resample_labels, resampling_matrix
    from igl_spheremap.mesh.operators import vertex_areas

    rng = np.random.default_rng(0)
    labels = np.argmax(T @ T[rng.choice(T.shape[0], parcels, replace=False)].T, axis=1)
    on_subject = resample_labels(resampling_matrix(T, TF, U), labels, "nearest")
    W = resampling_matrix(U, F, T, TF, method="adap_bary_area", current_area=vertex_areas(V, F),
                          new_area=vertex_areas(target_surface, TF))
    return float((resample_labels(W, on_subject, "majority") == labels).mean())


def measure_method(mesh, method):
    """One row in a child process."""
    import warnings

    from igl_spheremap import count_folds, register_surface, spherical_conformal_map
    from igl_spheremap.mesh.operators import vertex_areas
    from igl_spheremap.sphere.field import SphereField
    from igl_spheremap.sphere.folds import folds_after_rounding
    from igl_spheremap.uses.features import weighted_correlation
    from igl_spheremap.uses.rigid import rigid_align

    d = fsaverage5()
    V, F = load_mesh(mesh)
    T = d["sphere"] / 100.0
    TF, TV = d["F"], d["pial"]
    fs, ft = smoothed_mean_curvature(V, F), smoothed_mean_curvature(TV, TF)
    t = time.perf_counter()
    if method.startswith("CAT relaxed"):
        U0 = cat_sphere(V, F)
    else:
        U0 = spherical_conformal_map(V, F, kind="area_balanced", precision="float32").U
    sphere_s, t = time.perf_counter() - t, time.perf_counter()
    extra = {}
    if "rigid" in method:
        R, _, _ = rigid_align(U0, F, fs, T, TF, ft)
        U, reg_s = U0 @ R.T, None
    elif "Demons" in method:
        U = spherical_demons(V, F, U0, TV, T * 100.0, TF)
        reg_s = time.perf_counter() - t
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = register_surface(V, F, fs, T, TF, ft, sphere=U0, levels=levels())
        U, reg_s = res.U, time.perf_counter() - t
        extra = dict(success=res.success, warnings=res.warnings, below_margin=res.below_margin,
                     distortion=res.distortion, timings=res.timings)
    U = U / np.linalg.norm(U, axis=1, keepdims=True)
    cols_s, cols_t = fs, ft
    try:
        import cat_surf

        cols_s = np.c_[fs, cat_surf.sulcus_depth(V, F.astype(np.int32))]
        cols_t = np.c_[ft, cat_surf.sulcus_depth(TV, TF.astype(np.int32))]
    except ImportError:
        pass
    folds = count_folds(F, U)
    # the target is interpolated at the registered points: defined with folds too
    corr = weighted_correlation(cols_s, SphereField(T, TF, cols_t)(U, gradient=False)[0],
                                vertex_areas(V, F))
    return dict(method=method, corr=[float(c) for c in corr], folds=int(folds),
                stored_folds=int(folds_after_rounding(F, U, 100.0)), sphere_s=sphere_s,
                reg_s=reg_s, labels_kept=(label_round_trip(U, V, F, T, TF, TV)
                                          if folds == 0 else None), **extra)


METHODS = ["area-balanced sphere, rigid alignment only",
           "register_surface (area-balanced sphere, through a level-5 icosphere)",
           "Spherical Demons (CAT) from the area-balanced sphere",
           "CAT relaxed sphere: Spherical Demons (CAT)"]


def render(rows, env, args):
    names = [f"r {fw:g} mm curvature" for fw in FWHM_MM] + ["r CAT sulcus depth"]
    columns = [("method", "method", "", "l")]
    for j, name in enumerate(names):
        columns.append((name, lambda r, j=j: f"{r['corr'][j]:.3f}" if len(r.get("corr") or []) > j
                        else "–", "", "r"))
    columns += [("folds", "folds", "", "r"), ("folds as stored", "stored_folds", "", "r"),
                ("labels kept", lambda r: "–" if r.get("labels_kept") is None
                 else f"{100 * r['labels_kept']:.2f}%", "", "r"),
                ("sphere s", "sphere_s", ".0f", "r"), ("registration s", "reg_s", ".0f", "r"),
                ("success", "success", "", "l"), ("status", status_cell, "", "l")]
    return page("An individual cortex (pycortex S1) registered to fsaverage5", env,
                command("atlas_individual", args), markdown_table(rows, columns))


def main(argv=None):
    p = arguments(__doc__, meshes=None, timeout=1800.0)
    p.add_argument("--mesh", type=Path, default=DEFAULT_MESH_DIR / "pycortex_s1_pia_lh.obj")
    p.add_argument("--only", nargs="*", default=None, help="substrings of method names to run")
    args = parse(p, argv)
    names = [m for m in METHODS if not args.only or any(s in m for s in args.only)]
    run("atlas_individual", args, names,
        lambda m: dict(run_in_child(measure_method, dict(mesh=str(args.mesh), method=m),
                                    timeout=args.timeout), method=m), render,
        echo=lambda r: f"{r['method']}: {r.get('status')} {r.get('corr')} folds {r.get('folds')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
