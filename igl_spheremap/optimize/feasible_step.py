"""The largest step along the Cayley curve before an image face's signed volume reaches a threshold.

Along Algorithm 1's curve (paper Theorem 1, :func:`igl_spheremap.optimize.manifold.cayley_step`
with a tangent direction ``X``) vertex ``i`` moves as::

    Y_i(tau) = N_i(tau) / (1 + c_i tau^2),   N_i(tau) = (1 - c_i tau^2) U_i - tau X_i,   c_i = |X_i|^2 / 4.

The signed volume of face ``(i, j, k)`` is ``s(tau) = det[Y_i, Y_j, Y_k] = p(tau) / d(tau)``
with ``p = det[N_i, N_j, N_k]`` and ``d = prod (1 + c tau^2) > 0``.  By trilinearity ``p``
is a polynomial of degree 6.  The face stays above a threshold ``t >= 0`` while
``q(tau) = p(tau) - t d(tau) > 0``, a polynomial of degree 6 too.  This is the
spherical form of the per-triangle maximal step of Smith and Schaefer, "Bijective
parameterization with free boundaries", ACM TOG 34(4), 2015, Sec. 5 (where the planar
area along a straight line is a quadratic).

:func:`max_steps` returns, per face, a step below which ``q > 0`` is certified: the
first root of ``q`` on ``(0, tau_cap]``, approached from below by the roots of the
decreasing minorant ``q(t0) - sum_k |q^(k)(t0) / k!| (tau - t0)^k`` re-expanded at each
new point (each iterate is a lower bound of the first root, up to the rounding of
the coefficients; the sequence converges to the root).  Only faces whose minorant at
0 reaches zero before ``tau_cap`` are iterated, so a step costs 27 triple products per
face and a few polynomial evaluations on the faces at risk.
"""

import math

import numpy as np

from ..mesh.arrays import rowdot

#: :func:`max_steps` stops refining a face's step once it is within this relative
#: distance of the root.
ROOT_RTOL = 1e-2

#: Faces :func:`smallest_step` refines at a time: a few large vectorized passes cost less
#: than many small ones (``docs/decisions.md``).
CHUNK = 512

#: ``_BINOM[j, k] = C(j, k)``: the Taylor shift of a degree-6 polynomial.
_BINOM = np.array([[float(math.comb(j, k)) if k <= j else 0.0 for k in range(7)]
                   for j in range(7)])


def volume_polynomials(F, U, X, threshold=None):
    """Coefficients of ``q(tau) = det[N_i, N_j, N_k] - t prod(1 + c tau^2)`` per face.

    The determinant is expanded as ``det[N_i, N_j - N_i, N_k - N_i]``: each row is a
    quadratic polynomial in ``tau`` with vector coefficients, and the edge
    differences ``U_j - U_i`` are formed first, as in
    :func:`igl_spheremap.mesh.operators.signed_volumes`, so that the coefficients of a
    small face keep their relative accuracy.

    Parameters
    ----------
    F : (m, 3) int array
    U : (n, 3) float64 array
        Unit rows.
    X : (n, 3) float64 array
        Tangent direction (``U_i . X_i = 0``); the curve moves along ``-X``.
    threshold : (m,) float64 array, optional
        ``t`` per face (default 0), in the units of the signed volume ``det[U_i, U_j, U_k]``.

    Returns
    -------
    (m, 7) float64 array
        ``q(tau) = sum_k Q[:, k] tau^k``.
    """
    UT, XT = U.T, X.T
    c = 0.25 * rowdot(X, X)
    i, j, k = F[:, 0], F[:, 1], F[:, 2]
    Ui, Uj, Uk, Xi, Xj, Xk = UT[:, i], UT[:, j], UT[:, k], XT[:, i], XT[:, j], XT[:, k]
    ci, cj, ck = c[i], c[j], c[k]
    A = (Ui, -Xi, -ci * Ui)
    B = (Uj - Ui, Xi - Xj, ci * Ui - cj * Uj)
    C = (Uk - Ui, Xi - Xk, ci * Ui - ck * Uk)
    Q = np.zeros((F.shape[0], 7))
    for b in range(3):
        for d in range(3):
            BC = cross_columns(B[b], C[d])
            for a in range(3):
                Q[:, a + b + d] += (A[a] * BC).sum(axis=0)
    if threshold is not None:
        t = np.asarray(threshold, dtype=np.float64)
        c1, c2, c3 = ci, cj, ck
        Q[:, 0] -= t
        Q[:, 2] -= t * (c1 + c2 + c3)
        Q[:, 4] -= t * (c1 * c2 + c2 * c3 + c1 * c3)
        Q[:, 6] -= t * (c1 * c2 * c3)
    return Q


def cross_columns(a, b):
    """Cross products of the columns of two (3, m) arrays ((3, m) float64)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def poly_eval(Q, tau):
    """``q(tau)`` per face by Horner's rule (``tau`` a scalar or (m,))."""
    v = np.zeros(Q.shape[0])
    for k in range(6, -1, -1):
        v = v * tau + Q[:, k]
    return v


def taylor_shift(Q, t0):
    """Coefficients of ``q(t0 + h)`` in ``h``, per row (``t0`` (r,))."""
    P = t0[:, None] ** np.arange(7)[None, :]
    out = np.zeros_like(Q)
    for k in range(7):
        js = np.arange(k, 7)
        out[:, k] = (Q[:, js] * _BINOM[js, k][None, :] * P[:, js - k]).sum(axis=1)
    return out


def minorant_root(B, cap):
    """Largest ``h`` in ``[0, cap]`` with ``g(h) = B_0 - sum_k |B_k| h^k >= 0`` (``B_0 > 0``), per row.

    ``g`` is concave and decreasing on ``h >= 0``: Newton from ``cap`` (where
    ``g(cap) < 0``) decreases monotonically to the root, every tangent lying above
    ``g``; the last iterate is then backed off until ``g >= 0``.

    Parameters
    ----------
    B : (r, 7) float64 array
    cap : float or (r,) float64 array

    Returns
    -------
    (r,) float64 array
    """
    A = np.abs(B[:, 1:])
    h = np.broadcast_to(np.asarray(cap, dtype=np.float64), (B.shape[0],)).copy()
    todo = _minorant(h, B[:, 0], A)[0] < 0
    if not todo.any():
        return h
    b0, a, x = B[todo, 0], A[todo], h[todo]
    for _ in range(100):
        g, slope = _minorant(x, b0, a)
        x_new = np.maximum(x - g / np.minimum(slope, -1e-300), 0.0)
        done = np.all(x - x_new <= 1e-13 * x)
        x = x_new
        if done:
            break
    for e in range(60):  # back off below the root where rounding put x above it
        bad = _minorant(x, b0, a)[0] < 0
        if not bad.any():
            break
        x[bad] *= 1.0 - 1e-9 * 2.0 ** e
    x[_minorant(x, b0, a)[0] < 0] = 0.0
    h[todo] = x
    return h


def _minorant(x, b0, a):
    """``g(x) = b0 - sum_k a_k x^k`` (k = 1..6) and ``g'(x)`` by Horner's rule, per row."""
    p = a[:, 5].copy()
    dp = np.zeros_like(x)
    for k in range(4, -1, -1):
        dp = dp * x + p
        p = p * x + a[:, k]
    dp = dp * x + p
    return b0 - p * x, -dp


def max_steps(Q, tau_cap, iters=12):
    """Per face, a lower bound of the first root of ``q`` on ``(0, tau_cap]``.

    Parameters
    ----------
    Q : (m, 7) float64 array
        :func:`volume_polynomials`; faces with ``q(0) <= 0`` get 0.
    tau_cap : float
        Largest step of interest.
    iters : int
        Re-expansions of the minorant; a face stops earlier once ``q`` is not positive
        at ``(1 + ROOT_RTOL)`` times its bound (the bound is then that close to the root).

    Returns
    -------
    (m,) float64 array
        ``tau_f`` in ``[0, tau_cap]`` with ``q > 0`` on ``[0, tau_f)``; ``tau_cap`` for
        the faces safe up to it.
    """
    out = np.full(Q.shape[0], float(tau_cap))
    bad = Q[:, 0] <= 0
    out[bad] = 0.0
    risk = ~bad & (Q[:, 0] - np.abs(Q[:, 1:]) @ (float(tau_cap) ** np.arange(1, 7)) < 0)
    idx = np.flatnonzero(risk)
    if idx.size == 0:
        return out
    Qr, t = Q[idx], np.zeros(idx.size)
    active = np.ones(idx.size, dtype=bool)
    for _ in range(iters):
        a = np.flatnonzero(active)
        if a.size == 0:
            break
        B = taylor_shift(Qr[a], t[a])
        pos = B[:, 0] > 0
        active[a[~pos]] = False  # rounding put q <= 0 here: stop at this point
        a, B = a[pos], B[pos]
        if a.size == 0:
            break
        h = minorant_root(B, tau_cap - t[a])
        t_new = t[a] + h
        done = ((t_new >= tau_cap) | (h <= 1e-10 * np.maximum(t_new, 1e-300))
                | (poly_eval(Qr[a], (1.0 + ROOT_RTOL) * t_new) <= 0))
        t[a] = np.minimum(t_new, tau_cap)
        active[a[done]] = False
    out[idx] = t
    return out


def moved_faces(F, U, X, tau, slack):
    """Faces whose signed volume may change by ``slack`` or more over a step of at most ``tau``.

    Along the Cayley curve each vertex stays within ``delta_i = tau |X_i|`` of ``U_i``
    (the chord of the rotation by ``2 atan(tau |X_i| / 2)``).  With ``delta`` the largest
    of a face's three and ``P`` its chord perimeter, multilinearity of
    ``det[U_i, U_j - U_i, U_k - U_i]`` bounds the change by
    ``2 delta P + 4 delta^2 + delta (P + 2 delta)^2``; the faces where this bound reaches
    ``slack`` are returned (the others cannot reach their threshold).

    Parameters
    ----------
    F : (m, 3) int array
    U, X : (n, 3) float64 arrays
    tau : float
    slack : (m,) float64 array
        ``s_f - t_f``.

    Returns
    -------
    (m,) bool array
    """
    d = tau * np.sqrt(rowdot(X, X))[F].max(axis=1)
    Q = [U[F[:, k]] for k in range(3)]
    P = sum(np.sqrt(rowdot(Q[k] - Q[(k + 1) % 3], Q[k] - Q[(k + 1) % 3])) for k in range(3))
    return 2.0 * d * P + 4.0 * d * d + d * (P + 2.0 * d) ** 2 >= slack


def max_step(F, U, X, tau_cap, s, threshold):
    """The largest step (at most ``tau_cap``) along the Cayley curve from ``U`` in direction
    ``-X`` before some face's signed volume reaches its threshold.

    Parameters
    ----------
    F : (m, 3) int array
        The faces to keep above their thresholds.
    U, X : (n, 3) float64 arrays
    tau_cap : float
    s : (m,) float64 array
        Their signed volumes at ``U`` (above ``threshold``).
    threshold : (m,) float64 array

    Returns
    -------
    float
        ``min_f tau_f`` of :func:`max_steps` over the faces :func:`moved_faces` flags,
        ``tau_cap`` when none is flagged.
    """
    risk = np.flatnonzero(moved_faces(F, U, X, tau_cap, s - threshold))
    if risk.size == 0:
        return float(tau_cap)
    return smallest_step(volume_polynomials(F[risk], U, X, threshold[risk]), tau_cap)


def smallest_step(Q, tau_cap, chunk=CHUNK):
    """``min_f`` of :func:`max_steps` without refining every face.

    The first minorant root of each face is a lower bound of its step; faces are
    refined in order of that bound, and only while it is below the smallest step
    found so far.

    Parameters
    ----------
    Q : (m, 7) float64 array
        :func:`volume_polynomials`.
    tau_cap : float
    chunk : int
        Faces refined at a time.

    Returns
    -------
    float
    """
    if np.any(Q[:, 0] <= 0):
        return 0.0
    low = minorant_root(Q, float(tau_cap))
    order = np.argsort(low)
    best = float(tau_cap)
    for a in range(0, order.size, chunk):
        idx = order[a:a + chunk]
        idx = idx[low[idx] < best]
        if idx.size == 0:
            break
        best = min(best, float(max_steps(Q[idx], tau_cap).min()))
    return best
