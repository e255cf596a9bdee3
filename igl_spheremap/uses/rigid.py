"""Rigid alignment of a spherical map to a target sphere by the correlation of smoothed features.

A global search over rotations spread uniformly on SO(3) (super-Fibonacci
samples: Alexa, "Super-Fibonacci spirals: fast, low-discrepancy sampling of
SO(3)", CVPR 2022), scored by the correlation of heavily smoothed features,
then a local BFGS refinement of the best candidates on the correlation with
the target interpolated at the rotated points (its gradient with respect to a
rotation vector is the torque ``sum_i w_i dcorr/dg_i (X_i x grad g(X_i))``).  The
same search with the subject mirrored reports whether a reflection would fit
better (a right hemisphere registered to a left atlas, or a sphere of the
wrong orientation); a fold-free map cannot be reflected, so this is a check only.
It is the first stage of :func:`igl_spheremap.uses.atlas.register_sphere`
(FreeSurfer's ``mris_register`` starts the same way, with a search over
rotations of up to 64 degrees: Fischl et al., HBM 8 1999).
"""

import numpy as np
import scipy.optimize
from scipy.spatial import cKDTree

from ..mesh.operators import vertex_areas
from ..mesh.shapes import icosphere
from ..sphere.field import SphereField
from .features import heat_smooth, standardized


def super_fibonacci_rotations(n):
    """``n`` rotations spread uniformly over SO(3) (Alexa, CVPR 2022).

    Returns
    -------
    (n, 3, 3) float64 array
    """
    phi = np.sqrt(2.0)
    psi = 1.533751168755204288118041
    s = np.arange(n) + 0.5
    t = s / n
    r, R = np.sqrt(t), np.sqrt(1.0 - t)
    alpha, beta = 2.0 * np.pi * s / phi, 2.0 * np.pi * s / psi
    q = np.stack([r * np.sin(alpha), r * np.cos(alpha), R * np.sin(beta), R * np.cos(beta)], 1)
    return quaternion_matrices(q)


def quaternion_matrices(q):
    """Rotation matrices of unit quaternions ``(x, y, z, w)`` ((k, 4) -> (k, 3, 3))."""
    x, y, z, w = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], 1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], 1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], 1),
    ], 1)


def rotation_matrix(w):
    """``exp([w]_x)`` (Rodrigues), ``w`` (3,) a rotation vector in radians."""
    theta = float(np.linalg.norm(w))
    K = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    if theta < 1e-12:
        return np.eye(3) + K
    return np.eye(3) + np.sin(theta) / theta * K + (1 - np.cos(theta)) / theta ** 2 * K @ K


def rotation_angle(R):
    """Angle of a rotation matrix, degrees."""
    return float(np.degrees(np.arccos(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0))))


def _grid_scores(P, s, tree, g, rotations, chunk=256):
    """Correlation of ``s`` at points ``P`` with ``g`` (nearest vertex of ``tree``) for each rotation."""
    s = s - s.mean()
    out = np.empty(len(rotations))
    for a in range(0, len(rotations), chunk):
        R = rotations[a:a + chunk]
        X = np.einsum("kij,pj->kpi", R, P).reshape(-1, 3)
        vals = g[tree.query(X)[1]].reshape(len(R), -1)
        vals = vals - vals.mean(axis=1, keepdims=True)
        out[a:a + chunk] = (vals @ s) / (np.linalg.norm(vals, axis=1) * np.linalg.norm(s) + 1e-300)
    return out


def _refine(U, s, area, fld, R0):
    """Local maximum of the weighted correlation of ``s`` with ``fld`` at ``U R^T`` from ``R0``."""
    w = area / area.sum()
    s = s - w @ s
    ns = np.sqrt(w @ s ** 2)
    face = [None]

    def negcorr(v):
        R = rotation_matrix(v) @ R0
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
    return rotation_matrix(res.x) @ R0, -res.fun


def rigid_align(U, F, features, target_U, target_F, target_features, *, fwhm=30.0,
                n_rotations=2048, n_points=162, candidates=4, mirror_candidates=2, area=None):
    """The rotation of a spherical map that best correlates its features with a target's.

    Both sides' first feature is smoothed (``fwhm`` degrees, :func:`heat_smooth`).
    Every rotation of a super-Fibonacci sampling of SO(3) is scored by the
    correlation of the subject's feature at ``n_points`` subject vertices
    (those nearest to an icosphere's vertices) with the target's at the nearest
    target vertex; the best ``candidates`` (at least one grid spacing apart)
    are refined by BFGS on the area-weighted correlation at a subset of the
    subject's vertices with the target interpolated
    (:class:`igl_spheremap.sphere.field.SphereField`),
    and the best refined rotation is returned.  The search is repeated with the
    subject mirrored (``x -> -x``), for a reflection check only.

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
    n_rotations : int
        Size of the SO(3) sample (2048: about 17 degrees between neighbours).
    n_points : int
        Vertices of the icosphere whose nearest subject vertices are scored
        (162: level 2).  The refinement uses the subject vertices nearest to a
        finer icosphere (up to level 4, 2562 directions), each weighted by the
        subject area closest to its direction.
    candidates : int
        Grid maxima refined.
    mirror_candidates : int
        Grid maxima refined for the mirrored subject (0: no reflection check).
    area : (n,) float array, optional
        Subject vertex weights of the refinement (default: its sphere's vertex areas).

    Returns
    -------
    R : (3, 3) float64 array
        ``U @ R.T`` is aligned.
    correlation : float
        Its correlation (smoothed features).
    mirrored_correlation : float
        The best correlation with the subject mirrored.
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
    fld = SphereField(tU, target_F, g)
    level = int(round(np.log((n_points - 2) / 10.0) / np.log(4.0)))
    subject_tree = cKDTree(U)
    sub = np.unique(subject_tree.query(icosphere(max(level, 0))[0])[1])
    # the refinement: subject vertices nearest to a finer icosphere, weighted by the
    # subject's areas summed over each icosphere direction's nearest-vertex cell
    ref_level = max(level + 1, min(4, int(np.ceil(np.log(max(U.shape[0] / 4.0, 12) / 10.0) / np.log(4.0)))))
    ico_ref = icosphere(ref_level)[0]
    owner = cKDTree(ico_ref).query(U)[1]
    cell_area = np.bincount(owner, weights=area, minlength=ico_ref.shape[0])
    ref = subject_tree.query(ico_ref)[1]
    ref_w = np.zeros(U.shape[0])
    np.add.at(ref_w, ref, cell_area)
    ref = np.flatnonzero(ref_w)
    tree = cKDTree(tU)
    rotations = super_fibonacci_rotations(n_rotations)
    spacing = (8 * np.pi ** 2 / n_rotations) ** (1 / 3)

    def search(Us, candidates):
        scores = _grid_scores(Us[sub], s[sub], tree, g, rotations)
        order = np.argsort(-scores)
        picked = []
        for k in order:
            if all(np.radians(rotation_angle(rotations[k] @ rotations[j].T)) > spacing
                   for j in picked):
                picked.append(k)
            if len(picked) == candidates:
                break
        best = (None, -np.inf)
        for k in picked:
            R, c = _refine(Us[ref], s[ref], ref_w[ref], fld, rotations[k])
            if c > best[1]:
                best = (R, c)
        return best

    R, c = search(U, candidates)
    cm = np.nan
    if mirror_candidates:
        _, cm = search(U @ np.diag([-1.0, 1.0, 1.0]), mirror_candidates)
    return R, float(c), float(cm)
