"""Registration of mesh files (landmarks optional): what ``igl-spheremap register`` does."""

import time
import warnings
from pathlib import Path

import numpy as np

from ..errors import SphericalMapWarning
from ..io import (check_outputs, mesh_format, read_landmarks, read_vertex_data,
                  write_report, write_vertex_data)
from ..io.atomic import atomic_path
from ..options import map_options
from ..uses.registration import surface_map
from ..uses.side_by_side import DEFAULT_WORKERS
from .read_surface import read_surface
from .report import library_versions


def data_path(out, family):
    """Where transferred or resampled data goes: GIfTI for neuro inputs, ``.npz`` otherwise."""
    return Path(f"{out}.func.gii" if family in ("gifti", "freesurfer") else f"{out}_data.npz")


def write_data(path, X, names, *, labels=None, label_table=None):
    """Write data columns, then integer labels, with :func:`igl_spheremap.io.write_vertex_data`.

    Parameters
    ----------
    path : str or os.PathLike
        ``.func.gii`` / ``.shape.gii`` / ``.label.gii`` (``.gii.gz``) or ``.npz``.
    X : (n,) or (n, d) float array or None
        Values, one array per column.
    names : list of str
        A name per column of ``X`` (else ``column0``, ``column1``...).
    labels : (n,) int array, optional
        Written as ``labels``, as integers (GIfTI: int32 ``NIFTI_INTENT_LABEL``).
    label_table : dict, optional
        The labels' table (:func:`igl_spheremap.io.read_vertex_labels`).

    Raises
    ------
    ValueError
        As :func:`igl_spheremap.io.write_vertex_data` (labels beyond int32 in GIfTI, values
        in a ``.label.gii``).
    """
    columns = {}
    if X is not None:
        X = X[:, None] if X.ndim == 1 else X
        names = names if len(names) == X.shape[1] else [f"column{j}" for j in range(X.shape[1])]
        columns = {n: X[:, j] for j, n in enumerate(names)}
    if labels is not None:
        columns["labels"] = np.asarray(labels, dtype=np.int64)
    write_vertex_data(path, columns, label_table=label_table)


def register_files(mesh1, mesh2, landmarks1, landmarks2, out, *, data=None, mode="hard",
                   weight=None, descriptor_weight=None, coarse_levels=None, robust_scale="auto",
                   workers=DEFAULT_WORKERS, options=None, on_stage=None):
    """Register ``mesh1`` onto ``mesh2`` (:func:`igl_spheremap.surface_map`) and write the results.

    Writes, after checking every output path first: ``OUT.npz`` (surface 1's
    correspondence: ``face`` (n1,) rows of surface 2's faces, ``bary`` (n1, 3),
    ``faces2`` the faces those rows index, ``landmarks1``, ``landmarks2``,
    ``landmark_errors_deg``), with ``data`` surface 2's values carried to
    surface 1 (``OUT.func.gii`` when surface 1 is GIfTI or FreeSurfer, else
    ``OUT_data.npz``), and last the JSON report ``OUT.json`` (landmark errors,
    folds of both maps, the distortion of the map between the surfaces, seconds).

    Parameters
    ----------
    mesh1, mesh2 : str or os.PathLike
        Mesh files (:func:`igl_spheremap.io.read_mesh`).
    landmarks1, landmarks2 : str or os.PathLike or None
        Landmark files (:func:`igl_spheremap.io.read_landmarks`: vertex indices or
        ``x y z`` rows snapped to the nearest vertex, refused when far from it; the
        report gives the snapping distances), pairs in the same order; both
        ``None`` for none.
    out : str or os.PathLike
        Base path of the outputs.
    data : str or os.PathLike, optional
        Per-vertex data of surface 2 (:func:`igl_spheremap.io.read_vertex_data`).
    mode, weight, descriptor_weight, coarse_levels, robust_scale, workers, options, on_stage
        As in :func:`igl_spheremap.surface_map`.

    Returns
    -------
    dict
        The report.  Its distortion of the map between the surfaces
        (``SurfaceMapResult.distortion``, per face of surface 1, 1: isometric) is given as
        ``distortion_median``, ``distortion_p90`` (90th percentile) and ``distortion_max``;
        ``distortion_mean`` too, which a few faces crushed onto a sliver of surface 2 can
        make many times the median (``docs/decisions.md``), so the printed summary gives the
        median.

    Raises
    ------
    FileNotFoundError, ValueError, OSError, MeshError
        Unreadable inputs, bad landmarks or data, unwritable outputs.
    """
    t0 = time.perf_counter()
    family1 = mesh_format(mesh1)
    files = {"correspondence": Path(f"{out}.npz"), "report": Path(f"{out}.json"),
             "data": data_path(out, family1) if data else None}
    if (landmarks1 is None) != (landmarks2 is None):
        raise ValueError("landmark files come in pairs: give both or neither")
    check_outputs([mesh1, mesh2] + ([data] if data else []), files)
    V1, F1, _ = read_surface(mesh1, "surface 1")
    V2, F2, _ = read_surface(mesh2, "surface 2")
    none = (np.zeros(0, np.int64), np.zeros(0))
    (l1, d1), (l2, d2) = ((read_landmarks(landmarks1, V1, F1, return_distances=True),
                           read_landmarks(landmarks2, V2, F2, return_distances=True))
                          if landmarks1 is not None else (none, none))
    X2, names = read_vertex_data(data, len(V2)) if data else (None, None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SphericalMapWarning)
        res = surface_map(V1, F1, V2, F2, l1, l2, mode=mode, weight=weight,
                          descriptor_weight=descriptor_weight, coarse_levels=coarse_levels,
                          robust_scale=robust_scale, workers=workers,
                          options=map_options(options), on_stage=on_stage)
    Path(files["correspondence"]).parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(files["correspondence"]) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, face=res.face, bary=res.bary, faces2=res.map2.F, landmarks1=l1,
                            landmarks2=l2, landmark_errors_deg=res.landmark_errors)
    if data:
        write_data(files["data"], res.transfer(X2), names)
    report = _register_report(mesh1, mesh2, res, files, time.perf_counter() - t0)
    report["landmark_snap_distances"] = {"surface1": d1, "surface2": d2}
    write_report(files["report"], report)
    return report


def _register_report(mesh1, mesh2, res, files, seconds):
    def summary(r):
        return {"folds": int(r.folds), "converged": bool(r.converged),
                "success": bool(r.success), "message": r.message}

    return {"complete": True, "surface1": str(Path(mesh1).absolute()),
            "surface2": str(Path(mesh2).absolute()), "success": res.success,
            "message": res.message, "landmark_errors_deg": res.landmark_errors,
            "landmark_error_max_deg": float(np.max(res.landmark_errors, initial=0.0)),
            "landmark_distances": res.landmark_distances,
            "distortion_median": float(np.median(res.distortion)),
            "distortion_p90": float(np.percentile(res.distortion, 90)),
            "distortion_max": float(np.max(res.distortion)),
            "distortion_mean": float(np.mean(res.distortion)),
            "map1": summary(res.map1), "map2": summary(res.map2),
            "timings": {**res.timings, "total": seconds},
            "outputs": {k: str(Path(v).absolute()) for k, v in files.items() if v},
            "versions": library_versions()}

