"""Algebraic multigrid for the H1 metric: a smoothed aggregation hierarchy and its V-cycle.

Used by :func:`igl_spheremap.optimize.preconditioner.h1_preconditioner` with
``solver="amg"`` (``h1_solver="auto"`` above 50,000 vertices).  The building blocks
(strength of connection, aggregation, candidate fitting, spectral radius
estimates, Gauss-Seidel sweeps) are pyamg's; pyamg is imported only here.
"""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: Strength-of-connection threshold of the smoothed aggregation hierarchy.
#: pyamg's default (0: every edge is strong) coarsens cotangent matrices of
#: irregular meshes into aggregates that one V-cycle reduces poorly (energy
#: norm error 0.55 after one V-cycle on hcp_s1200_midthickness_left_32k,
#: 0.25 with 0.1); above ~0.15 the aggregates fall apart (0.84 at 0.15).
AMG_STRENGTH_THETA = 0.1

#: Seed of the start vectors of the spectral radius estimates (see
#: :func:`smoothed_aggregation_levels`).
AMG_SEED = 20140521

#: Arnoldi steps of each spectral radius estimate (see :func:`smoothed_aggregation_levels`).
RHO_STEPS = 8

#: pyamg's defaults for smoothed aggregation, which the hierarchy keeps.
_OMEGA = 4.0 / 3.0
_MAX_LEVELS = 10
_MAX_COARSE = 10

#: Coarsest AMG levels up to this size are solved with a dense pseudo-inverse.
_DENSE_COARSE_MAX = 500


def smoothed_aggregation_levels(K, seed=AMG_SEED):
    """Smoothed aggregation hierarchy of the SPD matrix ``K``, built from pyamg's pieces.

    The hierarchy of ``pyamg.smoothed_aggregation_solver(K, B=ones,
    strength=("symmetric", {"theta": AMG_STRENGTH_THETA}))`` with its default
    Jacobi prolongation smoother (``omega = 4/3``, weights ``omega / rho(D^-1 A)``),
    at most 10 levels, down to 10 unknowns, except for the estimates of ``rho``:
    one Arnoldi run of :data:`RHO_STEPS` steps from a start vector drawn from a
    generator local to the call, ``numpy.random.RandomState(seed)`` (one draw
    per level, in level order), so the hierarchy is reproducible bit for bit and
    no global state is touched (pyamg draws from numpy's global generator).

    Parameters
    ----------
    K : (n, n) scipy.sparse.csr_matrix of float64
        Symmetric positive definite.
    seed : int

    Returns
    -------
    (A, P, R) : three lists of sparse matrices
        Galerkin operators ``A`` (finest first, ``A[0] = K``), prolongations ``P``
        and restrictions ``R = P^T`` (one fewer each).
    """
    from pyamg.aggregation import fit_candidates, standard_aggregation
    from pyamg.strength import symmetric_strength_of_connection
    from pyamg.util.linalg import approximate_spectral_radius
    from pyamg.util.utils import get_diagonal, scale_rows

    rng = np.random.RandomState(seed)
    A, B = K, np.ones((K.shape[0], 1))
    As, Ps, Rs = [A], [], []
    while len(As) < _MAX_LEVELS and A.shape[0] > _MAX_COARSE:
        C = symmetric_strength_of_connection(A, theta=AMG_STRENGTH_THETA)
        T, B = fit_candidates(standard_aggregation(C)[0], B)
        D_inv_S = scale_rows(A, get_diagonal(A, inv=True), copy=True)
        # One Arnoldi run of RHO_STEPS steps (pyamg: up to 15 steps x 5 restarts after a
        # symmetry test): the same V-cycle convergence rate for less set-up (docs/decisions.md).
        rho = approximate_spectral_radius(D_inv_S, maxiter=RHO_STEPS, restart=0, symmetric=False,
                                          initial_guess=rng.rand(A.shape[0], 1))
        P = T - ((_OMEGA / rho) * D_inv_S) @ T
        R = P.T.conjugate()
        A = R @ A @ P
        A.sort_indices()  # greedy aggregation depends on the order of each row's entries
        As.append(A)
        Ps.append(P)
        Rs.append(R)
    return As, Ps, Rs


class VCycle:
    """``cycles`` V-cycles of a smoothed aggregation hierarchy, applied to all columns.

    The hierarchy (Galerkin operators ``A``, prolongations ``P``, restrictions
    ``R = P^T``) comes from :func:`smoothed_aggregation_levels`; the cycle is run here because
    pyamg's ``MultilevelSolver.solve`` takes one right-hand side (it ravels a
    2-D ``b``) and computes two residual norms per call.  The columns are kept
    in Fortran order so that pyamg's Gauss-Seidel sweeps each one in place on
    ``A`` (no ``kron(A, I_k)`` copies: 1M vertices, 1,433 -> ~1,160 MiB peak);
    residuals and transfers are sparse products with all columns.  Pre-smoothing is one forward sweep,
    post-smoothing one backward sweep (its adjoint), so the cycle is a
    symmetric operator; the coarsest level is solved exactly (dense
    pseudo-inverse, or SuperLU if it is large).
    """

    def __init__(self, levels, cycles):
        self.cycles = int(cycles)
        A, P, R = levels
        self.A = [sp.csr_matrix(X) for X in A]
        self.P = [sp.csr_matrix(X) for X in P]
        self.R = [sp.csr_matrix(X) for X in R]
        Ac = self.A[-1]
        if Ac.shape[0] <= _DENSE_COARSE_MAX:
            # Pseudo-inverse: the coarsest operator can be singular (a zero
            # 1 x 1 matrix when the free set of the fold barrier leaves
            # isolated vertices); pinv keeps the cycle symmetric there.
            pinv = np.linalg.pinv(Ac.toarray(), hermitian=True)
            self.coarse_solve = lambda b: pinv @ b
        else:
            self.coarse_solve = spla.splu(sp.csc_matrix(Ac)).solve

    @property
    def levels(self):
        """Number of unknowns on each level, finest first."""
        return [A.shape[0] for A in self.A]

    def _vcycle(self, lvl, x, b):
        if lvl == len(self.A) - 1:
            x += self.coarse_solve(b).reshape(x.shape)
            return
        A = self.A[lvl]
        _sweep(A, x, b, "forward")
        coarse_b = np.asfortranarray(self.R[lvl] @ (b - A @ x))
        coarse_x = np.zeros_like(coarse_b, order="F")
        self._vcycle(lvl + 1, coarse_x, coarse_b)
        x += self.P[lvl] @ coarse_x
        _sweep(A, x, b, "backward")

    def __call__(self, B):
        B = np.asfortranarray(B, dtype=np.float64)
        X = np.zeros_like(B, order="F")
        for _ in range(self.cycles):  # from X != 0 a V-cycle is X + V (B - A X)
            self._vcycle(0, X, B)
        return np.ascontiguousarray(X)


def _sweep(A, x, b, direction):
    """One Gauss-Seidel sweep of ``A x = b`` per column, in place (``x``, ``b`` in Fortran order)."""
    from pyamg.relaxation.relaxation import gauss_seidel

    if x.ndim == 1:
        gauss_seidel(A, x, b, sweep=direction)
        return
    for j in range(x.shape[1]):
        gauss_seidel(A, x[:, j], b[:, j], sweep=direction)


