"""Hard landmarks by continuation: the checks of landmarks and targets, and the steps that move them.

Each step moves every landmark a fraction of the way along the great circle to
its target by a smooth deformation of the sphere (Gaussian radial basis
interpolation of the landmarks' displacements, applied through the exponential
map); a step that would fold a face is halved, a step that did not is doubled
for the next.  A smooth deformation keeps every triangle's orientation in the
limit of small triangles, but not a nearly flat image triangle (the image of a
3D sliver, angles near 0, 0 and 180 degrees): the deformation's curvature over
the triangle can carry its middle vertex across the opposite edge.  Those few
faces are untangled locally (:func:`igl_spheremap.untangle_folds`) when that
leaves every landmark in place; otherwise the step is halved.  The deformation is smooth on the sphere (not on the surface), so
the crowded image triangles of thin features move almost rigidly and keep
their orientation.  Then Algorithm 1 minimizes the harmonic energy with the
landmarks fixed, under the fold barrier.
"""

import time

import numpy as np
from .algorithm1 import minimize
from .energies import HarmonicEnergy
from .metrics import count_folds, signed_volumes
from .sphere_product import rowdot, unit_rows
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


def _angles(A, B):
    return np.arctan2(np.linalg.norm(np.cross(A, B), axis=1), rowdot(A, B))


def slerp(A, B, t):
    """Points the fraction ``t`` of the way from ``A`` to ``B`` along great circles ((k, 3))."""
    if t >= 1.0:
        return B.copy()
    theta = _angles(A, B)
    s = np.sin(theta)
    safe = s > 1e-12
    wa = np.where(safe, np.sin((1.0 - t) * theta) / np.where(safe, s, 1.0), 1.0 - t)
    wb = np.where(safe, np.sin(t * theta) / np.where(safe, s, 1.0), t)
    return unit_rows(wa[:, None] * A + wb[:, None] * B)


def kernel_width(A, theta):
    """Chordal width of the Gaussian deformation kernel for landmarks at ``A`` moving by ``theta``.

    Half the median spacing of the landmarks (each landmark's correction stays
    local: the Möbius fit already took the global part), but at least three
    times the largest displacement (a bump carried further than its own width
    pinches the triangles in front of it), clipped to [0.05, 2].
    """
    from scipy.spatial import cKDTree

    spacing = np.median(cKDTree(A).query(A, k=2)[0][:, 1]) if A.shape[0] > 1 else 2.0
    return float(np.clip(max(0.5 * spacing, 3.0 * float(np.max(theta, initial=0.0))), 0.05,
                         2.0))


def deform(U, A, B, lm, chunk=1 << 16):
    """``U`` deformed smoothly so that the landmark rows go from ``A`` to ``B`` (exactly).

    The landmarks' displacements ``log_A(B)`` (tangent vectors whose length is
    the angle) are interpolated over the sphere by Gaussian radial basis
    functions of the chordal distance (width :func:`kernel_width`), projected on
    each vertex's tangent plane and applied through the exponential map; far
    from the landmarks nothing moves.
    """
    theta = _angles(A, B)
    T = B - rowdot(A, B)[:, None] * A
    nt = np.linalg.norm(T, axis=1)
    D = np.where(nt[:, None] > 0, T * (theta / np.where(nt > 0, nt, 1.0))[:, None], 0.0)
    sigma = kernel_width(A, theta)
    Phi = np.exp(-np.maximum(2.0 - 2.0 * A @ A.T, 0.0) / sigma ** 2)
    alpha = np.linalg.lstsq(Phi, D, rcond=None)[0]
    Y = np.empty_like(U)
    for a in range(0, U.shape[0], chunk):
        X = U[a:a + chunk]
        d = np.exp(-np.maximum(2.0 - 2.0 * X @ A.T, 0.0) / sigma ** 2) @ alpha
        d -= rowdot(d, X)[:, None] * X
        r = np.linalg.norm(d, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            Y[a:a + chunk] = (np.cos(r)[:, None] * X
                              + np.where(r[:, None] > 0, np.sin(r)[:, None] * d / r[:, None], 0))
    Y[lm] = B
    return Y


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
                         f"{100 * t:.0f}% of the way and local untangling could not repair "
                         "them without moving a landmark (landmarks in mirrored order, or "
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

    Returns
    -------
    Y : (n, 3) float64 array
        The deformed map (fold-free).
    t : float
        How far the landmarks got (1 when they are on ``Q``).
    """
    P0 = U[lm].copy()
    t, step = 0.0, 1.0
    while t < 1.0:
        t1 = min(1.0, t + step)
        Y = _fold_free(F, deform(U, U[lm], slerp(P0, Q, t1), lm), lm)
        if Y is None:
            step /= 2
            if step < 2.0 ** -MAX_HALVINGS:
                break
            continue
        U, t, step = Y, t1, min(2 * step, 1.0)
    return U, t


def _fold_free(F, Y, lm, max_folds=100):
    """``Y``, or ``Y`` with its few folded faces untangled around fixed landmarks; None if neither."""
    folds = count_folds(F, Y)
    if folds == 0:
        return Y
    if folds > max_folds:
        return None
    Z, left = untangle_folds(F, Y)
    return Z if left == 0 and np.array_equal(Z[lm], Y[lm]) else None
