"""Algorithm 2 rerun on a metric compressed where the map crowds below the float32 margin (issue #15)."""

import time

import numpy as np

from .compressed_metric import (compressed_lengths, crowding_direction, operators_of_lengths,
                                smooth_faces)
from .errors import MeshError
from .metrics import count_folds
from .mobius import mobius_center
from .precision import count_below_margin, unit_roundoff, volumes_and_margins
from .rounds import MapProblem, final_centering, gauss_round, run_rounds

#: Faces are pushed to this many times their margin (headroom for the reruns'
#: Algorithm 1, which may shrink them again down to the margin).
GAMMA = 8.0

#: ``K_f`` is multiplied by ``1 + deficit_f / DEFICIT_SCALE`` per step, the deficit
#: in nats of length (``log(GAMMA * margin / s)``, about the log of how much the
#: face's edges must grow).
DEFICIT_SCALE = 2.0


def compressed_metric_map(problem, U, max_steps=3):
    """Raise the faces of a fold-free map above their rounding margin by rerunning Algorithm 2 on a compressed metric.

    Each step: faces below ``GAMMA`` times their margin get
    ``K_f *= 1 + deficit_f / DEFICIT_SCALE`` (smoothed over two face rings,
    :func:`igl_spheremap.compressed_metric.smooth_faces`); the input metric is
    compressed by ``K`` along the crowding direction of the current map
    (:func:`igl_spheremap.compressed_metric.compressed_lengths`) and Algorithm 2
    reruns on its intrinsic Delaunay Laplacian, round 0 from the Gauss map under
    the margin barrier of ``options.precision``.  Stops when no face is below its
    margin, when a rerun folds (the previous map is kept) or when the metric's
    operators fail.  The map is Möbius-centered with the input's areas at the
    end if that leaves no more faces below the margin.

    Parameters
    ----------
    problem : igl_spheremap.rounds.MapProblem
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
            LK, areaK = operators_of_lengths(l, F, n)
        except (MemoryError, ValueError, RuntimeError, MeshError) as err:
            steps[-1]["error"] = f"{type(err).__name__}: {err}"
            break
        sub = MapProblem(mesh, LK, areaK, opts)
        ran, chosen, _ = run_rounds(sub, first=lambda p: gauss_round(p, barrier=True))
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

