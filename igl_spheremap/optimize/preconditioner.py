"""Inverse of the H1 (Sobolev) metric ``K = -L + M`` of the preconditioned gradient."""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

H1_SOLVERS = ("amg", "direct", "cholmod", "superlu")

#: Above this size SuperLU's minimum degree ordering of ``K + K^T`` costs more
#: than it saves (``docs/decisions.md``).
_MMD_MAX_SIZE = 150_000

#: ``h1_solver="auto"`` factorizes the H1 metric up to this many vertices and
#: uses the AMG V-cycle above: the factorization's time and memory grow faster
#: than ``n``, the V-cycle's like ``n`` (``docs/decisions.md``).
AUTO_DIRECT_MAX_SIZE = 50_000

#: Below this many rows ``solver="direct"`` factorizes by SuperLU, CHOLMOD installed or not:
#: inside ``surface_map`` sksparse-minimal's CHOLMOD corrupted the heap (glibc aborted the
#: interpreter) on systems of 6 to 13 rows, a 6-vertex surface's Laplace basis and a
#: 22-vertex surface's distortion stage (``docs/decisions.md``); SuperLU's exact solve costs
#: nothing at that size.
SMALL_SYSTEM = 100


def resolve_h1_solver(h1_solver, n):
    """The solver ``h1_solver`` means for a metric on a mesh of ``n`` vertices (whatever
    its unknowns per vertex).

    ``"auto"`` is ``"direct"`` up to :data:`AUTO_DIRECT_MAX_SIZE` vertices and
    ``"amg"`` above; the others are returned as they are.

    Raises
    ------
    ValueError
        If ``h1_solver`` is unknown.
    """
    if h1_solver == "auto":
        return "direct" if n <= AUTO_DIRECT_MAX_SIZE else "amg"
    if h1_solver not in H1_SOLVERS:
        raise ValueError(f"unknown h1_solver {h1_solver!r}; expected 'auto' or one of "
                         f"{H1_SOLVERS}")
    return h1_solver


def cholmod_available():
    """Whether a CHOLMOD backend can be imported (the ``cholmod`` extra).

    ``h1_solver="direct"`` uses it when it can, SuperLU otherwise.  Two packages
    give CHOLMOD: scikit-sparse 0.4 (built from source against SuiteSparse) and
    sksparse-minimal 0.3 (a wheel that bundles CHOLMOD, what the ``cholmod`` extra
    installs).

    Returns
    -------
    bool
    """
    return _cholmod() is not None


def _cholmod():
    """A function ``K -> solve`` by CHOLMOD's simplicial factorization, or None."""
    try:
        from sksparse import cholmod
        if hasattr(cholmod, "analyze"):  # the 0.4 API; 0.5 replaced it
            return lambda K: cholmod.analyze(K, mode="simplicial",
                                             ordering_method="amd").cholesky(K).solve_A
    except ImportError:
        pass
    try:
        from sksparse_minimal._cholespy_core import CholeskySolver
    except ImportError:
        return None
    return lambda K: _minimal_solver(CholeskySolver, K)


def _minimal_solver(CholeskySolver, K):
    """sksparse-minimal: CHOLMOD's supernodal LL^T, converted to simplicial for the solves.

    The supernodal factorization is the fastest here and simplicial solves are
    faster than supernodal ones for 3 right-hand sides (``docs/decisions.md``);
    ``change_factor(1, 0)`` is the conversion its own ``SparseCholesky`` uses.
    """
    n = K.shape[0]
    core = CholeskySolver(n, K.indptr.astype(np.int32), K.indices.astype(np.int32),
                          np.ascontiguousarray(K.data, dtype=np.float64))
    core.change_factor(1, 0)

    def solve(B):
        B = np.asarray(B, dtype=np.float64)
        X = np.zeros((n, 1 if B.ndim == 1 else B.shape[1]))
        core.solve(np.ascontiguousarray(B.reshape(n, -1)), X, 0)  # 0: CHOLMOD_A
        return X.reshape(B.shape)

    return solve


def backend_description():
    """Which H1 solver ``h1_solver="auto"`` uses here, in words (for ``--version``)."""
    direct = "CHOLMOD" if cholmod_available() else "SuperLU (scipy)"
    return (f"direct = {direct} up to {AUTO_DIRECT_MAX_SIZE:,} vertices, algebraic multigrid "
            "(pyamg) above")


def factorize(K, solver="direct"):
    """Exact inverse of the sparse symmetric positive definite matrix ``K``.

    Parameters
    ----------
    K : (n, n) sparse matrix of float64
        Symmetric positive definite.
    solver : {"direct", "cholmod", "superlu"}
        ``"direct"``: CHOLMOD when installed (the ``cholmod`` extra) and ``K`` has
        :data:`SMALL_SYSTEM` rows or more, SuperLU otherwise (see
        :func:`h1_preconditioner`).

    Returns
    -------
    callable
        ``solve(B)``: ``K^{-1} B`` for a ``(n,)`` or ``(n, k)`` float64 array ``B``.
    """
    K = sp.csc_matrix(K, dtype=np.float64)
    small = solver == "direct" and K.shape[0] < SMALL_SYSTEM
    cholmod = _cholmod() if solver in ("direct", "cholmod") and not small else None
    if solver == "cholmod" and cholmod is None:
        raise ModuleNotFoundError(
            "h1_solver='cholmod' needs CHOLMOD: pip install 'igl-spheremap[cholmod]' "
            "(the sksparse-minimal wheel), or scikit-sparse 0.4 built against SuiteSparse")
    if cholmod is not None:
        # scikit-sparse 0.4: simplicial LDL^T after an AMD ordering (55-75% of
        # SuperLU's time for factorization + 16 three-column solves on 6k-32k
        # meshes); sksparse-minimal: see _minimal_solver.
        return cholmod(K)
    spec = "MMD_AT_PLUS_A" if K.shape[0] <= _MMD_MAX_SIZE else "COLAMD"
    # Supernode relaxation 20 (panel 10): 5-30% faster factorization
    # than SuperLU's default on the test meshes (6k-32k vertices).
    lu = spla.splu(K, permc_spec=spec, diag_pivot_thresh=0.0, relax=20, panel_size=10,
                   options=dict(SymmetricMode=True))
    return lu.solve


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
    if solver != "amg":
        return factorize(K, solver)
    if int(cycles) < 1:
        raise ValueError(f"cycles must be >= 1, got {cycles}")
    from .amg import VCycle, smoothed_aggregation_levels  # pyamg only when used

    return VCycle(smoothed_aggregation_levels(sp.csr_matrix(K)), cycles)
