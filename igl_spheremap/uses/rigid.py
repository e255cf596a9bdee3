"""Rigid alignment of a spherical map to a target sphere by the correlation of smoothed features.

A global search over all rotations by the spherical-harmonic correlation of the
heavily smoothed features (:func:`igl_spheremap.sphere.harmonics.best_rotations`,
the search surface maps use too), then a local BFGS refinement of the best
candidates on the correlation with the target interpolated at the rotated points
(its gradient with respect to a rotation vector is the torque
``sum_i w_i dcorr/dg_i (X_i x grad g(X_i))``).  The same search with the subject
mirrored reports whether a reflection would fit better (a right hemisphere
registered to a left atlas, or a sphere of the wrong orientation); a fold-free map
cannot be reflected, so this is a check only.  It is the first stage of
:func:`igl_spheremap.uses.atlas.register_sphere` (FreeSurfer's ``mris_register``
starts the same way, with a search over rotations of up to 64 degrees: Fischl et
al., HBM 8 1999).
"""

import numpy as np
import scipy.optimize
from scipy.spatial import cKDTree

from ..mesh.operators import vertex_areas
from ..mesh.shapes import icosphere
from ..sphere.field import SphereField
from ..sphere.harmonics import MIRROR, best_rotations, rotvec_matrix, standardized_coefficients
from .features import heat_smooth, standardized

#: Degree of the spherical harmonic expansions of the global search (features smoothed
#: to ``fwhm`` = 30 degrees carry little above it).
SH_DEGREE = 12


def _refine(U, s, area, fld, R0):
    """Local maximum of the weighted correlation of ``s`` with ``fld`` at ``U R^T`` from ``R0``."""
    w = area / area.sum()
    s = s - w @ s
    ns = np.sqrt(w @ s ** 2)
    face = [None]

    def negcorr(v):
        R = rotvec_matrix(v) @ R0
        X = U @ R.T
        g, grad, face[0] = fld(X, face[0])
        g, grad = g[:, 0], grad[:, 0]
        gm = w @ g
        gc = g - gm
        ng = np.sqrt(w @ gc ** 2)
        c = (w @ (s * gc)) / (ns * ng)
        # d corr / d g_i = w_i (s_i / (ns ng) - c gc_i / ng^2); d g_i / d v = X_i x grad_i
        dg = w * (s / (ns * ng) - c * gc / ng ** 2)
        torque = (dg[:, None] * np.cross(X, grad)).sum(axis=0)
        return -c, -torque

    res = scipy.optimize.minimize(negcorr, np.zeros(3), jac=True, method="BFGS",
                                  options=dict(gtol=1e-7, maxiter=200))
    return rotvec_matrix(res.x) @ R0, -res.fun


def refinement_points(U, area):
    """Subject vertices nearest to an icosphere of about a quarter of their number (level 3
    to 4, 642 to 2562 directions), each weighted by the subject area closest to its direction.

    Parameters
    ----------
    U : (n, 3) float64 array
        The subject's sphere.
    area : (n,) float64 array

    Returns
    -------
    idx : (k,) int64 array
    weights : (k,) float64 array
    """
    level = min(4, max(3, int(np.ceil(np.log(max(U.shape[0] / 4.0, 12) / 10.0) / np.log(4.0)))))
    ico = icosphere(level)[0]
    cell_area = np.bincount(cKDTree(ico).query(U)[1], weights=area, minlength=ico.shape[0])
    nearest = cKDTree(U).query(ico)[1]
    w = np.zeros(U.shape[0])
    np.add.at(w, nearest, cell_area)
    idx = np.flatnonzero(w)
    return idx, w[idx]


def rigid_align(U, F, features, target_U, target_F, target_features, *, fwhm=30.0,
                degree=SH_DEGREE, candidates=4, mirror_candidates=2, area=None):
    """The rotation of a spherical map that best correlates its features with a target's.

    Both sides' first feature is smoothed (``fwhm`` degrees, :func:`heat_smooth`)
    and standardized.  The ``candidates`` best local maxima over all rotations of
    the correlation of their spherical harmonic expansions up to ``degree``
    (:func:`igl_spheremap.sphere.harmonics.best_rotations`) are refined by BFGS on
    the area-weighted correlation at :func:`refinement_points` with the target
    interpolated (:class:`igl_spheremap.sphere.field.SphereField`), and the best
    refined rotation is returned.  The search is repeated with the subject
    mirrored, for a reflection check only.

    Parameters
    ----------
    U : (n, 3) float array
        The subject's sphere (unit vectors).
    F : (m, 3) int array
    features : (n,) or (n, d) float array
        Subject features (the first column is used).
    target_U, target_F, target_features
        The target sphere, its faces and features (first column used).
    fwhm : float
        Smoothing, degrees.
    degree : int
        Of the expansions of the global search.
    candidates : int
        Maxima of the global search refined.
    mirror_candidates : int
        Maxima refined for the mirrored subject (0: no reflection check).
    area : (n,) float array, optional
        Subject vertex weights of the refinement (default: its sphere's vertex areas).

    Returns
    -------
    R : (3, 3) float64 array
        ``U @ R.T`` is aligned.
    correlation : float
        Its correlation (smoothed features).
    mirrored_correlation : float
        The best correlation with the subject mirrored (NaN without the check).
    """
    U = np.asarray(U, float)
    tU = np.asarray(target_U, float)
    tU = tU / np.linalg.norm(tU, axis=1, keepdims=True)
    fs = np.asarray(features, float)
    ft = np.asarray(target_features, float)
    fs = fs[:, 0] if fs.ndim == 2 else fs
    ft = ft[:, 0] if ft.ndim == 2 else ft
    fw = np.radians(fwhm)
    area = vertex_areas(U, F) if area is None else area
    s = standardized(heat_smooth(U, F, fs, fw), area)
    g = standardized(heat_smooth(tU, target_F, ft, fw), vertex_areas(tU, target_F))
    fld, subject = SphereField(tU, target_F, g), SphereField(U, F, s)
    g_coefficients = standardized_coefficients(lambda X: fld(X, gradient=False)[0][:, 0], degree)
    ref, ref_w = refinement_points(U, area)

    def search(M, count):
        s_coefficients = standardized_coefficients(
            lambda X: subject(X @ M.T, gradient=False)[0][:, 0], degree)
        refined = [_refine(U[ref] @ M.T, s[ref], ref_w, fld, R0)
                   for _, R0 in best_rotations(g_coefficients, s_coefficients, count)]
        return max(refined, key=lambda t: t[1])

    R, c = search(np.eye(3), candidates)
    cm = search(MIRROR, mirror_candidates)[1] if mirror_candidates else np.nan
    return R, float(c), float(cm)
