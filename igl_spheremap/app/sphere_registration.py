"""Register a subject's sphere to a target sphere from files: what ``igl-spheremap register-sphere`` does.

Reads the subject (a surface whose sphere is computed, or its sphere), the
features of both sides and the target sphere; registers
(:func:`igl_spheremap.uses.atlas_multires.register_surface`); writes the
registered sphere, FreeSurfer's ``?h.sphere.reg``: the subject's vertices in
the subject's order on the target sphere, at the target's radius, in the
target's frame, as a FreeSurfer surface or GIfTI by the output's name, with the
subject's volume geometry / GIfTI metadata (:func:`igl_spheremap.app.storage.output_metadata`);
and a JSON report.
"""

import time
import warnings
from pathlib import Path

import numpy as np

from ..conformal_map import spherical_conformal_map
from ..errors import SphericalMapWarning, plural
from ..io import (check_outputs, check_sphere_output, read_vertex_data,
                  stored_folds, write_mesh, write_report)
from ..mesh.arrays import off_sphere
from ..uses.atlas import registration_options
from ..uses.atlas_multires import register_surface
from ..uses.features import constant_columns, unmatched_columns
from .read_surface import read_surface
from .report import library_versions
from .storage import output_metadata

#: Features looked for next to a FreeSurfer surface when none are given, coarse to fine
#: (``surf/lh.white`` -> ``surf/lh.sulc``, ``surf/lh.curv``): sulcal depth then curvature.
DEFAULT_FEATURES = ("sulc", "curv")


def default_features(surface):
    """``?h.sulc`` and ``?h.curv`` next to a FreeSurfer surface ``?h.*`` (list of Path).

    Raises
    ------
    ValueError
        The surface is not named like ``lh.white``, or the files are missing.
    """
    path = Path(surface)
    hemi = path.name.split(".")[0]
    if hemi not in ("lh", "rh"):
        raise ValueError(f"no features given for '{path}', and it is not named like a FreeSurfer "
                         "surface (lh.*, rh.*) whose ?h.sulc and ?h.curv could be used; pass "
                         "--features (and --target-features)")
    found = [path.with_name(f"{hemi}.{k}") for k in DEFAULT_FEATURES]
    missing = [str(p) for p in found if not p.is_file()]
    if missing:
        raise ValueError(f"no features given for '{path}', and {', '.join(missing)} "
                         "not found; pass --features (and --target-features)")
    return found


def read_features(paths, vertices):
    """Per-vertex features from files, one column per file ((n, d) float64 array)."""
    cols = []
    for p in paths:
        X, _ = read_vertex_data(p, vertices)
        cols.append(X.reshape(vertices, -1))
    return np.hstack(cols)


def _subject_sphere(V, F, is_sphere, kind, opts):
    """The subject's sphere, its faces and its summary (a given sphere, or computed)."""
    if is_sphere:
        return V, F, {"source": "given"}
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SphericalMapWarning)
        res = spherical_conformal_map(V, F, kind=kind, precision=opts.precision)
    return res.U, res.F, {"source": kind, "folds": int(res.folds), "success": bool(res.success),
                          "message": res.message, "seconds": time.perf_counter() - t}


def _surface_of(path, U, F):
    """The subject's surface read from ``path``: the vertices of the sphere ``U`` with faces ``F``."""
    S, SF, _ = read_surface(path, "the subject's surface")
    if S.shape != U.shape or not np.array_equal(SF, F):
        raise ValueError(f"the surface '{path}' has {len(S):,} vertices and {len(SF):,} faces, "
                         f"the sphere {len(U):,} and {len(F):,}"
                         + (" (other faces)" if S.shape == U.shape and SF.shape == F.shape else "")
                         + ": pass the surface the sphere was made from")
    return S


def register_sphere_file(subject, target, out, *, features=None, target_features=None,
                         sphere=False, surface=None, kind="area_balanced", hemisphere=None,
                         report=None, options=None, on_stage=None):
    """Register ``subject`` to ``target`` by their features and write ``out`` (module docstring).

    Parameters
    ----------
    subject : str or os.PathLike
        The subject's surface (``lh.white``), or with ``sphere`` its sphere.
    target : str or os.PathLike
        The target sphere (``fsaverage/surf/lh.sphere``, a ``.sphere.surf.gii``, ...).
    out : str or os.PathLike
        The registered sphere: FreeSurfer (``lh.sphere.reg``) or GIfTI
        (``.surf.gii``) by its name, or a mesh format.
    features, target_features : list of str or os.PathLike, optional
        Per-vertex features (FreeSurfer curv format, GIfTI, ``.npy``, ...:
        :func:`igl_spheremap.io.read_vertex_data`), several coarse to fine, the
        same kinds on both sides; default :func:`default_features` next to each
        FreeSurfer surface (``?h.sulc`` then ``?h.curv``).
    sphere : bool
        ``subject`` is the subject's sphere (else its sphere is computed).
    surface : str or os.PathLike, optional
        With ``sphere``: the subject's surface (``lh.white``, same vertices and faces), against
        which a poor start sphere is flagged (a conformal sphere crushes the regions it
        crowds); without it that check cannot run and the report's ``notes`` say so.
    kind : {"area_balanced", "conformal"}
        The computed sphere (:func:`igl_spheremap.spherical_conformal_map`).
    hemisphere : {None, "left", "right"}
        For GIfTI metadata (:func:`igl_spheremap.app.storage.output_metadata`).
    report : str or os.PathLike or True, optional
        JSON report path; True for ``<out>.json``.
    options : MapOptions or dict, optional
        As :func:`igl_spheremap.uses.atlas.register_sphere`.
    on_stage : callable, optional
        Called with a short text before each stage.

    Returns
    -------
    dict
        The report: ``success``, ``message``, ``warnings``, ``notes``, ``start_area_log``
        (the start sphere's mean ``|log area ratio|`` against the surface; None when the
        surface is unknown), ``correlation_before``,
        ``correlation_after``, ``correlation_rigid``, ``correlation_mirrored``,
        ``folds``, ``folds_stored``, ``below_margin``, ``distortion``, ``radius``,
        ``vertices``, ``faces``, ``sphere``, ``levels``, ``timings``, ``outputs``, ...

    Raises
    ------
    FileNotFoundError, ValueError, OSError, MeshError
        Unreadable inputs, features of the wrong length or count, folded spheres,
        a ``surface`` without ``sphere`` or with other vertex or face counts, unwritable
        outputs (checked before the work).
    """
    t0 = time.perf_counter()
    stage = on_stage or (lambda text: None)
    features = [Path(p) for p in (features or default_features(subject))]
    target_features = [Path(p) for p in (target_features or default_features(target))]
    family = check_sphere_output(out, role="registered sphere")
    report_path = Path(f"{out}.json") if report is True else (Path(report) if report else None)
    if surface is not None and not sphere:
        raise ValueError("a surface is passed with a given sphere only (--sphere): without it "
                         "the subject is the surface")
    check_outputs([subject, target, *features, *target_features,
                   *([surface] if surface is not None else [])],
                  {"registered sphere": out, "report": report_path})
    V, F, in_family, in_meta = read_surface(subject, "the subject", return_metadata=True)
    S = None if surface is None else _surface_of(surface, V, F)
    T, TF, _ = read_surface(target, "the target sphere")
    message = off_sphere(T, f"the target '{target}'")
    if message:  # before the subject's sphere is computed
        raise ValueError(message)
    fs, ft = read_features(features, len(V)), read_features(target_features, len(T))
    message = unmatched_columns(fs, ft)
    if message:  # before the subject's sphere is computed
        raise ValueError(message)
    for paths, x in ((features, fs), (target_features, ft)):
        message = constant_columns(x, "the features " + ", ".join(f"'{p}'" for p in paths))
        if message:  # before the subject's sphere is computed
            raise ValueError(message)
    opts = registration_options(options)
    stage("subject sphere" if sphere else f"{kind} sphere of the subject")
    U, F, sphere_info = _subject_sphere(V, F, sphere, kind, opts)
    stage("registration")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SphericalMapWarning)
        res = register_surface(V if S is None else S, F, fs, T, TF, ft, sphere=U, options=opts)
    radius = float(np.linalg.norm(T, axis=1).mean())
    meta, _ = output_metadata(subject, in_family, in_meta, family, hemisphere)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    write_mesh(out, radius * res.U, F, family=family, metadata=meta)
    rep = _report(res, sphere_info, V, F, radius, stored_folds(out, F))
    if sphere and S is None:  # register_surface measured the sphere against itself
        rep["start_area_log"] = None
        rep["notes"] = ["the given sphere was not checked against the subject's surface (pass "
                        "it, e.g. --surface lh.white): a poor start, such as a conformal "
                        "sphere, is then not flagged"]
    rep["inputs"] = {"subject": str(Path(subject).absolute()), "target": str(Path(target).absolute()),
                     "features": [str(p.absolute()) for p in features],
                     "target_features": [str(p.absolute()) for p in target_features]}
    rep["outputs"] = {"registered_sphere": str(Path(out).absolute()),
                      "report": str(report_path.absolute()) if report_path else None}
    rep["timings"]["sphere"] = sphere_info.get("seconds", 0.0)
    rep["timings"]["total"] = time.perf_counter() - t0
    if report_path is not None:
        write_report(report_path, rep)
    return rep


def _report(res, sphere_info, V, F, radius, folds_stored):
    success = bool(res.success and folds_stored == 0)
    message = res.message if folds_stored == 0 else (
        f"{res.message}; the file stores {plural(folds_stored, 'folded face')}")
    return {"complete": True, "success": success, "message": message,
            "warnings": list(res.warnings), "vertices": int(len(V)), "faces": int(len(F)),
            "radius": radius, "sphere": sphere_info, "precision": res.precision,
            "correlation_before": res.correlation_before.tolist(),
            "correlation_after": res.correlation_after.tolist(),
            "correlation_rigid": res.correlation_rigid,
            "correlation_mirrored": res.correlation_mirrored, "start_area_log": res.start_area_log,
            "folds": int(res.folds), "folds_stored": int(folds_stored),
            "below_margin": int(res.below_margin), "distortion": res.distortion,
            "rotation": res.rotation.tolist(), "levels": res.levels,
            "seconds": res.seconds, "timings": dict(res.timings), "versions": library_versions()}
