"""Resampling between spheres: a surface with its data on a template sphere's connectivity, and
per-vertex data and labels carried through a registration, both ways (what ``mri_surf2surf`` and
Connectome Workbench's ``-metric-resample`` / ``-label-resample`` do).

Two spheres in the same frame (a subject's registered sphere, ``?h.sphere.reg``,
and a template's sphere; or a surface's own map and an icosphere,
:func:`igl_spheremap.mesh.shapes.icosphere`; or any closed template sphere,
fsaverage's, fs_LR 32k's) define a correspondence: each vertex of one lies in a
face of the other.  :func:`resampling_matrix` turns it into a sparse matrix
``W`` (rows: the new mesh's vertices, columns: the current mesh's), so that
``W @ data`` carries per-vertex data:

* ``"barycentric"``: each new vertex interpolates the face of the current
  sphere that holds it (:func:`igl_spheremap.sphere.locate.locate_on_sphere`),
  Workbench's ``BARYCENTRIC``;
* ``"adap_bary_area"``: area-corrected adaptive barycentric resampling,
  Workbench's ``ADAP_BARY_AREA`` (recommended there for metric and label data).
  Besides the forward weights, every current vertex is located on the new
  sphere and its barycentric weights are gathered by the new vertices
  ("reverse" weights); a new vertex uses its reverse weights when they involve
  a current vertex that its forward weights use too (the current mesh is at
  least as dense there), its forward weights otherwise.  Area correction: each
  new vertex's weights are multiplied by its area, each current vertex's
  weights (a column) rescaled to total that vertex's area, each row normalized
  to sum 1.  Downsampling then averages every current vertex in proportion to
  its area instead of sampling three, and an area integral is conserved.  The
  areas are those of the anatomical surfaces (e.g. midthickness), not of the
  spheres.

A ``mask`` (ROI) of the current mesh, e.g. its cortex without the medial wall,
gives its vertices outside weight 0; rows are renormalized and new vertices
left without weight get ``fill`` (NaN; labels: -1).  :func:`resample_labels`
carries integer labels by the largest total weight per label (``"majority"``,
Workbench's label resampling) or by the vertex of largest weight
(``"nearest"``).  :func:`registration_matrices` builds both directions of a
registration; :func:`resample` puts a whole surface on a template.
"""

from typing import NamedTuple, Optional

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError, plural
from ..mesh.arrays import as_points, as_weights, off_sphere, unit_rows
from ..mesh.operators import vertex_areas
from ..mesh.validate import validate_mesh
from ..sphere.folds import count_folds
from ..sphere.locate import locate_on_sphere
from ..sphere.transfer import barycentric_matrix

#: Methods of :func:`resampling_matrix`.
METHODS = ("barycentric", "adap_bary_area")

#: Methods of :func:`resample_labels`.
LABEL_METHODS = ("majority", "nearest")


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

    def __repr__(self):
        """Shapes and dtypes, not the arrays (a result prints as a summary)."""
        shown = ", ".join(f"{name}=None" if a is None else f"{name}={a.shape} {a.dtype}"
                          for name, a in zip(self._fields, self))
        return f"Resampled({shown})"


def resample(V, F, U, V_template, F_template, data=None, *, method="barycentric", mask=None,
             fill=np.nan):
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

    The template samples the sphere evenly, so a region the map crowds (a conformal
    map crowds limbs, tails and ears exponentially) gets few template vertices or none
    and is cut off (the dinosaur's legs and tail on ``icosphere(6)``; README gives the
    area kept).  Check the resampled area against the input's (``igl.doublearea``); an
    area-balanced sphere (``spherical_conformal_map(V, F, kind="area_balanced")``)
    spreads such regions.

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
        Per-vertex data of the input, carried by :func:`resampling_matrix` with
        ``method``: continuous quantities (thickness, curvature); for labels
        use :func:`resample_labels` on that matrix.
    method : {"barycentric", "adap_bary_area"}
        How ``data`` is carried (module docstring); ``"adap_bary_area"`` uses the
        vertex areas of ``(V, F)`` and of the resampled surface.  The positions
        ``V`` are always interpolated barycentrically.
    mask : (n,) array, optional
        Input vertices whose data is used (> 0); template vertices left
        without any get ``fill``.
    fill : float
        Data of template vertices with no weight (default NaN).

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
        template, the template is not a sphere (its vertices not at one radius
        about the origin, :data:`igl_spheremap.mesh.arrays.SPHERE_RADIUS_RTOL`; not a
        closed genus-0 mesh, or its faces do not tile the sphere under central
        projection: every face positively oriented), or any error of ``locate_on_sphere`` (folded or
        off-sphere ``U``, zero template directions).
    """
    V, U, data = _checked_surface(V, F, U, data, mask)
    F_template = _checked_template(V_template, F_template)
    face, bary = locate_on_sphere(U, F, V_template)
    M = barycentric_matrix(face, bary, F, U.shape[0])
    Vr = M @ V
    if data is not None and (method != "barycentric" or mask is not None):
        M = resampling_matrix(U, F, V_template, F_template, method=method,
                              current_area=vertex_areas(V, F),
                              new_area=vertex_areas(Vr, F_template), mask=mask)
    return Resampled(V=Vr, F=F_template, data=None if data is None else apply(M, data, fill),
                     face=face, bary=bary)


def _checked_surface(V, F, U, data, mask=None):
    """``V``, ``U`` and ``data`` as float64 arrays with one row per vertex of ``F``; ValueError
    naming the array at fault otherwise (non-finite data only where ``mask`` uses it)."""
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
        raise ValueError(f"V has {plural(bad, 'row')} with non-finite coordinates")
    n = V.shape[0]
    if data is not None:
        data = np.asarray(data, dtype=np.float64)
        if data.ndim not in (1, 2) or data.shape[0] != n:
            raise ValueError(f"data must be an (n,) or (n, d) array with n = {n}, got shape {data.shape}")
        bad = ~np.isfinite(data.reshape(n, -1)).all(axis=1)
        if mask is not None and np.shape(mask) == (n,):  # a wrong mask is named later
            bad &= np.asarray(mask, dtype=np.float64) > 0
        bad = np.count_nonzero(bad)
        if bad:
            raise ValueError(f"data has {plural(bad, 'row')} with non-finite values"
                         + ("" if mask is not None else " (a medial wall's NaN? leave those "
                            "vertices out with mask=, --mask on the command line)"))
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
        raise ValueError(f"F_template has {plural(bad, 'vertex index', 'vertex indices')} outside "
                         f"the {plural(max(k, 0), 'template vertex', 'template vertices')}")
    try:
        validate_mesh(V_template, F_template)
    except MeshError as err:
        raise ValueError(f"the template is not a sphere: {err}") from None
    message = off_sphere(V_template, "the template")
    if message:
        raise ValueError(message)
    T = np.asarray(V_template, dtype=np.float64)
    T = T / np.linalg.norm(T, axis=1, keepdims=True)
    folds = count_folds(F_template, T)
    if folds:
        raise ValueError(f"the template is not a sphere: {folds} of {F_template.shape[0]} faces fold "
                         "under central projection (a template sphere's faces must tile the sphere "
                         "seen from the origin, outward oriented, as an icosphere or ?h.sphere do)")
    return np.array(F_template, dtype=np.int64)


def resampling_matrix(current_U, current_F, new_U, new_F=None, *, method="barycentric",
                      current_area=None, new_area=None, mask=None):
    """Sparse matrix carrying per-vertex data from a current sphere to a new one (module docstring).

    Parameters
    ----------
    current_U : (n, 3) float array
        The current mesh's sphere (any radius; fold-free, faces outward).
    current_F : (m, 3) int array
    new_U : (k, 3) float array
        The new mesh's sphere in the same frame (any radius).
    new_F : (t, 3) int array, optional
        Its faces (needed by ``"adap_bary_area"``).
    method : {"barycentric", "adap_bary_area"}
    current_area, new_area : (n,) and (k,) float arrays, optional
        Vertex areas of the anatomical surfaces (needed by ``"adap_bary_area"``).
    mask : (n,) array, optional
        Current vertices to use (> 0).

    Returns
    -------
    (k, n) scipy.sparse.csr_matrix of float64
        Non-negative; rows sum to 1, except rows left without weight by the
        mask (all 0).

    Raises
    ------
    ValueError
        Unknown ``method``, missing faces or areas, areas that are not one positive
        finite number per vertex, spheres whose vertices are not at one radius
        (:func:`igl_spheremap.mesh.arrays.off_sphere`), or the errors of
        :func:`igl_spheremap.sphere.locate.locate_on_sphere`.
    """
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; expected one of {list(METHODS)}")
    for name, X in (("current_U", current_U), ("new_U", new_U)):
        message = off_sphere(as_points(X, name), name)
        if message:
            raise ValueError(message)
    Uc = unit_rows(current_U)
    face, bary = locate_on_sphere(Uc, current_F, unit_rows(new_U))
    W = barycentric_matrix(face, bary, current_F, Uc.shape[0])
    if method == "adap_bary_area":
        if new_F is None or current_area is None or new_area is None:
            raise ValueError("method='adap_bary_area' needs new_F, current_area and new_area")
        current_area = as_weights(current_area, Uc.shape[0], "current_area", positive=True)
        W = _adaptive(W, new_U, new_F, Uc, current_area,
                      as_weights(new_area, np.shape(new_U)[0], "new_area", positive=True))
    return W if mask is None else _masked(W, mask)


def _adaptive(forward, new_U, new_F, current_U, current_area, new_area):
    """Workbench's ADAP_BARY_AREA from the forward (barycentric) weights (module docstring)."""
    Un = unit_rows(new_U)
    face, bary = locate_on_sphere(Un, new_F, current_U)
    reverse = barycentric_matrix(face, bary, new_F, Un.shape[0]).T.tocsr()  # (k, n): gathered
    shared = forward.multiply(reverse) > 0
    use_reverse = np.asarray(shared.sum(axis=1)).ravel() > 0
    A = (sp.diags(use_reverse.astype(float)) @ reverse
         + sp.diags((~use_reverse).astype(float)) @ forward).tocsr()
    A = sp.diags(np.asarray(new_area, dtype=np.float64)) @ A
    colsum = np.asarray(A.sum(axis=0)).ravel()
    scale = np.zeros(A.shape[1])
    np.divide(np.asarray(current_area, dtype=np.float64), colsum, out=scale, where=colsum > 0)
    return _row_normalized(A @ sp.diags(scale))


def _row_normalized(A):
    A = sp.csr_matrix(A)
    A.eliminate_zeros()
    rowsum = np.asarray(A.sum(axis=1)).ravel()
    inv = np.zeros(A.shape[0])
    np.divide(1.0, rowsum, out=inv, where=rowsum > 0)
    W = (sp.diags(inv) @ A).tocsr()
    W.sort_indices()
    return W


def _masked(W, mask):
    """``W`` without the columns outside ``mask``, rows renormalized (empty rows stay 0)."""
    mask = np.asarray(mask)
    if mask.shape != (W.shape[1],):
        raise ValueError(f"mask must have one entry per current vertex ({W.shape[1]}), got "
                         f"shape {mask.shape}")
    return _row_normalized(W @ sp.diags((mask > 0).astype(float)))


def apply(W, data, fill=np.nan):
    """``W @ data`` with ``fill`` in the rows of ``W`` that have no weight.

    Parameters
    ----------
    W : (k, n) sparse matrix
    data : (n,) or (n, d) float array
    fill : float

    Returns
    -------
    (k,) or (k, d) float64 array
    """
    out = W @ np.asarray(data, dtype=np.float64)
    empty = np.diff(sp.csr_matrix(W).indptr) == 0
    if empty.any():
        out[empty] = fill
    return out


def resample_labels(W, labels, method="majority", fill=-1):
    """Carry integer labels (a parcellation, an annotation's indices) with a resampling matrix.

    Parameters
    ----------
    W : (k, n) sparse matrix
        From :func:`resampling_matrix`.
    labels : (n,) int array
    method : {"majority", "nearest"}
        ``"majority"``: the label of the largest summed weight (Workbench's label
        resampling); ``"nearest"``: the label of the vertex of largest weight.
    fill : int
        Label of rows with no weight.

    Returns
    -------
    (k,) int64 array

    Raises
    ------
    ValueError
        Unknown ``method``, ``labels`` of the wrong length, or labels that are not whole
        numbers.
    """
    if method not in LABEL_METHODS:
        raise ValueError(f"unknown label method {method!r}; expected one of {list(LABEL_METHODS)}")
    labels = np.asarray(labels)
    if labels.shape != (W.shape[1],):
        raise ValueError(f"labels must have one entry per current vertex ({W.shape[1]}), got "
                         f"shape {labels.shape}")
    if not np.issubdtype(labels.dtype, np.integer):
        whole = np.issubdtype(labels.dtype, np.floating) and np.all(np.isfinite(labels)) \
            and np.all(labels == np.round(labels))
        if not whole:  # 3.7 would become 3, NaN an arbitrary integer
            raise ValueError(f"labels must be integers, got dtype {labels.dtype} with values "
                             "that are not whole numbers (resample real-valued data instead)")
        labels = labels.astype(np.int64)
    W = sp.coo_matrix(W)
    out = np.full(W.shape[0], fill, dtype=np.int64)
    if W.nnz == 0:
        return out
    if method == "nearest":
        order = np.lexsort((-W.data, W.row))
        rows, first = np.unique(W.row[order], return_index=True)
        out[rows] = labels[W.col[order[first]]]
        return out
    codes, lab = np.unique(labels, return_inverse=True)
    M = sp.csr_matrix((W.data, (W.row, lab.ravel()[W.col])), shape=(W.shape[0], codes.size))
    M.sum_duplicates()
    has = np.diff(M.indptr) > 0
    out[has] = codes[np.asarray(M.argmax(axis=1)).ravel()[has]]
    return out


class Registration(NamedTuple):
    """Both directions of a registration: ``to_subject @ target_data``, ``to_target @ subject_data``."""

    to_subject: sp.csr_matrix
    """(n_subject, n_target): target data onto the subject's vertices."""
    to_target: sp.csr_matrix
    """(n_target, n_subject): subject data onto the target's vertices."""


def registration_matrices(registered_U, subject_F, target_U, target_F, *, method="barycentric",
                          subject_area=None, target_area=None, subject_mask=None,
                          target_mask=None):
    """Resampling matrices of a registration in both directions (``mri_surf2surf``).

    Parameters
    ----------
    registered_U : (n, 3) float array
        The subject's registered sphere (its vertices in the target's frame:
        ``?h.sphere.reg``, or :attr:`igl_spheremap.uses.atlas.AtlasRegistrationResult.U`).
    subject_F : (m, 3) int array
    target_U : (k, 3) float array
        The target's sphere.
    target_F : (t, 3) int array
    method : {"barycentric", "adap_bary_area"}
        ``"adap_bary_area"`` needs both areas.
    subject_area, target_area : arrays, optional
        Vertex areas of the anatomical surfaces.
    subject_mask, target_mask : arrays, optional
        Masks of the source side of each direction.

    Returns
    -------
    Registration
    """
    to_subject = resampling_matrix(target_U, target_F, registered_U, subject_F, method=method,
                                   current_area=target_area, new_area=subject_area,
                                   mask=target_mask)
    to_target = resampling_matrix(registered_U, subject_F, target_U, target_F, method=method,
                                  current_area=subject_area, new_area=target_area,
                                  mask=subject_mask)
    return Registration(to_subject=to_subject, to_target=to_target)
