"""Möbius transformations of a spherical map: normalization (centering, Baden-Crane-Kazhdan
2018), fits to point pairs, and the dilation about a point that spreads a crowded cap."""

import numpy as np

from ..mesh.arrays import as_points, as_weights, off_unit_sphere


def mobius_transform(U, c):
    """Apply the Möbius transformation of the sphere that sends ``c`` in the ball to 0.

    ``T_c(x) = (1 - |c|^2) (x - c) / |x - c|^2 - c`` for ``|x| = 1``: the restriction
    to the unit sphere of the hyperbolic translation of the unit ball that
    moves ``c`` to the origin.  It is conformal and orientation preserving
    on the sphere; flat image triangles that are small keep their orientation,
    but a large one (a sizeable part of a hemisphere) can change the sign of
    its signed volume, so fold counts should be taken after the transform.

    Parameters
    ----------
    U : (n, 3) float64 array
        Unit vectors (within ``mesh.arrays.UNIT_TOL`` of length 1): the formula is the
        transformation only on the unit sphere.
    c : (3,) float64 array
        Point with ``|c| < 1``.

    Returns
    -------
    (n, 3) float64 array
        Unit vectors (renormalized to remove rounding).

    Raises
    ------
    ValueError
        If ``c`` is not 3 finite numbers with ``|c| < 1``, ``U`` not (n, 3), or rows of
        ``U`` not finite or off the unit sphere (their count).
    """
    c = np.asarray(c, dtype=np.float64)
    if c.shape != (3,) or np.ndim(U) != 2 or np.shape(U)[1] != 3:
        raise ValueError(f"mobius_transform needs U of shape (n, 3) and c of shape (3,), got "
                         f"{np.shape(U)} and {c.shape}")
    off = off_unit_sphere(as_points(U))
    if off:
        raise ValueError(off)
    cc = float(c @ c)
    if not cc < 1.0:
        raise ValueError(f"Möbius center must lie inside the unit ball, got |c| = {np.sqrt(cc)}")
    Y = U - c
    s = np.einsum("ij,ij->i", Y, Y)
    np.divide(1.0 - cc, s, out=s)
    Y *= s[:, None]
    Y -= c
    np.einsum("ij,ij->i", Y, Y, out=s)
    np.sqrt(s, out=s)
    Y /= s[:, None]
    return Y


def dilation(U, c, factor):
    """The Möbius dilation of the sphere about the unit vector ``c`` by ``factor``.

    Stereographic projection from ``-c`` onto the plane tangent at ``c``, the plane scaled
    by ``factor`` about ``c``, and back: it fixes ``c`` and ``-c``, moves a point at the
    angle ``theta`` from ``c`` to ``2 atan(factor tan(theta / 2))`` along its great circle,
    and is conformal and orientation preserving (``dilation(dilation(U, c, a), c, 1 / a)``
    is ``U``).  With a large ``factor`` it spreads a crowded cap around ``c`` over a
    hemisphere.

    Rounding: everything is computed from ``U - c`` and the result returned as ``c`` plus
    a difference, so points near ``c`` keep their digits relative to their distance from
    it (positions near ``-c``, where the projection is singular, lose theirs).

    Parameters
    ----------
    U : (n, 3) float64 array
        Unit vectors, none at ``-c``.
    c : (3,) float64 array
        Unit vector.
    factor : float
        Positive.

    Returns
    -------
    (n, 3) float64 array
        Unit vectors.

    Raises
    ------
    ValueError
        If ``factor`` is not positive and finite.
    """
    if not 0.0 < factor < np.inf:
        raise ValueError(f"a dilation's factor must be positive and finite, got {factor}")
    D = np.asarray(U, dtype=np.float64) - c
    h = D @ c
    W = (D - np.outer(h, c)) * (2.0 * factor / (2.0 + h))[:, None]
    w2 = np.einsum("ij,ij->i", W, W)
    X = c + (4.0 * W - 2.0 * np.outer(w2, c)) / (4.0 + w2)[:, None]
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def mobius_center(U, weights, tol=1e-12, max_iter=100, max_step=0.5):
    """Möbius-normalize a map: make its weighted centroid the origin.

    Newton iteration on the centroid ``mu(c) = sum w_i T_c(U_i) / sum w_i``: at
    ``c = 0`` its Jacobian is ``-2 sum w_i (I - U_i U_i^T) / sum w_i`` (Baden,
    Crane, Kazhdan, "Möbius Registration", SGP 2018), so each step solves a
    3x3 system and applies :func:`mobius_transform`.  The result differs from
    ``U`` by a true Möbius transformation (not a radial re-projection).  Where the
    Jacobian is singular (the weight sits at one point, as in a map crowded below
    rounding) the step is ``max_step`` along ``mu``, the limit of the Newton step.

    Parameters
    ----------
    U : (n, 3) array_like of float
        Unit vectors.
    weights : (n,) array_like of float
        Non-negative vertex weights (the input surface's vertex areas).
    tol : float
        Stop when ``|mu| <= tol``.
    max_iter : int
    max_step : float
        Largest ``|c|`` of one step (keeps each step well conditioned).

    Returns
    -------
    U : (n, 3) float64 array
        Centered map.
    mu : float
        Final ``|mu|``.

    Raises
    ------
    ValueError
        ``U`` is not (n, 3) finite numbers, or ``weights`` not (n,) non-negative finite
        numbers with a positive sum.
    """
    # an array is checked, not converted: U's memory layout sets the summation order of the
    # products below, and a check must not change a map's bits; anything else (a list) is
    # converted
    if isinstance(U, np.ndarray):
        n = as_points(U, "U").shape[0]
    else:
        U = as_points(U, "U")
        n = U.shape[0]
    w = as_weights(weights, n, "weights")
    w = w / np.sum(w)
    for _ in range(max_iter):
        mu = w @ U
        nmu = float(np.linalg.norm(mu))
        if nmu <= tol:
            break
        J = 2.0 * (np.eye(3) - (U.T * w) @ U)
        try:
            c = np.linalg.solve(J, mu)
        except np.linalg.LinAlgError:  # all weight at one point: the step is along mu
            c = mu / nmu
        nc = float(np.linalg.norm(c))
        if nc > max_step:
            c *= max_step / nc
        U = mobius_transform(U, c)
    else:
        nmu = float(np.linalg.norm(w @ U))
    return U, nmu


def best_rotation(A, B):
    """Rotation ``R`` (3, 3), det +1, minimizing ``sum_i |R A_i - B_i|^2`` for (k, 3) ``A, B`` (Kabsch)."""
    W, _, Zt = np.linalg.svd(B.T @ A)
    d = np.sign(np.linalg.det(W @ Zt)) or 1.0
    return W @ np.diag([1.0, 1.0, d]) @ Zt


def ball_point(z):
    """The point ``tanh(|z|) z / |z|`` of the open unit ball for ``z`` in R^3 ((3,) float64).

    ``|z|`` is half the hyperbolic distance of the point from the origin (Poincaré
    ball): every hyperbolic translation of the ball, hence every Möbius
    transformation of the sphere up to a rotation (:func:`mobius_transform`),
    has one ``z``.
    """
    r = float(np.linalg.norm(z))
    return z * (np.tanh(r) / r) if r > 0 else np.zeros(3)


#: Cap on residual evaluations of :func:`mobius_fit` (each is O(k)).
MAX_FIT_EVALUATIONS = 2000


def mobius_fit(P, Q):
    """The Möbius transformation of the sphere that best maps the points ``P`` to ``Q``.

    Minimizes ``sum_i |T(P_i) - Q_i|^2`` over the orientation-preserving Möbius
    transformations ``T(x) = R T_c(x)`` (every one is a hyperbolic translation
    :func:`mobius_transform` followed by a rotation).  For each ``c`` the best
    ``R`` is the Kabsch rotation, so the search is over the 3 parameters of ``c``
    (``c = tanh(|z|) z / |z|``, Levenberg-Marquardt on the ``3k`` residuals from
    ``c = 0``: it stops on the relative change of the cost, where a simplex
    method's absolute tolerance either stops early or never, depending on the
    size of the residual).  Three points in
    general position are matched exactly; with fewer the fit is not unique
    (the one nearest ``c = 0`` is returned, a rotation for one or two points).

    Parameters
    ----------
    P, Q : (k, 3) float64 arrays
        Unit vectors, ``k >= 1``.

    Returns
    -------
    c : (3,) float64 array
        The ball point with ``|c| < 1`` of the hyperbolic translation.
    R : (3, 3) float64 array
        The rotation applied after it: ``T(x) = R @ mobius_transform(x, c)``.
    residual : float
        ``sqrt(mean_i |T(P_i) - Q_i|^2)`` (chordal).
    """
    from scipy.optimize import least_squares

    P = np.asarray(P, dtype=np.float64)
    Q = np.asarray(Q, dtype=np.float64)

    def residuals(z):
        X = mobius_transform(P, ball_point(z))
        return (X @ best_rotation(X, Q).T - Q).ravel()

    z = np.zeros(3)
    if P.shape[0] >= 3 and float(np.sum(residuals(z) ** 2)) > 1e-24:
        z = least_squares(residuals, z, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                          max_nfev=MAX_FIT_EVALUATIONS).x
    c = ball_point(z)
    X = mobius_transform(P, c)
    R = best_rotation(X, Q)
    return c, R, float(np.sqrt(np.mean(np.sum((X @ R.T - Q) ** 2, axis=1))))
