"""p-harmonic maps onto the sphere (paper Remark 1, Eq. 8) with Algorithm 1."""

from ._checks import as_points
from .algorithm1 import minimize
from .energies import PHarmonicEnergy
from .metrics import count_folds
from .options import map_options
from .validation import validate_mesh


def p_harmonic_map(V, F, U0, p, options=None, *, keep_fold_free=None, callback=None,
                   **option_values):
    """Minimize the p-harmonic energy ``1/p sum_f A_f |grad U|_f^p`` from an initial map.

    Paper Remark 1: the optimizer of Algorithm 1 minimizes Eq. 8 as well
    (:class:`igl_spheremap.energies.PHarmonicEnergy`, per-face gradients from
    ``igl.grad``, mesh scaled to area ``4 pi``).  ``p = 2`` is the harmonic energy
    with the cotangent Laplacian; larger ``p`` weighs large stretch more: the
    map spreads area more evenly (less area distortion) at the cost of angle
    distortion (README, "p-harmonic maps and area correction", has the measured trade-off).  For
    ``p != 2`` the energy is not Möbius invariant, so no Möbius normalization
    is applied: the minimizer picks its own placement.

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
        A closed, connected, genus-0 triangle mesh.
    U0 : (n, 3) array_like of float
        Initial map, indexed like ``V`` (e.g. ``spherical_conformal_map(V, F).U``).
    p : float
        Exponent, >= 2.
    options : MapOptions or dict, optional
        Algorithm 1's options (``gtol``, ``max_iter``, ``metric``, ``h1_solver``, ...).
    keep_fold_free : bool, optional
        Fold barrier (default: on when ``U0`` is fold-free).
    callback : callable, optional
        ``callback(k, U, energy, grad_norm)`` after each iteration.
    **option_values
        Fields of :class:`igl_spheremap.MapOptions`.

    Returns
    -------
    Algorithm1Result
        ``U`` indexed like ``V``; ``energy`` is the p-harmonic energy.

    Raises
    ------
    MeshError
        Invalid mesh.
    ValueError
        ``p < 2``, a bad ``U0`` or bad options.
    """
    opts = map_options(options, **option_values)
    mesh = validate_mesh(V, F)
    U0 = mesh.from_input(as_points(U0, "U0", rows=mesh.n_input))
    if keep_fold_free is None:
        keep_fold_free = count_folds(mesh.F, U0) == 0
    with opts.blas_limit():
        energy = PHarmonicEnergy(mesh.V, mesh.F, p, opts.metric, opts.h1_solver)
        result = minimize(energy, U0, mesh.F, opts, fold_barrier=keep_fold_free,
                          callback=callback)
    result.U = mesh.to_input(result.U)
    return result
