"""Folds of a spherical map: the orientation of every image face, exact and after rounding.

A face ``(i, j, k)`` of an outward-oriented mesh is *folded* in the map ``U``
when its image triangle is inverted or collapsed: the signed volume
``det[U_i, U_j, U_k]`` (:func:`igl_spheremap.mesh.operators.signed_volumes`) is
``<= 0``.  The *degree* of the map is the total signed solid angle of the image
faces over ``4 pi``: 1 for a fold-free map of a closed genus-0 surface.

A map is stored as ``R * U`` in some floating-point type (GIfTI: float32, at
``R = 100`` by this package's convention; FreeSurfer: float32, ``R = 100``).
Rounding moves every coordinate, so an image triangle whose signed volume is
positive in float64 can be folded once stored.  :func:`rounding_margin` bounds
that change: a map whose every face has ``s > rounding_margin(F, U, precision)``
keeps every face unfolded after rounding, at any radius ``R`` and in any
rotation of the sphere.

Derivation (``u`` = unit roundoff of the storage type, ``2**-24`` for float32).
Round to nearest gives ``fl(R x) = R x (1 + e)`` with ``|e| <= u`` (no overflow or
underflow), so in units of the unit sphere every vertex moves by ``d_i`` with
``|d_i,c| <= u |U_i,c|``, hence ``|d_i| <= u |U_i| = u`` whatever ``R``.  The signed
volume ``s = det[U_i, U_j, U_k]`` is multilinear, so exactly::

    s' - s = det[d_i, U_j, U_k] + det[U_i, d_j, U_k] + det[U_i, U_j, d_k]    (first order)
           + det[d_i, d_j, U_k] + det[d_i, U_j, d_k] + det[U_i, d_j, d_k]    (second order)
           + det[d_i, d_j, d_k]                                            (third order)

with ``|det[d_i, U_j, U_k]| = |d_i . (U_j x U_k)| <= u |U_j x U_k|``,
``|det[d_i, d_j, U_k]| <= u^2`` and ``|det[d_i, d_j, d_k]| <= u^3``.  For unit
vectors ``|U_j x U_k| = sin(theta) <= 2 sin(theta / 2) = |U_j - U_k|`` (the chord), so::

    |s' - s| <= u P + 3 u^2 + u^3,    P = |U_i - U_j| + |U_j - U_k| + |U_k - U_i|.

The margin is :data:`SAFETY` times this (headroom for the float64 evaluation of
``s`` and for rows that are unit only to rounding).  The bound uses the
Euclidean norm of ``d_i``, so it does not depend on the rotation of the sphere.
For a small face it asks for a height of about ``2 u`` over the longest edge:
an equilateral face needs edges of at least ~``4.2 u`` (2.5e-7 in float32).
``"float64"`` gets margin 0: the fold test ``s > 0`` itself.
"""

import numpy as np

from ..errors import plural
from ..mesh.arrays import as_faces, as_points, cross_rows, moved_unit_rows, rowdot
from ..mesh.operators import CHUNK_FACES, signed_volumes
from ..mesh.topology import vertex_face_incidence


def signed_image_volumes(F, U):
    """Six times the signed volume of the tetrahedron (0, U_i, U_j, U_k) per face.

    See :func:`signed_volumes` for how it is computed.

    Parameters
    ----------
    F : (m, 3) int array
    U : (n, 3) float array
        Points on (or near) the unit sphere (any radius: only signs and ratios matter).

    Returns
    -------
    s : (m,) float64 array
        Positive for a face whose image keeps the orientation of an outward
        oriented input; negative for an inverted (folded) face.

    Raises
    ------
    ValueError
        ``F`` is not (m, 3) integer indices into the rows of ``U``, or ``U`` is
        not (n, 3) finite numbers.
    """
    U = as_points(U, "U")
    return signed_volumes(as_faces(F, U.shape[0]), U)


def fold_mask(F, U):
    """``signed_volumes(F, U) <= 0`` without argument checks (the optimizer's fold test)."""
    return signed_volumes(F, U) <= 0.0


def folded_faces(F, U):
    """Boolean mask of folded (flipped) faces of the spherical image.

    A face is folded when its image triangle is inverted or collapsed: the
    signed volume of :func:`signed_image_volumes` is ``<= 0``.  This assumes the
    input mesh is oriented outward (:func:`igl_spheremap.validate_mesh` makes it so).

    Parameters
    ----------
    F : (m, 3) int array
    U : (n, 3) float64 array

    Returns
    -------
    (m,) bool array

    Raises
    ------
    ValueError
        As :func:`signed_image_volumes` (e.g. quads, or a ``U`` with fewer rows
        than ``F`` references).
    """
    return signed_image_volumes(F, U) <= 0.0


def count_folds(F, U):
    """Number of folded faces of the spherical image ``U`` (see :func:`folded_faces`).

    Parameters
    ----------
    F : (m, 3) int array
    U : (n, 3) float64 array

    Returns
    -------
    int

    Raises
    ------
    ValueError
        As :func:`signed_image_volumes`.
    """
    return int(np.count_nonzero(folded_faces(F, U)))


def map_degree(F, U):
    """Degree of the map: the total signed solid angle of the image faces over ``4 pi`` (float).

    Each face contributes the solid angle of its spherical triangle, with the
    sign of its orientation (Van Oosterom and Strackee, "The solid angle of a
    plane triangle", IEEE Trans. Biomed. Eng. 30(2), 1983:
    ``tan(Omega / 2) = det[U_i, U_j, U_k] / (1 + U_i.U_j + U_j.U_k + U_k.U_i)``).
    For a map of a closed surface it is an integer up to rounding: 1 for a
    fold-free map, 0 for a map collapsed onto part of the sphere with half of
    its image folded over the other half.

    Parameters
    ----------
    F : (m, 3) int array
        Faces, outward oriented.
    U : (n, 3) float64 array
        Points of a sphere about the origin, any radius (each row is taken as its
        direction: a FreeSurfer sphere of radius 100 has the degree of its unit map).

    Returns
    -------
    float

    Raises
    ------
    ValueError
        As :func:`signed_image_volumes`, or a row of ``U`` is zero (no direction).
    """
    U = as_points(U, "U")
    F = as_faces(F, U.shape[0])
    r = np.linalg.norm(U, axis=1)
    if not r.all():
        raise ValueError(f"U has {plural(int(np.count_nonzero(r == 0)), 'zero row')}: a "
                         "spherical map's rows are directions")
    U = U / r[:, None]
    Ui, Uj, Uk = U[F[:, 0]], U[F[:, 1]], U[F[:, 2]]
    dots = (np.einsum("ij,ij->i", Ui, Uj) + np.einsum("ij,ij->i", Uj, Uk)
            + np.einsum("ij,ij->i", Uk, Ui))
    return float(2.0 * np.arctan2(signed_volumes(F, U), 1.0 + dots).sum() / (4.0 * np.pi))


#: Unit roundoff (half the machine epsilon) of each storage type.  A float64
#: map is stored as it is computed (margin 0, the plain fold test).
UNIT_ROUNDOFF = {"float64": 0.0, "float32": 2.0 ** -24}

#: Factor on the bound of the module docstring.
SAFETY = 1.25

PRECISIONS = tuple(UNIT_ROUNDOFF)


def unit_roundoff(precision):
    """``u`` of a storage type (float): ``2**-24`` for ``"float32"``, 0 for ``"float64"``.

    Raises
    ------
    ValueError
        If ``precision`` is not one of :data:`PRECISIONS`.
    """
    if precision not in UNIT_ROUNDOFF:
        raise ValueError(f"unknown precision {precision!r}; expected one of {list(PRECISIONS)}")
    return UNIT_ROUNDOFF[precision]


def rounding_margin(F, U, precision="float32"):
    """Per face, the most that storing ``R * U`` in ``precision`` can change its signed image volume.

    A face with ``signed_image_volumes(F, U) > rounding_margin(F, U, precision)``
    stays unfolded when ``R * U`` is rounded to ``precision`` and read back, for
    any radius ``R > 0`` (without overflow or underflow) and after any rotation
    of ``U``.  Derivation in the module docstring (multilinearity of the
    determinant and ``|fl(x) - x| <= u |x|``).

    Parameters
    ----------
    F : (m, 3) int array
        Faces (indices into ``U``).
    U : (n, 3) float array
        Unit vectors (the map).
    precision : {"float32", "float64"}
        Storage type; ``"float64"`` gives zeros.

    Returns
    -------
    (m,) float64 array
        ``SAFETY * (u P + 3 u^2 + u^3)``, ``P`` the face's chord perimeter on the
        unit sphere, ``u`` the unit roundoff; same units as
        :func:`igl_spheremap.sphere.folds.signed_image_volumes` (six times a volume,
        i.e. ``det[U_i, U_j, U_k]``).

    Raises
    ------
    ValueError
        Unknown ``precision``, or ``F`` / ``U`` not valid faces and points.
    """
    u = unit_roundoff(precision)
    U = as_points(U, "U")
    return volumes_and_margins(as_faces(F, U.shape[0]), U, u)[1]


def below_margin(F, U, precision="float32"):
    """Faces whose signed image volume is at or below their rounding margin.

    For ``"float64"`` these are the folded faces
    (:func:`igl_spheremap.sphere.folds.folded_faces`); for ``"float32"`` the faces
    that rounding might fold.

    Parameters
    ----------
    F : (m, 3) int array
    U : (n, 3) float array
        Unit vectors.
    precision : {"float32", "float64"}

    Returns
    -------
    (m,) bool array

    Raises
    ------
    ValueError
        As :func:`rounding_margin`.
    """
    u = unit_roundoff(precision)
    U = as_points(U, "U")
    s, margin = volumes_and_margins(as_faces(F, U.shape[0]), U, u)
    return s <= margin


def folds_after_rounding(F, U, radius=1.0, dtype=np.float32):
    """Folded faces of ``U`` once stored as ``radius * U`` in ``dtype`` and read back (int).

    The reference the margin is tested against: numpy's own rounding
    (``astype``), then the fold test of :func:`igl_spheremap.sphere.folds.count_folds`.
    """
    Ur = (radius * np.asarray(U, dtype=np.float64)).astype(dtype).astype(np.float64)
    return count_folds(F, Ur)


def volumes_and_margins(F, U, u):
    """Signed image volumes and rounding margins of every face, in one pass (no argument checks).

    ``s`` is computed exactly as :func:`igl_spheremap.mesh.operators.signed_volumes`
    does (``((U_j - U_i) x (U_k - U_i)) . (U_i + U_j + U_k) / 3``, same
    operations), and the chord perimeter from the same gathered coordinates, in
    blocks of :data:`igl_spheremap.mesh.operators.CHUNK_FACES` faces: this runs in
    every line-search trial of the float32 barrier.

    Parameters
    ----------
    F : (m, 3) int64 array
    U : (n, 3) float64 array
    u : float
        Unit roundoff (:func:`unit_roundoff`); 0 gives zero margins.

    Returns
    -------
    s, margin : (m,) float64 arrays
    """
    F = np.asarray(F)
    X, Y, Z = np.array(np.asarray(U, dtype=np.float64).T, order="C")
    m = F.shape[0]
    s, P = np.empty(m), np.zeros(m)
    for a in range(0, m, CHUNK_FACES):
        b = min(a + CHUNK_FACES, m)
        i, j, k = np.array(F[a:b].T, dtype=np.intp)
        coords = []
        for C in (X, Y, Z):
            ci, cj, ck = C.take(i), C.take(j), C.take(k)
            coords.append((ci, cj - ci, ck - ci, ci + cj + ck))
        (xi, dxj, dxk, sx), (yi, dyj, dyk, sy), (zi, dzj, dzk, sz) = coords
        s[a:b] = ((dyj * dzk - dzj * dyk) * sx + (dzj * dxk - dxj * dzk) * sy
                  + (dxj * dyk - dyj * dxk) * sz)
        if u:
            P[a:b] = (np.sqrt(dxj * dxj + dyj * dyj + dzj * dzj)
                      + np.sqrt(dxk * dxk + dyk * dyk + dzk * dzk)
                      + np.sqrt((dxk - dxj) ** 2 + (dyk - dyj) ** 2 + (dzk - dzj) ** 2))
    s /= 3.0
    margin = SAFETY * (u * P + 3.0 * u * u + u ** 3) if u else np.zeros(m)
    return s, margin


def count_below_margin(F, U, u):
    """Number of faces whose signed image volume is at or below its margin (no argument checks).

    Parameters
    ----------
    F : (m, 3) int64 array
    U : (n, 3) float64 array
    u : float
        Unit roundoff (:func:`unit_roundoff`).

    Returns
    -------
    int
    """
    s, margin = volumes_and_margins(F, U, u)
    return int(np.count_nonzero(s <= margin))


def fold_free_blend(F, U_old, U_new, max_halvings=40, incidence=None, fixed=None,
                    corners="closing"):
    """``U_new`` pulled back toward the fold-free map ``U_old`` vertex by vertex until no face folds.

    Vertex ``v`` keeps a fraction ``alpha_v`` of its step: its chordal point is
    ``P_v = U_old_v + alpha_v (U_new_v - U_old_v)``, scaled back to the sphere, which
    leaves the signs of the faces' signed volumes ``det[P_i, P_j, P_k]`` as they are.
    That determinant is linear in each corner's ``alpha``, and its derivative in
    ``alpha_v`` is the determinant with ``P_v`` replaced by ``v``'s step.  So in each
    folded face only the corners whose step closes it (negative derivative) have their
    step halved, or all of its corners when none does (``corners="closing"``; with
    ``"all"``, every corner of a folded face); repeatedly, after ``max_halvings`` halvings
    set to 0.  A corner whose step opens the face keeps it, instead of the whole
    neighbourhood of a fold being cut back together.  A face whose three vertices are
    back at ``U_old`` bit for bit is not folded, so this ends with a fold-free map.  After
    the first test only the faces around the vertices just moved back are tested again.
    A vertex whose step is zero stays at ``U_old`` bit for bit
    (:func:`igl_spheremap.mesh.arrays.moved_unit_rows`).

    Parameters
    ----------
    F : (m, 3) int64 array
        Faces, oriented outward.
    U_old : (n, 3) float64 array
        Fold-free spherical map (unit rows).
    U_new : (n, 3) float64 array
        Proposed map (unit rows).
    max_halvings : int
    incidence : (n, m) scipy.sparse.csr_matrix, optional
        :func:`igl_spheremap.mesh.topology.vertex_face_incidence` of ``F``, if the caller has it.
    fixed : (n,) bool array, optional
        Vertices that keep their full step (e.g. landmarks on their targets).
    corners : {"closing", "all"}
        Which corners of a folded face have their step halved: those whose step closes
        it, or all three (the landmark bend's choice: there the folds at the fixed
        landmarks are left to a local untangling, which the closing corners alone leave
        more of; ``docs/decisions.md``).

    Returns
    -------
    U : (n, 3) float64 array
        The blend (unit rows): fold-free but for faces with a ``fixed`` corner whose
        other corners are back at ``U_old``.
    alpha : (n,) float64 array
        Fraction of each vertex's step kept, in [0, 1].

    Raises
    ------
    ValueError
        If ``corners`` is neither ``"closing"`` nor ``"all"``.
    """
    if corners not in ("closing", "all"):
        raise ValueError(f"corners must be 'closing' or 'all', got {corners!r}")
    n = U_old.shape[0]
    alpha = np.ones(n)
    U = np.array(U_new, dtype=np.float64)
    folded = np.flatnonzero(fold_mask(F, U))
    if folded.size == 0:
        return U, alpha
    if incidence is None:
        incidence = vertex_face_incidence(F, n)
    vertex_set, face_set = _IndexSet(n), _IndexSet(F.shape[0])
    it = 0
    D = U_new - U_old
    free = np.ones(n, dtype=bool) if fixed is None else ~np.asarray(fixed, dtype=bool)
    while folded.size:  # ends: each pass halves some alpha > 0 (or zeroes it) or stops
        moved = F[folded] if corners == "all" else _culprits(F[folded], U_old, D, alpha, free)
        moved = vertex_set.sorted(moved)
        moved = moved[(alpha[moved] > 0.0) & free[moved]]
        if moved.size == 0:
            break  # folds only ``fixed`` vertices could undo
        alpha[moved] *= 0.5 if it < max_halvings else 0.0
        Y = moved_unit_rows(U_old[moved], U_old[moved] + alpha[moved, None] * D[moved])
        U[moved] = np.where(alpha[moved, None] == 0.0, U_old[moved], Y)
        near = face_set.sorted(_row_indices(incidence, moved))
        folded = near[fold_mask(F[near], U)]
        it += 1
    return U, alpha


def _culprits(Ff, U_old, D, alpha, free):
    """The corners of the folded faces ``Ff`` (r, 3) whose steps are cut back (with repeats):
    the ``free`` corners with ``alpha > 0`` whose derivative of the face's signed volume in
    their ``alpha`` is negative, or every such corner of a face where none is
    (:func:`fold_free_blend`)."""
    corners = [U_old[Ff[:, c]] + alpha[Ff[:, c], None] * D[Ff[:, c]] for c in range(3)]
    g = np.empty(Ff.shape)
    for c in range(3):
        rows = list(corners)
        rows[c] = D[Ff[:, c]]
        g[:, c] = rowdot(rows[0], cross_rows(rows[1], rows[2]))
    can = (alpha[Ff] > 0) & free[Ff]
    act = (g < 0) & can
    none = ~act.any(axis=1)
    act[none] = can[none]
    return Ff[act]


def _row_indices(A, rows):
    """The column indices of the given rows of the CSR matrix ``A``, concatenated: what
    ``A[rows].indices`` holds, without building the submatrix (the blend's inner loop)."""
    start = A.indptr[rows]
    count = A.indptr[rows + 1] - start
    offsets = np.repeat(start - np.cumsum(count) + count, count)
    return A.indices[offsets + np.arange(offsets.size)]


class _IndexSet:
    """``np.unique`` of indices below ``size`` by a reused mask (the blend's inner loop calls it
    tens of times per step on a few hundred indices, where hashing costs more)."""

    def __init__(self, size):
        self.mask = np.zeros(size, dtype=bool)

    def sorted(self, idx):
        """The distinct values of ``idx`` in increasing order (int64 array)."""
        self.mask[idx] = True
        out = np.flatnonzero(self.mask)
        self.mask[out] = False
        return out
