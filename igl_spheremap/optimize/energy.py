"""The interface of an energy minimized by Algorithm 1 (in the spirit of pymanopt's cost functions).

An energy of a spherical map ``U`` (n, 3) gives its value and its Euclidean
gradient ``dE/dU`` (n, 3), and chooses the metric of the search direction
(:mod:`igl_spheremap.optimize.direction`: the paper's L2 product or the H1
preconditioner).  Algorithm 1 (:func:`igl_spheremap.optimize.minimize.minimize`) turns the
Euclidean gradient into the L2 gradient ``M^{-1} dE/dU`` (``M`` the lumped mass
of paper Eq. 13, :attr:`Energy.area`), projects it onto the tangent planes of the
spheres and applies the metric.

Adding an energy is a subclass in a new file: ``evaluate`` (one evaluation per
line-search trial, so keep it cheap and cache what the gradient reuses) and
``euclidean_gradient``, plus ``mobius_invariant`` if the Möbius gauge applies; its
``__init__`` passes the vertex areas and a metric object
(:func:`igl_spheremap.optimize.direction.make_metric`) to :class:`Energy`'s.
"""

from dataclasses import dataclass

import numpy as np

from .direction import METRIC_INTERFACE


@dataclass
class Evaluation:
    """An energy evaluated at a map.

    Attributes
    ----------
    U : (n, 3) float64 array
        The map.
    value : float
        The energy.
    LU : (n, 3) float64 array or None
        ``L @ U`` for the stiffness ``L`` of the energy's metric when the energy
        computed it (the H1 metric's step sizes reuse it), else None.
    cache : object
        Anything else the energy's gradient reuses.
    """

    U: np.ndarray
    value: float
    LU: np.ndarray = None
    cache: object = None


class Energy:
    """Base class of the energies of :mod:`igl_spheremap.optimize.energy`.

    Parameters
    ----------
    area : (n,) float64 array
        Vertex areas of the mesh scaled to total area ``4 pi`` (the lumped mass
        of paper Eq. 13; :func:`igl_spheremap.mesh.operators.to_sphere_area`).
    metric : L2Metric or H1Metric
        Metric of the search direction: an object, made by
        ``igl_spheremap.optimize.direction.make_metric("L2" or "H1", L, area)``
        (not the name itself).

    Raises
    ------
    TypeError
        If ``metric`` lacks what Algorithm 1 uses of a metric
        (:data:`igl_spheremap.optimize.direction.METRIC_INTERFACE`), e.g. the name ``"L2"``.

    Attributes
    ----------
    mobius_invariant : bool
        Whether the continuous energy is invariant under the Möbius
        transformations of the sphere, so that Algorithm 1 keeps the map
        Möbius-normalized (:class:`igl_spheremap.optimize.gauge.MobiusGauge`).
    """

    mobius_invariant = False

    def __init__(self, area, metric):
        missing = [a for a in METRIC_INTERFACE if not hasattr(metric, a)]
        if missing:
            raise TypeError(
                f"metric must be a metric object, not {type(metric).__name__} {metric!r:.40}: "
                "make it with igl_spheremap.optimize.direction.make_metric(name, L, area) "
                "(name 'L2' or 'H1', L the Laplacian, area the vertex areas); it lacks "
                + ", ".join(missing))
        self.area = np.asarray(area, dtype=np.float64)
        self.metric = metric

    def evaluate(self, U):
        """The energy at ``U`` (n, 3): an :class:`Evaluation`."""
        raise NotImplementedError

    def euclidean_gradient(self, ev):
        """``dE/dU`` (n, 3) at the evaluation ``ev``."""
        raise NotImplementedError

    def value(self, U):
        """The energy at ``U`` (float)."""
        return self.evaluate(U).value
