"""A conformal-distortion energy of a spherical map that is itself a fold barrier (not in the paper).

Per face ``f`` of the input mesh (scaled to total area ``4 pi``, area ``A_f``) let ``J_f``
be the affine map from the input triangle onto its chordal image triangle.  The MIPS
energy of Hormann and Greiner ("MIPS: an efficient global parametrization method",
2000) integrates ``|J_f|_F^2 / det J_f``; with the face's cotangent Dirichlet energy
``E_D,f = 1/4 sum_k cot(theta_k) |U_j - U_l|^2`` (``theta_k`` the input angle at corner
``k``, ``(j, l)`` the opposite edge) it is ``A_f |J_f|_F^2 / det J_f = 2 E_D,f A_f / A'_f``,
``A'_f`` the signed image area.  Here the signed image area is ``s_f / 2`` with
``s_f = det[U_i, U_j, U_k]`` the signed volume of the fold test
(:func:`igl_spheremap.mesh.operators.signed_volumes`), and the energy is half the MIPS
energy, so that its scale is the harmonic energy's::

    E(U) = sum_f E_D,f A_f / (s_f / 2) = sum_f c_f / s_f,   c_f = sum_k lam_fk |U_j - U_l|^2,

with ``lam_fk = (a_fk . b_fk) / 4`` from the input edges ``a_fk, b_fk`` at corner ``k``
(``a . b = 2 A_f cot theta_k``: finite on needle triangles).  Properties:

* ``E >= 4 pi``: ``E_D,f >= A'_f`` (the chordal image area, as for every linear map)
  and ``s_f = 2 A'_f d_f <= 2 A'_f`` (``d_f`` the distance of the image triangle's
  plane from the centre), so each term is at least ``A_f``.  Equality holds in the
  limit of small faces each similar to its image: a conformal map, refined
  (``1 - d_f`` is half the squared chordal circumradius).
* Scale invariant: a face and its image may be as small as the map needs; only
  their shapes count (the harmonic energy, by contrast, is lower with some crowded
  faces folded).
* A barrier: ``E = +inf`` when a face degenerates or inverts (``s_f <= 0``), and the
  term of a face grows without bound as ``s_f -> 0+``.

The search direction is preconditioned by :class:`NewtonMetric`, the energy's Hessian
on the tangent planes made positive semidefinite face by face (projected Newton,
:mod:`igl_spheremap.optimize.face_hessians`), set up again as the map changes.  With it
a crowded image face, whose weight is large, moves in proportion to its size.

Why not a :class:`igl_spheremap.optimize.distortion.JacobianEnergy`: that base measures a
face by the Jacobian onto its chordal image alone, while the denominator here is the
fold test's own signed volume ``s_f`` (which also carries the image plane's distance
from the centre).  So the barrier of this energy and the fold test are one quantity, and
the per-face maximal step (:mod:`igl_spheremap.optimize.feasible_step`) is exact for it.
"""

import numpy as np
import scipy.sparse as sp

from ..mesh.arrays import rowdot
from ..mesh.frames import tangent_bases
from ..mesh.mollify import mollified_edge_lengths
from ..mesh.operators import SPHERE_AREA
from ..sphere.folds import SAFETY, unit_roundoff, volumes_and_margins
from .energy import Energy, Evaluation
from .face_hessians import projected_tangent_hessians
from .feasible_step import cross_columns
from .preconditioner import h1_preconditioner, resolve_h1_solver

#: ``K`` gets this share of its own diagonal added: on a crowded map the face weights
#: ``1 / s_f`` span many orders of magnitude, and the lumped mass alone is lost to
#: rounding in the factorization there (``docs/decisions.md``).
DIAGONAL_SHIFT = 1e-6

#: The guard's unit roundoff in float64: a face's signed volume is kept above the rounding
#: margin of this roundoff, where float64 rounding changes it by at most 1e-4 of itself
#: (``2**-53 / 1e-4``): below it the energy of a crowded face is rounding noise and the
#: descent stalls instead of converging (``docs/decisions.md``).
GUARD_ROUNDOFF = 2.0 ** -53 / 1e-4

#: The shift used instead when ``K`` with :data:`DIAGONAL_SHIFT` gives no descent
#: direction (the face Hessians' small negative parts won; ``docs/decisions.md``).
FALLBACK_SHIFT = 1e-2

#: The metric is set up again when some face's weight changed by more than this
#: factor since the last set-up (``docs/decisions.md``).
REWEIGHT_FACTOR = 2.0


def corner_weights(V, F):
    """Per face of the mesh scaled to area ``4 pi``: ``lam_fk = (a_fk . b_fk) / 4`` per corner
    and the face's area ``A_f``, of the intrinsically mollified mesh.

    ``a_fk, b_fk`` are the edges from corner ``k`` of face ``f`` to its other two
    corners (``a . b = 2 A_f cot theta_fk``).  Where a face is nearly degenerate (a
    corner near 180 degrees) the lengths are mollified first
    (:func:`igl_spheremap.mesh.mollify.mollified_edge_lengths`) and ``a . b``, ``A_f``
    come from them (law of cosines, Heron): such a face's own shape is one no fold-free
    image can copy, and the descent otherwise spends thousands of iterations squeezing
    its image toward it (``docs/decisions.md``).  Elsewhere nothing changes.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array

    Returns
    -------
    lam : (m, 3) float64 array
    area : (m,) float64 array
        Summing to ``4 pi``.
    """
    lengths, eps = mollified_edge_lengths(V, F)
    if eps > 0.0:
        sq = lengths * lengths
        w = np.column_stack([0.5 * (sq[:, (k + 1) % 3] + sq[:, (k + 2) % 3] - sq[:, k])
                             for k in range(3)])
        s = 0.5 * lengths.sum(axis=1)
        area = np.sqrt(s * (s - lengths[:, 0]) * (s - lengths[:, 1]) * (s - lengths[:, 2]))
    else:
        P = [V[F[:, k]] for k in range(3)]
        w = np.column_stack([rowdot(P[(k + 1) % 3] - P[k], P[(k + 2) % 3] - P[k])
                             for k in range(3)])
        area = 0.5 * np.linalg.norm(np.cross(P[1] - P[0], P[2] - P[0]), axis=1)
    scale = SPHERE_AREA / area.sum()
    return w * (0.25 * scale), area * scale


class ConformalDistortionEnergy(Energy):
    """Half the MIPS energy of the chordal image (module docstring): ``>= 4 pi``, a fold barrier.

    With a storage precision whose rounding can fold small faces (``"float32"``) the
    faces above their rounding margin ``t_f`` at ``U0``
    (:func:`igl_spheremap.sphere.folds.rounding_margin`, a function of the face's chord
    perimeter) are *guarded*: their denominator is ``s_f - t_f``, so the energy is a
    barrier at the margin and pushes such faces away from it; the others keep ``s_f``.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
        The validated mesh (outward oriented).
    area : (n,) float64 array
        Vertex areas scaled to ``4 pi`` (the lumped mass of Algorithm 1).
    h1_solver : {"auto", "direct", "amg", "cholmod", "superlu"}
        How the metric is inverted.
    refactor_every : int
        Most iterations between two set-ups of the metric.
    precision : {"float64", "float32"}
        The storage precision of the map (``"float64"``: no margin).
    U0 : (n, 3) float64 array, optional
        The start, which decides the guarded faces; without it no face is guarded
        (enough to evaluate the energy of a given map).

    Notes
    -----
    ``mobius_invariant`` is True: the continuous energy is invariant under the
    Möbius transformations (a conformal map stays conformal), so Algorithm 1 keeps
    the map centred as for the harmonic energy.
    """

    mobius_invariant = True

    def __init__(self, V, F, area, h1_solver="auto", refactor_every=25, precision="float64",
                 U0=None):
        V = np.asarray(V, dtype=np.float64)
        self.F = np.asarray(F, dtype=np.int64)
        self.lam, self.face_area = corner_weights(V, self.F)
        self.u = max(unit_roundoff(precision), GUARD_ROUNDOFF)
        if U0 is None:
            self.guarded = np.zeros(self.F.shape[0], dtype=bool)
        else:
            s, margin = volumes_and_margins(self.F, U0, self.u)
            self.guarded = s > margin
        super().__init__(area, NewtonMetric(self, area, h1_solver, refactor_every))

    def terms(self, U):
        """``(c, d, (Q, e), s)``: ``c_f``, the denominators ``d_f`` (``s_f``, or ``s_f - t_f``
        on guarded faces), the corners ``Q_k`` and opposite edges ``e_k = Q_l - Q_j`` of
        every image face as (3, m) arrays, and the signed volumes ``s_f``.

        ``s_f`` is computed from edge differences as in
        :func:`igl_spheremap.mesh.operators.signed_volumes` (accurate on tiny faces).
        """
        UT = U.T
        Q = [UT[:, self.F[:, k]] for k in range(3)]
        e = [Q[(k + 2) % 3] - Q[(k + 1) % 3] for k in range(3)]
        c = sum(self.lam[:, k] * (e[k] * e[k]).sum(axis=0) for k in range(3))
        s = (cross_columns(-e[2], e[1]) * (Q[0] + Q[1] + Q[2])).sum(axis=0) / 3.0
        perimeter = sum(np.sqrt((x * x).sum(axis=0)) for x in e)
        t = SAFETY * (self.u * perimeter + 3.0 * self.u ** 2 + self.u ** 3)
        return c, s - np.where(self.guarded, t, 0.0), (Q, e), s

    def face_distortion(self, U):
        """Each face's term ``c_f / s_f`` over its input area ``A_f`` ((m,) float64): half its
        MIPS energy over its chordal image's distance from the centre, 1 for a small face
        similar to its image, ``+inf`` where ``s_f <= 0``."""
        c, _, _, s = self.terms(U)
        ratio = np.full(s.shape, np.inf)
        ratio[s > 0] = c[s > 0] / s[s > 0]
        return ratio / self.face_area

    def evaluate(self, U):
        """The energy at ``U`` (n, 3): ``+inf`` when some face has ``d_f <= 0`` or ``s_f <= 0``."""
        c, d, parts, s = self.terms(U)
        if not (np.all(d > 0) and np.all(s > 0)):
            return Evaluation(U=U, value=np.inf)
        return Evaluation(U=U, value=float(np.sum(c / d)), cache=(c, d, parts))

    def euclidean_gradient(self, ev):
        """``dE/dU`` (n, 3) at a finite evaluation.

        ``d c_f / d U_k = 2 (lam_j (U_k - U_l) + lam_l (U_k - U_j))`` and
        ``d s_f / d U_k = U_j x U_l``, the latter evaluated as
        ``U_k x (U_l - U_j) + (U_j - U_k) x (U_l - U_k)`` (edge differences again); on a
        guarded face ``d t_f / d U_k`` is ``SAFETY u`` times the unit vectors along the
        two edges from the other corners to ``U_k``.
        """
        c, d, (Q, e) = ev.cache
        g, h = 1.0 / d, c / (d * d)
        n = ev.U.shape[0]
        out = np.zeros((3, n))
        unit = [x / np.sqrt((x * x).sum(axis=0)) for x in e]
        gu = np.where(self.guarded, SAFETY * self.u, 0.0)
        for k in range(3):
            j, l = (k + 1) % 3, (k + 2) % 3  # the edges at corner k: e_l = Q_j - Q_k, e_j = Q_k - Q_l
            dc = 2.0 * (self.lam[:, j] * e[j] - self.lam[:, l] * e[l])
            dd = cross_columns(Q[k], e[k]) - cross_columns(e[l], e[j])
            dd -= gu * (unit[j] - unit[l])
            G = g * dc - h * dd
            for x in range(3):
                out[x] += np.bincount(self.F[:, k], weights=G[x], minlength=n)
        return out.T


class SparsePattern:
    """The sparsity pattern of ``K`` on the ``2 n`` tangent coordinates, set up once: the per-face
    6 x 6 blocks are summed into its CSC arrays by one ``bincount`` per set-up.

    Parameters
    ----------
    F : (m, 3) int64 array
    size : int
        ``2 n``.
    """

    def __init__(self, F, size):
        idx = (2 * F[:, :, None] + np.arange(2)[None, None, :]).reshape(-1, 6)
        rows, cols = np.repeat(idx, 6, axis=1).ravel(), np.tile(idx, (1, 6)).ravel()
        keys, self.slot = np.unique(cols * size + rows, return_inverse=True)  # column-major
        self.indices, col = keys % size, keys // size
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(col, minlength=size))])
        self.diagonal_slots = np.flatnonzero(self.indices == col)  # every vertex has a face
        self.size = size

    def matrix(self, H):
        """The sum of the blocks ``H`` ((m, 6, 6)) as a CSC matrix."""
        data = np.bincount(self.slot.ravel(), weights=H.ravel(), minlength=self.indices.size)
        return sp.csc_matrix((data, self.indices, self.indptr), shape=(self.size, self.size))

    def diagonal(self, A):
        """The diagonal of a matrix ``A`` of this pattern."""
        return A.data[self.diagonal_slots]

    def plus_diagonal(self, A, diag):
        """``A + diag(diag)`` for a matrix ``A`` of this pattern (CSC)."""
        data = A.data.copy()
        data[self.diagonal_slots] += diag
        return sp.csc_matrix((data, self.indices, self.indptr), shape=(self.size, self.size))


class NewtonMetric:
    """Projected Newton: the energy's Hessian on the tangent planes, made positive semidefinite
    face by face (:mod:`igl_spheremap.optimize.face_hessians`), plus the lumped mass.

    ``K = sum_f P_f(H_f) + M`` on the ``2 n`` tangent coordinates (plus
    :data:`DIAGONAL_SHIFT` of its diagonal); ``M`` makes it definite and weighs the
    Möbius directions as the H1 metric does.  The direction is ``X = K^{-1} M G`` on the
    free vertices.  ``K`` is set up again, at the last accepted iterate, when a face's
    ``1 / s_f`` changed by more than :data:`REWEIGHT_FACTOR` or after
    ``refactor_every`` iterations.

    The stopping rule of Algorithm 1 uses the Newton decrement ``<G, X>_M`` in this
    metric (:attr:`newton_decrement`): scale invariant like the energy, where the L2
    gradient of a crowded face is as large as the face is small.

    Parameters
    ----------
    energy : ConformalDistortionEnergy
    area : (n,) float64 array
    solver : {"auto", "direct", "amg", "cholmod", "superlu"}
        ``"auto"`` chooses by the vertex count, as for the H1 metric
        (:func:`igl_spheremap.optimize.preconditioner.resolve_h1_solver`), not by the ``2 n``
        unknowns: one V-cycle is a poorer stand-in for this metric's inverse than for the
        cotangent Laplacian's, so the exact direction pays off at least as far
        (``docs/decisions.md``).
    refactor_every : int
    """

    name = "newton"
    newton_decrement = True

    def __init__(self, energy, area, solver="auto", refactor_every=25):
        self.energy, self.area = energy, area
        self.solver = resolve_h1_solver(solver, area.size)
        self.refactor_every = refactor_every
        self._pattern = None  # set up at the first assembly (an energy may never need one)
        self.weights = self.K = self.solve = self.current = self.frames = None
        self.free = np.ones(area.size, dtype=bool)
        self.last_setup = 0

    def observe(self, ev):
        """Record the evaluation at an accepted iterate (the map ``K`` is set up at)."""
        self.current = ev

    def setup(self, free, k=0):
        """Set ``K`` up again on the ``free`` vertices at iteration ``k`` (assembled at the
        next :meth:`apply`, from the last observed iterate)."""
        self.last_setup, self.free, self.solve = k, free.copy(), None

    def assemble(self):
        """Assemble ``K`` at the last observed iterate and factorize it on the free vertices."""
        ev, n = self.current, self.area.size
        c, s, (Q, e) = ev.cache
        self.weights = 1.0 / s
        B = tangent_bases(ev.U)
        self.frames = (B[:, :, 0], B[:, :, 1])
        H = projected_tangent_hessians(self.energy.F, self.energy.lam, ev.U, c, s, Q, e,
                                       self.frames)
        if self._pattern is None:
            self._pattern = SparsePattern(self.energy.F, 2 * n)
        self.hessian = self._pattern.matrix(H)
        self._factorize(DIAGONAL_SHIFT)

    def _factorize(self, shift):
        """``K = hessian + M + shift diag(hessian)`` and its solver on the free vertices; with
        :data:`FALLBACK_SHIFT` when the factorization finds ``K`` not definite."""
        self.shift = shift
        self.K = self._pattern.plus_diagonal(
            self.hessian, np.repeat(self.area, 2) + shift * self._pattern.diagonal(self.hessian))
        keep = np.repeat(self.free, 2)
        try:
            self.solve = h1_preconditioner(self.K if keep.all() else self.K[keep][:, keep],
                                           self.solver)
        except ValueError:  # CHOLMOD: not positive definite
            if shift >= FALLBACK_SHIFT:
                raise
            self._factorize(FALLBACK_SHIFT)

    def due(self, k, constraints, refactor_every):
        """Whether to set ``K`` up again at iteration ``k`` (see the class docstring)."""
        if self.weights is None or self.current is None or self.current.cache is None:
            return False
        ratio = self.weights * self.current.cache[1]
        return (k - self.last_setup >= self.refactor_every
                or bool(np.any((ratio > REWEIGHT_FACTOR) | (ratio * REWEIGHT_FACTOR < 1.0))))

    def _coordinates(self, X):
        t1, t2 = self.frames
        return np.column_stack([rowdot(X, t1), rowdot(X, t2)]).ravel()

    def apply(self, MG):
        """``K^{-1} M G`` as a tangent field on the free vertices (0 elsewhere); None (the L2
        gradient is the direction) when even :data:`FALLBACK_SHIFT` gives no descent."""
        if self.solve is None:
            self.assemble()
        b = self._coordinates(MG)
        y = self._solve(b)
        if not np.vdot(b, y) > 0 and self.shift < FALLBACK_SHIFT:  # K was not definite
            self._factorize(FALLBACK_SHIFT)
            y = self._solve(b)
        if not np.vdot(b, y) > 0:  # still no descent direction: the L2 gradient instead
            return None
        y = y.reshape(-1, 2)
        t1, t2 = self.frames
        return y[:, :1] * t1 + y[:, 1:] * t2

    def _solve(self, b):
        keep = np.repeat(self.free, 2)
        if keep.all():
            return self.solve(b)
        y = np.zeros_like(b)
        y[keep] = self.solve(b[keep])
        return y

    def sq_norm(self, D, MD, new, old):
        """``<D, K D>`` of the step ``D`` (in the frames of the last set-up)."""
        d = self._coordinates(D)
        return float(d @ (self.K @ d))
