"""The punctured Tutte disk untangled in the plane: a start that gives up angle for area
(not in the paper).

The punctured Tutte embedding (:mod:`igl_spheremap.folding.tutte_start`) is fold-free in
exact arithmetic, but on a long shape its crowding grows geometrically with the
distance from the puncture: on a CT small intestine thousands of its faces underflow to
zero or negative area in float64, and on a CAD part thousands lie below the float32
rounding margin.  No conformal-type start can represent such shapes; this one trades
angle for area.  The disk, its link polygon held on the unit circle, is untangled by
minimizing the regularized energy of Garanzha, Kaporin, Kudryavtseva, Protais, Ray and
Sokolov, "Foldover-free maps in 50 lines of code", ACM TOG 40(4), 2021::

    E_eps(X) = sum_f A_f [(1 - lam) |J_f|_F^2 / 2 + lam (det J_f^2 + 1) / 2] / chi(det J_f, eps),
    chi(D, eps) = (D + sqrt(eps^2 + D^2)) / 2,

with ``J_f`` the Jacobian from a reference triangle to its planar image (the input
triangle, the mesh scaled to the disk's area; or, for a ring patch untangled in the rounds
(:func:`igl_spheremap.folding.untangle.untangle_patches`), an equilateral triangle of the
patch's mean area) and ``lam`` = :data:`AREA_WEIGHT`: for ``eps -> 0`` the MIPS
(conformal) energy blended with an area term, a barrier at ``det J = 0``; for
``eps > 0`` finite on folded and degenerate faces too.  ``eps`` is lowered after each
minimization by their rule (:func:`next_eps`) until every face is positive, then set
to 0.  Each ``eps`` is minimized by a few projected Newton steps (per-face Hessians
made positive semidefinite in closed form,
:func:`igl_spheremap.optimize.face_hessians.invariant_hessians`)
with a backtracking line search.  The untangled disk is lifted to the sphere by
:func:`igl_spheremap.folding.tutte_start.lift_disk`.
"""

import igl
import numpy as np
import scipy.sparse as sp

from ..mesh.frames import triangle_frames
from ..optimize.conformal_distortion import SparsePattern
from ..optimize.face_hessians import invariant_hessians
from ..optimize.preconditioner import h1_preconditioner
from ..sphere.chart import planar_signed_areas
from .tutte_start import lift_disk, puncture_vertex, tutte_disk

#: ``lam``: weight of the area term against the MIPS term.
AREA_WEIGHT = 0.5

#: ``eps`` of the first minimization, in units of ``det J`` (1 for an area-preserving map).
EPS_START = 0.05

#: Projected Newton steps per value of ``eps``.
NEWTON_STEPS = 6

#: Most values of ``eps`` before giving up.
MAX_STAGES = 200

#: Least ``sigma`` in :func:`next_eps`: ``eps`` falls by at least 10% per stage.
SIGMA_MIN = 0.1

def chi(D, eps):
    """The regularized determinant ``chi(D, eps) = (D + sqrt(eps^2 + D^2)) / 2`` (Garanzha et al.).

    Positive for every ``D`` when ``eps > 0``, about ``eps^2 / (4 |D|)`` for ``D << -eps`` and
    ``D`` for ``D >> eps``.

    Parameters
    ----------
    D : (f,) float64 array
        ``det J`` per face.
    eps : float
        ``>= 0``; with 0, ``D`` must be positive for the derivatives.

    Returns
    -------
    chi, dchi, d2chi : (f,) float64 arrays
        The value and its first two derivatives in ``D``.
    """
    r = np.sqrt(eps * eps + D * D)
    return 0.5 * (D + r), 0.5 * (1.0 + D / r), 0.5 * eps * eps / r ** 3


def next_eps(eps, energy_before, energy_after, dmin):
    """Garanzha et al.'s update of ``eps`` after a minimization (their Algorithm 1).

    ``sigma = max(1 - E_after / E_before, SIGMA_MIN)``, ``mu = (1 - sigma) chi(dmin, eps)``;
    ``eps`` becomes ``2 sqrt(mu (mu - dmin))`` while ``dmin < mu``, else 0 (every face is
    positive with room to spare: the energy is then the barrier itself).

    Parameters
    ----------
    eps : float
    energy_before, energy_after : float
        ``E_eps`` before and after the minimization at this ``eps``.
    dmin : float
        The least ``det J`` after it.

    Returns
    -------
    float
    """
    sigma = max(1.0 - energy_after / energy_before, SIGMA_MIN)
    mu = (1.0 - sigma) * chi(dmin, eps)[0]
    return 2.0 * np.sqrt(mu * (mu - dmin)) if dmin < mu else 0.0


class UntanglingEnergy:
    """``E_eps`` of the module docstring on the planar positions of a disk's vertices.

    Parameters
    ----------
    V : (n, 3) float64 array or int
        The input's vertices, whose triangles are the reference shapes; or the number of
        vertices ``n``, for equilateral reference triangles of equal area (the ideal
        elements Garanzha et al. untangle meshes toward).
    Fd : (f, 3) int64 array
        The disk's faces.
    total : float
        Area the reference triangles are scaled to (the disk's).
    area_weight : float
        ``lam`` in ``[0, 1]``.
    """

    def __init__(self, V, Fd, total, area_weight=AREA_WEIGHT):
        self.F, self.w = Fd, float(area_weight)
        if np.ndim(V) == 0:
            self.n = int(V)
            self.B, self.A = equilateral_frames(Fd.shape[0], total)
        else:
            self.n = V.shape[0]
            area = 0.5 * np.linalg.norm(np.cross(V[Fd[:, 1]] - V[Fd[:, 0]],
                                                 V[Fd[:, 2]] - V[Fd[:, 0]]), axis=1)
            _, self.B, self.A = triangle_frames(V * np.sqrt(total / area.sum()), Fd)
        self.D = jacobian_map(self.B)
        self.pattern = SparsePattern(Fd, 2 * self.n)

    def jacobians(self, X):
        """``J_f`` ((f, 2, 2)) of the planar positions ``X`` ((n, 2))."""
        F = self.F
        edges = np.stack([X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]]], axis=2)
        return edges @ self.B

    def parts(self, J, eps):
        """Per face: ``d = det J``, the numerator ``N``, its gradient in ``J``, ``chi``'s triple."""
        Jf = J.reshape(-1, 4)
        d = Jf[:, 0] * Jf[:, 3] - Jf[:, 1] * Jf[:, 2]
        cof = np.column_stack([Jf[:, 3], -Jf[:, 2], -Jf[:, 1], Jf[:, 0]])
        N = 0.5 * (1.0 - self.w) * (Jf * Jf).sum(axis=1) + 0.5 * self.w * (d * d + 1.0)
        gN = (1.0 - self.w) * Jf + (self.w * d)[:, None] * cof
        return d, cof, N, gN, chi(d, eps)

    def value(self, X, eps):
        """``E_eps(X)`` (float; ``+inf`` for ``eps = 0`` and a face with ``det J <= 0``) and
        ``det J`` per face ((f,))."""
        d, _, N, _, (c, _, _) = self.parts(self.jacobians(X), eps)
        with np.errstate(divide="ignore"):  # eps = 0: +inf on a face with det J <= 0
            return float(np.sum(self.A * N / c)), d

    def gradient(self, X, eps):
        """``dE_eps / dX`` ((n, 2))."""
        d, cof, N, gN, (c, c1, _) = self.parts(self.jacobians(X), eps)
        gJ = self.A[:, None] * (gN / c[:, None] - (N * c1 / (c * c))[:, None] * cof)
        g6 = np.einsum("fk,fkl->fl", gJ, self.D)
        return self.pattern_vector(g6)

    def pattern_vector(self, g6):
        """Sum per-face gradients ``(f, 6)`` (``x0, y0, x1, y1, x2, y2``) into ``(n, 2)``."""
        out = np.zeros((self.n, 2))
        for k in range(3):
            for a in range(2):
                out[:, a] += np.bincount(self.F[:, k], weights=g6[:, 2 * k + a], minlength=self.n)
        return out

    def hessian(self, X, eps):
        """The sum of the per-face Hessians made positive semidefinite ((2n, 2n) CSC).

        The integrand is ``Psi(I2, I3) = N / chi(I3, eps)`` of ``I2 = |J|_F^2`` and
        ``I3 = det J``, ``N = (1 - lam) I2 / 2 + lam (I3^2 + 1) / 2``: isotropic, so each
        face's Hessian in ``J`` is made positive semidefinite in closed form
        (:func:`igl_spheremap.optimize.face_hessians.invariant_hessians`) from the
        derivatives of ``Psi`` in the invariants.
        """
        J = self.jacobians(X)
        d, _, N, _, (c, c1, c2) = self.parts(J, eps)
        w = self.w
        d2 = 0.5 * (1.0 - w) / c
        d3 = w * d / c - N * c1 / c ** 2
        d23 = -0.5 * (1.0 - w) * c1 / c ** 2
        d33 = w / c - 2.0 * w * d * c1 / c ** 2 - N * c2 / c ** 2 + 2.0 * N * c1 ** 2 / c ** 3
        H = invariant_hessians(J, d2, d3, np.zeros_like(d), d23, d33) * self.A[:, None, None]
        return self.pattern.matrix(self.D.transpose(0, 2, 1) @ H @ self.D)


def equilateral_frames(m, total):
    """``(Dinv, area)`` of :func:`igl_spheremap.mesh.frames.triangle_frames` for ``m``
    equilateral triangles of area ``total / m`` each ((m, 2, 2) and (m,) float64)."""
    area = total / m
    side = np.sqrt(4.0 * area / np.sqrt(3.0))
    D = np.array([[side, 0.5 * side], [0.0, 0.5 * np.sqrt(3.0) * side]])
    return np.broadcast_to(np.linalg.inv(D), (m, 2, 2)).copy(), np.full(m, area)


def jacobian_map(B):
    """``dJ / dX`` per face ((f, 4, 6)): ``J`` row-major, ``X`` as ``x0, y0, x1, y1, x2, y2``.

    ``J[a, b] = sum_c (X_{c+1} - X_0)[a] B[c, b]``.
    """
    D = np.zeros((B.shape[0], 4, 6))
    for a in range(2):
        for b in range(2):
            for c in range(2):
                D[:, 2 * a + b, 2 * (c + 1) + a] += B[:, c, b]
                D[:, 2 * a + b, a] -= B[:, c, b]
    return D


def newton_steps(energy, X, free, eps, steps=NEWTON_STEPS):
    """A few projected Newton steps on ``E_eps`` over the ``free`` rows of ``X`` ((n, 2), copied).

    Each solves ``(H + delta I) p = -g`` (``H`` of :meth:`UntanglingEnergy.hessian`,
    ``delta`` 1e-10 of its mean diagonal) and halves the step until the Armijo test
    holds; stops early when a step lowers the energy by less than 1e-8 of itself.
    """
    X = X.copy()
    keep = np.repeat(free, 2)
    value = energy.value(X, eps)[0]
    for _ in range(steps):
        g = energy.gradient(X, eps).ravel()[keep]
        H = energy.hessian(X, eps)[keep][:, keep]
        H = H + sp.identity(H.shape[0], format="csc") * (1e-10 * H.diagonal().mean())
        p = -h1_preconditioner(H.tocsc(), "direct")(g)
        t, slope = 1.0, float(g @ p)
        while t > 1e-12:
            Y = X.copy()
            Y.reshape(-1)[keep] += t * p
            trial = energy.value(Y, eps)[0]
            if trial <= value + 1e-4 * t * slope:
                break
            t *= 0.5
        else:
            break
        done = value - trial <= 1e-8 * value
        X, value = Y, trial
        if done:
            break
    return X


def untangle_disk(V, Fd, X0, fixed, area_weight=AREA_WEIGHT, max_stages=MAX_STAGES):
    """Garanzha et al.'s Algorithm 1 on a planar disk: ``E_eps`` minimized for falling ``eps``.

    Parameters
    ----------
    V : (n, 3) float64 array or None
        The input's vertices (reference shapes), or None for equilateral reference
        triangles (:class:`UntanglingEnergy`).
    Fd : (f, 3) int64 array
        The disk's faces (counter-clockwise in ``X0``'s orientation).
    X0 : (n, 2) float64 array
        Start (non-finite rows are treated as 0; they must be ``fixed`` or in no face).
    fixed : (n, ) bool array
        Rows that do not move (the link polygon, the puncture).
    area_weight : float
    max_stages : int
        Most values of ``eps`` before giving up.

    Returns
    -------
    X : (n, 2) float64 array
    info : dict
        ``stages`` (values of ``eps``), ``min_det`` (least ``det J``; positive when untangled).
    """
    X = np.where(np.isfinite(X0), X0, 0.0)
    total = float(planar_signed_areas(X, Fd).sum())
    energy = UntanglingEnergy(X.shape[0] if V is None else V, Fd, total, area_weight)
    free, eps = ~np.asarray(fixed, dtype=bool), EPS_START
    for stage in range(1, max_stages + 1):
        before = energy.value(X, eps)[0]
        X = newton_steps(energy, X, free, eps)
        after, d = energy.value(X, eps)
        if eps == 0.0 and d.min() > 0:
            break
        eps = next_eps(eps, before, after, float(d.min()))
    return X, dict(stages=stage, min_det=float(d.min()))


def untangled_sphere_map(V, F, kind="mean_value"):
    """The punctured Tutte disk of ``(V, F)`` untangled (:func:`untangle_disk`) and lifted.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
        A validated mesh (closed, genus 0, outward oriented).
    kind : {"cotan_positive", "mean_value", "uniform"}
        The Tutte weights of the disk it starts from.

    Returns
    -------
    U : (n, 3) float64 array
        Unit rows; fold-free when ``info["min_det"] > 0`` (up to the lift's rounding:
        count its folds).
    info : dict
        :func:`untangle_disk`'s and :func:`igl_spheremap.folding.tutte_start.lift_disk`'s.
    """
    v = puncture_vertex(V, F)
    X, Fd = tutte_disk(V, F, v, kind)
    fixed = np.zeros(V.shape[0], dtype=bool)
    fixed[np.asarray(igl.boundary_loop(Fd), dtype=np.int64)] = fixed[v] = True
    X, info = untangle_disk(V, Fd, X, fixed)
    U, lift = lift_disk(V, F, X, Fd, v)
    return U, {**info, **lift}
