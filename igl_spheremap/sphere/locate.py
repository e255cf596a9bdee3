"""Point location on a fold-free spherical triangle mesh (central projection)."""

import igl
import numpy as np

from ..errors import plural
from ..mesh.arrays import off_unit_sphere
from .folds import count_folds, map_degree

COVER_TOL = 1e-6
"""Largest accepted relative gap between the faces' total solid angle and ``4 pi``."""

WALK_STEPS = 256
"""Steps of the walk across edges before a point falls back to the search over all faces."""

JUMP_AFTER = 4
"""Steps of :func:`locate_from`'s walk after which the points still walking start again from
the nearest chordal face (``igl.AABB``), when the caller gives the tree."""

ROUND_EPS = 16.0 * np.finfo(np.float64).eps
"""Relative rounding allowance of the signed volumes (see :func:`_cone_volumes`)."""

BRUTE_CHUNK = 1 << 20
"""Face-point pairs per block of the fallback search over all faces."""


def locate_on_sphere(U, F, P):
    """Face and barycentric coordinates of directions on a spherical triangle mesh.

    The faces of a fold-free spherical map ``(U, F)`` define cones from the
    origin that tile the sphere; the face of a direction ``P`` is the one whose
    cone contains it (three signed volumes ``det[P, U_j, U_k]``,
    ``det[U_i, P, U_k]``, ``det[U_i, U_j, P]`` non-negative), and its
    barycentric coordinates are those of the point where the ray along ``P``
    meets the plane of the flat (chordal) triangle, i.e. the three volumes
    divided by their sum.  Candidates come from libigl: the nearest face of the
    chordal mesh (``igl.AABB.squared_distance``).  Where the chordal triangles'
    gap to the sphere makes that face wrong (crowded maps, large triangles), a
    walk across the edges of the mesh toward ``P`` finds the face whose cone
    contains it; a point the walk does not settle within :data:`WALK_STEPS`
    steps is located by testing every face.

    A point on an edge or vertex (to rounding: a volume above ``-ROUND_EPS``
    times its error scale) gets one of the faces that share it and coordinates
    clipped to ``>= 0``: the vertex opposite a containing edge gets weight 0,
    so the interpolated value is the same whichever face is returned.

    Parameters
    ----------
    U : (n, 3) float64 array
        Unit vectors (``| |U_i| - 1 | <= 1e-6``, ``mesh.arrays.UNIT_TOL``): a spherical map.
    F : (m, 3) int array
        Triangles of ``U``, oriented outward (every ``det[U_i, U_j, U_k] > 0``);
        closed, so that the cones cover the sphere once.
    P : (k, 3) float array
        Query directions; any non-zero length (they are normalized).

    Returns
    -------
    face : (k,) int64 array
        Row of ``F`` whose cone contains ``P``.
    bary : (k, 3) float64 array
        Barycentric coordinates with respect to ``F[face]``, non-negative, rows
        summing to 1 (to rounding); ``bary @ U[F[face]]`` is the chordal point on
        the ray along ``P``.

    Raises
    ------
    ValueError
        If a shape is wrong, ``U`` or ``P`` holds non-finite values, a row of
        ``P`` has zero length, ``U`` is off the unit sphere, ``F`` indexes
        outside ``U``, the map has folded faces, or the faces' cones do not cover
        the sphere exactly once (an open or multiply wrapped mesh).  The message
        gives the number of offending elements.

    Notes
    -----
    Source: barycentric coordinates by central (gnomonic) projection of the
    sphere onto each chordal triangle; the walk is the visibility walk of
    Devillers, Pion, Teillaud, "Walking in a triangulation", IJFCS 13(2), 2002,
    carried to the cones of a spherical triangulation.
    """
    U, F, P = _validated(U, F, P)
    k = P.shape[0]
    if k == 0:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 3))
    face = np.ascontiguousarray(chordal_tree(U, F).squared_distance(U, F, P)[1], dtype=np.int64)
    face, s = locate_from(U, F, P, face)
    np.maximum(s, 0.0, out=s)
    s /= s.sum(axis=1, keepdims=True)
    return face, s


def chordal_tree(U, F):
    """libigl's AABB tree of the chordal triangles ``(U, F)`` (``igl.AABB``): the nearest chordal
    face is where :func:`locate_on_sphere` starts each walk and where :func:`locate_from`'s
    far-walking points jump to.

    Parameters
    ----------
    U : (n, 3) float64 array
        A spherical map (unit rows).
    F : (m, 3) int64 array
        Its faces.

    Returns
    -------
    igl.AABB
        Initialized on ``(U, F)``; query it with the same arrays.
    """
    tree = igl.AABB()
    tree.init(U, F)
    return tree


def locate_from(U, F, P, face, TT=None, tree=None):
    """Faces whose cones contain the directions ``P``, walking from the faces ``face``.

    The incremental form of :func:`locate_on_sphere` for callers that locate
    nearby points again and again (an optimizer moving a map a little): no
    checks and no search structure, a walk across edges from the given faces
    (Devillers, Pion, Teillaud 2002), then the search over all faces for a
    point the walk does not settle within :data:`WALK_STEPS` steps.

    Parameters
    ----------
    U : (n, 3) float64 array
        A fold-free spherical map with unit rows (not checked).
    F : (m, 3) int64 array
        Its faces, oriented outward.
    P : (k, 3) float64 array
        Unit directions.
    face : (k,) int64 array
        Starting faces (e.g. the faces of the previous call).
    TT : (m, 3) int64 array, optional
        ``igl.triangle_triangle_adjacency(F)[0]``; computed when needed if not given.
    tree : igl.AABB, optional
        :func:`chordal_tree` of ``(U, F)``.  Given, the points the walk has not settled after
        :data:`JUMP_AFTER` steps walk on from their nearest chordal face, as
        :func:`locate_on_sphere` starts: a few points walking far (a long move, or across
        a crowded region of the map) otherwise take one step each per pass.

    Returns
    -------
    face : (k,) int64 array
    volumes : (k, 3) float64 array
        The signed volumes ``det[P, U_j, U_k]`` (cyclically) in ``F[face]``:
        non-negative up to rounding; divided by their sum they are the
        barycentric coordinates of :func:`locate_on_sphere`.
    """
    face = np.array(face, dtype=np.int64)
    s = np.empty((P.shape[0], 3))
    todo = np.arange(P.shape[0])
    for step in range(WALK_STEPS):
        if step == JUMP_AFTER and tree is not None:
            face[todo] = tree.squared_distance(U, F, P[todo])[1]
        si, inside, worst = _cone_volumes(U, F[face[todo]], P[todo])
        s[todo[inside]] = si[inside]
        todo, worst = todo[~inside], worst[~inside]
        if todo.size == 0:
            break
        # step across the edge opposite the vertex of the most negative volume
        if TT is None:
            TT = igl.triangle_triangle_adjacency(F)[0]
        face[todo] = TT[face[todo], (worst + 1) % 3]
    for p in todo:
        face[p], s[p] = _search_all_faces(U, F, P[p])
    return face, s


def _cone_volumes(U, Fq, P):
    """Signed volumes of ``P`` against faces ``Fq`` (one face per point), and the cone test.

    ``s_0 = det[P, U_j, U_k] = P . ((U_j - P) x (U_k - P))`` (and cyclically):
    differences first, so tiny triangles near ``P`` keep accurate signs.  A
    volume counts as non-negative down to ``-ROUND_EPS * (|a| + |b| + |a||b|)``
    (``a, b`` the two differences), its rounding error bound.

    Returns ``s`` (q, 3), ``inside`` (q,) bool, and per point the corner whose
    volume, divided by the opposite edge length (a signed distance of ``P`` to
    the edge's plane), is most negative (0 where ``inside``; an edge of zero
    length in ``U - P`` is never stepped across).
    """
    Pt = np.ascontiguousarray(P.T)
    Ut = np.ascontiguousarray(U.T) if U.flags.c_contiguous else U.T
    D = [Ut[:, Fq[:, c]] - Pt for c in range(3)]  # U_i - P, U_j - P, U_k - P as (3, q)
    s = np.empty((3, Pt.shape[1]))
    for c in range(3):
        (ax, ay, az), (bx, by, bz) = D[(c + 1) % 3], D[(c + 2) % 3]
        s[c] = Pt[0] * (ay * bz - az * by) + Pt[1] * (az * bx - ax * bz) + Pt[2] * (ax * by - ay * bx)
    s = s.T
    inside = np.all(s > 0.0, axis=1)
    worst = np.zeros(s.shape[0], dtype=np.int64)
    near = np.flatnonzero(~inside)  # on an edge to rounding, or outside
    if near.size:
        Dn = np.stack([d[:, near].T for d in D], axis=1)  # (q', 3, 3)
        nD = np.linalg.norm(Dn, axis=2)
        a, b = nD[:, [1, 2, 0]], nD[:, [2, 0, 1]]
        sn = s[near]
        inside[near] = np.all(sn >= -ROUND_EPS * (a + b + a * b), axis=1)
        edge = np.linalg.norm(Dn[:, [2, 0, 1]] - Dn[:, [1, 2, 0]], axis=2)  # opposite each corner
        # an edge whose ends differ by less than the rounding of U - P (a crowded map seen
        # from afar) has a zero volume and no side to step across
        distance = np.divide(sn, edge, out=np.full_like(sn, np.inf), where=edge > 0.0)
        worst[near] = np.argmin(distance, axis=1)
    return s, inside, worst


def _search_all_faces(U, F, p):
    """Face whose cone contains direction ``p``, testing every face (fallback of the walk)."""
    m = F.shape[0]
    best, best_score = -1, -np.inf
    step = max(1, BRUTE_CHUNK // 3)
    for a in range(0, m, step):
        Fq = F[a:a + step]
        s, inside, _ = _cone_volumes(U, Fq, np.broadcast_to(p, (Fq.shape[0], 3)))
        if np.any(inside):
            j = int(np.flatnonzero(inside)[0])
            return a + j, s[j]
        score = (s / np.maximum(s.sum(axis=1, keepdims=True), 1e-300)).min(axis=1)
        j = int(np.argmax(score))
        if score[j] > best_score:
            best, best_score = a + j, score[j]
    raise ValueError(f"no face of the spherical mesh contains the direction {p.tolist()} "
                     f"(closest: face {best}, smallest coordinate {best_score:.3g}); "
                     "the faces do not tile the sphere")


def _validated(U, F, P):
    """Checked float64/int64 copies of the inputs; ``P`` normalized."""
    U = np.ascontiguousarray(U, dtype=np.float64)
    F = np.asarray(F)
    P = np.asarray(P, dtype=np.float64)
    if U.ndim != 2 or U.shape[1] != 3:
        raise ValueError(f"U must be an (n, 3) array, got shape {U.shape}")
    if F.ndim != 2 or F.shape[1] != 3 or F.shape[0] == 0:
        raise ValueError(f"F must be a non-empty (m, 3) array of triangles, got shape {F.shape}")
    if not np.issubdtype(F.dtype, np.integer):
        raise ValueError(f"F must hold integer vertex indices, got dtype {F.dtype}")
    if P.ndim != 2 or P.shape[1] != 3:
        raise ValueError(f"P must be a (k, 3) array of directions, got shape {P.shape}")
    F = np.ascontiguousarray(F, dtype=np.int64)
    n = U.shape[0]
    bad = np.count_nonzero((F < 0) | (F >= n))
    if bad:
        raise ValueError(f"F has {plural(bad, 'vertex index', 'vertex indices')} outside [0, {n})")
    bad = np.count_nonzero(~np.isfinite(U).all(axis=1))
    if bad:
        raise ValueError(f"U has {plural(bad, 'row')} with non-finite coordinates")
    off = off_unit_sphere(U)
    if off:
        raise ValueError(off)
    folds = count_folds(F, U)
    if folds:
        raise ValueError(f"the spherical map has {plural(folds, 'folded face')} (or F is not "
                         "oriented outward); point location needs a fold-free map")
    _check_covers_once(U, F)
    bad = np.count_nonzero(~np.isfinite(P).all(axis=1))
    if bad:
        raise ValueError(f"P has {plural(bad, 'row')} with non-finite coordinates")
    norm = np.linalg.norm(P, axis=1)
    bad = np.count_nonzero(norm == 0.0)
    if bad:
        raise ValueError(f"P has {plural(bad, 'zero-length row')} (a direction is needed)")
    # Directions already unit to rounding stay bit for bit (a vertex of U is then exactly a vertex).
    rescale = np.abs(norm - 1.0) > 4.0 * np.finfo(np.float64).eps
    P = P.copy()
    P[rescale] /= norm[rescale, None]
    return U, F, P


def _check_covers_once(U, F):
    """Raise unless the map has degree 1 (:func:`igl_spheremap.sphere.folds.map_degree`)."""
    degree = map_degree(F, U)
    if abs(degree - 1.0) > COVER_TOL:
        raise ValueError(f"the faces of the spherical map cover the sphere {degree:.6g} "
                         "times, not once (is the mesh closed and the map bijective?)")
