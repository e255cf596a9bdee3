"""Hard landmarks by continuation: the checks of landmarks and targets, and the steps that move them.

Each step moves every landmark a fraction of the way along the great circle to
its target by a smooth deformation of the sphere (thin-plate spline
interpolation of the landmarks' displacements, applied through the exponential
map: :mod:`igl_spheremap.landmark_deform`); a step that would fold a face is
halved, a step that did not is doubled for the next. A smooth deformation
keeps every triangle's orientation in the limit of small triangles, but not a
nearly flat image triangle (the image of a 3D sliver, angles near 0, 0 and 180
degrees): the deformation's curvature over the triangle can carry its middle
vertex across the opposite edge. Those few faces are untangled locally
(:func:`igl_spheremap.untangle_folds`) with the landmarks held fixed; if folds
remain, the step is halved. The deformation is smooth on the sphere (not on
the surface), so the crowded image triangles of thin features move almost
rigidly and keep their orientation. Then Algorithm 1 minimizes the harmonic
energy with the landmarks fixed, under the fold barrier.
"""

import time

import numpy as np
from .algorithm1 import minimize
from .energies import HarmonicEnergy
from .landmark_deform import AFFINE_MIN_LANDMARKS, deform, slerp
from .metrics import count_folds, signed_volumes
from .untangle import untangle_folds

#: A step is halved at most this many times before the landmarks are declared
#: unreachable without folds.
MAX_HALVINGS = 10


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
    lm = np.asarray(landmarks)
    if lm.ndim != 1 or lm.size == 0:
        raise ValueError(f"landmarks must be a non-empty 1-D array of vertex indices, got "
                         f"shape {lm.shape} (at least 1 landmark)")
    if lm.dtype == bool or not np.issubdtype(lm.dtype, np.integer):
        raise ValueError(f"landmarks must be integer vertex indices, got dtype {lm.dtype}")
    bad = (lm < 0) | (lm >= mesh.n_input)
    if bad.any():
        raise ValueError(f"{int(bad.sum())} landmark indices outside 0..{mesh.n_input - 1}")
    if np.unique(lm).size < lm.size:
        raise ValueError(f"{lm.size - np.unique(lm).size} duplicate landmark indices")
    if targets.shape[0] != lm.size:
        raise ValueError(f"{lm.size} landmarks but {targets.shape[0]} targets")
    norm = np.linalg.norm(targets, axis=1)
    off = np.abs(norm - 1.0) > 1e-6
    if off.any():
        raise ValueError(f"{int(off.sum())} targets are not on the unit sphere (norm "
                         f"{norm[off][0]:.6g}; normalize them)")
    Q = targets / norm[:, None]
    from scipy.spatial import cKDTree

    pairs = cKDTree(Q).query_pairs(1e-9)
    if pairs:
        raise ValueError(f"{len(pairs)} pairs of landmarks with the same target")
    inverse = np.full(mesh.n_input, -1, dtype=np.int64)
    inverse[mesh.vertex_index] = np.arange(mesh.vertex_index.size)
    ours = inverse[lm]
    if (ours < 0).any():
        raise ValueError(f"{int((ours < 0).sum())} landmarks are vertices used by no face")
    _check_orientation(mesh.F, ours, Q)
    return ours, Q


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
        raise ValueError(f"{int((vol <= 0).sum())} faces have all three vertices as landmarks "
                         "with targets in mirrored (clockwise) order: no fold-free map "
                         "reaches them")


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
    opts, F = problem.options, problem.F
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
    fixed = np.zeros(U.shape[0], dtype=bool)
    fixed[lm] = True
    energy = HarmonicEnergy(problem.L, problem.area, opts.metric, opts.h1_solver)
    # The dilation projection stays (gauge): the discrete energy is not Möbius
    # invariant, and without it the map would drift along the Möbius orbit even
    # with every landmark already on its target.
    run = minimize(energy, Y, F, opts, fixed=fixed, fold_barrier=True, gauge=opts.mobius)
    U = run.U
    rnd = problem.round(len(rounds), "landmark", Y, run, 0, t0, rounds[-1])
    rounds.append(rnd)
    if callback is not None:
        callback(rnd)
    return U, None if run.converged else f"did not converge: {run.message}"


def deformed(F, U, lm, Q):
    """``U`` deformed in fold-free steps until its landmark rows are ``Q``.

    With ``k <= 4`` landmarks the spline with the constant polynomial is tried
    first and, if it does not get all the way, the affine one (neither is
    better on every pair: :data:`igl_spheremap.landmark_deform.AFFINE_MIN_LANDMARKS`);
    the map that got further is returned.

    Returns
    -------
    Y : (n, 3) float64 array
        The deformed map (fold-free).
    t : float
        How far the landmarks got (1 when they are on ``Q``).
    """
    best = None
    for linear in ([False, True] if len(lm) < AFFINE_MIN_LANDMARKS else [True]):
        Y, t = _steps(F, U, lm, Q, linear)
        if t == 1.0:
            return Y, t
        if best is None or t > best[1]:
            best = Y, t
    return best


def _steps(F, U, lm, Q, linear):
    """:func:`deformed` with one polynomial part (``linear``) of the spline."""
    P0 = U[lm].copy()
    t, step = 0.0, 1.0
    while t < 1.0:
        t1 = min(1.0, t + step)
        Y = _fold_free(F, deform(U, U[lm], slerp(P0, Q, t1), lm, linear=linear), lm)
        if Y is None:
            step /= 2
            if step < 2.0 ** -MAX_HALVINGS:
                break
            continue
        U, t, step = Y, t1, min(2 * step, 1.0)
    return U, t


def _fold_free(F, Y, lm, max_folds=100):
    """``Y``, or ``Y`` with its few folded faces untangled with the landmarks fixed; None if neither.

    The landmarks stay on their step targets: untangling without them fixed moved
    landmarks next to a flipped sliver and the step had to be refused.
    """
    folds = count_folds(F, Y)
    if folds == 0:
        return Y
    if folds > max_folds:
        return None
    fixed = np.zeros(Y.shape[0], dtype=bool)
    fixed[lm] = True
    Z, left = untangle_folds(F, Y, fixed=fixed)
    return Z if left == 0 else None
