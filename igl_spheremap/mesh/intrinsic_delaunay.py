"""The intrinsic Delaunay cotangent Laplacian: libigl's, or the same edge flips with bounded
work on meshes with slivers (where libigl's flips can loop until memory runs out)."""

import math

import igl
import numpy as np

from ..errors import MeshError, plural
from .mollify import mollified_edge_lengths, triangle_slack

NEEDLE_RTOL = 1e-2
"""Shortest / longest edge of a face below which libigl's intrinsic Delaunay flips are not used."""
CAP_RTOL = 1e-10
"""Relative triangle-inequality slack of a face below which they are not used either."""

SLACK_RTOL = 8 * np.finfo(np.float64).eps
"""A triangle is degenerate when ``min(l_i + l_j - l_k)`` is at most this times its longest edge."""


def intrinsic_delaunay_cotmatrix(V, F):
    """Cotangent Laplacian of the intrinsic Delaunay retriangulation of ``(V, F)``.

    ``igl.intrinsic_delaunay_cotmatrix`` unless a face is a sliver
    (:func:`sliver_statistics` below :data:`NEEDLE_RTOL` or :data:`CAP_RTOL`);
    then :func:`bounded_intrinsic_delaunay_cotmatrix_of_lengths`, the same flips
    with bounded work (identical wherever libigl ends; a flip that would make a
    degenerate triangle is skipped, so a few weights may stay negative).  Where a
    face is a cap of zero area (its lengths meet the triangle inequality within
    :data:`SLACK_RTOL`: a vertex on the opposite edge, as STL exports close
    T-junctions), no cotangent of it is finite, and the flips run on the
    intrinsically mollified lengths (:func:`igl_spheremap.mesh.mollify.mollified_edge_lengths`,
    Sharp and Crane 2020) instead.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array

    Returns
    -------
    L : (n, n) scipy.sparse matrix of float64
        Symmetric negative semidefinite; rows sum to zero.

    Raises
    ------
    MeshError
        ``problem="slivers"``: the flip limit of
        :func:`bounded_intrinsic_delaunay_cotmatrix` reached.
    """
    F = np.asarray(F, dtype=np.int64)
    l = igl.edge_lengths(np.asarray(V, dtype=np.float64), F)
    if _degenerate(l).any():  # caps of zero area: the flips of the mollified metric
        l = mollified_edge_lengths(V, F)[0]
        return bounded_intrinsic_delaunay_cotmatrix_of_lengths(l, F)[0]
    if _has_slivers(l):
        return bounded_intrinsic_delaunay_cotmatrix_of_lengths(l, F)[0]
    return igl.intrinsic_delaunay_cotmatrix(V, F)[0]


def intrinsic_operators(l, F, n):
    """Intrinsic Delaunay cotangent Laplacian and vertex areas of a metric given by edge lengths.

    libigl's ``intrinsic_delaunay_triangulation`` and ``cotmatrix_intrinsic``, or
    the bounded flips when a face is a sliver (as :func:`intrinsic_delaunay_cotmatrix`).

    Parameters
    ----------
    l : (m, 3) float64 array
        Edge lengths, column ``c`` opposite corner ``c`` (``igl.edge_lengths`` order).
    F : (m, 3) int64 array
    n : int
        Number of vertices.

    Returns
    -------
    L : (n, n) scipy.sparse.csr_matrix
    area : (n,) float64 array
        Barycentric vertex areas of the metric (``igl.massmatrix_intrinsic``).

    Raises
    ------
    MeshError
        Degenerate lengths or the flip limit (from the bounded flips).
    """
    if _has_slivers(l):
        L = bounded_intrinsic_delaunay_cotmatrix_of_lengths(l, F)[0]
    else:
        ld, Fd = igl.intrinsic_delaunay_triangulation(l, F)[:2]
        L = igl.cotmatrix_intrinsic(ld, Fd)
    M = igl.massmatrix_intrinsic(l, F, igl.MASSMATRIX_TYPE_BARYCENTRIC)
    area = np.zeros(n)
    area[: M.shape[0]] = M.diagonal()
    return L.tocsr(), area


def sliver_statistics(V, F):
    """Per face: shortest / longest edge, and the relative slack of the triangle inequality.

    From the edge lengths ``igl.intrinsic_delaunay_cotmatrix`` starts from
    (``igl.edge_lengths(V, F)``).  A flip computes the new edge's length by the
    law of cosines from the quad's long sides, with relative error
    ``~ eps / edge_ratio**2`` where the new edge is short; libigl's flips break
    down (NaN lengths, endless flips) once that exceeds the slack of a new
    triangle (needles: small edge ratio), or when an input triangle's own slack
    is at rounding level (caps).  The thresholds :data:`NEEDLE_RTOL` and
    :data:`CAP_RTOL` are chosen in ``docs/decisions.md``.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array

    Returns
    -------
    edge_ratio : (m,) float64 array
        ``min(l) / max(l)`` per face, in ``[0, 1]``.
    slack : (m,) float64 array
        ``min_k (l_i + l_j - l_k) / max(l)`` per face, in ``[0, 1]``; <= 0 when
        the lengths violate or meet the triangle inequality.
    """
    return _ratio_and_slack(igl.edge_lengths(np.asarray(V, dtype=np.float64),
                                             np.asarray(F, dtype=np.int64)))


def _ratio_and_slack(l):
    lo = np.minimum(np.minimum(l[:, 0], l[:, 1]), l[:, 2])
    hi = np.maximum(np.maximum(l[:, 0], l[:, 1]), l[:, 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        return lo / hi, triangle_slack(l) / hi


def _degenerate(l):
    """Per face: its lengths meet the triangle inequality within :data:`SLACK_RTOL` (a cap of
    zero intrinsic area, on which no cotangent is finite)."""
    return ~(triangle_slack(l) > SLACK_RTOL * l.max(axis=1))


def _has_slivers(l):
    edge_ratio, slack = _ratio_and_slack(l)
    return bool(edge_ratio.min() < NEEDLE_RTOL or slack.min() < CAP_RTOL)


def _valid(a, b, c):
    """Triangle inequality with a margin that keeps every tan_half_angle of libigl finite."""
    return min(a + b - c, b + c - a, c + a - b) > SLACK_RTOL * max(a, b, c)


def _tan_half(a, b, c):
    """libigl's tan_half_angle: tan of half the angle opposite ``a`` (same operations)."""
    return math.sqrt(((a - b + c) * (a + b - c)) / ((a + b + c) * (-a + b + c)))


def _cot(a, b, c):
    t = _tan_half(a, b, c)
    return (1.0 - t * t) / (2 * t)


def bounded_intrinsic_delaunay_cotmatrix(V, F, max_flips=None):
    """``igl.intrinsic_delaunay_cotmatrix(V, F)[0]`` with a flip limit and no NaN lengths.

    libigl 2.6.3's ``intrinsic_delaunay_triangulation`` computes a flipped edge's
    length by the law of cosines from the quad's two long sides, with error
    ``~ eps * l_max**2 / l_new``.  Next to needles that can exceed the slack of
    a new triangle's triangle inequality; ``tan_half_angle`` is then NaN, the
    Delaunay test ``w >= 0`` fails for NaN forever, and its flip stack grows by
    three entries per flip until memory runs out.  This is the same
    algorithm, operation for operation (same lengths, same flip order, so the
    same matrix bit for bit wherever libigl terminates with finite lengths),
    except that a flip whose new triangles would violate the triangle
    inequality (margin :data:`SLACK_RTOL`) is skipped (that edge keeps a
    negative weight), and at most ``max_flips`` flips are made.  Pure Python,
    so slower than libigl (``benchmarks/sliver_statistic.py``).

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
    max_flips : int, optional
        Default ``10 * (number of edges) + 1000``, far above the flips a mesh
        needs (``docs/decisions.md``).

    Returns
    -------
    L : (n, n) scipy.sparse.csc_matrix of float64
        As ``igl.cotmatrix_intrinsic`` of the flipped triangulation.
    skipped : int
        Flips skipped because they would have made a degenerate triangle.

    Raises
    ------
    MeshError
        ``problem="slivers"``: ``count`` faces whose edge lengths (as libigl
        computes them) are degenerate, or the flip limit was reached (``count``
        = flips).
    """
    F = np.asarray(F, dtype=np.int64)
    return bounded_intrinsic_delaunay_cotmatrix_of_lengths(
        igl.edge_lengths(np.asarray(V, dtype=np.float64), F), F, max_flips)


def bounded_intrinsic_delaunay_cotmatrix_of_lengths(l, F, max_flips=None):
    """:func:`bounded_intrinsic_delaunay_cotmatrix` of an intrinsic metric given by edge lengths.

    Parameters
    ----------
    l : (m, 3) float64 array
        Edge lengths, column ``c`` opposite corner ``c`` (``igl.edge_lengths`` order);
        the lengths of an edge agree in its two faces.
    F : (m, 3) int64 array
    max_flips : int, optional

    Returns, Raises
        As :func:`bounded_intrinsic_delaunay_cotmatrix`.
    """
    F = np.asarray(F, dtype=np.int64)
    l = np.asarray(l, dtype=np.float64)
    bad = _degenerate(l)
    if bad.any():
        k = int(np.count_nonzero(bad))
        raise MeshError.invalid("slivers", k, (
            f"{plural(k, 'face')} whose edge lengths meet "
            f"the triangle inequality within rounding (first: face {np.flatnonzero(bad)[0]}): "
            "caps of zero intrinsic area; collapse or remesh them (e.g. pymeshfix)."))
    _, uE, EMAP, uEC, uEE = igl.unique_edge_map(F)
    m, ne = F.shape[0], uE.shape[0]
    max_flips = 10 * ne + 1000 if max_flips is None else max_flips
    L, Fl, emap, uee, uec = l.tolist(), F.tolist(), EMAP.tolist(), uEE.tolist(), uEC.tolist()
    ue2e = [uee[uec[i]:uec[i + 1]] for i in range(ne)]
    Q, flips, skipped = list(range(ne)), 0, 0
    while Q:
        ue = Q.pop()
        if len(ue2e[ue]) != 2:
            continue
        h1, h2 = ue2e[ue]
        f1, c1, f2, c2 = h1 % m, h1 // m, h2 % m, h2 // m
        e, a, b = L[f1][c1], L[f1][(c1 + 1) % 3], L[f1][(c1 + 2) % 3]
        c, d = L[f2][(c2 + 1) % 3], L[f2][(c2 + 2) % 3]
        if _cot(e, a, b) + _cot(e, c, d) >= 0:  # libigl's is_intrinsic_delaunay
            continue
        ta, td = _tan_half(a, b, e), _tan_half(d, e, c)
        try:
            tad = (ta + td) / (1.0 - ta * td)
            f = math.sqrt(b * b + c * c - 2.0 * b * c * ((1.0 - tad * tad) / (1.0 + tad * tad)))
        except (ZeroDivisionError, ValueError):  # angle sum exactly pi, or rounding below 0
            f = math.nan
        if not (_valid(f, b, c) and _valid(f, d, a)):
            skipped += 1
            continue
        if flips == max_flips:
            raise MeshError.invalid("slivers", flips, (
                f"the intrinsic Delaunay edge flips did not end within "
                f"{plural(flips, 'flip')}; collapse the short edges or remesh, or use "
                "laplacian_kind=\"cotan\"."))
        flips += 1
        _flip(Fl, L, emap, ue2e, m, ue, (h1, h2, f1, c1, f2, c2), (f, b, c, d, a), Q)
    return igl.cotmatrix_intrinsic(np.array(L), np.array(Fl, dtype=np.int64)), skipped


def _flip(Fl, L, emap, ue2e, m, ue, he, lengths, Q):
    """libigl's flip_edge plus the length update of intrinsic_delaunay_triangulation."""
    h1, h2, f1, c1, f2, c2 = he
    f, b, c, d, a = lengths
    v1, v2, v4, v3 = Fl[f1][(c1 + 1) % 3], Fl[f1][(c1 + 2) % 3], Fl[f1][c1], Fl[f2][c2]
    e24, e41 = f1 + ((c1 + 1) % 3) * m, f1 + ((c1 + 2) % 3) * m
    e13, e32 = f2 + ((c2 + 1) % 3) * m, f2 + ((c2 + 2) % 3) * m
    u24, u41, u13, u32 = emap[e24], emap[e41], emap[e13], emap[e32]
    L[f1], L[f2] = [f, b, c], [f, d, a]
    Fl[f1], Fl[f2] = [v1, v3, v4], [v2, v4, v3]
    emap[f1] = emap[f2] = ue
    emap[f1 + m], emap[f1 + 2 * m], emap[f2 + m], emap[f2 + 2 * m] = u41, u13, u32, u24
    for u, old, new in ((ue, h1, f1), (ue, h2, f2), (u13, e13, f1 + 2 * m),
                        (u32, e32, f2 + m), (u24, e24, f2 + 2 * m), (u41, e41, f1 + m)):
        hs = ue2e[u]
        hs[hs.index(old)] = new
    Q += [u24, u41, u13, u32]
