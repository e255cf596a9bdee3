"""Meshes built from scratch: icospheres (the templates of cortical surfaces), ellipsoids and
capsules (elongated shapes whose conformal maps crowd), split icospheres (thin triangles on a
sphere), for examples, tests and benchmarks."""

import numbers

import igl
import numpy as np

MAX_LEVEL = 9
"""Largest accepted subdivision level: 2,621,442 vertices, 5,242,880 faces (~190 MB of arrays)."""


#: Vertex orders of :func:`icosphere`.
ICOSPHERE_ORDERS = ("igl", "freesurfer")

#: FreeSurfer's names of its icosahedral templates and their levels.
FSAVERAGE_LEVELS = {"fsaverage3": 3, "fsaverage4": 4, "fsaverage5": 5, "fsaverage6": 6,
                    "fsaverage": 7}

#: Faces of level 0 in FreeSurfer's order (``ic0``), before the orientation swap of
#: :func:`icosphere` ``order="freesurfer"`` (vertex numbering of its Notes).
FREESURFER_LEVEL0_FACES = np.array([
    [0, 4, 3], [0, 5, 4], [0, 1, 5], [0, 2, 1], [0, 3, 2],
    [3, 8, 2], [3, 9, 8], [3, 4, 9], [4, 10, 9], [4, 5, 10],
    [5, 6, 10], [5, 1, 6], [1, 7, 6], [1, 2, 7], [2, 8, 7],
    [8, 9, 11], [9, 10, 11], [10, 6, 11], [6, 7, 11], [7, 8, 11],
], dtype=np.int64)


def icosphere(level, order="igl"):
    """Unit icosphere: the regular icosahedron subdivided ``level`` times.

    Every new vertex is the normalized midpoint of an edge of the previous
    level, and the vertex sets are nested (the first ``10 * 4**(level - 1) + 2``
    rows are the vertices of level ``level - 1``, bit for bit).  Level 7 has
    the 163,842 vertices of FreeSurfer's ``fsaverage`` (``ico7``) sphere, level
    5 the 10,242 of ``fsaverage5``.  Two vertex orders (and frames):

    * ``"igl"`` (default): ``igl.icosahedron`` subdivided by libigl's 4-to-1
      midpoint subdivision (``igl.upsample``).
    * ``"freesurfer"``: the vertex and face order and the frame of FreeSurfer's
      icosahedral spheres (``fsaverage``, ``fsaverageN`` = level ``N``; also a
      name of :data:`FSAVERAGE_LEVELS` as ``level``), so that data computed on
      it is fsaverage-ordered data (Notes).  FreeSurfer's files store these
      vertices at radius 100, rounded to about 1e-4 of the unit sphere.

    Parameters
    ----------
    level : int or str
        Number of subdivision steps, ``0 <= level <= MAX_LEVEL`` (9), or with
        ``order="freesurfer"`` a name such as ``"fsaverage5"``.
    order : {"igl", "freesurfer"}

    Returns
    -------
    V : (10 * 4**level + 2, 3) float64 array
        Unit vectors (norms 1 to rounding).
    F : (20 * 4**level, 3) int64 array
        Triangles, oriented outward (counter-clockwise seen from outside), so
        every face has a positive signed volume ``det[V_i, V_j, V_k]``.

    Raises
    ------
    TypeError
        If ``level`` is not an integer (``bool`` is refused too) or a known name, or a
        template name comes without ``order="freesurfer"`` (the message says so).
    ValueError
        If ``level`` is negative, above :data:`MAX_LEVEL`, an unknown name, or
        ``order`` is unknown.

    Notes
    -----
    FreeSurfer's order, as reproduced here (checked against fsaverage5's
    ``lh.sphere``: the same 20,480 faces index for index and every vertex
    within 1e-4 of the file's, by ``tests/test_templates.py``): level 0 has
    vertex 0 at the north pole ``(0, 0, 1)``, vertices 1-5 on the ring
    ``z = 1/sqrt(5)`` at azimuths -72, 0, 72, 144, 216 degrees, vertices 6-10 on
    the ring ``z = -1/sqrt(5)`` at -108, -36, 36, 108, 180 degrees, vertex 11 at
    the south pole, and the faces of :data:`FREESURFER_LEVEL0_FACES`.  Each
    subdivision goes through the faces ``(a, b, c)`` in order; each edge
    ``(a, b)``, ``(b, c)``, ``(c, a)`` not seen before gets a new vertex (the
    normalized midpoint), numbered in order of first appearance.  The new faces
    are first the corner face ``(a, ab, ca)`` of every face, then face by face
    ``(ab, b, bc)``, ``(ca, ab, bc)``, ``(ca, bc, c)``; the stored faces have
    their second and third index swapped (outward).

    Source: the geodesic icosahedral grid (Baumgardner & Frederickson, SIAM J.
    Numer. Anal. 1985) used for cortical surface templates (Fischl, Sereno,
    Tootell, Dale, Hum. Brain Mapp. 1999).
    """
    if order not in ICOSPHERE_ORDERS:
        raise ValueError(f"unknown icosphere order {order!r}; expected one of {list(ICOSPHERE_ORDERS)}")
    if order == "freesurfer" and isinstance(level, str):
        if level not in FSAVERAGE_LEVELS:
            raise ValueError(f"unknown template {level!r}; expected one of {list(FSAVERAGE_LEVELS)}")
        level = FSAVERAGE_LEVELS[level]
    if isinstance(level, str) and level in FSAVERAGE_LEVELS:
        raise TypeError(f"the template {level!r} is an icosphere level in FreeSurfer's order: "
                         f"icosphere({level!r}, order=\"freesurfer\")")
    if isinstance(level, bool) or not isinstance(level, numbers.Integral):
        raise TypeError(f"icosphere level must be an integer, got {type(level).__name__} {level!r}")
    level = int(level)
    if not 0 <= level <= MAX_LEVEL:
        size = f" ({10 * 4 ** level + 2} vertices)" if level > MAX_LEVEL else ""
        raise ValueError(f"icosphere level must be between 0 and {MAX_LEVEL}, got {level}{size}")
    if order == "freesurfer":
        V, F = _freesurfer_level0(), FREESURFER_LEVEL0_FACES.copy()
        for _ in range(level):
            V, F = _freesurfer_subdivide(V, F)
        return np.ascontiguousarray(V), np.ascontiguousarray(F[:, [0, 2, 1]])
    V, F = igl.icosahedron()
    V = V / np.linalg.norm(V, axis=1, keepdims=True)
    for _ in range(level):
        n = V.shape[0]
        V, F = igl.upsample(V, F)  # keeps the old vertices on top, bit for bit
        V[n:] /= np.linalg.norm(V[n:], axis=1, keepdims=True)
    return np.ascontiguousarray(V, dtype=np.float64), np.ascontiguousarray(F, dtype=np.int64)


def _freesurfer_level0():
    z, r = 1.0 / np.sqrt(5.0), 2.0 / np.sqrt(5.0)
    upper = np.radians(-72.0 + 72.0 * np.arange(5))
    lower = np.radians(-108.0 + 72.0 * np.arange(5))
    V = np.zeros((12, 3))
    V[0], V[11] = (0.0, 0.0, 1.0), (0.0, 0.0, -1.0)
    V[1:6] = np.c_[r * np.cos(upper), r * np.sin(upper), np.full(5, z)]
    V[6:11] = np.c_[r * np.cos(lower), r * np.sin(lower), np.full(5, -z)]
    return V


def _freesurfer_subdivide(V, F):
    """One subdivision by FreeSurfer's rule (:func:`icosphere` Notes), faces before the swap."""
    a, b, c = F.T
    m = F.shape[0]
    E = np.stack([np.stack([a, b], 1), np.stack([b, c], 1), np.stack([c, a], 1)], 1).reshape(-1, 2)
    key = np.sort(E, axis=1)
    _, first, inverse = np.unique(key[:, 0] * V.shape[0] + key[:, 1], return_index=True,
                                  return_inverse=True)
    rank = np.empty(first.size, dtype=np.int64)
    rank[np.argsort(first)] = np.arange(first.size)  # new vertices in order of first appearance
    mid = V.shape[0] + rank[inverse.ravel()]
    order = np.argsort(rank)
    P = V[key[first[order], 0]] + V[key[first[order], 1]]
    Vn = np.vstack([V, P / np.linalg.norm(P, axis=1, keepdims=True)])
    ab, bc, ca = mid.reshape(m, 3).T
    rest = np.stack([np.stack([ab, b, bc], 1), np.stack([ca, ab, bc], 1),
                     np.stack([ca, bc, c], 1)], 1).reshape(-1, 3)
    return Vn, np.vstack([np.stack([a, ab, ca], 1), rest])


def ellipsoid(aspect, level=3):
    """Icosphere of ``level`` scaled by ``(1, 1, aspect)``: convex, its conformal map crowds the tips.

    Parameters
    ----------
    aspect : float
        Length of the z axis over the other two (> 0).
    level : int
        Icosphere level (:func:`icosphere`).

    Returns
    -------
    V : (10 * 4**level + 2, 3) float64 array
    F : (20 * 4**level, 3) int64 array
        Outward oriented.
    """
    V, F = icosphere(level)
    return V * np.array([1.0, 1.0, float(aspect)]), F


def capsule(aspect=50.0, radius=0.5, n_around=16):
    """Closed capsule (a cylinder with hemispherical caps) of length / width ``aspect``.

    Rings of ``n_around`` vertices about the z axis, spaced about one edge length
    apart along the profile, plus a pole at each end; outward oriented.  Convex,
    so star-shaped about its centre, but its Gauss map is degenerate on the
    cylinder (every ring maps to the equator).  ``aspect=50``: 4,114 vertices.

    Parameters
    ----------
    aspect : float
        Length / width (> 1).
    radius : float
        Radius of the cylinder.
    n_around : int
        Vertices per ring.

    Returns
    -------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
    """
    h = (aspect - 1.0) * 2.0 * radius  # length of the cylinder
    ds = 2.0 * np.pi * radius / n_around
    n_cap = max(2, int(round(np.pi / 2.0 * radius / ds)))
    n_cyl = max(1, int(round(h / ds)))
    phi = np.pi / 2.0 * np.arange(1, n_cap + 1) / n_cap
    profile = ([(-h / 2 - radius * np.cos(a), radius * np.sin(a)) for a in phi]
               + [(-h / 2 + h * i / n_cyl, radius) for i in range(1, n_cyl)]
               + [(h / 2 + radius * np.cos(a), radius * np.sin(a)) for a in phi[::-1]])
    th = 2.0 * np.pi * np.arange(n_around) / n_around
    rings = [np.column_stack([r * np.cos(th), r * np.sin(th), np.full(n_around, z)])
             for z, r in profile]
    V = np.vstack([[[0.0, 0.0, -h / 2 - radius]], *rings, [[0.0, 0.0, h / 2 + radius]]])
    N, j = n_around, np.arange(n_around)
    j1 = (j + 1) % N
    F = [np.column_stack([np.zeros(N, dtype=np.int64), 1 + j1, 1 + j])]
    for k in range(len(rings) - 1):
        a, b = 1 + k * N, 1 + (k + 1) * N
        quads = [np.column_stack([a + j, a + j1, b + j1]), np.column_stack([a + j, b + j1, b + j])]
        F.append(np.stack(quads, axis=1).reshape(-1, 3))  # the two triangles of each quad in turn
    top, last = V.shape[0] - 1, 1 + (len(rings) - 1) * N
    F.append(np.column_stack([np.full(N, top), last + j, last + j1]))
    return V, np.vstack(F).astype(np.int64)


def split_icosphere(level=3, t=0.03):
    """The icosphere with every face split 1-to-4 at points ``t`` along its edges.

    Each edge is split at the fraction ``t`` of its length from its lower-numbered
    end (not at its middle), so the new triangles are thin but not degenerate.
    Its vertices lie near the unit sphere, so the central projection is fold-free
    and nearly conformal, while a map held near a poor start is far from it: a
    test of whether a map is as conformal as the mesh allows.

    Parameters
    ----------
    level : int
        Icosphere level before the split (:func:`icosphere`).
    t : float
        Where each edge is split, in ``(0, 1)``.

    Returns
    -------
    V : (10 * 4**(level+1) + 2, 3) float64 array
    F : (20 * 4**(level+1), 3) int64 array
        Outward oriented.
    """
    V, F = icosphere(level)
    n, m = V.shape[0], F.shape[0]
    E = np.sort(np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    uE, inv = np.unique(E, axis=0, return_inverse=True)
    inv = inv.ravel()
    P = (1.0 - t) * V[uE[:, 0]] + t * V[uE[:, 1]]
    ab, bc, ca = n + inv[:m], n + inv[m:2 * m], n + inv[2 * m:]
    a, b, c = F.T
    F4 = np.vstack([np.column_stack([a, ab, ca]), np.column_stack([ab, b, bc]),
                    np.column_stack([ca, bc, c]), np.column_stack([ab, bc, ca])])
    return np.vstack([V, P]), np.ascontiguousarray(F4, dtype=np.int64)
