"""The rounds of Algorithm 2: each builds an initial map and runs Algorithm 1 from it.

Every strategy takes the problem and the previous round and returns a new
:class:`igl_spheremap.result.Round` (or None when it does not apply):

* :func:`gauss_round`: the Gauss map (Definition 1), then Algorithm 1 without
  the fold barrier (the Gauss map folds on thin features);
* :func:`star_round`: the star map of the previous map's weighted Laplace-Beltrami
  eigenfunctions (Section 4.2), its few remaining folds untangled (not in the
  paper), then Algorithm 1, under the fold barrier when the start is fold-free;
* :func:`local_round`: the previous map's isolated folds untangled and
  Algorithm 1 rerun only around them (not in the paper,
  :func:`igl_spheremap.local_repair.local_repair`).

Maps are passed between rounds in the validated mesh's vertex order; the Round
objects hold them in the input's order.
"""

import time
from dataclasses import dataclass

import numpy as np

from .algorithm1 import minimize
from .eigen_projection import star_map_of
from .energies import HarmonicEnergy
from .gauss import vertex_normals
from .local_repair import local_repair
from .metrics import count_folds
from .mobius import mobius_center
from .result import Round
from .untangle import untangle_folds


@dataclass
class MapProblem:
    """A validated mesh with the operators of Algorithm 1 and the run's options.

    Attributes
    ----------
    mesh : igl_spheremap.ValidatedMesh
    L : (n, n) sparse matrix
        The Laplacian of ``options.laplacian_kind``.
    area : (n,) float64 array
        Vertex areas scaled to total area ``4 pi``.
    options : MapOptions
    on_iteration : callable or None
        ``on_iteration(k, U, energy, grad_norm)`` (a progress bar).
    """

    mesh: object
    L: object
    area: np.ndarray
    options: object
    on_iteration: object = None

    @property
    def F(self):
        return self.mesh.F

    def minimize(self, U0, fold_barrier, index):
        """Algorithm 1 for the harmonic energy from ``U0`` (validated order)."""
        opts = self.options
        energy = HarmonicEnergy(self.L, self.area, opts.metric, opts.h1_solver)
        run = minimize(energy, U0, self.F, opts, fold_barrier=fold_barrier,
                       callback=self.on_iteration)
        return _finite(run, index)

    def round(self, index, kind, U_init, run, folds_init, t0, previous=None, **details):
        """A :class:`Round` in the input's vertex order."""
        to_input = self.mesh.to_input
        run.U = to_input(run.U)
        if details.get("Phi") is not None:
            details["Phi"] = to_input(details["Phi"])
        return Round(index=index, kind=kind, U_init=to_input(U_init), run=run,
                     folds_before=folds_init, seconds=time.perf_counter() - t0,
                     folds_previous=None if previous is None else previous.folds_after,
                     **details)


def _finite(run, index):
    if not np.all(np.isfinite(run.U)):
        raise RuntimeError(f"Algorithm 1 produced non-finite values in round {index}")
    return run


def gauss_round(problem):
    """Round 0: Algorithm 1 from the Gauss map, without the fold barrier."""
    t0 = time.perf_counter()
    U_init = vertex_normals(problem.mesh.V, problem.F)
    run = problem.minimize(U_init, fold_barrier=False, index=0)
    return problem.round(0, "gauss", U_init, run, count_folds(problem.F, U_init), t0)


def star_round(problem, previous, index):
    """Round ``index``: Algorithm 1 from the star map of the previous map (Algorithm 2).

    The star map's folds, if any, are untangled first (``options.untangle``); the
    fold barrier (``options.keep_fold_free``) applies when the start is fold-free.
    From a start that still folds, the barrier would keep those faces folded
    and, measured on pycortex (2 folds left after untangling), crawl at ~0.5 s
    per iteration, so such rounds run free.
    """
    t0 = time.perf_counter()
    opts = problem.options
    U_prev = problem.mesh.from_input(previous.U)
    U_init, Phi, lam, reflected = star_map_of(problem.F, U_prev, problem.L, problem.area)
    folds_star = count_folds(problem.F, U_init)
    if folds_star and opts.untangle:
        U_init, _ = untangle_folds(problem.F, U_init)
    folds_init = count_folds(problem.F, U_init)
    run = problem.minimize(U_init, opts.keep_fold_free and folds_init == 0, index)
    return problem.round(index, "star", U_init, run, folds_init, t0, previous, Phi=Phi,
                         eigenvalues=lam, reflected=reflected, folds_star=folds_star)


def local_round(problem, previous, index):
    """Round ``index`` as a local repair of the previous map's folds, or None if it does not apply.

    The previous map is Möbius-centered first (with ``options.mobius``), then
    :func:`igl_spheremap.local_repair.local_repair` untangles its folds and
    re-minimizes around them under the fold barrier.
    """
    t0 = time.perf_counter()
    U_prev = problem.mesh.from_input(previous.U)
    if problem.options.mobius:
        U_prev, _ = mobius_center(U_prev, problem.area)
    repaired = local_repair(problem.L, problem.area, problem.F, U_prev, problem.options)
    if repaired is None:
        return None
    U_init, run, region = repaired
    run.folds = count_folds(problem.F, run.U)
    return problem.round(index, "local", U_init, _finite(run, index), 0, t0, previous,
                         region=int(region.sum()))
