"""Map one mesh file onto the sphere and write the sphere, per-vertex data and a JSON report."""

import time
import warnings
from pathlib import Path

from ..conformal_map import spherical_conformal_map
from ..errors import SphericalMapWarning, plural
from ..io import (check_output_paths, file_digest, mesh_format, output_paths, read_mesh,
                  stored_folds, write_mesh, write_report, write_vertex_data)
from .report import map_report, round_row
from .storage import check_storage, default_radius, output_metadata, storage_options
from .vertex_data import vertex_data


def map_file(input_path, output=None, *, options=None, report=None, data=False, data_path=None,
             outdir=None, radius=None, file_precision=None, hemisphere=None, on_round=None,
             progress=False, kind="conformal"):
    """Read a mesh, map it with :func:`igl_spheremap.spherical_conformal_map`, write the results.

    Every output path is checked before any work
    (:func:`igl_spheremap.io.check_output_paths`: writable, not the input, not
    STL).  Then writes, each atomically: the sphere (same format family as the
    input unless ``output`` names another) with the faces the map was computed
    on (``result.F``: orientation repairs included), the per-vertex data when
    ``data`` (see :func:`igl_spheremap.app.vertex_data.vertex_data`; ``.npz`` for
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
    hemisphere : {None, "left", "right"}, optional
        The hemisphere the GIfTI outputs name (``AnatomicalStructurePrimary``);
        default: the input's, else its file name's
        (:func:`igl_spheremap.app.storage.output_metadata`).
    on_round : callable, optional
        Called with :func:`round_row` of each round as it finishes.
    progress : bool, default False
        tqdm progress bar of Algorithm 1 iterations on stderr.
    kind : {"conformal", "area_balanced"}
        The sphere (:func:`igl_spheremap.spherical_conformal_map`): conformal
        (default), or area-balanced for registration and resampling.

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
    mesh_format(input_path)  # a missing input or a folder is named as such, before its outputs
    paths = output_paths(input_path, output, outdir=outdir)
    opts = storage_options(options, paths.sphere, paths.family, file_precision)
    report_path = paths.report if report is True else (Path(report) if report else None)
    data_file = Path(data_path) if data_path else paths.data
    check_output_paths(input_path, paths, report_path=report_path,
                       data_path=data_file if data else None)
    radius = default_radius(paths.family) if radius is None else radius
    check_storage(paths.sphere, paths.family, radius, file_precision)
    input_digest = file_digest(input_path)
    V, F, in_family, in_meta = read_mesh(input_path, return_metadata=True)
    timings = {"read": time.perf_counter() - t0}
    result, rounds = _mapped(V, F, opts, on_round, progress, timings, kind)
    t = time.perf_counter()
    meta, data_meta = output_metadata(input_path, in_family, in_meta, paths.family, hemisphere)
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
    out = map_report(input_path, in_family, V, F, result, vdata, rounds, timings)
    out["input_polygons"] = int(in_meta.get("polygons") or 0)
    if out["input_polygons"]:
        k = out["input_polygons"]
        out["validation_notes"].insert(0, f"{plural(k, 'face')} of the file with more than three "
                                          f"corners {'was' if k == 1 else 'were'} split into "
                                          "triangle fans")
    _stored_verdict(out, folds_stored, paths, radius)
    out["outputs"] = {"sphere": str(paths.sphere.absolute()),
                      "data": str(data_file.absolute()) if data else None,
                      "report": str(report_path.absolute()) if report_path else None}
    out["digests"] = {"input": input_digest, "sphere": file_digest(paths.sphere),
                      "data": file_digest(data_file) if data else None}
    out["options"] = {**opts.to_dict(), "kind": kind, "radius": float(radius), "data": bool(data),
                      "output_family": paths.family, "file_precision": file_precision}
    if report_path is not None:
        write_report(report_path, out)
    return out


def _mapped(V, F, opts, on_round, progress, timings, kind="conformal"):
    """The map of ``(V, F)`` and its rows per round (:func:`round_row`); adds to ``timings``."""
    rounds = []

    def callback(rnd):
        rounds.append(round_row(V, F, rnd))
        if on_round is not None:
            on_round(rounds[-1])

    t = time.perf_counter()
    with warnings.catch_warnings():
        # The caller reports folds and non-convergence from the result itself.
        warnings.simplefilter("ignore", SphericalMapWarning)
        result = spherical_conformal_map(V, F, opts, kind=kind, callback=callback,
                                         progress=progress)
    timings["map"] = time.perf_counter() - t
    timings.update({f"map_{k}": v for k, v in result.timings.items()})
    return result, rounds


def _stored_verdict(out, folds_stored, paths, radius):
    """Put the folds of the stored sphere into the report; a file with folds is no success."""
    out["folds_stored"] = int(folds_stored)
    if not folds_stored or out["folds"]:
        return
    out["success"] = False
    out["message"] = (
        f"the map is fold-free, but the sphere as stored in '{paths.sphere.name}' has "
        f"{plural(folds_stored, 'folded face')}: the format rounds the coordinates (float32 at "
        f"radius {radius:g}) and the smallest image triangles (area "
        f"{out['min_image_area']:.2g}) flip; map with precision='float32' (--precision "
        "float32), or write .obj, .off or .ply, which store every digit")


