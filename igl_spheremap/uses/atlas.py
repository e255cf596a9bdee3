"""Atlas registration of a spherical map: a fold-free deformation that matches features to a target sphere.

What FreeSurfer's ``mris_register`` writes as ``?h.sphere.reg``: the subject's
vertices placed on the target (atlas) sphere so that the subject's features
(sulcal depth, curvature) match the target's.  :func:`register_sphere` does it
in two stages:

1. **Rigid alignment** (:func:`igl_spheremap.uses.rigid.rigid_align`): the
   rotation that maximizes the correlation of heavily smoothed features, by a
   global search over rotations spread uniformly on SO(3) then a local
   refinement; the same search with the subject mirrored reports whether a
   reflection would fit better (a left hemisphere registered to a right atlas).
2. **Deformation**, coarse to fine (:class:`Level`): at each level both sides'
   features are smoothed by heat diffusion on their spheres and standardized,
   and Algorithm 1 (:func:`igl_spheremap.optimize.minimize.minimize`) minimizes
   :class:`igl_spheremap.optimize.matching.FeatureMatchEnergy` (squared feature
   differences, the target interpolated at the moving points, plus the
   membrane energy of the map on the rigidly aligned start sphere) under the
   fold barrier with the rounding margin of ``precision``: the result is
   fold-free by construction, and with ``"float32"`` stays fold-free when
   stored as float32 at any radius.

References: Fischl, Sereno, Tootell, Dale, "High-resolution intersubject
averaging and a coordinate system for the cortical surface", HBM 8 1999;
Yeo, Sabuncu, Vercauteren, Ayache, Fischl, Golland, "Spherical Demons: fast
diffeomorphic landmark-free surface registration", IEEE TMI 29(3) 2010;
Robinson et al., "MSM: a new flexible framework for multimodal surface
matching", NeuroImage 100 2014.
"""

import time
import warnings
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial import cKDTree

from ..errors import SphericalMapWarning, plural
from ..mesh.arrays import as_faces, as_points, as_weights, off_sphere, unit_rows
from ..mesh.operators import laplacian, to_sphere_area, vertex_areas
from ..mesh.shapes import icosphere
from ..optimize.matching import FeatureMatchEnergy
from ..optimize.minimize import minimize
from ..optimize.result import success_first_repr
from ..options import map_options
from ..sphere.field import SphereField
from ..sphere.folds import below_margin, count_folds
from ..sphere.quality import angle_distortion, area_distortion
from .features import (constant_columns, heat_smooth, standardized, unmatched_columns,
                       weighted_correlation)
from .rigid import rigid_align


@dataclass(frozen=True)
class Level:
    """One level of the coarse-to-fine deformation.

    Attributes
    ----------
    fwhm : float
        Full width at half maximum of the feature smoothing, degrees of arc (0: none).
    sigma : float
        Smoothing length of the search direction's Sobolev metric, degrees.
    data_weight : float
        ``lambda`` of :class:`igl_spheremap.optimize.matching.FeatureMatchEnergy`
        (features standardized, areas summing to ``4 pi``).
    reg_weight : float
        ``mu``, the weight of the membrane energy.
    max_iter : int
        Algorithm 1 iterations.
    feature_weights : tuple of float, optional
        Per-feature weights at this level (default: :func:`feature_schedule`).
    """

    fwhm: float
    sigma: float
    data_weight: float = 10.0
    reg_weight: float = 1.0
    max_iter: int = 100
    feature_weights: tuple = None

    def __post_init__(self):
        bad = [name for name in ("fwhm", "sigma", "data_weight", "reg_weight", "max_iter")
               if not np.isfinite(getattr(self, name)) or getattr(self, name) < 0]
        if bad:
            raise ValueError(f"Level: {', '.join(bad)} must be finite and >= 0, got "
                             + ", ".join(f"{name}={getattr(self, name)!r}" for name in bad))


#: The default schedule: feature smoothing from 20 degrees down to none, the
#: metric's smoothing length following it.
DEFAULT_LEVELS = (Level(20.0, 20.0), Level(10.0, 10.0), Level(5.0, 5.0), Level(2.5, 3.0),
                  Level(0.0, 2.0))

#: Registration defaults of the options (:class:`igl_spheremap.MapOptions`) where
#: they differ from the map's: the float32 margin (a ``?h.sphere.reg`` is stored
#: as float32), a finer tolerance (each level stops at ``max_iter``), and three
#: step shortenings before the fold barrier freezes vertices.
OPTION_DEFAULTS = dict(precision="float32", gtol=1e-6, max_fold_shrinks=3)

#: Mean |log area ratio| of the start sphere against the subject's surface
#: (:func:`igl_spheremap.area_distortion`) above which the start is called poor: a sphere
#: whose density is far from an atlas sphere's (a conformal sphere of a cortex: 0.6-0.9;
#: area-balanced: about 0.2), from which the registration matches the features on a
#: crushed sphere and the correspondence is doubtful (``docs/decisions.md``).
POOR_START_AREA_LOG = 0.45

#: Icosphere level of the cells of ``area_log_coarse`` (642 cells, about 8 degrees).
COARSE_CELLS_LEVEL = 3


def feature_schedule(n_features, levels=DEFAULT_LEVELS):
    """Levels with features entering coarse to fine: feature ``j`` from level ``round(j (L-1) / d)`` on.

    The first feature (e.g. sulcal depth) drives every level; each further one
    (e.g. curvature) is added at a finer level and stays on.  Levels that give
    ``feature_weights`` keep them.

    Parameters
    ----------
    n_features : int
    levels : sequence of Level

    Returns
    -------
    tuple of Level
    """
    L = len(levels)
    start = [int(round(j * (L - 1) / n_features)) for j in range(n_features)]
    return tuple(lv if lv.feature_weights is not None else
                 replace(lv, feature_weights=tuple(float(k >= s) for s in start))
                 for k, lv in enumerate(levels))


@dataclass
class AtlasRegistrationResult:
    """Outcome of :func:`register_sphere` (scipy.optimize style).

    Attributes
    ----------
    U : (n, 3) float64 array
        The registered sphere: the subject's vertices (subject order) as unit
        vectors in the target's frame (scale by the target's radius to write
        ``?h.sphere.reg``).
    rotation : (3, 3) float64 array
        The rigid alignment applied to the start sphere (``U0 @ rotation.T``).
    correlation_rigid, correlation_mirrored : float
        Correlation of the smoothed first feature after the rigid search, and
        the best one with the subject mirrored (NaN without the rigid stage).
    correlation_before, correlation_after : (d,) float64 arrays
        Per feature, the area-weighted correlation of the subject's feature with
        the target's interpolated at the subject's points (unsmoothed), at the
        start sphere as given and at ``U``.
    folds : int
        Folded faces of ``U`` (float64).
    below_margin : int
        Faces at or below their rounding margin for ``precision`` (0 with
        ``"float32"``: fold-free when stored as float32 at any radius).
    precision : str
        The storage precision the fold barrier protected.
    distortion : dict
        How much the deformation changed the rigidly aligned start sphere:
        ``area_log_mean`` / ``area_log_max`` (|log area ratio| of the faces),
        ``angle_mean_deg``.
    levels : list of dict
        Per level: fwhm, sigma, iterations, frozen vertices, correlation, seconds.
    warnings : list of str
        What makes the result doubtful although it is fold-free (a poor start).
    seconds : float
    timings : dict of str -> float
    start_area_log : float or None
        Mean |log area ratio| of the start sphere against the subject's surface
        (None when the surface is not given).
    start_below_margin : int
        Faces of the start sphere at or below their rounding margin (the fold
        barrier lets them stay there: a start made with ``precision="float32"``
        has none).
    F : (m, 3) int64 array or None
        The subject's faces when the registration computed its sphere
        (:func:`igl_spheremap.uses.atlas_multires.register_surface`: outward oriented).
    """

    U: np.ndarray = field(repr=False)
    rotation: np.ndarray
    correlation_rigid: float
    correlation_mirrored: float
    correlation_before: np.ndarray
    correlation_after: np.ndarray
    folds: int
    below_margin: int
    precision: str = "float32"
    distortion: dict = field(default_factory=dict)
    levels: list = field(default_factory=list, repr=False)
    warnings: list = field(default_factory=list)
    seconds: float = 0.0
    timings: dict = field(default_factory=dict)
    start_below_margin: int = 0
    start_area_log: float = None
    F: np.ndarray = field(default=None, repr=False)

    @property
    def improved(self):
        """Whether every feature's correlation with the target rose."""
        return bool(np.all(self.correlation_after > self.correlation_before))

    @property
    def success(self):
        """Fold-free as stored in ``precision``, the match improved, and no warning."""
        return (self.folds == 0 and self.below_margin == 0 and self.improved
                and not self.warnings)

    __repr__ = success_first_repr

    @property
    def message(self):
        """One line: folds, correlations, warnings."""
        corr = ", ".join(f"{a:.3f} -> {b:.3f}" for a, b in
                         zip(self.correlation_before, self.correlation_after))
        text = (f"{plural(self.folds, 'fold')}, {plural(self.below_margin, 'face')} below the "
                f"{self.precision} margin; feature correlation {corr}")
        if self.below_margin and self.start_below_margin:
            text += (f" (the start sphere had {plural(self.start_below_margin, 'face')} below the "
                     f"margin: make it with precision='{self.precision}')")
        return "; ".join([text] + list(self.warnings))


class TargetSphere:
    """The target sphere with its features (and optional mask), smoothed per level.

    Parameters
    ----------
    U : (k, 3) float array
        The target sphere, any radius, fold-free.
    F : (t, 3) int array
    features : (k,) or (k, d) float array
    weights : (k,) float array, optional
        A mask of the target in [0, 1] (e.g. 0 on its medial wall).
    """

    def __init__(self, U, F, features, weights=None):
        self.U, self.F = unit_rows(U), np.asarray(F, dtype=np.int64)
        f = np.asarray(features, dtype=np.float64)
        self.f = f[:, None] if f.ndim == 1 else f
        self.L, self.area = laplacian(self.U, self.F), vertex_areas(self.U, self.F)
        self.raw = SphereField(self.U, self.F, self.f)
        self.mask = None if weights is None else SphereField(self.U, self.F, weights)

    def field(self, fwhm):
        """The standardized features smoothed to ``fwhm`` degrees, as a SphereField."""
        g = heat_smooth(self.U, self.F, self.f, np.radians(fwhm), L=self.L, area=self.area)
        return SphereField(self.U, self.F, standardized(g, self.area))

    def mask_at(self, U):
        """The mask interpolated at ``U`` ((n,) in [0, 1]), or None."""
        if self.mask is None:
            return None
        return np.clip(self.mask(U, gradient=False)[0][:, 0], 0.0, 1.0)

    def correlation(self, U, F, features):
        """Per feature, the area-weighted correlation of ``features`` with the target's at ``U``."""
        return weighted_correlation(features, self.raw(U, gradient=False)[0],
                                    vertex_areas(U, F))


def run_level(U, F, fs, target, L0, lev, vertex_weights, opts):
    """One level: smooth and standardize both sides, minimize under the fold barrier.

    Returns the map and the level's row (fwhm, sigma, iterations, frozen, correlation, seconds).
    """
    t = time.perf_counter()
    # both sides standardized with the areas of their spheres in the target's frame (the
    # subject's: its current map), so that at the true correspondence s == g
    area = to_sphere_area(vertex_areas(U, F))
    s = standardized(heat_smooth(U, F, fs, np.radians(lev.fwhm), area=area), area)
    fld = target.field(lev.fwhm)
    vw, mw = vertex_weights, target.mask_at(U)
    if mw is not None:
        vw = mw if vw is None else vw * mw
    energy = FeatureMatchEnergy(fld, s, area, L0, lev.data_weight, lev.reg_weight,
                                np.radians(lev.sigma), lev.feature_weights, vw, opts.h1_solver)
    run = minimize(energy, U, F, opts.updated(max_iter=lev.max_iter),
                   fold_barrier=opts.fold_barrier)
    corr = weighted_correlation(s, fld(run.U, gradient=False)[0], area)
    return run.U, dict(fwhm=lev.fwhm, sigma=lev.sigma, iterations=run.nit, frozen=run.frozen,
                       converged=run.converged, message=run.message,
                       correlation=corr.tolist(), seconds=time.perf_counter() - t)


def registration_options(options=None, **option_values):
    """The options of a registration: :data:`OPTION_DEFAULTS` under the given ones (MapOptions)."""
    opts = map_options(options, **option_values)
    return opts.updated(**{k: v for k, v in OPTION_DEFAULTS.items() if k not in opts.explicit})


def deformation_distortion(F, U0, U):
    """How much ``U`` distorts ``U0`` (dict of float).

    ``area_log_mean`` / ``area_log_max``: |log area ratio| of the faces (normalized
    areas); ``angle_mean_deg``: mean angle change of the corners; ``area_log_coarse``:
    the area-weighted mean |log ratio| of the areas of the cells of an icosphere of
    :data:`COARSE_CELLS_LEVEL` (each vertex in the cell nearest to it on ``U0``): the
    area moved between regions, independent of the resolution.
    """
    a = np.abs(area_distortion(U0, F, U))
    owner = cKDTree(icosphere(COARSE_CELLS_LEVEL)[0]).query(unit_rows(U0))[1]
    a0 = np.bincount(owner, weights=vertex_areas(U0, F))
    a1 = np.bincount(owner, weights=vertex_areas(U, F))
    used = a0 > 0
    w, r = a0[used] / a0[used].sum(), a1[used] / a1.sum() / (a0[used] / a0.sum())
    return dict(area_log_mean=float(a.mean()), area_log_max=float(a.max()),
                area_log_coarse=float(w @ np.abs(np.log(r))),
                angle_mean_deg=float(angle_distortion(U0, F, U).mean()))


def _checked(U, F, features, target_U, target_F, target_features):
    """Validated arrays: unit spheres, int64 faces, (n, d) features; ValueError naming the fault."""
    for name, X in (("the subject's sphere U", U), ("the target sphere target_U", target_U)):
        message = off_sphere(as_points(X, name.split()[-1]), name)
        if message:
            raise ValueError(message)
    U = unit_rows(as_points(U, "U"))
    F = as_faces(F, U.shape[0], "F")
    T = unit_rows(as_points(target_U, "target_U"))
    TF = as_faces(target_F, T.shape[0], "target_F")
    cols = []
    for name, x, n in (("features", features, U.shape[0]),
                       ("target_features", target_features, T.shape[0])):
        shape = np.shape(x)
        x = np.asarray(x, dtype=np.float64)
        x = x[:, None] if x.ndim == 1 else x
        if x.ndim != 2 or x.shape[0] != n:
            raise ValueError(f"{name} must be (n,) or (n, d) values with n = {n}, got shape "
                             f"{shape}")
        bad = int(np.count_nonzero(~np.isfinite(x).all(axis=1)))
        if bad:
            raise ValueError(f"{name} has {plural(bad, 'row')} with NaN or infinite values")
        message = constant_columns(x, name)
        if message:
            raise ValueError(message)
        cols.append(x)
    message = unmatched_columns(*cols)
    if message:
        raise ValueError(message)
    for name, S, G in (("subject", U, F), ("target", T, TF)):
        folds = count_folds(G, S)
        if folds:
            raise ValueError(f"the {name} sphere has {plural(folds, 'folded face')}; registration "
                             "needs fold-free spheres (faces oriented outward)")
    return U, F, cols[0], T, TF, cols[1]


def start_area_log(surface, F, U):
    """Mean |log area ratio| of the sphere ``U`` against the surface (float; None without one)."""
    if surface is None:
        return None
    return float(np.abs(area_distortion(as_points(surface, "surface", rows=len(U)), F, U)).mean())


def start_warnings(start_area, correlation_rigid, correlation_mirrored):
    """Why a result is doubtful although fold-free (list of str).

    A start sphere whose area distortion against the subject's surface
    (``start_area``, :func:`start_area_log`; None when unknown) is above
    :data:`POOR_START_AREA_LOG`, and features that agree better with the subject
    mirrored (a hemisphere of the other side, an inside-out sphere).
    """
    out = []
    if start_area is not None and start_area > POOR_START_AREA_LOG:
        out.append(f"poor start: the start sphere's mean |log area ratio| against the surface is "
                   f"{start_area:.2f} (> {POOR_START_AREA_LOG}), so the registration matches the "
                   "features on a crushed sphere and the correspondence is doubtful (an "
                   "area-balanced sphere, spherical_conformal_map(..., kind='area_balanced') or "
                   "--kind area_balanced, usually reaches about 0.2; where it does not, its "
                   "relaxation stalled)")
    if correlation_mirrored > correlation_rigid:
        out.append(f"the mirrored subject fits better ({correlation_mirrored:.2f} > "
                   f"{correlation_rigid:.2f}): a hemisphere of the other side?")
    return out


def register_sphere(U, F, features, target_U, target_F, target_features, *, levels=None,
                    rigid=True, rigid_fwhm=30.0, vertex_weights=None, target_weights=None,
                    surface=None, options=None, callback=None, **option_values):
    """Register a subject's spherical map to a target sphere by its features, fold-free.

    The rigid stage (:func:`igl_spheremap.uses.rigid.rigid_align`), then level
    by level (:class:`Level`) Algorithm 1 on
    :class:`igl_spheremap.optimize.matching.FeatureMatchEnergy` under the fold
    barrier (module docstring).  Both sides' features are smoothed on their
    spheres (the subject's current map, the target sphere) and standardized
    with those spheres' areas; the membrane energy is taken on the rigidly
    aligned start sphere.  A step that would break the barrier is shortened
    ``max_fold_shrinks`` times before the vertices of the faces it would fold
    are frozen for the rest of the level.

    Parameters
    ----------
    U : (n, 3) float array
        The subject's sphere, any radius, fold-free with ``F`` oriented outward
        (an area-balanced sphere is the better start:
        ``spherical_conformal_map(V, F, kind="area_balanced")``).
    F : (m, 3) int array
        The subject's faces.
    features : (n,) or (n, d) float array
        Subject features, any units (e.g. sulcal depth, then curvature: several
        enter coarse to fine, :func:`feature_schedule`); the rigid stage uses the first.
    target_U : (k, 3) float array
        The target sphere, any radius, fold-free (e.g. fsaverage's ``?h.sphere``).
    target_F : (t, 3) int array
    target_features : (k,) or (k, d) float array
        The target's features, the same kinds in the same columns.
    levels : sequence of Level, optional
        The schedule (default :data:`DEFAULT_LEVELS`).
    rigid : bool
        Run the rigid stage (else start from ``U`` as given).
    rigid_fwhm : float
        Feature smoothing of the rigid stage, degrees.
    vertex_weights : (n,) float array, optional
        Data weights of the subject's vertices in [0, 1] (e.g. 0 on its medial wall).
    target_weights : (k,) float array, optional
        A mask of the target in [0, 1], interpolated at the moving points at
        the start of each level.
    surface : (n, 3) float array, optional
        The subject's surface: with it a poor start sphere is flagged
        (:func:`start_warnings`; :func:`igl_spheremap.register_surface` passes it).
    options : MapOptions or dict, optional
        Algorithm 1's options; ``fold_barrier`` (default on) and ``precision``
        (default ``"float32"``: the rounding margin the barrier keeps),
        ``h1_solver``, ``max_fold_shrinks`` (default 3), ``gtol`` (default 1e-6),
        ``blas_threads``.  Defaults: :data:`OPTION_DEFAULTS`.
    callback : callable, optional
        ``callback(level_index, U)`` after each level.
    **option_values
        Fields of :class:`igl_spheremap.MapOptions`.

    Returns
    -------
    AtlasRegistrationResult
        ``U`` (n, 3) unit vectors in the target's frame, subject order;
        ``success`` needs a fold-free map as stored, a better match and no warning.

    Raises
    ------
    ValueError
        Bad shapes, non-finite values, different feature counts, weights outside
        [0, 1] or all 0, levels with negative settings, folded spheres,
        spheres whose vertices are not at one radius about the origin
        (:data:`igl_spheremap.mesh.arrays.SPHERE_RADIUS_RTOL`: a surface or an
        ellipsoid passed for its sphere) or bad options.

    Warns
    -----
    SphericalMapWarning
        A result that is not a success: folds or faces below the margin, no
        better match, or a doubtful one (:func:`start_warnings`).
    """
    t0 = time.perf_counter()
    U, F, fs, T, TF, ft = _checked(U, F, features, target_U, target_F, target_features)
    for name, w, n in (("vertex_weights", vertex_weights, U.shape[0]),
                       ("target_weights", target_weights, T.shape[0])):
        if w is not None:
            as_weights(w, n, name, at_most=1.0)
    opts = registration_options(options, **option_values)
    levels = feature_schedule(fs.shape[1], DEFAULT_LEVELS if levels is None else tuple(levels))
    target = TargetSphere(T, TF, ft, target_weights)
    with opts.blas_limit():
        result = _register(U, F, fs, target, levels, rigid, rigid_fwhm, vertex_weights, opts,
                           callback)
    result.start_area_log = start_area_log(surface, F, U)
    result.warnings = start_warnings(result.start_area_log, result.correlation_rigid,
                                     result.correlation_mirrored)
    result.seconds = time.perf_counter() - t0
    if not result.success:
        warnings.warn(f"register_sphere: {result.message}", SphericalMapWarning, stacklevel=2)
    return result


def _register(U, F, fs, target, levels, rigid, rigid_fwhm, vertex_weights, opts, callback):
    corr_before = target.correlation(U, F, fs)
    t = time.perf_counter()
    R, c_rigid, c_mirror = np.eye(3), np.nan, np.nan
    if rigid:
        R, c_rigid, c_mirror = rigid_align(U, F, fs, target.U, target.F, target.f,
                                           fwhm=rigid_fwhm, area=vertex_areas(U, F))
    U0 = U @ R.T
    timings = {"rigid": time.perf_counter() - t}
    L0 = laplacian(U0, F, "cotan")
    vw = None if vertex_weights is None else np.asarray(vertex_weights, dtype=np.float64)
    Ucur, rows = U0, []
    for k, lev in enumerate(levels):
        Ucur, row = run_level(Ucur, F, fs, target, L0, lev, vw, opts)
        rows.append(row)
        if callback is not None:
            callback(k, Ucur)
    timings["deform"] = sum(row["seconds"] for row in rows)
    distortion = deformation_distortion(F, U0, Ucur)
    return AtlasRegistrationResult(
        U=Ucur, rotation=R, correlation_rigid=float(c_rigid),
        correlation_mirrored=float(c_mirror), correlation_before=corr_before,
        correlation_after=target.correlation(Ucur, F, fs), folds=count_folds(F, Ucur),
        below_margin=int(below_margin(F, Ucur, opts.precision).sum()),
        precision=opts.precision, distortion=distortion, levels=rows,
        start_below_margin=int(below_margin(F, U, opts.precision).sum()),
        timings=timings)
