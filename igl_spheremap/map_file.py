"""Map one mesh file onto the sphere and write the sphere, per-vertex data and a JSON report."""

import platform
import time
import warnings
from datetime import datetime, timezone
from importlib import metadata as _metadata
from pathlib import Path

import numpy as np

from .algorithm2 import spherical_conformal_map
from .errors import SphericalMapWarning
from .io import (STORED_PRECISION, check_output_paths, output_paths, read_mesh, stored_folds,
                 write_mesh, write_report, write_vertex_data)
from .metrics import angle_distortion
from .operators import SPHERE_AREA
from .options import map_options
from .vertex_data import vertex_data

#: Radius of the spheres written in the neuroimaging formats (GIfTI, FreeSurfer):
#: FreeSurfer's ``?h.sphere`` and the HCP's ``*.sphere.*.surf.gii`` have radius
#: 100 (mm).  Spheres in the mesh formats (OBJ, OFF, PLY) are unit spheres.
NEURO_RADIUS = 100.0


def default_radius(family):
    """Radius of a written sphere: :data:`NEURO_RADIUS` for GIfTI and FreeSurfer, else 1."""
    return NEURO_RADIUS if family in ("gifti", "freesurfer") else 1.0


def storage_options(options, sphere, family, file_precision=None):
    """The options of a map written to ``sphere``: ``precision`` follows the file unless given.

    When ``precision`` is not given explicitly and the sphere is stored as float32
    (GIfTI by default, FreeSurfer; :data:`igl_spheremap.io.STORED_PRECISION`, or
    ``file_precision``), the map is made with ``precision="float32"`` so that the
    file is fold-free too; else ``"float64"``.  A method without the fold barrier
    (``keep_fold_free=False``, e.g. ``method="paper"``) keeps ``"float64"``: the
    margin needs the barrier.

    Parameters
    ----------
    options : MapOptions or dict or None
    sphere : str or os.PathLike
        Path of the sphere file (its extension names the mesh format).
    family : {"mesh", "gifti", "freesurfer"}
    file_precision : {None, "float32", "float64"}, optional
        As in :func:`map_file`.

    Returns
    -------
    MapOptions
    """
    opts = map_options(options)
    if "precision" in opts.explicit or not opts.keep_fold_free:
        return opts
    key = Path(sphere).suffix.lower() if family == "mesh" else family
    stored = file_precision or STORED_PRECISION.get(key)
    return opts.updated(precision="float32" if stored == "float32" else "float64")


_HEMISPHERES = {"lh": "CortexLeft", "rh": "CortexRight"}


def library_versions():
    """Versions of Python and of the libraries a run depends on (dict of str -> str)."""
    out = {"python": platform.python_version(), "platform": platform.platform()}
    for dist in ("igl-spheremap", "libigl", "numpy", "scipy", "pyamg", "scikit-sparse",
                 "sksparse-minimal", "nibabel", "dask", "distributed"):
        try:
            out[dist] = _metadata.version(dist)
        except _metadata.PackageNotFoundError:
            pass
    return out


def round_row(V, F, rnd):
    """Summary of one :class:`igl_spheremap.Round` for tables and reports.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
        The mesh that was mapped (``rnd.U`` is indexed like ``V``; angles do not
        depend on the orientation of ``F``).
    rnd : igl_spheremap.Round

    Returns
    -------
    dict
        ``round, kind``, ``folds_previous`` (folds of the map the round started
        from: the previous round's result; None for round 0), ``folds_before``
        (folds of its initial map), ``folds_after``, ``nit``, ``folds_star`` (folds
        of the star map before untangling), ``frozen`` (vertices frozen by the fold
        barrier), ``converged``, ``energy_over_4pi`` (harmonic energy / 4 pi, 1 for
        a conformal map), ``angle_distortion_mean_deg`` (mean over corners,
        degrees), ``seconds, message``.
    """
    return {"round": rnd.index, "kind": rnd.kind,
            "folds_previous": None if rnd.folds_previous is None else int(rnd.folds_previous),
            "folds_before": int(rnd.folds_before),
            "folds_after": int(rnd.folds_after), "nit": int(rnd.nit),
            "folds_star": None if rnd.folds_star is None else int(rnd.folds_star),
            "frozen": int(rnd.frozen),
            "converged": bool(rnd.converged),
            "energy_over_4pi": float(rnd.energy) / SPHERE_AREA,
            "angle_distortion_mean_deg": float(np.mean(angle_distortion(V, F, rnd.U))),
            "seconds": float(rnd.seconds), "message": rnd.message}


def _output_metadata(input_path, in_family, in_meta, out_family):
    hemi = _HEMISPHERES.get(Path(input_path).name[:2].lower()) \
        if Path(input_path).name[2:3] == "." else None
    meta = {"create_stamp": f"created by igl-spheremap from {Path(input_path).name}"}
    if out_family == "gifti":
        gmeta = dict(in_meta.get("gifti_meta", {}))
        if hemi and "AnatomicalStructurePrimary" not in gmeta:
            gmeta["AnatomicalStructurePrimary"] = hemi
        gmeta["GeometricType"] = "Spherical"
        meta["gifti_meta"] = gmeta
    if out_family == "freesurfer" and in_family == "freesurfer":
        meta["volume_info"] = in_meta.get("volume_info")
    data_meta = {}
    structure = meta.get("gifti_meta", {}).get("AnatomicalStructurePrimary", hemi)
    if structure:
        data_meta["AnatomicalStructurePrimary"] = structure
    return meta, data_meta


def map_file(input_path, output=None, *, options=None, report=None, data=False, data_path=None,
             outdir=None, radius=None, file_precision=None, on_round=None, progress=False):
    """Read a mesh, map it with :func:`igl_spheremap.spherical_conformal_map`, write the results.

    Every output path is checked before any work
    (:func:`igl_spheremap.io.check_output_paths`: writable, not the input, not
    STL).  Then writes, each atomically: the sphere (same format family as the
    input unless ``output`` names another) with the faces the map was computed
    on (``result.F``: orientation repairs included), the per-vertex data when
    ``data`` (see :func:`igl_spheremap.vertex_data.vertex_data`; ``.npz`` for
    libigl formats, ``.func.gii`` for GIfTI/FreeSurfer), and last the JSON
    report when ``report`` is given, with ``"complete": true``: a report on disk
    means every output it lists was written.  The sphere is read back and its
    folds counted as stored (``folds_stored``: float32 formats round the
    crowded images of thin features); ``success`` needs both counts at 0.

    Parameters
    ----------
    input_path : str or os.PathLike
        Any file :func:`igl_spheremap.io.read_mesh` reads.
    output : str or os.PathLike, optional
        The sphere's path; default from :func:`igl_spheremap.io.output_paths`
        (``<stem>_sphere.<ext>`` in ``outdir``).
    options : MapOptions or dict, optional
        Options of the map (:class:`igl_spheremap.MapOptions`).  Without an
        explicit ``precision``, it follows the sphere file (:func:`storage_options`:
        ``"float32"`` for GIfTI and FreeSurfer).
    report : str or os.PathLike or True, optional
        JSON report path; True for the default name next to the sphere.
    data : bool, default False
        Write per-vertex data.
    data_path : str or os.PathLike, optional
        Where to write it (default next to the sphere).
    outdir : str or os.PathLike, optional
        Directory for default names (default: the current directory).  Missing
        folders of the outputs are created (not at the file system root).
    radius : float, optional
        Radius of the written sphere; default :func:`default_radius`: 100 for
        GIfTI and FreeSurfer (like FreeSurfer's and the HCP's spheres), 1 for
        the mesh formats.
    file_precision : {None, "float32", "float64"}, optional
        Numbers in the sphere file (:func:`igl_spheremap.io.write_mesh`): None is
        the format's own (float64 for OBJ/OFF/PLY, float32 for GIfTI and
        FreeSurfer); ``"float64"`` for GIfTI writes exact but non-standard files.
    on_round : callable, optional
        Called with :func:`round_row` of each round as it finishes.
    progress : bool, default False
        tqdm progress bar of Algorithm 1 iterations on stderr.

    Returns
    -------
    dict
        The report (also written when ``report`` is given): ``folds``,
        ``folds_stored``, ``converged``, ``success``, ``message``, ``nit``,
        ``energy_over_4pi``, ``centroid_norm``, ``min_image_area``,
        ``angle_distortion_mean_deg``, ``angle_distortion_sd_deg``,
        ``folded_vertices``, ``rounds`` (list of :func:`round_row`), ``timings``
        (seconds), ``input``, ``vertices``, ``faces``, ``outputs``, ``options``,
        ``versions``, ``complete``.

    Raises
    ------
    FileNotFoundError, ValueError, OSError
        Unreadable input, an output that cannot or must not be written
        (checked before the map runs), or invalid options.
    igl_spheremap.MeshError
        The mesh is not a closed genus-0 triangle mesh (from
        :func:`igl_spheremap.validate_mesh`), raised before any output is written.
    """
    t0 = time.perf_counter()
    input_path = Path(input_path)
    paths = output_paths(input_path, output, outdir=outdir)
    opts = storage_options(options, paths.sphere, paths.family, file_precision)
    report_path = paths.report if report is True else (Path(report) if report else None)
    data_file = Path(data_path) if data_path else paths.data
    check_output_paths(input_path, paths, report_path=report_path,
                       data_path=data_file if data else None)
    V, F, in_family, in_meta = read_mesh(input_path, return_metadata=True)
    timings = {"read": time.perf_counter() - t0}
    if radius is None:
        radius = default_radius(paths.family)
    rounds = []

    def callback(rnd):
        rounds.append(round_row(V, F, rnd))
        if on_round is not None:
            on_round(rounds[-1])

    t = time.perf_counter()
    with warnings.catch_warnings():
        # The caller reports folds and non-convergence from the result itself.
        warnings.simplefilter("ignore", SphericalMapWarning)
        result = spherical_conformal_map(V, F, opts, callback=callback, progress=progress)
    timings["map"] = time.perf_counter() - t
    timings.update({f"map_{k}": v for k, v in result.timings.items()})
    t = time.perf_counter()
    meta, data_meta = _output_metadata(input_path, in_family, in_meta, paths.family)
    for p in (paths.sphere, data_file if data else None, report_path):
        if p is not None:
            Path(p).parent.mkdir(parents=True, exist_ok=True)
    write_mesh(paths.sphere, radius * result.U, result.F, family=paths.family, metadata=meta,
               precision=file_precision)
    folds_stored = stored_folds(paths.sphere, result.F)
    vdata = vertex_data(V, result.F, result.U)
    if data:
        write_vertex_data(data_file, vdata, metadata=data_meta)
    timings["write"] = time.perf_counter() - t
    timings["total"] = time.perf_counter() - t0
    out = _report(input_path, in_family, V, F, result, vdata, rounds, timings)
    _stored_verdict(out, folds_stored, paths, radius)
    out["outputs"] = {"sphere": str(paths.sphere.absolute()),
                      "data": str(data_file.absolute()) if data else None,
                      "report": str(report_path.absolute()) if report_path else None}
    out["options"] = {**opts.to_dict(), "radius": float(radius), "data": bool(data),
                      "output_family": paths.family, "file_precision": file_precision}
    if report_path is not None:
        write_report(report_path, out)
    return out


def _stored_verdict(out, folds_stored, paths, radius):
    """Put the folds of the stored sphere into the report; a file with folds is no success."""
    out["folds_stored"] = int(folds_stored)
    if not folds_stored or out["folds"]:
        return
    out["success"] = False
    out["message"] = (
        f"the map is fold-free, but the sphere as stored in '{paths.sphere.name}' has "
        f"{folds_stored} folded faces: the format rounds the coordinates (float32 at radius "
        f"{radius:g}) and the smallest image triangles (area {out['min_image_area']:.2g}) "
        "flip; map with precision='float32' (--precision float32), or write .obj, .off or "
        ".ply, which store every digit")


def _report(input_path, in_family, V, F, result, vdata, rounds, timings):
    """The report's entries that describe the input and the map."""
    ad = angle_distortion(V, result.F, result.U)
    return {
        "complete": True,
        "input": str(input_path.absolute()),
        "input_family": in_family,
        "vertices": int(V.shape[0]),
        "faces": int(F.shape[0]),
        "folds": int(result.folds),
        "converged": bool(result.converged),
        "success": bool(result.success),
        "message": result.message,
        "nit": int(result.nit),
        "energy_over_4pi": float(result.energy_over_4pi),
        "centroid_norm": float(result.centroid_norm),
        "min_image_area": float(result.min_image_area),
        "angle_distortion_mean_deg": float(ad.mean()),
        "angle_distortion_sd_deg": float(ad.std()),
        "folded_vertices": int(np.count_nonzero(vdata["folded"])),
        "orientation_flipped": bool(result.orientation_flipped),
        "validation_notes": list(result.mesh.notes),
        "rounds": rounds,
        "timings": timings,
        "versions": library_versions(),
        "finished": datetime.now(timezone.utc).isoformat(timespec="seconds"),
    }
