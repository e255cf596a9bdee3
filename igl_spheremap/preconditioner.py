"""Inverse of the H1 (Sobolev) metric ``K = -L + M`` of the preconditioned gradient."""

import numpy as np
import pyamg
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from pyamg.relaxation.relaxation import gauss_seidel
from threadpoolctl import ThreadpoolController

H1_SOLVERS = ("amg", "direct", "cholmod", "superlu")

#: Strength-of-connection threshold of the smoothed aggregation hierarchy.
#: pyamg's default (0: every edge is strong) coarsens cotangent matrices of
#: irregular meshes into aggregates that one V-cycle reduces poorly (energy
#: norm error 0.55 after one V-cycle on hcp_s1200_midthickness_left_32k,
#: 0.25 with 0.1); above ~0.15 the aggregates fall apart (0.84 at 0.15).
AMG_STRENGTH_THETA = 0.1

#: Seed of numpy's global generator while pyamg builds a hierarchy (see h1_preconditioner).
_AMG_SEED = 20140521

#: Right-hand sides smoothed together (the map's 3 coordinates).
_MAX_BLOCK = 4

#: Coarsest AMG levels up to this size are solved with a dense pseudo-inverse.
_DENSE_COARSE_MAX = 500

#: Above this size SuperLU's minimum degree ordering of ``K + K^T`` costs more
#: than it saves (300k vertices: 32 s against 9 s for COLAMD; 100k: 1.0 s
#: against 1.7 s).
_MMD_MAX_SIZE = 150_000

_CONTROLLER = None  # threadpoolctl's view of the loaded BLAS libraries, made on first use

_CHOLMOD = None  # sksparse.cholmod once looked up; False if it is not installed


def cholmod_available():
    """Whether CHOLMOD (scikit-sparse 0.4, the ``cholmod`` extra) can be imported.

    ``h1_solver="direct"`` uses it when it can, SuperLU otherwise.  The import
    is tried once per process.

    Returns
    -------
    bool
        True if ``sksparse.cholmod`` imports and has the 0.4 API (``analyze``).
    """
    return _cholmod() is not None


def _cholmod():
    global _CHOLMOD
    if _CHOLMOD is None:
        try:
            from sksparse import cholmod
            cholmod.analyze  # the 0.4 API; 0.5 replaced it
        except (ImportError, AttributeError):
            cholmod = False
        _CHOLMOD = cholmod
    return _CHOLMOD or None


def _factorize(K, solver):
    """Exact inverse of the SPD matrix ``K``: ``solve(B) = K^{-1} B``."""
    K = sp.csc_matrix(K, dtype=np.float64)
    if solver == "direct":
        solver = "cholmod" if cholmod_available() else "superlu"
    if solver == "cholmod":
        cholmod = _cholmod()
        if cholmod is None:
            raise ModuleNotFoundError(
                "h1_solver='cholmod' needs scikit-sparse 0.4 (sksparse.cholmod.analyze): "
                "pip install 'igl-spheremap[cholmod]' (builds against SuiteSparse, e.g. "
                "Debian's libsuitesparse-dev)")
        # Simplicial LDL^T after an AMD ordering: on the test meshes (6k-32k
        # vertices) its factorization plus 16 solves with 3 right-hand sides
        # took 55-75% of SuperLU's time; the supernodal factorization's solves
        # were 2-3x slower than the simplicial ones, and METIS / nested
        # dissection orderings cost more to compute than they saved.
        factor = cholmod.analyze(K, mode="simplicial", ordering_method="amd").cholesky(K)
        return factor.solve_A
    spec = "MMD_AT_PLUS_A" if K.shape[0] <= _MMD_MAX_SIZE else "COLAMD"
    # Supernode relaxation 20 (panel 10): 5-30% faster factorization
    # than SuperLU's default on the test meshes (6k-32k vertices).
    lu = spla.splu(K, permc_spec=spec, diag_pivot_thresh=0.0, relax=20, panel_size=10,
                   options=dict(SymmetricMode=True))
    return lu.solve


def one_blas_thread():
    """Context manager limiting the BLAS libraries loaded by numpy/scipy to one thread.

    The BLAS calls of the H1 solvers and of Algorithm 1 are small (n x 3
    products, 3 x 3 solves, SuperLU's supernode kernels, pyamg's Arnoldi
    estimates), where threads only add synchronization; on a loaded 2-core
    machine OpenBLAS's spinning threads made hcp_s1200_midthickness_left_32k
    take 1.5 s instead of 0.7 s, and pyamg's set-up 1 s instead of 0.05 s.
    Uses threadpoolctl; the libraries are looked up once (~7 ms), after that
    entering the limit costs ~20 us.
    """
    global _CONTROLLER
    if _CONTROLLER is None:
        _CONTROLLER = ThreadpoolController()
    return _CONTROLLER.limit(limits=1, user_api="blas")


class _VCycle:
    """``cycles`` V-cycles of a pyamg hierarchy, applied to all columns of ``B`` at once.

    The hierarchy (Galerkin operators ``A``, prolongations ``P``,
    restrictions ``R = P^T``) is pyamg's; the cycle is run here because
    pyamg's ``MultilevelSolver.solve`` takes one right-hand side (it ravels a
    2-D ``b``) and computes two residual norms per call.  With ``k`` columns
    stored row-major, the Gauss-Seidel sweeps run on ``kron(A, I_k)``: its
    sweep over the interleaved unknowns is exactly one sweep per column in the
    same vertex order, in one call; residuals and transfers are sparse
    products with all ``k`` columns.  Pre-smoothing is one forward sweep,
    post-smoothing one backward sweep (its adjoint), so the cycle is a
    symmetric operator; the coarsest level is solved exactly (dense
    pseudo-inverse, or SuperLU if it is large).
    """

    def __init__(self, ml, cycles):
        self.cycles = int(cycles)
        self.A = [sp.csr_matrix(lvl.A) for lvl in ml.levels]
        self.P = [sp.csr_matrix(lvl.P) for lvl in ml.levels[:-1]]
        self.R = [sp.csr_matrix(lvl.R) for lvl in ml.levels[:-1]]
        Ac = self.A[-1]
        if Ac.shape[0] <= _DENSE_COARSE_MAX:
            # Pseudo-inverse: the coarsest operator can be singular (a zero
            # 1 x 1 matrix when the free set of the fold barrier leaves
            # isolated vertices); pinv keeps the cycle symmetric there.
            pinv = np.linalg.pinv(Ac.toarray(), hermitian=True)
            self.coarse_solve = lambda b: pinv @ b
        else:
            self.coarse_solve = spla.splu(sp.csc_matrix(Ac)).solve
        self._kron = {}

    @property
    def levels(self):
        """Number of unknowns on each level, finest first."""
        return [A.shape[0] for A in self.A]

    def _smoothing_matrices(self, k):
        if k not in self._kron:
            eye = sp.identity(k, format="csr")
            self._kron[k] = [A if k == 1 else sp.kron(A, eye, format="csr")
                             for A in self.A[:-1]]
        return self._kron[k]

    def _vcycle(self, lvl, x, b, Ak):
        if lvl == len(self.A) - 1:
            x += self.coarse_solve(b).reshape(x.shape)
            return
        A, S = self.A[lvl], Ak[lvl]
        gauss_seidel(S, x.reshape(-1), b.reshape(-1), sweep="forward")
        coarse_b = self.R[lvl] @ (b - A @ x)
        coarse_x = np.zeros_like(coarse_b)
        self._vcycle(lvl + 1, coarse_x, coarse_b, Ak)
        x += self.P[lvl] @ coarse_x
        gauss_seidel(S, x.reshape(-1), b.reshape(-1), sweep="backward")

    def __call__(self, B):
        B = np.asarray(B, dtype=np.float64)
        if B.ndim == 2 and B.shape[1] > _MAX_BLOCK:
            # kron(A, I_k) has k times the entries of A: wide blocks go in slices.
            return np.hstack([self(B[:, j:j + _MAX_BLOCK])
                              for j in range(0, B.shape[1], _MAX_BLOCK)])
        B = np.ascontiguousarray(B)
        X = np.zeros_like(B)
        Ak = self._smoothing_matrices(1 if B.ndim == 1 else B.shape[1])
        for _ in range(self.cycles):  # from X != 0 a V-cycle is X + V (B - A X)
            self._vcycle(0, X, B, Ak)
        return X


def h1_preconditioner(K, solver="amg", *, cycles=1):
    """Approximate (``"amg"``) or exact (the others) inverse of the SPD matrix ``K``.

    Built for the H1 metric ``K = -L + M`` of :func:`igl_spheremap.harmonic_map`
    (``L`` the cotangent Laplacian, ``M`` the lumped mass matrix, or their
    restriction to the vertices that are free to move), a shifted graph
    Laplacian: symmetric positive definite.

    Parameters
    ----------
    K : (n, n) sparse matrix of float64
        Symmetric positive definite.
    solver : {"amg", "direct", "cholmod", "superlu"}
        ``"amg"``: ``cycles`` V-cycles of pyamg's smoothed aggregation
        hierarchy of ``K`` (strength threshold :data:`AMG_STRENGTH_THETA`,
        one forward Gauss-Seidel sweep before the coarse-grid correction and
        one backward sweep after it), started from zero.  This is a fixed
        symmetric positive definite linear operator, spectrally equivalent to
        ``K^{-1}`` (the post-smoother is the adjoint of the pre-smoother); its
        set-up and each application cost O(n) time and memory.
        ``"cholmod"``: CHOLMOD's simplicial ``L D L^T`` factorization of ``K``
        after an AMD ordering (scikit-sparse 0.4, the ``cholmod`` extra).
        ``"superlu"``: SuperLU factorization of ``K`` in symmetric mode
        (minimum degree ordering of ``K + K^T`` up to 150k unknowns, COLAMD
        above; diagonal pivots, as ``K`` is SPD).  ``"direct"``: ``"cholmod"``
        if scikit-sparse is installed, ``"superlu"`` otherwise.  The three are
        the exact inverse; their fill-in and time grow faster than ``n``.
    cycles : int
        Number of V-cycles of ``"amg"`` (more is closer to ``K^{-1}``).

    Returns
    -------
    callable
        ``apply(B)``: for a ``(n,)`` or ``(n, k)`` float64 array ``B``, the
        array ``K^{-1} B`` (approximately for ``"amg"``) of the same shape.

    Raises
    ------
    ValueError
        If ``solver`` is unknown, ``cycles < 1`` or ``K`` is not square.
    ModuleNotFoundError
        If ``solver="cholmod"`` and scikit-sparse 0.4 is not installed.
    """
    if solver not in H1_SOLVERS:
        raise ValueError(f"unknown H1 solver {solver!r}; expected one of {H1_SOLVERS}")
    if K.shape[0] != K.shape[1]:
        raise ValueError(f"K must be square, got shape {K.shape}")
    with one_blas_thread():
        if solver != "amg":
            return _factorize(K, solver)
        if int(cycles) < 1:
            raise ValueError(f"cycles must be >= 1, got {cycles}")
        K = sp.csr_matrix(K)
        # pyamg draws the start vectors of its spectral radius estimates (the
        # Jacobi prolongation smoother's weights) from numpy's global
        # generator; a fixed seed, with the caller's state put back, makes the
        # hierarchy and so the whole run reproducible bit for bit.
        state = np.random.get_state()
        np.random.seed(_AMG_SEED)
        try:
            ml = pyamg.smoothed_aggregation_solver(
                K, B=np.ones((K.shape[0], 1)),
                strength=("symmetric", {"theta": AMG_STRENGTH_THETA}),
                improve_candidates=None, presmoother=None, postsmoother=None)
        finally:
            np.random.set_state(state)
        return _VCycle(ml, cycles)
