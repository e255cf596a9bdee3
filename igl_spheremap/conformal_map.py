"""The spherical conformal map end to end: validation, Algorithm 2 (:mod:`igl_spheremap.folding`)
and, for a storage precision, the float32 repairs (:mod:`igl_spheremap.precision`)."""

import time
import warnings

import numpy as np

from .errors import SphericalMapWarning, plural
from .folding.centering import final_centering
from .folding.guaranteed import guaranteed_map
from .folding.problem import MapProblem
from .folding.result import Round, build_result
from .folding.rounds import run_rounds
from .mesh.validate import validate_mesh
from .optimize.area_balanced import relax_validated, relaxation_options
from .options import map_options
from .precision.repair import make_representable
from .sphere.folds import below_margin, count_folds


#: The kinds of sphere :func:`spherical_conformal_map` makes.
KINDS = ("conformal", "area_balanced")


def spherical_conformal_map(V, F, options=None, *, kind="conformal", callback=None,
                            progress=False, **option_values):
    """Folding-free spherical conformal map of a closed genus-0 mesh (paper Algorithm 2).

    Stage 0 runs Algorithm 1 (:func:`igl_spheremap.optimize.minimize.minimize`, harmonic
    energy) from the Gauss map.  While the map has folded faces and fewer than
    ``max_rounds`` rounds ran, round ``k`` builds the star map of the weighted
    Laplace-Beltrami eigenfunctions of the current map (Section 4.2, Eqs. 20-27,
    :func:`igl_spheremap.star_map`) and reruns Algorithm 1 from it
    (:mod:`igl_spheremap.folding.rounds`).

    ``method="folding_free"`` (default) differs from the paper as documented in
    README.md: intrinsic Delaunay cotangent Laplacian, H1-preconditioned
    gradient, Möbius normalization kept during the iteration, and, once a map
    is fold-free, a fold barrier.  When the folds left by stage 0 are isolated,
    round 1 is a *local repair* instead of a star-map round.  ``method="paper"``
    is the published algorithm.  The returned map is Möbius-centered (with
    ``mobius``); if that centering folds a near-degenerate sliver, its vertices
    get the kernel moves of :func:`igl_spheremap.untangle_folds`, and if faces
    stay folded the uncentered map is returned.

    With ``precision="float32"`` the map must also survive being stored as
    ``R * U`` in float32 at any radius ``R`` (GIfTI, FreeSurfer): the fold barrier
    keeps every face's signed image volume above its rounding margin
    (:func:`igl_spheremap.sphere.folds.rounding_margin`), and faces still below it
    after the rounds are lifted by :func:`igl_spheremap.precision.repair.make_representable`
    (cluster inflation, compressed-metric rerun or central-projection start; some
    angle distortion on thin features).  A round that collapses the map (energy
    below half of ``4 pi``) is dropped for the best earlier round; the message says so.

    ``kind="area_balanced"`` then relaxes the conformal map toward low area and
    edge-length distortion (:mod:`igl_spheremap.optimize.area_balanced`: the
    symmetric Dirichlet energy under the fold barrier, with the margin of
    ``precision``), a sphere made for registration and resampling rather than
    for angles; its stage is the last of ``rounds`` (kind ``"area_balanced"``).

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions (any units; the map does not depend on scale).
    F : (m, 3) array_like of int
        Triangles of a closed, manifold, connected genus-0 mesh.  Mixed or inward
        orientation is repaired (``result.F``, ``result.mesh.notes``).
    options : MapOptions or dict, optional
        See :class:`igl_spheremap.MapOptions` for every option and the precedence.
    kind : {"conformal", "area_balanced"}
        ``"conformal"`` (default): the paper's map.  ``"area_balanced"``: the
        conformal map relaxed as above (when it is fold-free; its stopping rule
        is :data:`igl_spheremap.optimize.area_balanced.MAX_ITER` and ``GTOL``).
    callback : callable, optional
        ``callback(round)`` with each finished :class:`igl_spheremap.Round`.
    progress : bool
        Show a tqdm progress bar of Algorithm 1 iterations on stderr.
    **option_values
        Fields of :class:`igl_spheremap.MapOptions` (``method``, ``max_rounds``,
        ``gtol``, ``max_iter``, ``laplacian_kind``, ``metric``, ``mobius``,
        ``fold_barrier``, ``untangle``, ``local_repair``, ``polish``, ``h1_solver``,
        ``precision`` (``"float64"``, default, or ``"float32"``), ...); they
        override ``options``.

    Returns
    -------
    SphericalMapResult
        ``U`` (n, 3) float64 unit vectors indexed like ``V``; ``F`` the faces it
        was computed on; ``folds``, ``converged``, ``success``, ``message``,
        ``rounds``, ``mesh``, ``timings``, ``below_margin`` (faces at or below
        their rounding margin for ``precision``; ``success`` needs 0), ``repair``
        (the float32 repair tried, or None), ``notes``, ...

    Raises
    ------
    MeshError
        If the mesh is invalid (see :func:`igl_spheremap.validate_mesh`).
    ValueError
        If an option is unknown, invalid or conflicts with another.
    RuntimeError
        If the eigensolver fails or a step produces non-finite values.

    Warns
    -----
    SphericalMapWarning
        If the returned map has folded faces, faces below their ``precision``
        rounding margin (which storing it may fold), or Algorithm 1 did not
        converge (the result says so too: ``success`` is False).
    """
    if kind not in KINDS:
        raise ValueError(f"unknown kind {kind!r}; expected one of {list(KINDS)}")
    opts = map_options(options, **option_values)
    with opts.blas_limit():
        result = _spherical_conformal_map(V, F, opts, callback, progress, kind)
    if not result.success:
        warnings.warn(f"spherical_conformal_map: {result.message}", SphericalMapWarning,
                      stacklevel=2)
    return result


def _spherical_conformal_map(V, F, opts, callback, progress, kind="conformal"):
    t0 = time.perf_counter()
    mesh = validate_mesh(V, F)
    result, problem = map_validated(mesh, opts, callback, progress, t0)
    if kind == "area_balanced" and result.folds == 0:
        result = area_balanced_result(result, problem, callback)
        result.seconds = time.perf_counter() - t0
    return result


def area_balanced_result(conformal, problem, callback=None, max_iter=None):
    """A fold-free conformal map relaxed toward the area-balanced sphere, as a result with one
    more round (:func:`igl_spheremap.optimize.area_balanced.relax_validated`).

    Parameters
    ----------
    conformal : SphericalMapResult
        Fold-free map of ``problem``'s mesh.
    problem : igl_spheremap.folding.problem.MapProblem
        From :func:`map_validated`.
    callback : callable, optional
        Called with the relaxation's :class:`Round`.
    max_iter : int, optional
        Iterations of the relaxation (default
        :data:`igl_spheremap.optimize.area_balanced.MAX_ITER`).  Given, the relaxation
        stops part way between the conformal and the area-balanced map by design, and
        the result counts as converged when the conformal map did.

    Returns
    -------
    SphericalMapResult
    """
    t = time.perf_counter()
    mesh = problem.mesh
    U0 = mesh.from_input(conformal.U)
    opts = relaxation_options(problem.options)
    run = relax_validated(mesh, U0, opts if max_iter is None else opts.updated(max_iter=max_iter))
    rnd = Round(index=len(conformal.rounds), kind="area_balanced", U_init=conformal.U, run=run,
                folds_before=0, seconds=time.perf_counter() - t, fold_barrier=True)
    run.U = mesh.to_input(run.U)
    if callback is not None:
        callback(rnd)
    rounds = conformal.rounds + [rnd]
    what = "area-balanced sphere" if max_iter is None else "part way to the area-balanced sphere"
    message = (f"{what}: {plural(run.nit, 'iteration')} of the symmetric Dirichlet energy "
               f"from the conformal map ({run.message}); conformal map: {conformal.message}")
    converged = conformal.converged and (run.converged or max_iter is not None)
    result = build_result(problem, rounds, mesh.from_input(run.U), run.folds, message,
                          chosen=rnd, converged=converged)
    result.repair = conformal.repair
    result.timings = {**conformal.timings, "area_balanced": rnd.seconds}
    return result


def map_validated(mesh, opts, callback=None, progress=False, t0=None):
    """Algorithm 2 on a validated mesh (:func:`spherical_conformal_map` without the checks).

    Returns
    -------
    result : SphericalMapResult
    problem : igl_spheremap.folding.problem.MapProblem
        The operators the run used (for a caller that continues from the map).
    """
    t0 = time.perf_counter() if t0 is None else t0
    timings = {"validate": time.perf_counter() - t0}
    t = time.perf_counter()
    problem = MapProblem.of(mesh, opts)
    timings["laplacian"] = time.perf_counter() - t
    t = time.perf_counter()
    bar = _progress_bar(problem) if progress else None
    try:
        rounds, chosen, note = run_rounds(problem, callback=callback)
    finally:
        if bar is not None:
            bar.close()
    timings["rounds"] = time.perf_counter() - t
    t = t_finish = time.perf_counter()
    U, folds = final_centering(problem, chosen.U, chosen.folds_after)
    repair, converged = None, chosen.converged
    if problem.options.precision != "float64" and folds == 0 and \
            below_margin(problem.F, U, problem.options.precision).any():
        U, repair, converged = make_representable(problem, U, chosen)
        folds = count_folds(problem.F, U)
        timings["repair"] = time.perf_counter() - t
    notes = [n for n in (note, repair and repair["summary"]) if n]
    if opts.guaranteed_path:
        t, known = time.perf_counter(), len(rounds)
        U, start, path = guaranteed_map(problem, rounds, U, chosen, folds)
        for rnd in rounds[known:] if callback is not None else ():
            callback(rnd)  # the guaranteed path's rounds, reported like Algorithm 2's
        if start is not None:
            chosen, converged, folds = start, start.converged, start.folds_after
        notes += [path] if path else []
        timings["guaranteed"] = time.perf_counter() - t
    result = build_result(problem, rounds, U, folds, chosen=chosen, converged=converged,
                          notes=notes)
    result.repair = repair
    timings["finish"] = (time.perf_counter() - t_finish - timings.get("repair", 0.0)
                         - timings.get("guaranteed", 0.0))
    result.timings, result.seconds = timings, time.perf_counter() - t0
    return result, problem


def _progress_bar(problem):
    from tqdm.auto import tqdm

    bar = tqdm(desc="Algorithm 1", unit="it", leave=False)

    def on_iteration(k, U, E, g):
        bar.update(1)
        bar.set_postfix(energy_4pi=f"{E / (4 * np.pi):.5f}", grad=f"{g:.1e}")

    problem.on_iteration = on_iteration
    return bar
