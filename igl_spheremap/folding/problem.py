"""A validated mesh with the operators of Algorithm 1 and the options of a run: what every
round of Algorithm 2 works on."""

import time
from dataclasses import dataclass

import numpy as np

from ..mesh.operators import laplacian, to_sphere_area, vertex_areas
from ..optimize.harmonic import HarmonicEnergy
from ..optimize.minimize import minimize
from .result import Round


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

    @classmethod
    def of(cls, mesh, options):
        """The problem of a validated mesh: the Laplacian of ``options.laplacian_kind`` and the
        vertex areas scaled to ``4 pi``."""
        return cls(mesh, laplacian(mesh.V, mesh.F, options.laplacian_kind),
                   to_sphere_area(vertex_areas(mesh.V, mesh.F)), options)

    @property
    def F(self):
        return self.mesh.F

    def minimize(self, U0, fold_barrier, index, precision=None):
        """Algorithm 1 for the harmonic energy from ``U0`` (validated order).

        ``precision`` overrides ``options.precision``: the rounding margin the
        fold barrier keeps (``"float64"``: the plain fold barrier).
        """
        opts = self.options
        if precision is not None and precision != opts.precision:
            opts = opts.updated(precision=precision)
        energy = HarmonicEnergy(self.L, self.area, opts.metric, opts.h1_solver)
        run = minimize(energy, U0, self.F, opts, fold_barrier=fold_barrier,
                       callback=self.on_iteration)
        return finite(run, index)

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


def finite(run, index):
    """``run`` (an :class:`igl_spheremap.optimize.result.Algorithm1Result`), or a
    RuntimeError when its map holds non-finite values."""
    if not np.all(np.isfinite(run.U)):
        raise RuntimeError(f"Algorithm 1 produced non-finite values in round {index}")
    return run
