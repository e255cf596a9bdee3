"""The guaranteed path (not in the paper): when the rounds' map cannot be trusted, maps that
are fold-free by construction, then a descent of the conformal distortion that keeps them so.

:func:`verdict` accepts the map of Algorithm 2's rounds only when nothing contradicts
it: fold-free, no face below the rounding margin of ``options.precision``, degree 1
(:func:`igl_spheremap.sphere.folds.map_degree`), and at most half the vertices frozen
by the fold barrier (a map held near its start is no minimizer; a fold-free map whose
Algorithm 1 only ran out of iterations is returned as it is, not converged).  An accepted
map whose harmonic energy is below :data:`COLLAPSED_ENERGY` times ``4 pi``
(:func:`collapse_suspect`) is not returned outright either: it competes with the
guaranteed path's maps on angle distortion.
Otherwise :func:`guaranteed_map` builds the candidates:

* ``"central"``: the central projection from the kernel centre of a star-shaped mesh
  (:func:`igl_spheremap.folding.starts.central_projection`);
* ``"tutte"``: the punctured Tutte embedding lifted stereographically
  (:mod:`igl_spheremap.folding.tutte_start`), with the first of
  :data:`~igl_spheremap.folding.tutte_start.TUTTE_WEIGHTS` whose start is fold-free
  and above the rounding margin; where rounding broke every one, ``"untangled"``: the
  disk untangled in the plane at the cost of some angle
  (:mod:`igl_spheremap.folding.untangled_disk`), where the rounds' map can start a
  descent built only if that descent fails (:func:`start_groups`);
* ``"polish"``: the rounds' map, when it is fold-free and of degree 1 but was rejected (held
  by the barrier, or input slivers below the margin), represented by the initial map of its
  round (:func:`held_start`), each with its input slivers lifted
  (:func:`~igl_spheremap.sphere.sliver_lift.lift_slivers`, as :func:`quality` judges maps);

the one of least conformal distortion followed by the conformal descent
(:func:`conformal_descent`): Algorithm 1 on
the conformal-distortion energy
(:class:`igl_spheremap.optimize.conformal_distortion.ConformalDistortionEnergy`,
infinite on a folded face) with each step capped before any face folds or goes below
its margin (:meth:`igl_spheremap.optimize.barrier.FreeVertices.max_step`); no vertex is
frozen.  Of that map and the rounds' map it returns the fold-free, degree-1 map without
faces below the margin that has the least mean angle distortion, among those that can be a
success if there are any: the rounds' map if :func:`verdict` accepted it, a descent if it
converged (a stalled descent is no minimizer, even with a lower angle distortion).

An accepted map whose round froze more than :data:`POLISH_SHARE` of the vertices (Algorithm 1
stopped where the barrier held them, not at a minimum), or with more than that share of the
surface's area on faces whose conformal distortion is above :data:`POLISH_DISTORTION` times a
conformal map's (a harmonic map can be fold-free with a few image faces spread over much of the
sphere and the rest crowded between them), or any accepted map with ``polish="always"``, is
descended from as well (the ``"polish"`` round, from the initial map of the round where the
barrier held it: :func:`held_start`); the descent's map is kept when it converged and lowers the
mean angle distortion.
"""

import time

import numpy as np

from ..errors import plural
from ..mesh.operators import SPHERE_AREA, dirichlet_energy, vertex_areas
from ..optimize.conformal_distortion import ConformalDistortionEnergy
from ..optimize.minimize import minimize
from ..sphere.folds import below_margin, count_folds, map_degree
from ..sphere.mobius import mobius_center
from ..sphere.quality import angle_distortion
from ..sphere.sliver_lift import lift_slivers
from .problem import finite
from .result import FROZEN_SHARE
from .starts import central_projection
from .tutte_start import fold_free_tutte_maps
from .untangled_disk import untangled_sphere_map

#: An accepted map whose round froze more than this share of the vertices under the fold
#: barrier is polished (:func:`guaranteed_map`): Algorithm 1 stopped there because the barrier
#: held those vertices, not at a minimum (docs/decisions.md).
POLISH_SHARE = 0.1

#: An accepted map with more than :data:`POLISH_SHARE` of the surface's area on faces whose
#: conformal distortion is above this many times a conformal map's (half their MIPS energy,
#: :meth:`~igl_spheremap.optimize.conformal_distortion.ConformalDistortionEnergy.face_distortion`;
#: 2 is a dilatation above 2 + sqrt 3) is polished (:func:`guaranteed_map`): on coarse CAD
#: parts Algorithm 1 can converge to a fold-free harmonic map with a few image faces each
#: spread over a tenth of the sphere and the rest crowded between them (docs/decisions.md).
POLISH_DISTORTION = 2.0

#: An accepted map whose harmonic energy is below this many times ``4 pi`` may have collapsed
#: in all but its degree (:func:`collapse_suspect`): a smooth map of degree 1 has
#: ``E >= 4 pi``, equal for a conformal one, and a piecewise-linear one gets far below it
#: where a few image faces span the sphere and the rest are crushed.  On meshes of long
#: needle triangles (a CAD rod whose sides run its whole length) the harmonic energy
#: prefers that to a conformal map, and no descent from it lifts the crushed faces in
#: bounded time; a very coarse mesh can have a fold-free minimizer below it that is the
#: best map there is (docs/decisions.md).
COLLAPSED_ENERGY = 0.5

#: The conformal descent stops when the Newton decrement ``sqrt(<G, X>_K / 4 pi)`` of its
#: energy is at most this (``docs/decisions.md``).
DESCENT_GTOL = 1e-3

#: The conformal descent's line search is monotone: Zhang and Hager's averaging weight
#: ``xi`` (Algorithm 1 line 5) is 0, so the reference value is the last energy.  The
#: nonmonotone rule suits the gradient steps of Barzilai and Borwein; with the Newton metric
#: the step is already scaled by the curvature, and accepting increases let the steps
#: oscillate about the minimum instead of settling (``docs/decisions.md``).
DESCENT_XI = 0.0


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
        return False, plural(folds, "folded face")
    if abs(degree - 1.0) > 0.25:
        return False, f"degree {degree:.2f}"
    if below:
        return False, f"{plural(below, 'face')} below their {opts.precision} rounding margin"
    if frozen > FROZEN_SHARE * n:
        energy = dirichlet_energy(problem.L, U) / SPHERE_AREA
        return False, f"the fold barrier froze {frozen} of {n} vertices (E/4pi = {energy:.2f})"
    return True, "accepted"


def conformal_descent(problem, U0, index):
    """Algorithm 1 on the conformal-distortion energy from a fold-free ``U0`` (validated order).

    The fold barrier never freezes a vertex: each step is capped by the per-face
    maximal step along the Cayley curve and a trial that folds a face (or, with
    ``precision="float32"``, takes a face to its rounding margin) is shortened
    (:func:`igl_spheremap.optimize.minimize.minimize` with ``feasible=True``).  Every
    accepted step lowers the energy (:data:`DESCENT_XI`, the monotone Armijo rule).  It
    stops at :data:`DESCENT_GTOL` (the energy's own stopping quantity) or
    ``options.max_iter``.

    Returns
    -------
    igl_spheremap.optimize.result.Algorithm1Result
        ``energy`` is the conformal distortion (``4 pi`` for a conformal map).
    """
    opts = problem.options.updated(gtol=DESCENT_GTOL, xi=DESCENT_XI)
    energy = ConformalDistortionEnergy(problem.mesh.V, problem.F, problem.area, opts.h1_solver,
                                       opts.refactor_every, opts.precision, U0)
    run = minimize(energy, U0, problem.F, opts, fold_barrier=True, feasible=True,
                   callback=problem.on_iteration)
    return finite(run, index)


def start_round(problem, kind, U_init, index, previous=None):
    """A round of the guaranteed path: :func:`conformal_descent` from ``U_init`` (a Round)."""
    t0 = time.perf_counter()
    run = conformal_descent(problem, U_init, index)
    return problem.round(index, kind, U_init, run, count_folds(problem.F, U_init), t0, previous,
                         fold_barrier=True)


def candidate_rounds(problem, index, previous=None, rounds_map=None):
    """The rounds of the guaranteed path (list of Round, usually one).

    The starts come in the groups of :func:`start_groups`; within a group they are scored
    by the conformal distortion, the energy the descent minimizes, and
    :func:`conformal_descent` runs from the least of them: one descent, not one per start
    (``docs/decisions.md``).  Only when it ends without a valid (:func:`quality`), converged
    map does the next start run, and only when a whole group gave none is the next group
    built.
    """
    mesh, F = problem.mesh, problem.F
    energy = ConformalDistortionEnergy(mesh.V, F, problem.area)
    rounds = []

    def settled(kind, U):  # descend from U; whether that gave a valid, converged map
        r = start_round(problem, kind, U, index + len(rounds), rounds[-1] if rounds else previous)
        rounds.append(r)
        return r.run.converged and quality(problem, mesh.from_input(r.U))[0]

    for group in start_groups(problem, rounds_map):
        scored = [(energy.value(U), kind, U) for kind, U in group if U is not None]
        scored = sorted((t for t in scored if np.isfinite(t[0])), key=lambda t: t[0])
        if any(settled(kind, U) for _, kind, U in scored):
            break
    return rounds


def start_groups(problem, rounds_map=None):
    """The guaranteed path's starts, fold-free by construction, as lists of ``(kind, U)``
    (validated order; ``U`` None where a start does not exist), each group built only
    when the ones before gave no valid, converged map (:func:`candidate_rounds`).

    ``"central"`` (:func:`~igl_spheremap.folding.starts.central_projection`), the first Tutte
    weighting above the rounding margin and ``rounds_map`` as ``"polish"``; where rounding
    broke every Tutte weighting, also the starts built to be representable at the cost of
    angle (:func:`untangled_starts`).  Those come in a second group when ``rounds_map`` is
    given: the rounds' map is then itself a representable start near the conformal map, and
    the untangled disk, by far the costliest start (a projected Newton descent in the
    plane), is built only if its descent fails (``docs/decisions.md``).

    Where a Tutte weighting above the margin is a start, the first fold-free weighting
    passed over for its faces below the margin (in float32) comes last, alone.  The energy
    does not guard those faces, so its descent may end with some still below (:func:`quality`
    lifts the input slivers among them), but nothing keeps it from lifting them, and a start
    this much closer to conformal than the uniform Tutte map can converge where that one's
    descent stalls (``docs/decisions.md``).  It runs only where every other start failed, so
    no map that was a success changes.
    """
    mesh, F = problem.mesh, problem.F
    above, below = _tutte_maps(problem)
    first = [("central", central_projection(mesh.V, F)), *above, ("polish", rounds_map)]
    if above:
        yield first
        yield below
    elif rounds_map is not None:
        yield first
        yield untangled_starts(problem, below)
    else:
        yield first + untangled_starts(problem, below)


def untangled_starts(problem, below):
    """Where rounding broke every Tutte start: ``"untangled"``, the disk untangled at the
    cost of some angle (:func:`igl_spheremap.folding.untangled_disk.untangled_sphere_map`)
    when its lift is fold-free and, once the input slivers it leaves below the margin are
    lifted (:func:`igl_spheremap.sphere.sliver_lift.lift_slivers`), above the margin; then
    ``below``, the first fold-free Tutte embedding (a list of ``(kind, U)``, maybe empty)."""
    F, precision = problem.F, problem.options.precision
    U, _ = untangled_sphere_map(problem.mesh.V, F)
    if count_folds(F, U) == 0:
        U = lift_slivers(F, U, precision)  # input slivers it left below the margin
        if not below_margin(F, U, precision).any():
            return [("untangled", U), *below]
    return below


def _tutte_maps(problem):
    """``(above, below)``: ``[("tutte", U)]`` for the first fold-free Tutte map with no face
    below the rounding margin, else ``[]``; the first fold-free one before it, as ``below``."""
    F, precision = problem.F, problem.options.precision
    below = []
    for U in fold_free_tutte_maps(problem.mesh.V, F):
        if not below_margin(F, U, precision).any():
            return [("tutte", U)], below
        below = below or [("tutte", U)]
    return [], below


def quality(problem, U):
    """``(valid, angle, U)``: fold-free, degree 1 and above the margin; mean angle distortion
    (degrees) of ``U``, Möbius-centred when that keeps it valid (validated order).

    A fold-free ``U`` is judged with its faces below the rounding margin lifted
    (:func:`~igl_spheremap.sphere.sliver_lift.lift_slivers`; a map with none is judged
    unchanged): the descent from a start passed over for such faces
    (the last group of :func:`start_groups`) does not guard them, and can converge with a few input
    slivers still below the margin, which a single-corner move clears."""
    F, opts = problem.F, problem.options
    U = _lifted(problem, U)
    ok = _valid(problem, U)
    if opts.mobius:
        Uc, _ = mobius_center(U, vertex_areas(problem.mesh.V, F))
        if np.all(np.isfinite(Uc)) and _valid(problem, Uc) >= ok:
            U, ok = Uc, _valid(problem, Uc)
    return ok, float(angle_distortion(problem.mesh.V, F, U).mean()), U


def guaranteed_map(problem, rounds, U, chosen, folds):
    """The rounds' map if :func:`verdict` accepts it, else the best map of the guaranteed path.

    An accepted map that the barrier partly held (more than :data:`POLISH_SHARE` of the
    vertices frozen) or with more than that share of its area on faces distorted above
    :data:`POLISH_DISTORTION` (``options.polish="auto"``), or every accepted map with
    ``"always"``, is also the start of :func:`conformal_descent`; the descent's map is
    returned when it converged with the lower mean angle distortion.

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
        Which path produced it and why (None when the rounds' map was accepted and not
        polished).
    """
    ok, why = verdict(problem, U, chosen, folds)
    suspect = collapse_suspect(problem, U) if ok else None
    if suspect:
        ok, why = False, suspect
    mode = problem.options.polish
    polish_why = _polish_reason(problem, U, chosen) if ok and mode == "auto" else None
    if ok and not (mode == "always" or polish_why):
        return U, None, None
    if ok:
        start, source = held_start(problem, U, chosen)
        polished = start_round(problem, "polish", start, len(rounds), rounds[-1])
        rounds.append(polished)
        cands = [polished] if polished.run.converged else []  # never trade a success for it
        why = f"{polish_why or 'polish=' + repr(mode)}; from {source}"
    else:
        lifted = _lifted(problem, U)
        polish = held_start(problem, lifted, chosen, lift=True)[0] \
            if _valid(problem, lifted) else None
        cands = candidate_rounds(problem, len(rounds), rounds[-1], polish)
        rounds.extend(cands)
    scored = [(quality(problem, X), r) for r, X in
              [(chosen, U)] + [(r, problem.mesh.from_input(r.U)) for r in cands]]
    valid = [(angle, X, r) for (ok, angle, X), r in scored if ok]
    if not valid:
        return U, None, f"no map fold-free by construction did better than the rounds' ({why})"
    settled = [t for t in valid if ((ok or suspect) if t[2] is chosen else t[2].run.converged)]
    angle, X, r = min(settled or valid, key=lambda t: t[0])
    if ok:
        judged = scored[1][0] if cands else None
        return X, (None if r is chosen else r), polish_note(
            scored[0][0][1], angle, r is chosen, why, _descent_outcome(polished.run, judged))
    energy = dirichlet_energy(problem.L, X) / SPHERE_AREA
    distortion = ConformalDistortionEnergy(problem.mesh.V, problem.F, problem.area).value(X)
    path = "the rounds" if r is chosen else f"the guaranteed path ({r.kind} start)"
    if r is not chosen and r.kind == "untangled":
        path += (f", which gave up angle for area: every Tutte embedding of this mesh crowds "
                 f"below its {problem.options.precision} rounding")
    taken = "kept over the guaranteed path's maps" if r is chosen else "alone was not taken"
    return X, (None if r is chosen else r), (
        f"fold-free from {path}: conformal distortion {distortion / SPHERE_AREA:.3f} and "
        f"E/4pi = {energy:.3f} (both 1 for a conformal map), mean angle distortion "
        f"{angle:.2f} deg; the rounds' map {taken} ({why})")


def collapse_suspect(problem, U):
    """Why an accepted map competes with the guaranteed path's maps instead of being
    returned outright, or None: its harmonic energy is below :data:`COLLAPSED_ENERGY` times
    ``4 pi`` (a smooth map of degree 1 has ``E >= 4 pi``).

    Parameters
    ----------
    problem : igl_spheremap.folding.problem.MapProblem
        Its Laplacian ``L`` (intrinsic Delaunay by default) gives the energy.
    U : (n, 3) float64 array
        The map :func:`verdict` accepted (validated order, unit vectors).

    Returns
    -------
    str or None
    """
    energy = dirichlet_energy(problem.L, U) / SPHERE_AREA
    if energy >= COLLAPSED_ENERGY:
        return None
    return (f"E/4pi = {energy:.3f}, below {COLLAPSED_ENERGY:g}: possibly collapsed in all but "
            f"its degree, most image faces crushed (a conformal map has E/4pi = 1)")


def held_start(problem, U, chosen, lift=False):
    """Where a descent from the rounds' map ``U`` starts: the initial map of its round when the
    fold barrier held that round.

    Where the barrier froze more than :data:`POLISH_SHARE` of the vertices, Algorithm 1 stopped
    where they were held, and the frozen regions keep the scale that the free ones around them
    were fitted to: a descent from there first undoes that, one capped step at a time.  The
    round's initial map (the star map, paper Section 4.2; the Tutte map of a restart) has no
    such seam, and is fold-free where the round ran under the barrier (docs/decisions.md).

    Parameters
    ----------
    problem : igl_spheremap.folding.problem.MapProblem
    U : (n, 3) float64 array
        The rounds' map (validated order), fold-free.
    chosen : Round
        The round it came from.
    lift : bool
        Take the round's initial map with its faces below the rounding margin lifted
        (:func:`~igl_spheremap.sphere.sliver_lift.lift_slivers`), as :func:`quality` judges
        maps: for the start of a rejected rounds' map, itself lifted.

    Returns
    -------
    start : (n, 3) float64 array
        ``chosen.U_init`` in validated order if the barrier held that round and it can start the
        descent (fold-free, of degree 1, above the rounding margin), else ``U``.
    source : str
        Which, in words (for the message).
    """
    if _barrier_held(chosen, U.shape[0]):
        U0 = problem.mesh.from_input(chosen.U_init)
        U0 = _lifted(problem, U0) if lift else U0
        if _valid(problem, U0):
            return U0, f"the initial map of the {chosen.kind} round the barrier held"
    return U, "the accepted map"


def _barrier_held(chosen, n):
    """Whether the fold barrier froze more than :data:`POLISH_SHARE` of the ``n`` vertices in
    the round ``chosen``."""
    return int(chosen.frozen or 0) > POLISH_SHARE * n


def _lifted(problem, U):
    """``U`` (validated order) with its faces below the rounding margin lifted where it is
    fold-free (:func:`~igl_spheremap.sphere.sliver_lift.lift_slivers`), else ``U``."""
    if count_folds(problem.F, U):
        return U
    return lift_slivers(problem.F, U, problem.options.precision)


def _valid(problem, U):
    """Whether ``U`` (validated order) is a map the guaranteed path may start from or return:
    fold-free, of degree 1 and no face below the rounding margin of ``options.precision``."""
    return count_folds(problem.F, U) == 0 and abs(map_degree(problem.F, U) - 1.0) <= 0.25 and \
        not below_margin(problem.F, U, problem.options.precision).any()


def _polish_reason(problem, U, chosen):
    """Why ``polish="auto"`` descends from the accepted map ``U`` (validated order), or None:
    its round's barrier froze more than :data:`POLISH_SHARE` of the vertices, its round's
    start kept untangled patches (``Round.patched``: Algorithm 1 from there stays in a basin
    the patches chose, not a conformal one), or more than :data:`POLISH_SHARE` of the
    surface's area is on faces distorted above :data:`POLISH_DISTORTION`."""
    n = U.shape[0]
    if _barrier_held(chosen, n):
        return f"the fold barrier had frozen {chosen.frozen} of {n} vertices"
    if chosen.patched:
        return "its round started from untangled patches, shaped toward equilateral triangles"
    energy = ConformalDistortionEnergy(problem.mesh.V, problem.F, problem.area)
    share = energy.face_area[energy.face_distortion(U) > POLISH_DISTORTION].sum() / SPHERE_AREA
    if share > POLISH_SHARE:
        return (f"{share:.0%} of the surface's area was on faces with more than "
                f"{POLISH_DISTORTION:g} times a conformal map's distortion")
    return None


def polish_note(before, after, kept, why, outcome):
    """The message's note on a polish: the mean angle distortion (degrees) of the accepted map
    ``before`` and of the best map ``after``; ``kept``: the accepted map won; ``why`` the
    polish ran; ``outcome`` what the descent gave when it lost (:func:`_descent_outcome`)."""
    if kept:
        return (f"polish ({why}): {outcome}; the rounds' map kept ({before:.2f} deg mean angle "
                f"distortion)")
    return (f"polished by the conformal descent ({why}): mean angle distortion {before:.2f} -> "
            f"{after:.2f} deg")


def _descent_outcome(run, judged):
    """Why a polish's map lost to the rounds' map, in words.

    Parameters
    ----------
    run : igl_spheremap.optimize.result.Algorithm1Result
        The conformal descent's run.
    judged : tuple or None
        :func:`quality` of its map, ``(valid, angle, U)``; None where it did not converge
        (its map is then not judged).

    Returns
    -------
    str
    """
    if judged is None:
        return f"the conformal descent did not converge ({run.message})"
    if not judged[0]:
        return ("the conformal descent converged to a map that is not valid (a fold, a degree "
                "other than 1 or a face below the rounding margin)")
    return (f"the conformal descent converged at {judged[1]:.2f} deg mean angle distortion, "
            f"no lower")
