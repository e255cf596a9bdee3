"""Atlas registration of large subjects through an icosphere, and from a surface alone.

On a subject with many more vertices than the target (an individual cortex of
150k vertices against fsaverage5's 10k), Algorithm 1 at full resolution moves
the sphere slowly: the coarse levels need large smooth displacements, and every
step is checked against the fold barrier of hundreds of thousands of tiny
faces.  Spherical Demons works on an icosahedral pyramid for the same reason
(Yeo et al., IEEE TMI 29(3) 2010, Section III-E).  :func:`register_sphere_multires`:

1. the subject's features are carried to an icosphere (FreeSurfer's order,
   :func:`igl_spheremap.mesh.shapes.icosphere`) laid on its start sphere, by
   area-corrected adaptive barycentric weights
   (:func:`igl_spheremap.uses.resampling.resampling_matrix`, ``"adap_bary_area"``:
   every subject vertex contributes in proportion to its area, no aliasing);
2. the icosphere is registered with the whole schedule
   (:func:`igl_spheremap.uses.atlas.register_sphere`, rigid stage included);
3. the map is lifted to the subject: each subject vertex keeps its barycentric
   coordinates in the icosphere face that holds it on the start sphere, taken
   on the registered icosphere;
4. faces the lift leaves folded are untangled locally
   (:func:`igl_spheremap.untangle_folds`); if any remain, the icosphere's
   displacement is halved (blended with its rigidly aligned start) and the
   lift tried again, down to 1/16 (then the rigidly aligned start); from that
   fold-free map Algorithm 1 moves the vertices toward the full lift under the
   fold barrier (:class:`igl_spheremap.optimize.matching.PointMatchEnergy`);
5. the last level of the schedule runs at full resolution from the lifted map
   under the fold barrier.

:func:`register_surface` starts from a surface: its area-balanced sphere
(:func:`igl_spheremap.spherical_conformal_map`, ``kind="area_balanced"``),
then either registration.
"""

import time
import warnings
from dataclasses import replace

import numpy as np

from ..conformal_map import spherical_conformal_map
from ..errors import SphericalMapWarning
from ..folding.untangle import untangle_folds
from ..mesh.arrays import unit_rows
from ..mesh.operators import laplacian, to_sphere_area, vertex_areas
from ..mesh.shapes import icosphere
from ..optimize.matching import PointMatchEnergy
from ..optimize.minimize import minimize
from ..sphere.folds import count_folds
from .atlas import (DEFAULT_LEVELS, TargetSphere, deformation_distortion, register_sphere,
                    registration_options, start_area_log, start_warnings)
from .resampling import resampling_matrix

#: Subjects with more vertices than this are registered through an icosphere by
#: :func:`register_surface` (fsaverage5's 10,242 vertices go straight).
MULTIRES_ABOVE = 30_000


def _lift(U0, F, ico, ico_F, ico_registered):
    """The subject's vertices moved by the icosphere's registration: (U, folds left, untangled)."""
    U = unit_rows(resampling_matrix(ico, ico_F, U0) @ ico_registered)
    folds = count_folds(F, U)
    if not folds:
        return U, 0, 0
    U, left = untangle_folds(F, U)
    return U, int(left), int(folds)


def _follow(U, F, Q, opts, iterations=200, weight=100.0, sigma_deg=2.0):
    """From the fold-free ``U``, as close to ``Q`` as the fold barrier allows (Algorithm 1)."""
    energy = PointMatchEnergy(Q, to_sphere_area(vertex_areas(U, F)), laplacian(U, F, "cotan"),
                              weight, np.radians(sigma_deg))
    run = minimize(energy, U, F, opts.updated(gtol=1e-8, max_iter=iterations),
                   fold_barrier=opts.fold_barrier)
    return run.U


def lifted(U0, F, ico, ico_F, coarse, opts):
    """The subject's fold-free map from the registered icosphere (steps 3-4 of the module docstring).

    Returns
    -------
    U : (n, 3) float64 array
    info : dict
        ``lift_untangled`` (folded faces the lifts untangled), ``lift_share``
        (the share of the icosphere's displacement lifted directly).
    """
    Ul, bad, untangled = _lift(U0, F, ico, ico_F, coarse.U)
    share, start = 1.0, ico @ coarse.rotation.T
    while bad and share > 1.0 / 16:
        share /= 2
        Ul, bad, more = _lift(U0, F, ico, ico_F, unit_rows((1 - share) * start + share * coarse.U))
        untangled += more
    if bad:
        Ul, share = U0 @ coarse.rotation.T, 0.0
    if share < 1.0:
        Ul = _follow(Ul, F, unit_rows(resampling_matrix(ico, ico_F, U0) @ coarse.U), opts)
    return Ul, dict(lift_untangled=untangled, lift_share=share)


def register_sphere_multires(U, F, features, target_U, target_F, target_features, *,
                             levels=None, coarse_level=5, polish_iter=100, subject_area=None,
                             surface=None, options=None, **kwargs):
    """:func:`igl_spheremap.uses.atlas.register_sphere` through an icosphere (module docstring).

    Parameters
    ----------
    U, F, features, target_U, target_F, target_features
        As :func:`igl_spheremap.uses.atlas.register_sphere`.
    levels : sequence of Level, optional
        The schedule (default :data:`igl_spheremap.uses.atlas.DEFAULT_LEVELS`):
        all of it on the icosphere, its last level again at full resolution.
    coarse_level : int
        Icosphere level (5: 10,242 vertices, the resolution of fsaverage5 and of
        Spherical Demons' finest level).
    polish_iter : int
        Iterations of the full-resolution level (0: none).
    subject_area : (n,) float array, optional
        Vertex areas weighting the subject's features on the icosphere (the
        anatomical surface's; default: the start sphere's).
    surface : (n, 3) float array, optional
        The subject's surface (flags a poor start, as in ``register_sphere``).
    options : MapOptions or dict, optional
        As :func:`igl_spheremap.uses.atlas.register_sphere`.
    **kwargs
        Other keywords of :func:`igl_spheremap.uses.atlas.register_sphere`
        (``vertex_weights`` is used at full resolution only).

    Returns
    -------
    AtlasRegistrationResult
        Of the full-resolution level, with ``rotation``, ``correlation_rigid``,
        ``correlation_mirrored``, ``correlation_before`` and ``warnings`` of the
        icosphere's stage, ``levels`` of both stages, and ``timings``
        ``coarse``, ``lift`` and ``polish``.
    """
    t0 = time.perf_counter()
    levels = DEFAULT_LEVELS if levels is None else tuple(levels)
    opts = registration_options(options)
    U0, F = unit_rows(U), np.asarray(F, dtype=np.int64)
    fs = np.asarray(features, dtype=np.float64)
    ico, ico_F = icosphere(coarse_level, order="freesurfer")
    if subject_area is None:
        subject_area = vertex_areas(U0 if surface is None else np.asarray(surface, float), F)
    area = np.asarray(subject_area, dtype=np.float64)
    W = resampling_matrix(U0, F, ico, ico_F, method="adap_bary_area", current_area=area,
                          new_area=vertex_areas(ico, ico_F))
    coarse_kwargs = {k: v for k, v in kwargs.items() if k != "vertex_weights"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SphericalMapWarning)
        coarse = register_sphere(ico, ico_F, W @ fs, target_U, target_F, target_features,
                                 levels=levels, options=opts, **coarse_kwargs)
        t1 = time.perf_counter()
        Ul, info = lifted(U0, F, ico, ico_F, coarse, opts)
        t2 = time.perf_counter()
        fine = register_sphere(Ul, F, fs, target_U, target_F, target_features,
                               levels=[replace(levels[-1], max_iter=polish_iter)], rigid=False,
                               options=opts, **kwargs)
    fine.rotation = coarse.rotation
    fine.distortion = deformation_distortion(F, U0 @ coarse.rotation.T, fine.U)
    fine.start_area_log = start_area_log(surface, F, U0)
    fine.warnings = start_warnings(fine.start_area_log, coarse.correlation_rigid,
                                   coarse.correlation_mirrored)
    fine.correlation_rigid = coarse.correlation_rigid
    fine.correlation_mirrored = coarse.correlation_mirrored
    fine.correlation_before = TargetSphere(target_U, target_F, target_features).correlation(
        U0, F, fs.reshape(len(fs), -1))
    fine.levels = ([dict(lv, stage="coarse") for lv in coarse.levels]
                   + [dict(lv, stage="full", **info) for lv in fine.levels])
    fine.timings = dict(coarse=t1 - t0, lift=t2 - t1, polish=time.perf_counter() - t2)
    fine.seconds = time.perf_counter() - t0
    _warn_unless_success(fine, "register_sphere_multires")
    return fine


def _warn_unless_success(result, name):
    if not result.success:
        warnings.warn(f"{name}: {result.message}", SphericalMapWarning, stacklevel=3)


def register_surface(V, F, features, target_U, target_F, target_features, *, sphere=None,
                     multiresolution=None, options=None, **kwargs):
    """Register a subject's surface to a target sphere: its area-balanced sphere, then the registration.

    Parameters
    ----------
    V : (n, 3) float array
    F : (m, 3) int array
        The subject's closed genus-0 surface (e.g. ``lh.white``).
    features, target_U, target_F, target_features
        As :func:`igl_spheremap.uses.atlas.register_sphere`.
    sphere : (n, 3) float array, optional
        The subject's sphere; default its area-balanced sphere
        (``spherical_conformal_map(V, F, kind="area_balanced")`` with the
        registration's ``precision``).
    multiresolution : bool, optional
        Through an icosphere (:func:`register_sphere_multires`); default when
        the subject has more than :data:`MULTIRES_ABOVE` vertices.
    options : MapOptions or dict, optional
        As :func:`igl_spheremap.uses.atlas.register_sphere` (the sphere uses
        its ``precision``).
    **kwargs
        Keywords of the registration function.

    Returns
    -------
    AtlasRegistrationResult
        In ``F``'s vertex numbering (the sphere's faces, oriented outward, are
        ``result.F``); ``timings["sphere"]`` the seconds of the sphere.
    """
    t = time.perf_counter()
    opts = registration_options(options)
    F = np.asarray(F, dtype=np.int64)
    if sphere is None:
        mapped = spherical_conformal_map(V, F, kind="area_balanced", precision=opts.precision)
        sphere, F = mapped.U, mapped.F
    seconds = time.perf_counter() - t
    if multiresolution is None:
        multiresolution = np.shape(V)[0] > MULTIRES_ABOVE
    run = register_sphere_multires if multiresolution else register_sphere
    result = run(sphere, F, features, target_U, target_F, target_features, surface=V,
                 options=opts, **kwargs)
    result.F = F
    result.timings["sphere"] = seconds
    result.seconds += seconds
    return result
