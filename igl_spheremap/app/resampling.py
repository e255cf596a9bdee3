"""Resampling of mesh files onto template spheres, and through a registration both ways:
what ``igl-spheremap resample`` does (``mri_surf2surf``, Workbench's ``-metric-resample``)."""

import time
import warnings
from pathlib import Path

from ..conformal_map import spherical_conformal_map
from ..errors import SphericalMapWarning
from ..io import (check_data_output, check_outputs, check_sphere_output, output_paths, read_mesh,
                  read_vertex_data, read_vertex_labels, read_vertex_mask, write_mesh,
                  write_report)
from ..mesh.arrays import off_sphere, unit_rows
from ..mesh.operators import vertex_areas
from ..mesh.shapes import icosphere
from ..options import map_options
from ..uses.resampling import apply, resample, resample_labels, resampling_matrix
from .report import library_versions
from .surface_files import data_path, write_data


def _template(level, template, order):
    """The template sphere: a file's, or the icosphere of ``level`` in ``order``."""
    if template is not None:
        T, TF, _ = read_mesh(template)
        return T, TF
    return icosphere(level, order=order)


def _sphere_of(V, F, sphere, options):
    """The mesh's sphere in the template's frame: a file (``?h.sphere.reg``) or its conformal map."""
    if sphere is not None:
        S, SF, _ = read_mesh(sphere)
        if S.shape != V.shape or SF.shape != F.shape:
            raise ValueError(f"the sphere '{sphere}' has {len(S)} vertices and {len(SF)} faces, "
                             f"the mesh {len(V)} and {len(F)}: not its sphere")
        message = off_sphere(S, f"the sphere '{sphere}'")
        if message:  # a surface passed for its sphere: named, not counted as folds
            raise ValueError(message)
        return unit_rows(S), SF, {"source": str(Path(sphere).absolute())}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SphericalMapWarning)
        result = spherical_conformal_map(V, F, map_options(options))
    return result.U, result.F, {"source": "conformal", "success": bool(result.success),
                                "message": result.message, "folds": int(result.folds)}


def _frame_notes(template, order, sphere):
    """What the report says when an atlas's vertex order is asked for without a registration."""
    if sphere is not None or (template is None and order != "freesurfer"):
        return []
    frame = "the template sphere" if template is not None else "fsaverage's vertex order"
    return [f"the mesh's own conformal map was resampled onto {frame}: it is not registered to "
            "the atlas, so vertex i of the output is not the atlas's vertex i on the anatomy "
            "(register first, register-sphere, and pass --sphere ?h.sphere.reg)"]


def resample_file(mesh, level, out, *, data=None, labels=None, mask=None, method="barycentric",
                  label_method="majority", template=None, sphere=None, order="igl",
                  options=None):
    """Resample ``mesh`` (and its data, labels) onto a template sphere; write the results.

    The template is the icosphere of ``level`` (:func:`igl_spheremap.icosphere`,
    vertex ``order`` ``"igl"`` or ``"freesurfer"``: fsaverage's), or the sphere
    file ``template`` (fsaverage's ``lh.sphere``, an fs_LR sphere).  The mesh's
    sphere is ``sphere`` (its registered sphere, ``?h.sphere.reg``, in the
    template's frame) or its conformal map.  Writes ``OUT`` (the mesh with the
    template's connectivity), with ``data`` / ``labels`` the values resampled
    (:func:`igl_spheremap.uses.resampling.resampling_matrix` with ``method``;
    labels by :func:`igl_spheremap.uses.resampling.resample_labels` with
    ``label_method``; ``mask`` the mesh's vertices to use) next to it
    (``<OUT base>.func.gii`` for GIfTI/FreeSurfer, ``<OUT base>_data.npz``
    otherwise), and ``<OUT base>.json``.  Data, labels and masks are read by
    :func:`igl_spheremap.io.read_vertex_data`, :func:`~igl_spheremap.io.read_vertex_labels`
    and :func:`~igl_spheremap.io.read_vertex_mask`; the labels are written as
    integers, with the input's label table
    (:func:`igl_spheremap.app.surface_files.write_data`).

    Returns
    -------
    dict
        The report; its ``notes`` say when an atlas's frame (a template file, or
        ``order="freesurfer"``) was used without ``sphere``: the output is then in the
        atlas's vertex order but not in its correspondence.
    """
    t0 = time.perf_counter()
    paths = output_paths(mesh, out)
    base = paths.report.with_suffix("")
    extra = [p for p in (data, labels, mask, template, sphere) if p]
    files = {"surface": paths.sphere, "report": paths.report,
             "data": data_path(base, paths.family) if (data or labels) else None}
    check_sphere_output(paths.sphere, paths.family, role="resampled surface")
    check_outputs([mesh] + extra, files)
    V, F, _ = read_mesh(mesh)
    X, names = read_vertex_data(data, len(V)) if data else (None, [])
    L, table = read_vertex_labels(labels, len(V)) if labels else (None, None)
    M = read_vertex_mask(mask, len(V)) if mask else None
    T, TF = _template(level, template, order)
    U, F, sphere_info = _sphere_of(V, F, sphere, options)
    res = resample(V, F, U, T, TF, data=X, method=method, mask=M)
    Path(paths.sphere).parent.mkdir(parents=True, exist_ok=True)
    write_mesh(paths.sphere, res.V, res.F, family=paths.family)
    if L is not None:
        W = resampling_matrix(U, F, T, TF, method=method, current_area=vertex_areas(V, F),
                              new_area=vertex_areas(res.V, TF), mask=M)
        L = resample_labels(W, L, label_method)
    if data or labels:
        write_data(files["data"], None if X is None else res.data, names, labels=L,
                   label_table=table)
    report = {"complete": True, "input": str(Path(mesh).absolute()),
              "template": str(Path(template).absolute()) if template else f"icosphere {level}",
              "level": None if template else int(level), "order": None if template else order,
              "method": method, "vertices": int(len(T)), "faces": int(len(TF)),
              "sphere": sphere_info, "map_success": sphere_info.get("success", True),
              "map_message": sphere_info.get("message", "given sphere"),
              "seconds": time.perf_counter() - t0,
              "outputs": {k: str(Path(v).absolute()) for k, v in files.items() if v},
              "notes": _frame_notes(template, order, sphere),
              "versions": library_versions()}
    write_report(files["report"], report)
    return report


def from_template_file(mesh, sphere, template, out, *, data=None, labels=None, mask=None,
                       method="barycentric", label_method="majority", template_surface=None):
    """Carry a template's data and labels to a subject through its registered sphere.

    The reverse direction of :func:`resample_file` (``mri_surf2surf`` from
    fsaverage to a subject): every vertex of ``mesh`` is located on the
    ``template`` sphere at its place on ``sphere`` (``?h.sphere.reg``) and the
    template's values are carried there by
    :func:`igl_spheremap.uses.resampling.resampling_matrix`.
    ``"adap_bary_area"`` uses the vertex areas of ``mesh`` and of
    ``template_surface`` (the template's anatomical surface, e.g. fsaverage's
    white; default the template sphere itself).  ``mask`` is the template's.
    Writes ``out`` (``.func.gii`` / ``.shape.gii`` or ``.npz``: the data columns,
    then ``labels`` as integers with the input's label table; ``.label.gii``: the
    labels only) and ``<out>.json``.

    Returns
    -------
    dict
        The report.
    """
    t0 = time.perf_counter()
    if not (data or labels):
        raise ValueError("nothing to carry: give data and/or labels of the template")
    files = {"data": Path(out), "report": Path(f"{out}.json")}
    inputs = [mesh, sphere, template] + [p for p in (data, labels, mask, template_surface) if p]
    check_data_output(out)
    check_outputs(inputs, files)
    V, F, _ = read_mesh(mesh)
    U, F, _ = _sphere_of(V, F, sphere, None)
    T, TF, _ = read_mesh(template)
    message = off_sphere(T, f"the template '{template}'")
    if message:
        raise ValueError(message)
    TA = vertex_areas(read_mesh(template_surface)[0] if template_surface else T, TF)
    X, names = read_vertex_data(data, len(T)) if data else (None, [])
    L, table = read_vertex_labels(labels, len(T)) if labels else (None, None)
    M = read_vertex_mask(mask, len(T)) if mask else None
    W = resampling_matrix(T, TF, U, F, method=method, current_area=TA,
                          new_area=vertex_areas(V, F), mask=M)
    write_data(files["data"], None if X is None else apply(W, X), names,
               labels=None if L is None else resample_labels(W, L, label_method),
               label_table=table)
    report = {"complete": True, "input": str(Path(mesh).absolute()), "method": method,
              "vertices": int(len(V)), "template_vertices": int(len(T)),
              "seconds": time.perf_counter() - t0,
              "outputs": {k: str(Path(v).absolute()) for k, v in files.items()},
              "versions": library_versions()}
    write_report(files["report"], report)
    return report
