"""Landmark-matched spherical maps: the conformal map bent so that landmarks meet their targets.

:func:`landmark_map` starts from the folding-free conformal map (Algorithm 2),
aligns it to the targets with the Möbius transformation that fits them best
(:func:`igl_spheremap.sphere.mobius.mobius_fit`), then either

* ``mode="hard"``: moves the landmarks onto their targets in continuation steps
  (:mod:`igl_spheremap.uses.landmarks`), each a smooth deformation of the
  sphere followed by Algorithm 1 for the harmonic energy with the landmarks
  fixed, under the fold barrier; or
* ``mode="soft"``: deforms the same way, then minimizes the landmark-matching
  energy (:class:`igl_spheremap.uses.landmarks.LandmarkEnergy`) under the fold barrier.

Both keep the map fold-free; a configuration they cannot reach without folds
ends as an honest failure (``success`` False, a message, a warning).

The continuation of ``mode="hard"``: each step moves every landmark a fraction
of the way along the great circle to its target by a smooth deformation of the
sphere (thin-plate spline interpolation of the landmarks' displacements,
applied through the exponential map: :mod:`igl_spheremap.uses.spline`); a step
that would fold a face is halved, a step that did not is doubled for the next.
A smooth deformation keeps every triangle's orientation in the limit of small
triangles, but not a nearly flat image triangle (the image of a 3D sliver,
angles near 0, 0 and 180 degrees): the deformation's curvature over the
triangle can carry its middle vertex across the opposite edge.  Those few faces
are untangled locally (:func:`igl_spheremap.untangle_folds`) with the landmarks
held fixed; if folds remain, the step is halved.  The deformation is smooth on
the sphere (not on the surface), so the crowded image triangles of thin
features move almost rigidly and keep their orientation.  Then Algorithm 1
minimizes the harmonic energy with the landmarks fixed, under the fold barrier.
"""

import time
import warnings

import numpy as np

from ..conformal_map import map_validated
from ..errors import SphericalMapWarning, plural
from ..folding.result import build_result, with_reorientation
from ..folding.untangle import untangle_folds
from ..mesh.arrays import as_points
from ..mesh.operators import dirichlet_energy, signed_volumes
from ..mesh.validate import validate_mesh
from ..optimize.direction import make_metric
from ..optimize.energy import Energy, Evaluation
from ..optimize.harmonic import HarmonicEnergy
from ..optimize.minimize import minimize
from ..options import map_options
from ..sphere.folds import count_folds, fold_free_blend
from ..sphere.geodesics import angles, slerp
from ..sphere.mobius import mobius_fit, mobius_transform
from .spline import AFFINE_MIN_LANDMARKS, deform

MODES = ("hard", "soft")

#: ``weight`` of ``mode="soft"`` when none is given.
DEFAULT_WEIGHT = 100.0

#: ``mode="soft"``: default largest landmark error (degrees) that counts as met; 2 degrees is
#: a chord of 0.035, :data:`igl_spheremap.uses.correspondence.SOFT_TOL` times the unit
#: sphere's ``sqrt(4 pi)``, the tolerance of ``surface_map``'s soft landmarks.
SOFT_TOL_DEG = 2.0

#: :func:`deformed`: a step's folds are untangled on the faces within this many edge rings
#: of them (``within`` of :func:`igl_spheremap.untangle_folds`: its Tutte patches reach 12
#: rings, their holes one more), at a cost that does not grow with the mesh.
UNTANGLE_WITHIN = 14

#: A step is halved at most this many times before the landmarks are declared
#: unreachable without folds.
MAX_HALVINGS = 10


def landmark_map(V, F, landmarks, targets, *, mode="hard", weight=None, landmark_tol=None,
                 options=None, callback=None, progress=False, **option_values):
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
    landmark_tol : float, optional
        ``mode="soft"`` only: the largest landmark error, in degrees, that counts as met
        (default :data:`SOFT_TOL_DEG`, 2 degrees); > 0.
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
        not be reached without folds (the map returned is then the last
        fold-free one) or, with ``mode="soft"``, when a landmark ends farther than
        ``landmark_tol`` from its target (a larger ``weight`` pulls it closer).

    Raises
    ------
    MeshError
        Invalid mesh.
    ValueError
        Bad landmarks (none, duplicates, out of range, on a vertex no face uses),
        bad targets (wrong shape, not finite, off the unit sphere, two equal), a
        face whose three vertices are landmarks with targets in the opposite
        orientation (no fold-free map reaches them), an unknown ``mode``, a
        ``weight`` or ``landmark_tol`` with ``mode="hard"``, or a non-positive one.

    Warns
    -----
    SphericalMapWarning
        If the result is not a success.
    """
    opts = map_options(options, **option_values)
    t0 = time.perf_counter()
    mesh = validate_mesh(V, F)
    landmarks, targets, weight, tol = _checked(mesh, landmarks, targets, mode, weight,
                                               landmark_tol)
    with opts.blas_limit():
        base, problem = map_validated(mesh, opts, callback, progress, t0)
        result = _bend(problem, base, landmarks, targets, mode, weight, callback)
    if result.failure is None and mode == "soft" and result.landmark_errors.max() > tol:
        far = result.landmark_errors > tol
        result.failure = (f"{int(far.sum())} of {far.size} landmarks farther than "
                          f"landmark_tol = {tol:g} deg from their targets (largest "
                          f"{result.landmark_errors.max():.3g} deg; a larger weight pulls "
                          f"them closer), fold-free; {result.message}")
        result.message = result.failure
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
    err = np.degrees(angles(U[landmarks], targets))
    result.landmark_errors = err
    if msg is None:
        result.message = with_reorientation(
            f"{plural(len(landmarks), 'landmark')} {'on' if mode == 'hard' else 'near'} their "
            f"targets (largest error {err.max():.3g} deg), fold-free; {rounds[-1].message}",
            problem.mesh)
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


def _checked(mesh, landmarks, targets, mode, weight, tol):
    """Landmarks in the validated numbering, unit targets, the weight and the tolerance;
    ValueErrors otherwise."""
    if mode not in MODES:
        raise ValueError(f"unknown mode {mode!r}; expected one of {list(MODES)}")
    if mode == "hard" and (weight is not None or tol is not None):
        raise ValueError("weight and landmark_tol apply to mode='soft' only")
    if mode == "soft":
        weight = DEFAULT_WEIGHT if weight is None else weight
        tol = SOFT_TOL_DEG if tol is None else tol
        for name, x in (("weight", weight), ("landmark_tol", tol)):
            if not (np.isfinite(x) and x > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {x}")
    lm, Q = checked_landmarks(mesh, landmarks, as_points(targets, "targets"))
    return lm, Q, weight, tol


def checked_landmarks(mesh, landmarks, targets):
    """Landmarks in ``mesh``'s numbering and unit targets, or a ValueError naming the problem.

    Parameters
    ----------
    mesh : igl_spheremap.ValidatedMesh
    landmarks : (k,) array_like of int
        Rows of the input ``V``.
    targets : (k, 3) float64 array
        Finite.

    Returns
    -------
    lm : (k,) int64 array
    Q : (k, 3) float64 array
    """
    ours = landmark_vertices(mesh, landmarks)
    if targets.shape[0] != ours.size:
        raise ValueError(f"{plural(ours.size, 'landmark')} but "
                         f"{plural(targets.shape[0], 'target')}")
    norm = np.linalg.norm(targets, axis=1)
    off = np.abs(norm - 1.0) > 1e-6
    if off.any():
        raise ValueError(f"{plural(int(off.sum()), 'target is', 'targets are')} not on the unit "
                         f"sphere (norm {norm[off][0]:.6g}; normalize them)")
    Q = targets / norm[:, None]
    from scipy.spatial import cKDTree

    pairs = cKDTree(Q).query_pairs(1e-9)
    if pairs:
        raise ValueError(f"{plural(len(pairs), 'pair')} of landmarks with the same target")
    _check_orientation(mesh.F, ours, Q)
    return ours, Q


def landmark_vertices(mesh, landmarks, name="landmark"):
    """Distinct landmark vertices (rows of the input ``V``) in ``mesh``'s numbering ((k,) int64).

    Raises
    ------
    ValueError
        Not a non-empty 1-D integer array, indices out of range, duplicates, or
        vertices used by no face (the message names ``name``).
    """
    lm = np.asarray(landmarks)
    if lm.ndim != 1 or lm.size == 0:
        raise ValueError(f"{name}s must be a non-empty 1-D array of vertex indices, got "
                         f"shape {lm.shape} (at least 1 landmark)")
    if lm.dtype == bool or not np.issubdtype(lm.dtype, np.integer):
        raise ValueError(f"{name}s must be integer vertex indices, got dtype {lm.dtype}")
    bad = (lm < 0) | (lm >= mesh.n_input)
    if bad.any():
        raise ValueError(f"{plural(int(bad.sum()), name + ' index', name + ' indices')} outside "
                         f"0..{mesh.n_input - 1}")
    values, first = np.unique(lm, return_index=True)
    if values.size < lm.size:
        k = np.setdiff1d(np.arange(lm.size), first)[0]  # the first repeat
        what = plural(lm.size - values.size, f"duplicate {name} index",
                      f"duplicate {name} indices")
        raise ValueError(f"{what} (first: vertex {lm[k]} at positions "
                         f"{np.flatnonzero(lm == lm[k]).tolist()}, counted from 0: lines of a "
                         "landmark file counted from 1 are one more)")
    inverse = np.full(mesh.n_input, -1, dtype=np.int64)
    inverse[mesh.vertex_index] = np.arange(mesh.vertex_index.size)
    ours = inverse[lm]
    if (ours < 0).any():
        what = plural(int((ours < 0).sum()), f"{name} is a vertex", f"{name}s are vertices")
        raise ValueError(f"{what} used by no face")
    return ours


def _check_orientation(F, lm, Q):
    """Refuse faces whose three vertices are landmarks with targets in mirrored order."""
    where = np.full(int(F.max()) + 1, -1, dtype=np.int64)
    where[lm] = np.arange(lm.size)
    all_three = (where[F] >= 0).all(axis=1)
    if not all_three.any():
        return
    T = Q[where[F[all_three]]]
    vol = signed_volumes(np.arange(3 * len(T)).reshape(-1, 3), T.reshape(-1, 3))
    if (vol <= 0).any():
        raise ValueError(f"{plural(int((vol <= 0).sum()), 'face has', 'faces have')} all three "
                         "vertices as landmarks with targets in mirrored (clockwise) order: no "
                         "fold-free map reaches them")


def continuation(problem, U, lm, Q, rounds, callback):
    """Move the landmarks of ``U`` (validated order) onto ``Q`` fold-free; append the rounds.

    First the deformation steps carry the landmarks all the way (the map stays a
    smooth deformation of ``U``, fold-free by construction, each step halved
    while it would fold a face), then one Algorithm 1 run minimizes the harmonic
    energy with the landmarks fixed, under the fold barrier.  (Minimizing between
    the steps makes spikes around the fixed landmarks whose nearly flat
    triangles the next step flips; see :data:`MAX_HALVINGS`.)

    Returns
    -------
    U : (n, 3) float64 array
        The last fold-free map (landmarks on ``Q`` on success).
    message : str or None
        None on success, else why the landmarks were not reached.
    """
    t0 = time.perf_counter()
    F = problem.F
    U_start = U
    Y, t = deformed(F, U, lm, Q)
    if t < 1.0:
        return U_start, (f"the landmarks cannot be reached without folds: a deformation step "
                         f"folded faces even at 1/{2 ** MAX_HALVINGS} of its length, "
                         f"{100 * t:.0f}% of the way and local untangling with the landmarks "
                         "fixed could not repair them (landmarks in mirrored order, or "
                         "targets much closer together than the landmarks' image triangles); "
                         "the map returned is the conformal map after the Möbius "
                         "transformation that fits the landmarks to the targets best")
    run = relaxed(problem, Y, lm)
    U = run.U
    rnd = problem.round(len(rounds), "landmark", Y, run, 0, t0, rounds[-1])
    rounds.append(rnd)
    if callback is not None:
        callback(rnd)
    return U, None if run.converged else f"did not converge: {run.message}"


def relaxed(problem, Y, lm):
    """Algorithm 1 for the harmonic energy from the fold-free map ``Y`` with the vertices ``lm``
    fixed, under the fold barrier (validated order); the :class:`Algorithm1Result`.

    The dilation projection stays (gauge): the discrete energy is not Möbius
    invariant, and without it the map would drift along the Möbius orbit even
    with every landmark already on its target.
    """
    opts = problem.options
    fixed = np.zeros(Y.shape[0], dtype=bool)
    fixed[lm] = True
    energy = HarmonicEnergy(problem.L, problem.area, opts.metric, opts.h1_solver)
    return minimize(energy, Y, problem.F, opts, fixed=fixed, fold_barrier=True,
                    gauge=opts.mobius)


#: Folded faces of a deformation step above which :func:`deformed` halves the step at once
#: instead of trying to untangle them locally.
MAX_UNTANGLED = 100


def deformed(F, U, lm, Q, max_untangled=MAX_UNTANGLED):
    """``U`` deformed in fold-free steps until its landmark rows are ``Q``.

    With ``k <= 4`` landmarks the spline with the constant polynomial is tried
    first and, if it does not get all the way, the affine one (neither is
    better on every pair: :data:`igl_spheremap.uses.spline.AFFINE_MIN_LANDMARKS`);
    the map that got further is returned.  A step that folds at most
    ``max_untangled`` faces has them untangled locally with the landmarks fixed
    (:func:`igl_spheremap.untangle_folds`); one that folds more is halved.

    Returns
    -------
    Y : (n, 3) float64 array
        The deformed map (fold-free).
    t : float
        How far the landmarks got (1 when they are on ``Q``).
    """
    best = None
    for linear in ([False, True] if len(lm) < AFFINE_MIN_LANDMARKS else [True]):
        Y, t = _steps(F, U, lm, Q, linear, max_untangled)
        if t == 1.0:
            return Y, t
        if best is None or t > best[1]:
            best = Y, t
    return best


def _steps(F, U, lm, Q, linear, max_untangled):
    """:func:`deformed` with one polynomial part (``linear``) of the spline."""
    P0 = U[lm].copy()
    t, step = 0.0, 1.0
    while t < 1.0:
        t1 = min(1.0, t + step)
        Y = _fold_free(F, U, deform(U, U[lm], slerp(P0, Q, t1), lm, linear=linear), lm,
                       max_untangled)
        if Y is None:
            step /= 2
            if step < 2.0 ** -MAX_HALVINGS:
                break
            continue
        U, t, step = Y, t1, min(2 * step, 1.0)
    return U, t


def _fold_free(F, U, Y, lm, max_untangled):
    """``Y`` (the step from the fold-free ``U``), or ``Y`` with its folded faces repaired with the
    landmarks fixed; None if neither.

    The repair first pulls the vertices of the folded faces back toward ``U``
    (:func:`igl_spheremap.sphere.folds.fold_free_blend`), then, if folds remain and
    there were at most ``max_untangled``, untangles them
    (:func:`igl_spheremap.untangle_folds`).  The landmarks stay on their step
    targets: untangling without them fixed moved landmarks next to a flipped
    sliver and the step had to be refused.
    """
    folds = count_folds(F, Y)
    if folds == 0:
        return Y
    fixed = np.zeros(Y.shape[0], dtype=bool)
    fixed[lm] = True
    Z = fold_free_blend(F, U, Y, fixed=fixed, corners="all")[0]
    if count_folds(F, Z) == 0:
        return Z
    if folds > max_untangled:
        return None
    Z, left = untangle_folds(F, Y, fixed=fixed, within=UNTANGLE_WITHIN)
    return Z if left == 0 else None


class LandmarkEnergy(Energy):
    """``E(U) = -1/2 tr(U^T L U) + lambda/2 sum_i |U_{p_i} - q_i|^2``.

    The harmonic energy (Eqs. 6, 13) plus a quadratic penalty pulling each
    landmark vertex ``p_i`` toward its target ``q_i`` on the unit sphere (Lui,
    Wang, Chan, Thompson, "Landmark constrained genus zero surface conformal
    mapping and its application to brain mapping research", Applied Numerical
    Mathematics 2007; the paper names this use of its optimizer in Section 1).
    ``dE/dU = -L U + lambda S^T (S U - q)`` with ``S`` the selection of the landmark
    rows.  The landmarks fix the Möbius freedom, so no gauge applies
    (``mobius_invariant`` is False).

    Parameters
    ----------
    L : (n, n) sparse matrix
        Negative semidefinite Laplacian.
    area : (n,) float64 array
        Vertex areas, mesh scaled to total area ``4 pi``.
    landmarks : (k,) int array
        Distinct vertex indices.
    targets : (k, 3) float64 array
        Unit vectors.
    weight : float
        ``lambda`` (> 0, dimensionless: the harmonic energy of a conformal map is
        ``4 pi``, a landmark 1 radian off adds about ``lambda / 2``).
    metric : {"H1", "L2"}
    h1_solver : str
    """

    mobius_invariant = False

    def __init__(self, L, area, landmarks, targets, weight, metric="H1", h1_solver="auto"):
        super().__init__(area, make_metric(metric, L, area, h1_solver))
        self.L = L
        self.landmarks = np.asarray(landmarks, dtype=np.int64)
        self.targets = np.asarray(targets, dtype=np.float64)
        self.weight = float(weight)

    def evaluate(self, U):
        LU = self.L @ U
        D = U[self.landmarks] - self.targets
        value = dirichlet_energy(self.L, U, LU) + 0.5 * self.weight * float(np.vdot(D, D))
        return Evaluation(U=U, value=value, LU=LU, cache=D)

    def euclidean_gradient(self, ev):
        g = -ev.LU
        g[self.landmarks] += self.weight * ev.cache
        return g
