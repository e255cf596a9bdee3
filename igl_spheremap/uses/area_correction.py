"""Area-correcting Möbius transformation of a spherical conformal map (Choi et al. 2020)."""

import warnings
from typing import NamedTuple

import igl
import numpy as np

from ..errors import SphericalMapWarning, plural
from ..mesh.arrays import off_unit_sphere
from ..sphere.folds import count_below_margin, count_folds, unit_roundoff
from ..sphere.mobius import ball_point, mobius_transform

XATOL = 1e-6
"""Nelder-Mead tolerance on the hyperbolic translation vector ``w`` (see :func:`mobius_area_correction`)."""

FATOL = 1e-12
"""Nelder-Mead tolerance on the objective."""

MAX_EVALUATIONS = 2000
"""Objective evaluations per Nelder-Mead run."""

RESTARTS = 1
"""Extra Nelder-Mead runs from the best point so far (a fresh simplex escapes a collapsed one)."""

W_MAX = 30.0
"""Largest hyperbolic translation distance tried (``|c| = tanh(15)``, 2e-13 below 1)."""


class MobiusAreaCorrection(NamedTuple):
    """Result of :func:`mobius_area_correction`; unpacks as ``U, c, distortion, ...``."""

    U: np.ndarray
    """(n, 3) float64: the corrected map, ``mobius_transform(U_input, c)``."""
    c: np.ndarray
    """(3,) float64, ``|c| < 1``: center of the hyperbolic translation that was applied."""
    distortion: float
    """Objective at ``c``: mean over faces of ``|log area ratio|`` (see the function)."""
    initial_distortion: float
    """Objective of the input map (``c = 0``)."""
    folds: int
    """Folded faces of the returned map (never more than the input had)."""
    evaluations: int
    """Objective evaluations used."""


def mobius_area_correction(V, F, U, precision=None):
    """Möbius transformation of the sphere that minimizes the area distortion of a map.

    A spherical conformal map stays conformal under every Möbius transformation
    of the sphere, so the one with the least area distortion can be chosen
    freely (Choi, Leung-Liu, Gu, Lui 2020).  Rotations do not change areas, so
    only the hyperbolic translations of the unit ball remain:
    ``mobius_transform(U, c)`` with ``|c| < 1``, three parameters.  The
    objective, as in the paper's code and LaPy 1.7, is the mean over faces of
    ``|log((|U(T)| / sum |U(T)|) / (|T| / sum |T|))|`` (flat triangle areas,
    both sides normalized to total 1, unweighted mean, non-finite terms of
    degenerate faces left out), i.e. the mean of
    ``abs(igl_spheremap.sphere.quality.area_distortion(V, F, U))`` over the faces whose
    input and initial image areas are non-zero (a face collapsing on the way
    makes it +inf).  It is minimized by Nelder-Mead over ``w`` in R^3 with
    ``c = ball_point(w / 2)`` (:func:`igl_spheremap.sphere.mobius.ball_point`:
    ``|w|`` is the hyperbolic distance of the translation), starting from the identity and restarted :data:`RESTARTS`
    times from the best point.  A Möbius transformation keeps the orientation
    of small image triangles, but a large flat triangle can flip: if the
    optimum has more folded faces than the input (or, for ``precision="float32"``,
    more faces at or below their float32 rounding margin), the search is run
    again with every such point rejected (objective +inf), and its best point
    returned.

    Parameters
    ----------
    V : (n, 3) float array
        Input surface.
    F : (m, 3) int array
        Faces, outward oriented.
    U : (n, 3) float array
        Spherical (conformal) map of ``(V, F)``, unit vectors.
    precision : {None, "float64", "float32"}
        Storage precision the map must stay fold-free in
        (:func:`igl_spheremap.sphere.folds.rounding_margin`).  Default: ``"float32"``
        when every face of ``U`` is above its float32 margin (a map made for
        GIfTI or FreeSurfer stays storable), else ``"float64"``.

    Returns
    -------
    MobiusAreaCorrection
        Named tuple ``(U, c, distortion, initial_distortion, folds,
        evaluations)``; ``distortion <= initial_distortion`` always (``c = 0``
        is returned when nothing better is found).

    Raises
    ------
    ValueError
        If a shape is wrong, ``V`` or ``U`` hold non-finite values, ``U`` is off
        the unit sphere (beyond 1e-6), ``F`` indexes outside ``V``, or
        ``precision`` is unknown.

    Warns
    -----
    SphericalMapWarning
        If the returned map has folded faces (only when the input had them).

    Notes
    -----
    Source: G. P. T. Choi, Y. Leung-Liu, X. Gu, L. M. Lui, "Parallelizable
    global conformal parameterization of simply-connected surfaces via partial
    welding", SIAM J. Imaging Sci. 13(3), 2020 (the Möbius area correction);
    the parameterization of the Möbius group modulo rotations by the ball
    follows Baden, Crane, Kazhdan, "Möbius Registration", SGP 2018.
    """
    V, F, U = _validated(V, F, U)
    a, b = igl.doublearea(V, F), igl.doublearea(U, F)
    keep = (a > 0) & (b > 0)  # degenerate input faces and collapsed input images are left out
    log_a = np.log(a[keep] / a.sum())
    folds0 = count_folds(F, U)
    u = _storage_roundoff(F, U, precision)
    below0 = count_below_margin(F, U, u)
    evaluations = 0

    def objective(w, guard):
        nonlocal evaluations
        evaluations += 1
        if not np.linalg.norm(w) <= W_MAX:
            return np.inf
        Uc = mobius_transform(U, ball_point(0.5 * w))
        if guard and count_below_margin(F, Uc, u) > below0:
            return np.inf
        return _mean_abs_log_ratio(F, Uc, log_a, keep)

    f0 = objective(np.zeros(3), False)
    w, f = _nelder_mead(lambda w: objective(w, False), np.zeros(3), f0)
    if count_below_margin(F, mobius_transform(U, ball_point(0.5 * w)), u) > below0:
        # the optimum flips a large flat triangle (or brings a face below its margin):
        # search again, refusing every point that does
        w, f = _nelder_mead(lambda w: objective(w, True), np.zeros(3), f0)
    c = ball_point(0.5 * w)
    Uc = mobius_transform(U, c)
    folds = count_folds(F, Uc)
    if folds:
        warnings.warn(f"Möbius area correction: the map has {plural(folds, 'folded face')} (the "
                      f"input had {folds0})", SphericalMapWarning, stacklevel=2)
    return MobiusAreaCorrection(U=Uc, c=c, distortion=float(f), initial_distortion=float(f0),
                                folds=folds, evaluations=evaluations)


def _storage_roundoff(F, U, precision):
    """Unit roundoff of the margin the correction keeps (see ``precision``)."""
    if precision is None:
        u32 = unit_roundoff("float32")
        return u32 if count_below_margin(F, U, u32) == 0 else 0.0
    return unit_roundoff(precision)


def _nelder_mead(fun, w0, f0):
    """Best point of ``1 + RESTARTS`` Nelder-Mead runs, each from the best point so far."""
    import scipy.optimize  # only when the correction runs
    best_w, best_f, step = w0, f0, 0.1
    for _ in range(1 + RESTARTS):
        simplex = best_w + np.vstack([np.zeros(3), step * np.eye(3)])
        res = scipy.optimize.minimize(fun, best_w, method="Nelder-Mead", options=dict(
            initial_simplex=simplex, xatol=XATOL, fatol=FATOL, maxfev=MAX_EVALUATIONS))
        if res.fun < best_f:
            step = float(np.clip(10.0 * np.linalg.norm(res.x - best_w), 1e-4, 0.1))
            best_w, best_f = res.x, float(res.fun)
        else:
            step = max(0.1 * step, 1e-4)
    return best_w, best_f


def _mean_abs_log_ratio(F, U, log_a, keep):
    """Mean over the kept faces of ``|log(normalized image area) - log_a|``; +inf if one collapses."""
    b = igl.doublearea(U, F)
    bk = b[keep]
    if not np.all(bk > 0):
        return np.inf
    return float(np.mean(np.abs(np.log(bk / b.sum()) - log_a)))


def _validated(V, F, U):
    V = np.asarray(V, dtype=np.float64)
    U = np.ascontiguousarray(U, dtype=np.float64)
    F = np.asarray(F)
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"V must be an (n, 3) array, got shape {V.shape}")
    if U.shape != V.shape:
        raise ValueError(f"U must have the shape of V {V.shape}, got {U.shape}")
    if F.ndim != 2 or F.shape[1] != 3 or F.shape[0] == 0 or not np.issubdtype(F.dtype, np.integer):
        raise ValueError(f"F must be a non-empty (m, 3) integer array, got shape {F.shape}, dtype {F.dtype}")
    F = np.ascontiguousarray(F, dtype=np.int64)
    bad = np.count_nonzero((F < 0) | (F >= V.shape[0]))
    if bad:
        raise ValueError(f"F has {plural(bad, 'vertex index', 'vertex indices')} outside "
                         f"[0, {V.shape[0]})")
    for name, X in (("V", V), ("U", U)):
        bad = np.count_nonzero(~np.isfinite(X).all(axis=1))
        if bad:
            raise ValueError(f"{name} has {plural(bad, 'row')} with non-finite coordinates")
    off = off_unit_sphere(U)
    if off:
        raise ValueError(off)
    return V, F, U
