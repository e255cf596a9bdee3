"""Landmark-matched spherical maps: the conformal map bent so that landmarks meet their targets.

:func:`landmark_map` starts from the folding-free conformal map (Algorithm 2),
aligns it to the targets with the Möbius transformation that fits them best
(:func:`igl_spheremap.mobius.mobius_fit`), then either

* ``mode="hard"``: moves the landmarks onto their targets in continuation steps
  (:mod:`igl_spheremap.landmark_steps`), each a smooth deformation of the
  sphere followed by Algorithm 1 for the harmonic energy with the landmarks
  fixed, under the fold barrier; or
* ``mode="soft"``: deforms the same way, then minimizes the landmark-matching
  energy (:class:`igl_spheremap.energies.LandmarkEnergy`) under the fold barrier.

Both keep the map fold-free; a configuration they cannot reach without folds
ends as an honest failure (``success`` False, a message, a warning).
"""

import time
import warnings

import numpy as np

from ._checks import as_points
from .algorithm1 import minimize
from .algorithm2 import build_result, map_validated
from .energies import LandmarkEnergy
from .errors import SphericalMapWarning
from .landmark_steps import continuation, deformed
from .metrics import count_folds
from .mobius import mobius_fit, mobius_transform
from .options import map_options
from .validation import validate_mesh

MODES = ("hard", "soft")

#: ``weight`` of ``mode="soft"`` when none is given.
DEFAULT_WEIGHT = 100.0


def landmark_map(V, F, landmarks, targets, *, mode="hard", weight=None, options=None,
                 callback=None, progress=False, **option_values):
    """Spherical map of a closed genus-0 mesh whose landmark vertices go to given points.

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
        A closed, connected, genus-0 triangle mesh.
    landmarks : (k,) array_like of int
        Distinct vertex indices (rows of ``V`` used by ``F``), ``k >= 1``.
    targets : (k, 3) array_like of float
        Where each landmark goes: points on the unit sphere (norm within 1e-6
        of 1; they are normalized), distinct.
    mode : {"hard", "soft"}
        ``"hard"``: each landmark ends exactly on its target (to rounding,
        <= 1e-12) and the rest minimizes the harmonic energy with the landmarks
        fixed.  ``"soft"``: minimizes ``E + weight / 2 sum |U_p - q|^2`` (Lui et al.
        2007); the landmark error falls as ``weight`` grows.
    weight : float, optional
        ``mode="soft"`` only (default :data:`DEFAULT_WEIGHT`); > 0, dimensionless
        (the harmonic energy of a conformal map is ``4 pi``).
    options : MapOptions or dict, optional
        Options of the conformal map and of every Algorithm 1 run.
    callback : callable, optional
        ``callback(round)`` with each finished :class:`igl_spheremap.Round`.
    progress : bool
        tqdm progress bar of the conformal map's iterations.
    **option_values
        Fields of :class:`igl_spheremap.MapOptions`.

    Returns
    -------
    SphericalMapResult
        As :func:`igl_spheremap.spherical_conformal_map` (rounds: the conformal
        map's, then ``"landmark"`` rounds), with ``landmark_errors`` (k,) in
        degrees.  ``success`` is False, with a message, when the landmarks could
        not be reached without folds; the map returned is then the last
        fold-free one.

    Raises
    ------
    MeshError
        Invalid mesh.
    ValueError
        Bad landmarks (none, duplicates, out of range, on a vertex no face uses),
        bad targets (wrong shape, not finite, off the unit sphere, two equal), a
        face whose three vertices are landmarks with targets in the opposite
        orientation (no fold-free map reaches them), an unknown ``mode``, a
        ``weight`` with ``mode="hard"`` or a non-positive one.

    Warns
    -----
    SphericalMapWarning
        If the result is not a success.
    """
    opts = map_options(options, **option_values)
    t0 = time.perf_counter()
    mesh = validate_mesh(V, F)
    landmarks, targets, weight = _checked(mesh, landmarks, targets, mode, weight)
    with opts.blas_limit():
        base, problem = map_validated(mesh, opts, callback, progress, t0)
        result = _bend(problem, base, landmarks, targets, mode, weight, callback)
    result.seconds = time.perf_counter() - t0
    if not result.success:
        warnings.warn(f"landmark_map: {result.message}", SphericalMapWarning, stacklevel=2)
    return result


def _bend(problem, base, landmarks, targets, mode, weight, callback):
    """The landmark stage after the conformal map ``base``."""
    t = time.perf_counter()
    rounds = list(base.rounds)
    U = _aligned(problem, problem.mesh.from_input(base.U), landmarks, targets)
    if base.folds:
        U, msg = problem.mesh.from_input(base.U), "the conformal map has folds: " + base.message
    elif mode == "soft":
        U, msg = _soft(problem, U, landmarks, targets, weight, rounds, callback)
    else:
        U, msg = continuation(problem, U, landmarks, targets, rounds, callback)
    result = build_result(problem, rounds, U, count_folds(problem.F, U), message=msg)
    result.failure = msg
    err = np.degrees(np.arctan2(np.linalg.norm(np.cross(U[landmarks], targets), axis=1),
                                np.sum(U[landmarks] * targets, axis=1)))
    result.landmark_errors = err
    if msg is None:
        result.message = (f"{len(landmarks)} landmarks {'on' if mode == 'hard' else 'near'} "
                          f"their targets (largest error {err.max():.3g} deg), fold-free; "
                          f"{rounds[-1].message}")
    result.timings = {**base.timings, "landmarks": time.perf_counter() - t}
    return result


def _aligned(problem, U, landmarks, targets):
    """``U`` after the Möbius transformation that best fits the landmarks to the targets.

    If the transformation folds faces (it can flip large flat image triangles),
    only its rotation is applied.
    """
    c, R, _ = mobius_fit(U[landmarks], targets)
    Y = mobius_transform(U, c) @ R.T if np.any(c) else U @ R.T
    if count_folds(problem.F, Y):
        _, R, _ = mobius_fit(U[landmarks][:2], targets[:2])
        Y = U @ R.T
    return Y


def _soft(problem, U, landmarks, targets, weight, rounds, callback):
    """Minimize the landmark energy from the map deformed onto the targets.

    From the fitted conformal map itself the penalty pulls single vertices, whose
    stars the fold barrier soon freezes (the error then hardly depends on the
    weight); from the smoothly deformed map (landmarks on their targets) the
    landmarks relax back toward the conformal positions as far as the weight lets them.
    """
    t0 = time.perf_counter()
    opts = problem.options
    U_init, _ = deformed(problem.F, U, landmarks, targets)
    energy = LandmarkEnergy(problem.L, problem.area, landmarks, targets, weight, opts.metric,
                            opts.h1_solver)
    run = minimize(energy, U_init, problem.F, opts, fold_barrier=True)
    rnd = problem.round(len(rounds), "landmark", U_init, run, count_folds(problem.F, U_init),
                        t0, rounds[-1])
    rounds.append(rnd)
    if callback is not None:
        callback(rnd)
    return problem.mesh.from_input(rnd.U), None if run.converged else (
        f"landmark energy not minimized: {run.message}")


def _checked(mesh, landmarks, targets, mode, weight):
    """Landmarks in the validated numbering, unit targets and the weight; ValueErrors otherwise."""
    if mode not in MODES:
        raise ValueError(f"unknown mode {mode!r}; expected one of {list(MODES)}")
    if mode == "hard" and weight is not None:
        raise ValueError("weight applies to mode='soft' only")
    if mode == "soft":
        weight = DEFAULT_WEIGHT if weight is None else weight
        if not (np.isfinite(weight) and weight > 0):
            raise ValueError(f"weight must be a finite number > 0, got {weight}")
    from .landmark_steps import checked_landmarks

    lm, Q = checked_landmarks(mesh, landmarks, as_points(targets, "targets"))
    return lm, Q, weight
