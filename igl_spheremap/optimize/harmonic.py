"""The harmonic (Dirichlet) energy of paper Eq. 6, discretized as in Eq. 13, and Algorithm 1 for it."""

from ..mesh.operators import dirichlet_energy, laplacian, to_sphere_area, vertex_areas
from ..options import map_options
from .direction import make_metric
from .energy import Energy, Evaluation
from .minimize import minimize_map


class HarmonicEnergy(Energy):
    """``E(U) = -1/2 tr(U^T L U)`` (paper Eqs. 6 and 13) with ``dE/dU = -L U``.

    For a conformal bijection onto the unit sphere ``E = 4 pi``; every conformal
    map of a genus-0 surface is a critical point, and the continuous energy is
    Möbius invariant (the discrete one is not: Algorithm 1 keeps the map
    normalized, :mod:`igl_spheremap.optimize.gauge`).

    Parameters
    ----------
    L : (n, n) sparse matrix
        Negative semidefinite Laplacian (:func:`igl_spheremap.mesh.operators.laplacian`;
        the paper's is the cotangent Laplacian).
    area : (n,) float64 array
        Vertex areas, mesh scaled to total area ``4 pi``.
    metric : {"H1", "L2"}
        ``"L2"``: the paper's Riemannian gradient; ``"H1"``: preconditioned by the
        Sobolev metric ``-L + M`` (README, "How the default differs", item 3).
    h1_solver : {"auto", "direct", "amg", "cholmod", "superlu"}
        How the H1 metric is inverted.

    Raises
    ------
    ValueError
        Unknown ``metric`` or ``h1_solver``.
    """

    mobius_invariant = True

    def __init__(self, L, area, metric="H1", h1_solver="auto"):
        super().__init__(area, make_metric(metric, L, area, h1_solver))
        self.L = L

    def evaluate(self, U):
        """One product ``L U``; the value and :meth:`euclidean_gradient` reuse it."""
        LU = self.L @ U
        return Evaluation(U=U, value=dirichlet_energy(self.L, U, LU), LU=LU)

    def euclidean_gradient(self, ev):
        """``-L U`` (n, 3)."""
        return -ev.LU


def harmonic_map(V, F, U0, options=None, *, fold_barrier=False, callback=None,
                 **option_values):
    """Paper Algorithm 1 alone: minimize the discrete harmonic energy from an initial map.

    Minimizes ``E(U) = -1/2 tr(U^T L U)`` (paper Eq. 6 discretized by Eq. 13,
    :class:`igl_spheremap.optimize.harmonic.HarmonicEnergy`) subject to ``|U_i| = 1`` with
    :func:`minimize`.  Inner products are the lumped L2 products
    ``sum_i A_i x_i . y_i`` of Eq. 13 on the mesh scaled to total area ``4 pi``,
    so one tolerance means the same on every mesh.  Stopping rule: the RMS
    Riemannian gradient ``sqrt(sum_i A_i |G_i|^2 / 4 pi) <= gtol``.
    ``laplacian_kind="cotan", metric="L2", mobius=False`` is Algorithm 1 exactly
    as published.

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
        Closed genus-0 triangle mesh (validated and oriented outward by
        :func:`igl_spheremap.validate_mesh`).
    U0 : (n, 3) array_like of float
        Initial map (e.g. :func:`gauss_map` or :func:`star_map`), indexed like ``V``;
        rows are normalized.
    options : MapOptions or dict, optional
        Uses ``laplacian_kind``, ``metric``, ``h1_solver``, ``mobius``, ``gtol``,
        ``max_iter`` and the line-search constants (:class:`igl_spheremap.MapOptions`).
    fold_barrier : bool
        A step may not fold a face that is not folded in ``U0`` (after its
        Möbius centering); such faces may unfold and then stay unfolded.  Under
        the barrier the map is not re-centered.  With ``precision="float32"``
        the barrier keeps the float32 rounding margin
        (:mod:`igl_spheremap.optimize.barrier`), and re-centers when that keeps it.
    callback : callable, optional
        ``callback(k, U, energy, grad_norm)`` after each accepted iteration
        (``U`` in the validated mesh's vertex order).
    **option_values
        Fields of :class:`igl_spheremap.MapOptions`; they override ``options``.

    Returns
    -------
    Algorithm1Result
        ``U`` indexed like ``V``; ``success`` needs a converged and fold-free map.

    Raises
    ------
    MeshError
        If the mesh is invalid.
    ValueError
        If ``U0`` is not an (n, 3) array of finite numbers, has a zero row (no
        direction), or an option is invalid.

    Warns
    -----
    SphericalMapWarning
        If the map has folded faces (Algorithm 1 from a folded start, such as
        the Gauss map of a mesh with thin features, can end folded) or did not
        converge.
    """
    opts = map_options(options, **option_values)

    def energy(mesh):
        return HarmonicEnergy(laplacian(mesh.V, mesh.F, opts.laplacian_kind),
                              to_sphere_area(vertex_areas(mesh.V, mesh.F)), opts.metric,
                              opts.h1_solver)

    return minimize_map(energy, V, F, U0, opts, fold_barrier=fold_barrier, callback=callback,
                        caller="harmonic_map")
