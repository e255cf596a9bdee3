"""The outcome of one run of Algorithm 1 (scipy.optimize style)."""

from dataclasses import dataclass, field, fields

import numpy as np


def success_first_repr(result):
    """``repr`` of a result dataclass with ``success`` (a property, which the dataclass's own
    repr leaves out) first, then the fields marked for repr (not the arrays).

    Set as ``__repr__ = success_first_repr`` in the class body, where ``@dataclass`` keeps it.
    """
    shown = ", ".join(f"{f.name}={getattr(result, f.name)!r}" for f in fields(result) if f.repr)
    return f"{type(result).__name__}(success={result.success!r}, {shown})"


@dataclass
class Algorithm1Result:
    """Outcome of one run of Algorithm 1 (:func:`igl_spheremap.optimize.minimize.minimize`).

    Attributes
    ----------
    U : (n, 3) float64 array
        Final map, unit rows.
    converged : bool
        True when the stopping rule was met.
    message : str
        Why the iteration stopped.
    nit : int
        Accepted iterations.
    energy : float
        Final energy, dimensionless (``4 pi`` for the harmonic energy of a
        conformal bijection).
    grad_norm : float
        Final RMS Riemannian gradient ``sqrt(sum_i A_i |G_i|^2 / 4 pi)`` over the
        free vertices.
    energy_history, grad_norm_history : list of float
        One value per iterate, starting with the initial map.
    folds : int
        Folded faces of ``U``.
    mobius_steps : int
        How many times the map was re-centered during the run.
    seconds : float
        Wall time.
    frozen : int
        Vertices frozen by the fold barrier (fixed vertices not counted).
    """

    U: np.ndarray = field(repr=False)
    converged: bool
    message: str
    nit: int
    energy: float
    grad_norm: float
    energy_history: list = field(default_factory=list, repr=False)
    grad_norm_history: list = field(default_factory=list, repr=False)
    folds: int = 0
    mobius_steps: int = 0
    seconds: float = 0.0
    frozen: int = 0

    @property
    def success(self):
        """``converged`` and fold-free: a folded map is no spherical map, converged or not."""
        return bool(self.converged and self.folds == 0)

    __repr__ = success_first_repr


#: The name the public :func:`igl_spheremap.harmonic_map` documents.
HarmonicMapResult = Algorithm1Result
