"""The guaranteed path (not in the paper): when the rounds' map cannot be trusted, maps that
are fold-free by construction, then Algorithm 1 under the fold barrier from them.

:func:`verdict` accepts the map of Algorithm 2's rounds only when nothing contradicts
it: fold-free, no face below the rounding margin of ``options.precision``, degree 1
(:func:`igl_spheremap.sphere.folds.map_degree`), and at most half the vertices frozen
by the fold barrier (a map held near its start is no minimizer; a fold-free map whose
Algorithm 1 only ran out of iterations is returned as it is, not converged).
Otherwise :func:`guaranteed_map` builds the candidates:

* ``"central"``: the central projection from the kernel centre of a star-shaped mesh
  (:func:`igl_spheremap.folding.starts.central_projection`);
* ``"tutte"``: the punctured Tutte embedding lifted stereographically
  (:mod:`igl_spheremap.folding.tutte_start`), with the first of
  :data:`~igl_spheremap.folding.tutte_start.TUTTE_WEIGHTS` whose start is fold-free;

each followed by the barrier descent (:func:`barrier_descent`), and returns, among
them and the rounds' map, the fold-free, degree-1 map without faces below the margin
that has the least mean angle distortion.
"""

import time

import numpy as np

from ..mesh.operators import SPHERE_AREA, dirichlet_energy, vertex_areas
from ..sphere.folds import below_margin, count_folds, map_degree
from ..sphere.mobius import mobius_center
from ..sphere.quality import angle_distortion
from .result import FROZEN_SHARE
from .starts import central_projection
from .tutte_start import TUTTE_WEIGHTS, tutte_sphere_map

#: Most Algorithm 1 runs of one barrier descent.
DESCENT_CYCLES = 4


def verdict(problem, U, chosen, folds):
    """Whether the rounds' map ``U`` (validated order) can be returned, and if not why.

    Parameters
    ----------
    problem : igl_spheremap.folding.problem.MapProblem
    U : (n, 3) float64 array
        The map after the rounds (and, in float32, the repairs).
    chosen : Round
        The round it came from (its frozen vertices).
    folds : int
        Its folded faces.

    Returns
    -------
    ok : bool
    why : str
        ``"accepted"``, or what contradicts the map.
    """
    n, opts = U.shape[0], problem.options
    below = int(below_margin(problem.F, U, opts.precision).sum())
    degree = map_degree(problem.F, U)
    frozen = int(chosen.frozen or 0)
    if folds:
        return False, f"{folds} folded faces"
    if abs(degree - 1.0) > 0.25:
        return False, f"degree {degree:.2f}"
    if below:
        return False, f"{below} faces below their {opts.precision} rounding margin"
    if frozen > FROZEN_SHARE * n:
        energy = dirichlet_energy(problem.L, U) / SPHERE_AREA
        return False, f"the fold barrier froze {frozen} of {n} vertices (E/4pi = {energy:.2f})"
    return True, "accepted"


def barrier_descent(problem, U0, index):
    """Algorithm 1 under the fold barrier from a fold-free ``U0``, rerun while it froze vertices.

    Each run starts from the previous map with every vertex free again (at most
    :data:`DESCENT_CYCLES` runs, and only while the energy drops by 1%), so the
    energy never rises and no face folds.

    Returns
    -------
    igl_spheremap.optimize.result.Algorithm1Result
        The last run, its ``nit`` the total of all runs.
    """
    run, nit, energy = None, 0, np.inf
    for _ in range(DESCENT_CYCLES):
        run = problem.minimize(U0 if run is None else run.U, True, index)
        nit += run.nit
        if run.frozen == 0 or run.energy > energy * (1.0 - 1e-2):
            break
        energy = run.energy
    run.nit = nit
    return run


def start_round(problem, kind, U_init, index, previous=None):
    """A round of the guaranteed path: :func:`barrier_descent` from ``U_init`` (a Round)."""
    t0 = time.perf_counter()
    run = barrier_descent(problem, U_init, index)
    return problem.round(index, kind, U_init, run, count_folds(problem.F, U_init), t0, previous,
                         fold_barrier=True)


def candidate_rounds(problem, index, previous=None):
    """The rounds of the fold-free starts by construction (list of Round, possibly empty)."""
    mesh, F = problem.mesh, problem.F
    out = []
    U = central_projection(mesh.V, F)
    if U is not None:
        out.append(start_round(problem, "central", U, index, previous))
    for weights in TUTTE_WEIGHTS:
        U, _ = tutte_sphere_map(mesh.V, F, weights)
        if count_folds(F, U) == 0:
            out.append(start_round(problem, "tutte", U, index + len(out), previous))
            break
    return out


def quality(problem, U):
    """``(valid, angle, U)``: fold-free, degree 1 and above the margin; mean angle distortion
    (degrees) of ``U``, Möbius-centred when that keeps it valid (validated order)."""
    F, opts = problem.F, problem.options

    def valid(X):
        return (count_folds(F, X) == 0 and not below_margin(F, X, opts.precision).any()
                and abs(map_degree(F, X) - 1.0) <= 0.25)

    ok = valid(U)
    if opts.mobius:
        Uc, _ = mobius_center(U, vertex_areas(problem.mesh.V, F))
        if np.all(np.isfinite(Uc)) and valid(Uc) >= ok:
            U, ok = Uc, valid(Uc)
    return ok, float(angle_distortion(problem.mesh.V, F, U).mean()), U


def guaranteed_map(problem, rounds, U, chosen, folds):
    """The rounds' map if :func:`verdict` accepts it, else the best map of the guaranteed path.

    Parameters
    ----------
    problem : igl_spheremap.folding.problem.MapProblem
    rounds : list of Round
        Algorithm 2's rounds; the candidates' rounds are appended.
    U : (n, 3) float64 array
        The rounds' map (validated order); ``chosen`` and ``folds`` as in :func:`verdict`.

    Returns
    -------
    U : (n, 3) float64 array
        The map (validated order).
    chosen : Round or None
        The guaranteed path's round it came from, or None for the rounds' map.
    note : str or None
        Which path produced it and why (None when the rounds' map was accepted).
    """
    ok, why = verdict(problem, U, chosen, folds)
    if ok:
        return U, None, None
    cands = candidate_rounds(problem, len(rounds), rounds[-1])
    rounds.extend(cands)
    scored = [(quality(problem, X), r) for r, X in
              [(chosen, U)] + [(r, problem.mesh.from_input(r.U)) for r in cands]]
    valid = [(angle, X, r) for (ok, angle, X), r in scored if ok]
    if not valid:
        return U, None, f"no map fold-free by construction did better than the rounds' ({why})"
    angle, X, r = min(valid, key=lambda t: t[0])
    energy = dirichlet_energy(problem.L, X) / SPHERE_AREA
    path = "the rounds" if r is chosen else f"the guaranteed path ({r.kind} start)"
    return X, (None if r is chosen else r), (f"fold-free from {path}: E/4pi = {energy:.3f} (1 for a conformal map), mean "
                  f"angle distortion {angle:.2f} deg; the rounds' map alone was not taken ({why})")
