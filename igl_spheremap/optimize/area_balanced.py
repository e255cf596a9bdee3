"""The area-balanced sphere: a fold-free spherical map with low area and edge-length distortion.

A conformal map of a cortex (or of any surface with long protrusions) shrinks
some regions by orders of magnitude: angles are kept, areas are not.  An
atlas's sphere is far from conformal to any one subject, and for registration
and resampling an even vertex density matters more than angles.  The
area-balanced map starts from the fold-free conformal map and minimizes the
symmetric Dirichlet energy (:class:`igl_spheremap.optimize.distortion.SymmetricDirichletEnergy`)
with Algorithm 1 under the fold barrier, keeping the rounding margin of
``precision``: area and angle distortion traded against each other, the role
of FreeSurfer's ``mris_sphere`` (Fischl, Sereno, Dale, NeuroImage 9 1999).

:func:`igl_spheremap.spherical_conformal_map` makes it with
``kind="area_balanced"``; :func:`area_balanced_map` runs the relaxation from
any fold-free start.
"""

import warnings

import igl
import numpy as np

from ..errors import SphericalMapWarning, plural
from ..mesh.arrays import as_points, unit_rows
from ..mesh.validate import validate_mesh
from ..options import map_options
from ..sphere.folds import below_margin, count_folds
from ..sphere.quality import area_distortion
from .distortion import SymmetricDirichletEnergy
from .minimize import minimize
from .result import Algorithm1Result

#: The relaxation's stopping rule (the conformal map before it keeps the options' own):
#: the RMS Riemannian gradient at most :data:`GTOL`, or a relative decrease of the energy
#: below :data:`FTOL` over each of :data:`STALLED_CHUNKS` consecutive chunks of :data:`CHUNK`
#: iterations (the slow tail of meshes with thin features; one such chunk can be followed
#: by progress once the metric is set up again), or :data:`MAX_ITER` iterations; chosen in
#: ``docs/decisions.md``.
MAX_ITER = 1000
GTOL = 1e-6
FTOL = 1e-4
CHUNK = 25
STALLED_CHUNKS = 2

#: Shortenings of a step that would fold a face before the fold barrier freezes vertices
#: instead (the options' ``max_fold_shrinks`` unless given): with the energy-weighted
#: H1 metric a step long enough for the bulk of the mesh can still fold a crowded face
#: (the energy does not see orientation), and freezing those vertices at the first
#: shortening froze nearly the whole of a cortex (``docs/decisions.md``).
FOLD_SHRINKS = 8

#: A relaxation that ended (by ``gtol``, :data:`FTOL` or ``max_iter``) with more than
#: ``CRUSHED_SHARE`` of the surface's area on faces below ``CRUSHED_RATIO`` of their share of
#: the sphere has not converged, and its message says so: where the conformal map crushes thin
#: extremities by orders of magnitude, the fold barrier holds the relaxation there while the
#: rest is balanced (``docs/decisions.md``).
CRUSHED_RATIO = 1e-2
CRUSHED_SHARE = 0.1


def relax_validated(mesh, U0, opts, callback=None):
    """The relaxation on a validated mesh (``U0`` in its vertex order, fold-free).

    Algorithm 1 runs in chunks of :data:`CHUNK` iterations (each a fresh start
    under the fold barrier, its H1 metric weighted by the energy's per-face
    stiffness at the chunk's start:
    :meth:`igl_spheremap.optimize.distortion.JacobianEnergy.reweight`) until the
    stopping rule of :data:`FTOL` or the options' ``gtol`` / ``max_iter``.

    Returns
    -------
    Algorithm1Result
        In the validated mesh's vertex order; ``converged`` when ``gtol`` or ``FTOL``
        stopped it, unless more than :data:`CRUSHED_SHARE` of the surface's area is still
        crushed (:func:`crushed_share`; the message then begins "not area-balanced", whatever
        stopped it).
    """
    energy = SymmetricDirichletEnergy(mesh.V, mesh.F, opts.metric, opts.h1_solver)
    U, runs, done, stalls = unit_rows(U0), [], 0, 0
    while not runs or done < opts.max_iter:  # one run even at max_iter=0: the start's report
        energy.reweight(U)
        run = minimize(energy, U, mesh.F, opts.updated(max_iter=min(CHUNK, opts.max_iter - done)),
                       fold_barrier=True, callback=callback)
        runs.append(run)
        U, done = run.U, done + run.nit
        if run.converged or run.nit == 0:
            break
        stalls = stalls + 1 if run.energy_history[0] - run.energy < FTOL * run.energy else 0
        if stalls >= STALLED_CHUNKS:
            run.converged = True
            run.message = (f"energy decreased by less than {FTOL:g} (relative) over "
                           f"{STALLED_CHUNKS} chunks of {CHUNK} iterations")
            break
    joined = _joined(runs)
    if not joined.converged and done >= opts.max_iter:  # not the last chunk's own max_iter
        joined.message = f"reached max_iter={opts.max_iter}"
    share = crushed_share(mesh.V, mesh.F, joined.U)
    if share > CRUSHED_SHARE:
        joined.converged = False
        joined.message = (f"not area-balanced: {joined.message}, with {share:.0%} of the "
                          f"surface's area on faces below {CRUSHED_RATIO:.0%} of their share of "
                          "the sphere (crushed by the conformal map, held there by the fold "
                          "barrier)")
    return joined


def crushed_share(V, F, U):
    """The share of the surface's area (float in [0, 1]) on faces whose image has less than
    :data:`CRUSHED_RATIO` of their share of the sphere's area (both normalized to 1:
    :func:`igl_spheremap.sphere.quality.area_distortion`).

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
    U : (n, 3) float64 array
        A spherical map of ``(V, F)``.

    Returns
    -------
    float
    """
    area = igl.doublearea(V, F)
    crushed = area_distortion(V, F, U) < np.log(CRUSHED_RATIO)
    return float(area[crushed].sum() / area.sum())


def _joined(runs):
    """One Algorithm1Result of consecutive runs."""
    last = runs[-1]
    return Algorithm1Result(
        U=last.U, converged=last.converged, message=last.message, nit=sum(r.nit for r in runs),
        energy=last.energy, grad_norm=last.grad_norm,
        energy_history=runs[0].energy_history[:1] + [e for r in runs for e in r.energy_history[1:]],
        grad_norm_history=(runs[0].grad_norm_history[:1]
                           + [g for r in runs for g in r.grad_norm_history[1:]]),
        folds=last.folds, seconds=sum(r.seconds for r in runs),
        frozen=max(r.frozen for r in runs))


def area_balanced_map(V, F, U0, options=None, *, callback=None, **option_values):
    """Relax a fold-free spherical map toward low area and edge-length distortion.

    Minimizes the symmetric Dirichlet energy of the map
    (:class:`igl_spheremap.optimize.distortion.SymmetricDirichletEnergy`) with
    Algorithm 1 under the fold barrier (module docstring); the result stays
    fold-free, and above the rounding margin of ``precision`` when ``U0`` is.

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
        A closed, connected, genus-0 triangle mesh.
    U0 : (n, 3) array_like of float
        A fold-free spherical map of it, indexed like ``V`` (e.g.
        ``spherical_conformal_map(V, F).U``).
    options : MapOptions or dict, optional
        Uses ``metric``, ``h1_solver``, ``precision`` and the line-search
        constants; ``max_iter`` and ``gtol`` default to :data:`MAX_ITER` and
        :data:`GTOL` unless given.
    callback : callable, optional
        ``callback(k, U, energy, grad_norm)`` after each iteration.
    **option_values
        Fields of :class:`igl_spheremap.MapOptions`.

    Returns
    -------
    Algorithm1Result
        ``U`` indexed like ``V``; ``energy`` the symmetric Dirichlet energy
        (``8 pi`` for an isometry, dimensionless); ``converged`` False when ``max_iter``
        stopped it or more than :data:`CRUSHED_SHARE` of the surface's area is still
        crushed (:func:`crushed_share`), the message saying which.

    Raises
    ------
    MeshError
        Invalid mesh.
    ValueError
        A bad ``U0`` or options, or a ``U0`` with folds.

    Warns
    -----
    SphericalMapWarning
        Faces below their rounding margin (from a ``U0`` that had them).
    """
    opts = _relax_options(options, option_values)
    mesh = validate_mesh(V, F)
    U0 = mesh.from_input(as_points(U0, "U0", rows=mesh.n_input))
    folds = count_folds(mesh.F, unit_rows(U0))
    if folds:
        raise ValueError(f"U0 has {plural(folds, 'folded face')}; the area-balanced map starts "
                         "from a fold-free map")
    with opts.blas_limit():
        result = relax_validated(mesh, U0, opts, callback)
    below = int(below_margin(mesh.F, result.U, opts.precision).sum())
    result.U = mesh.to_input(result.U)
    if below and opts.precision != "float64":
        warnings.warn(f"area_balanced_map: {plural(below, 'face')} below their {opts.precision} "
                      "rounding margin (the start had them)", SphericalMapWarning, stacklevel=2)
    return result


def _relax_options(options, option_values):
    opts = map_options(options, **option_values)
    given = opts.explicit
    return opts.updated(max_iter=None if "max_iter" in given else MAX_ITER,
                        gtol=None if "gtol" in given else GTOL,
                        max_fold_shrinks=None if "max_fold_shrinks" in given else FOLD_SHRINKS)


def relaxation_options(opts):
    """The options of the relaxation after a conformal map made with ``opts`` (a MapOptions).

    Everything but the stopping rule and the barrier's shortenings is kept; ``max_iter``,
    ``gtol`` and ``max_fold_shrinks`` are :data:`MAX_ITER`, :data:`GTOL` and
    :data:`FOLD_SHRINKS` (the conformal map's are for the harmonic energy).
    """
    return opts.updated(max_iter=MAX_ITER, gtol=GTOL, max_fold_shrinks=FOLD_SHRINKS)
