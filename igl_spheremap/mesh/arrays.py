"""Arrays of points and triangles: argument checks shared by the public functions (clear
errors naming the problem and the count), and the row-wise operations on (n, 3) arrays."""

import numpy as np

from ..errors import plural

_ONES3 = np.ones(3)


def rowdot(X, Y):
    """Row-wise dot products of two (n, 3) arrays ((n,) float64; faster than einsum for n x 3)."""
    return (X * Y) @ _ONES3


def cross_rows(X, Y):
    """Row-wise cross products of two (n, 3) arrays (broadcast like ``np.cross`` over the
    leading axes; their common dtype).

    The same arithmetic as ``np.cross`` (the same bits), without its axis handling, which
    costs 3-4x the products themselves on the sizes here (a few faces to 50k).
    """
    X, Y = np.asarray(X), np.asarray(Y)
    out = np.empty(np.broadcast_shapes(X.shape, Y.shape), dtype=np.result_type(X, Y))
    for k in range(3):
        i, j = (k + 1) % 3, (k + 2) % 3
        np.multiply(X[..., i], Y[..., j], out=out[..., k])
        out[..., k] -= X[..., j] * Y[..., i]
    return out


def unit_rows(U):
    """``U`` with every row scaled to length 1 (float64 copy)."""
    U = np.asarray(U, dtype=np.float64)
    return U / np.linalg.norm(U, axis=1, keepdims=True)


#: Largest ``| |U_i| - 1 |`` of a row accepted as a unit vector (a spherical map stored in
#: float32 is within 6e-8).
UNIT_TOL = 1e-6


def off_unit_sphere(U, name="U"):
    """A ValueError's message when a row of ``U`` ((n, 3), finite) is farther than
    :data:`UNIT_TOL` from length 1, else None.

    Returns
    -------
    str or None
        Names ``name``, the count of such rows and the largest ``| |U_i| - 1 |`` (a sphere
        of radius 100, as FreeSurfer stores ``?h.sphere``, passed where unit vectors belong).
    """
    off = np.abs(np.linalg.norm(np.asarray(U, dtype=np.float64), axis=1) - 1.0)
    bad = int(np.count_nonzero(off > UNIT_TOL))
    if not bad:
        return None
    return (f"{name} has {plural(bad, 'row')} off the unit sphere (largest | |U_i| - 1 | = "
            f"{off.max():.3g} > {UNIT_TOL:g}); divide {name} by its row norms first")


#: A sphere's vertices lie at one radius: a given sphere (an atlas's ``?h.sphere``, a template)
#: is refused where a vertex is farther than this share of the median radius from it.
#: fsaverage5's ``sphere`` is within 8e-5 (float32 storage and FreeSurfer's own rounding).
SPHERE_RADIUS_RTOL = 1e-2


def off_sphere(X, name, rtol=SPHERE_RADIUS_RTOL):
    """A ValueError's message when the points ``X`` ((n, 3)) are not on one sphere about the
    origin, else None.

    Returns
    -------
    str or None
        Names ``name``, the count of vertices farther than ``rtol`` times the median radius
        from it, and the range of radii (a surface or an ellipsoid passed where its
        sphere belongs).
    """
    r = np.linalg.norm(np.asarray(X, dtype=np.float64), axis=1)
    median = float(np.median(r))
    bad = int(np.count_nonzero(np.abs(r - median) > rtol * median))
    if not bad:
        return None
    return (f"{name} is not a sphere: {bad} of {r.size} vertices are more than {rtol:.0%} off its "
            f"median radius {median:.4g} (radii {r.min():.4g} to {r.max():.4g}); pass the "
            "surface's sphere (e.g. ?h.sphere, an icosphere), not the surface")


def as_weights(w, n, name, *, positive=False, at_most=None):
    """``w`` as an (n,) float64 array of finite per-vertex weights, else a ValueError.

    Parameters
    ----------
    w : array_like
    n : int
        Vertices: one weight each.
    name : str
        Named in messages.
    positive : bool
        Every weight above 0 (areas); else at least 0, with a positive sum.
    at_most : float, optional
        Upper bound (1 for a mask).

    Returns
    -------
    (n,) float64 array

    Raises
    ------
    ValueError
        Another shape, or the count of weights outside the range (NaN included).
    """
    w = np.asarray(w, dtype=np.float64)
    if w.shape != (n,):
        raise ValueError(f"{name} must have one weight per vertex ({n}), got shape {w.shape}")
    ok = np.isfinite(w) & ((w > 0) if positive else (w >= 0))
    if at_most is not None:
        ok &= w <= at_most
    bad = int(np.count_nonzero(~ok))
    if bad:
        low = "above 0" if positive else "at least 0"
        high = "" if at_most is None else f" and at most {at_most:g}"
        raise ValueError(f"{name} has {plural(bad, 'value that is', 'values that are')} not "
                         f"finite, {low}{high}")
    if not w.sum() > 0:
        raise ValueError(f"{name} sums to 0: no vertex has weight")
    return w


def moved_unit_rows(U, X):
    """``X`` ((n, 3)) with its rows scaled to length 1, except the rows equal to ``U``'s, which
    stay ``U``'s bit for bit ((n, 3) float64 copy).

    Scaling a unit row again changes it by rounding; where a spherical map crowds faces to
    1e-11 and less, that is a visible share of a face, so a step that leaves a vertex where
    it is must not move it.
    """
    X = np.array(X, dtype=np.float64)
    moved = np.any(X != U, axis=1)
    X[moved] /= np.linalg.norm(X[moved], axis=1, keepdims=True)
    return X


def as_points(X, name="U", rows=None):
    """``X`` as a C-contiguous float64 (k, 3) array of finite numbers.

    Parameters
    ----------
    X : array_like
    name : str
        Name used in the messages.
    rows : int, optional
        Required number of rows (one per vertex of the mesh).

    Returns
    -------
    (k, 3) float64 array

    Raises
    ------
    ValueError
        Not a rectangular numeric array, wrong shape, wrong number of rows, or rows
        with NaN or infinite values (their count and the first one are given).
    """
    try:
        X = np.ascontiguousarray(X, dtype=np.float64)
    except (ValueError, TypeError) as err:
        raise ValueError(f"{name} must be a (k, 3) array of real numbers ({err})") from None
    if X.ndim != 2 or X.shape[1] != 3:
        raise ValueError(f"{name} has shape {X.shape}; expected (k, 3), one 3-D point per row")
    if rows is not None and X.shape[0] != rows:
        raise ValueError(f"{name} has {plural(X.shape[0], 'row')}; expected {rows}, one per "
                         "vertex of the mesh (a slice or another mesh's array?)")
    bad = ~np.isfinite(X).all(axis=1)
    if bad.any():
        raise ValueError(f"{name} has {plural(int(bad.sum()), 'row')} with NaN or infinite "
                         f"values (first: row {int(np.flatnonzero(bad)[0])})")
    return X


def as_faces(F, vertices=None, name="F"):
    """``F`` as a C-contiguous int64 (m, 3) array of vertex indices.

    Parameters
    ----------
    F : array_like
    vertices : int, optional
        Number of vertices: indices must lie in ``0..vertices-1``.
    name : str

    Returns
    -------
    (m, 3) int64 array

    Raises
    ------
    ValueError
        Not rectangular, not triangles (e.g. quads), non-integer entries, or
        indices out of range (their count is given).
    """
    try:
        A = np.asarray(F)
    except (ValueError, TypeError) as err:
        raise ValueError(f"{name} must be an (m, 3) array of vertex indices ({err})") from None
    if A.ndim != 2 or A.shape[1] != 3:
        what = f"; polygons with {plural(A.shape[1], 'corner')} must be triangulated first" \
            if A.ndim == 2 else ""
        raise ValueError(f"{name} has shape {A.shape}; expected (m, 3) triangles{what}")
    if A.dtype == bool or not (np.issubdtype(A.dtype, np.integer)
                               or np.issubdtype(A.dtype, np.floating)):
        raise ValueError(f"{name} has dtype {A.dtype}; expected integer vertex indices")
    if np.issubdtype(A.dtype, np.floating):
        frac = ~np.isfinite(A) | (A != np.round(A))
        if frac.any():
            what = plural(int(frac.sum()), "non-integer entry", "non-integer entries")
            raise ValueError(f"{name} has {what}; expected integer vertex indices")
    A = np.ascontiguousarray(A, dtype=np.int64)
    if vertices is not None:
        _check_range(A, vertices, name, f" (the map has {plural(vertices, 'row')})")
    return A


def as_map_of(V, F, U):
    """``(V, F, U)`` checked for the quality measures: ``U`` has one row per row of ``V``.

    Returns
    -------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
    U : (n, 3) float64 array

    Raises
    ------
    ValueError
        As :func:`as_points` and :func:`as_faces`.
    """
    V = as_points(V, "V")
    return V, as_faces(F, V.shape[0]), as_points(U, "U", rows=V.shape[0])


def vertex_values(x, n, name):
    """``x`` as an (n,) float64 array of finite values, else a ValueError naming ``name``.

    Parameters
    ----------
    x : array_like
    n : int or None
        Required length (one value per vertex); None: any length >= 1.
    name : str

    Returns
    -------
    (n,) float64 array

    Raises
    ------
    ValueError
        Another shape, or NaN or infinite values (their count and the first index).
    """
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 1 or not x.size or (n is not None and x.size != n):
        want = "at least one value" if n is None else f"one value per vertex ({n})"
        raise ValueError(f"{name} has shape {x.shape}; expected a 1-D array with {want}")
    bad = ~np.isfinite(x)
    if bad.any():
        what = plural(int(bad.sum()), "NaN or infinite value")
        raise ValueError(f"{name} has {what} of {x.size} (first: index "
                         f"{int(np.flatnonzero(bad)[0])})")
    return x


def vertex_indices(idx, n, name):
    """``idx`` as a (k,) int64 array of vertex indices in ``0..n-1``, else a ValueError.

    Raises
    ------
    ValueError
        Not integers, or indices out of range (their count and the first one).
    """
    a = np.atleast_1d(np.asarray(idx))
    if a.ndim != 1 or (a.size and not np.issubdtype(a.dtype, np.integer)):
        raise ValueError(f"{name} must be integer vertex indices, got {a.dtype} of shape "
                         f"{a.shape}")
    a = a.astype(np.int64)
    _check_range(a, n, name, "")
    return a


def _check_range(A, n, name, context):
    """Raise a ValueError counting the entries of ``A`` outside ``0..n-1`` (and the first)."""
    bad = (A < 0) | (A >= n)
    if bad.any():
        raise ValueError(f"{name} has {plural(int(bad.sum()), 'index', 'indices')} outside "
                         f"0..{n - 1} (first: {int(A[bad][0])}){context}")
