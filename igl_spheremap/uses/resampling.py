"""Resampling: a surface with its data on a template sphere's connectivity (an icosphere,
:func:`igl_spheremap.mesh.shapes.icosphere`, or any closed template)."""

from typing import NamedTuple, Optional

import numpy as np

from ..errors import MeshError
from ..mesh.validate import validate_mesh
from ..sphere.folds import count_folds
from ..sphere.locate import locate_on_sphere
from ..sphere.transfer import barycentric_matrix


class Resampled(NamedTuple):
    """Result of :func:`resample`; unpacks as ``V, F, data, face, bary``."""

    V: np.ndarray
    """(k, 3) float64: the input surface at the template vertices."""
    F: np.ndarray
    """(t, 3) int64: the template's faces (a copy)."""
    data: Optional[np.ndarray]
    """(k,) or (k, d) float64: the per-vertex data at the template vertices, or None."""
    face: np.ndarray
    """(k,) int64: face of the input mesh holding each template vertex (on the sphere)."""
    bary: np.ndarray
    """(k, 3) float64: its barycentric coordinates in that face."""


def resample(V, F, U, V_template, F_template, data=None):
    """Re-triangulate a surface (and its per-vertex data) with a template's connectivity.

    Each template vertex, a direction on the unit sphere (e.g. a vertex of
    :func:`igl_spheremap.mesh.shapes.icosphere`), is located on the spherical map
    ``(U, F)`` of the input by
    :func:`igl_spheremap.sphere.locate.locate_on_sphere`, and the input's
    positions ``V`` and ``data`` are interpolated there with the same
    barycentric coordinates (:func:`igl_spheremap.sphere.transfer.barycentric_matrix`).
    The result is the input surface with the template's vertex count and faces:
    the icosahedral resampling of cortical surfaces (FreeSurfer ``fsaverage``,
    ``mri_surf2surf``) and spherical remeshing in graphics.

    Parameters
    ----------
    V : (n, 3) float array
        Input surface positions (any units; the output has the same units).
    F : (m, 3) int array
        Input faces, outward oriented.
    U : (n, 3) float64 array
        Fold-free spherical map of ``(V, F)`` (unit vectors).
    V_template : (k, 3) float array
        Template vertices on the sphere (non-zero directions; normalized).
    F_template : (t, 3) int array
        Template faces, indices into ``V_template``.
    data : (n,) or (n, d) float array, optional
        Per-vertex data of the input.  Interpolated linearly, so suited to
        continuous quantities (thickness, curvature, coordinates); for labels
        take the largest coordinate's vertex from ``face``/``bary`` instead.

    Returns
    -------
    Resampled
        Named tuple ``(V, F, data, face, bary)``: ``V`` (k, 3) float64 the
        resampled surface, ``F`` (t, 3) int64 the template faces, ``data``
        (k,) or (k, d) float64 or None, and ``face`` (k,) int64 / ``bary``
        (k, 3) float64 from the location step (reuse them with
        ``barycentric_matrix`` for more data).

    Raises
    ------
    ValueError
        If ``U``, ``V``, ``data`` or ``F_template`` have the wrong shape, ``V`` or
        ``data`` hold non-finite values, ``F_template`` indexes outside the
        template, the template is not a sphere (not a closed genus-0 mesh, or
        its faces do not tile the sphere under central projection: every face
        positively oriented), or any error of ``locate_on_sphere`` (folded or
        off-sphere ``U``, zero template directions).
    """
    V, U, data = _checked_surface(V, F, U, data)
    F_template = _checked_template(V_template, F_template)
    face, bary = locate_on_sphere(U, F, V_template)
    M = barycentric_matrix(face, bary, F, U.shape[0])
    return Resampled(V=M @ V, F=F_template,
                     data=None if data is None else M @ data, face=face, bary=bary)


def _checked_surface(V, F, U, data):
    """``V``, ``U`` and ``data`` as float64 arrays with one row per vertex of ``F``; ValueError
    naming the array at fault otherwise."""
    n = int(np.max(F)) + 1 if np.size(F) else 0
    V = np.asarray(V, dtype=np.float64)
    if V.ndim != 2 or V.shape[1] != 3 or V.shape[0] < n:
        raise ValueError(f"V must be an (n, 3) array with a row for every vertex of F (n >= {n}), "
                         f"got shape {V.shape}")
    U = np.asarray(U, dtype=np.float64)
    if U.ndim != 2 or U.shape[1] != 3 or U.shape[0] != V.shape[0]:
        raise ValueError(f"U must be the spherical map, an ({V.shape[0]}, 3) array with one row per "
                         f"row of V, got shape {U.shape}")
    bad = np.count_nonzero(~np.isfinite(V).all(axis=1))
    if bad:
        raise ValueError(f"V has {bad} rows with non-finite coordinates")
    n = V.shape[0]
    if data is not None:
        data = np.asarray(data, dtype=np.float64)
        if data.ndim not in (1, 2) or data.shape[0] != n:
            raise ValueError(f"data must be an (n,) or (n, d) array with n = {n}, got shape {data.shape}")
        bad = np.count_nonzero(~np.isfinite(data.reshape(n, -1)).all(axis=1))
        if bad:
            raise ValueError(f"data has {bad} rows with non-finite values")
    return V, U, data


def _checked_template(V_template, F_template):
    """The template's faces (int64) after checking that ``(V_template, F_template)`` is a sphere.

    A template sphere is a closed genus-0 mesh whose faces tile the sphere under
    central projection: every face positively oriented as seen from the origin.
    """
    F_template = np.asarray(F_template)
    k = np.shape(V_template)[0] if np.ndim(V_template) == 2 else -1
    if (F_template.ndim != 2 or F_template.shape[1] != 3
            or not np.issubdtype(F_template.dtype, np.integer)):
        raise ValueError(f"F_template must be a (t, 3) integer array, got shape {F_template.shape}, "
                         f"dtype {F_template.dtype}")
    bad = np.count_nonzero((F_template < 0) | (F_template >= k))
    if bad:
        raise ValueError(f"F_template has {bad} vertex indices outside the {max(k, 0)} template vertices")
    try:
        validate_mesh(V_template, F_template)
    except MeshError as err:
        raise ValueError(f"the template is not a sphere: {err}") from None
    T = np.asarray(V_template, dtype=np.float64)
    T = T / np.linalg.norm(T, axis=1, keepdims=True)
    folds = count_folds(F_template, T)
    if folds:
        raise ValueError(f"the template is not a sphere: {folds} of {F_template.shape[0]} faces fold "
                         "under central projection (a template sphere's faces must tile the sphere "
                         "seen from the origin, outward oriented, as an icosphere or ?h.sphere do)")
    return np.array(F_template, dtype=np.int64)
