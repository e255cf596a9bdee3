"""A mesh metric compressed along the direction a conformal map crowds in.

A conformal map crowds thin and elongated parts exponentially (a tube of length
/ circumference ``M`` spans a length ratio of ~``exp(2 pi M)``).  Compressing the
metric of each crowded face by a factor ``K_f >= 1`` along the gradient of the
log conformal factor (the direction in which the map shrinks) and mapping that
metric conformally gives, for the input metric, a quasi-conformal map with
dilatation ``K_f`` on those faces and conformal elsewhere: angle distortion traded
for room where the float32 margin needs it
(:func:`compressed_metric_map`).
"""

import time

import igl
import numpy as np

from ..errors import MeshError
from ..folding.centering import final_centering
from ..folding.problem import MapProblem
from ..folding.rounds import gauss_round, run_rounds
from ..mesh.intrinsic_delaunay import intrinsic_operators
from ..mesh.operators import to_sphere_area
from ..sphere.folds import count_below_margin, count_folds, unit_roundoff, volumes_and_margins
from ..sphere.mobius import mobius_center
from ..sphere.quality import conformal_factor


#: Faces are pushed to this many times their margin (headroom for the reruns'
#: Algorithm 1, which may shrink them again down to the margin).
GAMMA = 8.0

#: ``K_f`` is multiplied by ``1 + deficit_f / DEFICIT_SCALE`` per step, the deficit
#: in nats of length (``log(GAMMA * margin / s)``, about the log of how much the
#: face's edges must grow).
DEFICIT_SCALE = 2.0


def compressed_lengths(V, F, direction, K):
    """Edge lengths of the metric compressed by ``1 / K_f`` along ``direction[f]`` in each face.

    In face ``f`` the metric is ``g - (1 - 1 / K_f^2) d d^T`` (``d`` a unit vector in
    the face plane), a valid metric on that face.  An edge's lengths in its two
    faces differ slightly and are averaged; then faces left (nearly) degenerate
    get their two shorter edges lengthened until ``l_max <= (l_a + l_b) / 1.01``.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
    direction : (m, 3) float64 array
        Unit vectors in the face planes (zero rows: no compression).
    K : (m,) float64 array
        Compression factors, >= 1.

    Returns
    -------
    (m, 3) float64 array
        Edge lengths, column ``c`` opposite corner ``c`` (``igl.edge_lengths`` order).
    """
    E = np.stack([V[F[:, 2]] - V[F[:, 1]], V[F[:, 0]] - V[F[:, 2]],
                  V[F[:, 1]] - V[F[:, 0]]], axis=1)  # (m, 3 edges, 3)
    proj = np.einsum("mek,mk->me", E, direction)
    l2 = np.einsum("mek,mek->me", E, E) - (1.0 - 1.0 / K[:, None] ** 2) * proj ** 2
    _, uE, EMAP = igl.unique_edge_map(F)[:3]
    m, ne = F.shape[0], uE.shape[0]
    flat = np.sqrt(np.maximum(l2, 0.0)).T.ravel()  # half-edge f + m * c (libigl's order)
    lu = np.bincount(EMAP, weights=flat, minlength=ne) / np.bincount(EMAP, minlength=ne)
    return _fatten(lu, EMAP.reshape(3, m).T)


def _fatten(lu, emap, slack=1e-2, passes=20):
    """Lengthen the two shorter edges of faces that violate ``l_max <= (l_a + l_b) / (1 + slack)``.

    Edges are shared, so this repeats (each edge takes the largest demand of its
    faces).  libigl's intrinsic Delaunay flips fail on nearly degenerate faces.
    """
    rows = np.arange(emap.shape[0])[:, None]
    for _ in range(passes):
        lf = lu[emap]
        order = np.argsort(lf, axis=1)
        srt = lf[rows, order]
        bad = (1.0 + slack) * srt[:, 2] - srt[:, 0] - srt[:, 1] > 0
        if not bad.any():
            break
        scale = np.ones(emap.shape[0])
        scale[bad] = (1.0 + slack) * srt[bad, 2] / (srt[bad, 0] + srt[bad, 1])
        np.maximum.at(lu, emap[rows, order][:, :2].ravel(),
                      (srt[:, :2] * scale[:, None]).ravel())
    return lu[emap]


def crowding_direction(V, F, U):
    """Unit gradient of the log conformal factor in each face ((m, 3) float64; zero where flat).

    The direction in which the map ``U`` shrinks the mesh fastest
    (:func:`igl_spheremap.sphere.quality.conformal_factor`, ``igl.grad``).
    """
    u = 0.5 * np.log(np.maximum(conformal_factor(V, F, U), 1e-300))
    m = F.shape[0]
    g = (igl.grad(V, F) @ u).reshape(3, m).T
    norm = np.linalg.norm(g, axis=1)
    out = np.zeros_like(g)
    ok = norm > 0
    out[ok] = g[ok] / norm[ok, None]
    return out


def smooth_faces(F, x, n, steps=2):
    """A per-face quantity averaged through the vertices ``steps`` times, never lowered."""
    cnt = np.maximum(np.bincount(F.ravel(), minlength=n), 1)
    for _ in range(steps):
        xv = np.bincount(F.ravel(), weights=np.repeat(x, 3), minlength=n) / cnt
        x = np.maximum(x, xv[F].mean(axis=1))
    return x


def compressed_metric_map(problem, U, max_steps=3):
    """Raise the faces of a fold-free map above their rounding margin by rerunning Algorithm 2 on a compressed metric.

    Each step: faces below ``GAMMA`` times their margin get
    ``K_f *= 1 + deficit_f / DEFICIT_SCALE`` (smoothed over two face rings,
    :func:`smooth_faces`); the input metric is
    compressed by ``K`` along the crowding direction of the current map
    (:func:`compressed_lengths`) and Algorithm 2
    reruns on its intrinsic Delaunay Laplacian, round 0 from the Gauss map under
    the margin barrier of ``options.precision``.  Stops when no face is below its
    margin, when a rerun folds (the previous map is kept) or when the metric's
    operators fail.  The map is Möbius-centered with the input's areas at the
    end if that leaves no more faces below the margin.

    Parameters
    ----------
    problem : igl_spheremap.folding.problem.MapProblem
        The input mesh's problem (its ``options.precision`` gives the margin).
    U : (n, 3) float64 array
        A fold-free map in the validated mesh's order.
    max_steps : int

    Returns
    -------
    U : (n, 3) float64 array
        Validated order.
    info : dict
        ``steps`` (per step: faces ``below`` the margin, ``K_max``, and
        ``error`` or ``rerun_folds`` when it stopped there), ``K_max``,
        ``K_faces``, ``converged`` (of the last rerun kept), ``rounds``.
    """
    mesh, F, opts = problem.mesh, problem.F, problem.options
    u = unit_roundoff(opts.precision)
    n, K = mesh.V.shape[0], np.ones(F.shape[0])
    steps, rounds, converged = [], [], None
    for _ in range(max_steps):
        s, margin = volumes_and_margins(F, U, u)
        steps.append(dict(below=int(np.count_nonzero(s <= margin)), K_max=float(K.max())))
        if not steps[-1]["below"]:
            break
        t = time.perf_counter()
        with np.errstate(divide="ignore"):
            deficit = np.maximum(np.log(GAMMA * margin / np.where(s > 0, s, np.inf)), 0.0)
        K = K * (1.0 + smooth_faces(F, deficit, n) / DEFICIT_SCALE)
        try:
            l = compressed_lengths(mesh.V, F, crowding_direction(mesh.V, F, U), K)
            LK, areaK = intrinsic_operators(l, F, n)
        except (MemoryError, ValueError, RuntimeError, MeshError) as err:
            steps[-1]["error"] = f"{type(err).__name__}: {err}"
            break
        sub = MapProblem(mesh, LK, to_sphere_area(areaK), opts)
        ran, chosen, _ = run_rounds(sub, first=lambda p: gauss_round(p, p.options.precision))
        U_new, folds = final_centering(sub, chosen.U, chosen.folds_after)
        steps[-1]["seconds"] = time.perf_counter() - t
        if folds:
            steps[-1]["rerun_folds"] = folds
            break
        U, rounds, converged = U_new, ran, chosen.converged
    if opts.mobius:
        Uc, _ = mobius_center(U, problem.area)
        if count_folds(F, Uc) == 0 and count_below_margin(F, Uc, u) <= count_below_margin(F, U, u):
            U = Uc
    return U, dict(steps=steps, K_max=float(K.max()), K_faces=int(np.count_nonzero(K > 1.0)),
                   converged=converged, rounds=rounds)

