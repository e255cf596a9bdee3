"""A mesh metric compressed along the direction a conformal map crowds in (issue #15).

A conformal map crowds thin and elongated parts exponentially (a tube of length
/ circumference ``M`` spans a length ratio of ~``exp(2 pi M)``).  Compressing the
metric of each crowded face by a factor ``K_f >= 1`` along the gradient of the
log conformal factor (the direction in which the map shrinks) and mapping that
metric conformally gives, for the input metric, a quasi-conformal map with
dilatation ``K_f`` on those faces and conformal elsewhere: angle distortion traded
for room where the float32 margin needs it
(:func:`igl_spheremap.compressed_metric_map.compressed_metric_map`).
"""

import igl
import numpy as np

from .bounded_intrinsic_delaunay import bounded_intrinsic_delaunay_cotmatrix_of_lengths
from .metrics import conformal_factor
from .operators import CAP_RTOL, NEEDLE_RTOL, to_sphere_area


def compressed_lengths(V, F, direction, K):
    """Edge lengths of the metric compressed by ``1 / K_f`` along ``direction[f]`` in each face.

    In face ``f`` the metric is ``g - (1 - 1 / K_f^2) d d^T`` (``d`` a unit vector in
    the face plane), a valid metric on that face.  An edge's lengths in its two
    faces differ slightly and are averaged; then faces left (nearly) degenerate
    get their two shorter edges lengthened until ``l_max <= (l_a + l_b) / 1.01``.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
    direction : (m, 3) float64 array
        Unit vectors in the face planes (zero rows: no compression).
    K : (m,) float64 array
        Compression factors, >= 1.

    Returns
    -------
    (m, 3) float64 array
        Edge lengths, column ``c`` opposite corner ``c`` (``igl.edge_lengths`` order).
    """
    E = np.stack([V[F[:, 2]] - V[F[:, 1]], V[F[:, 0]] - V[F[:, 2]],
                  V[F[:, 1]] - V[F[:, 0]]], axis=1)  # (m, 3 edges, 3)
    proj = np.einsum("mek,mk->me", E, direction)
    l2 = np.einsum("mek,mek->me", E, E) - (1.0 - 1.0 / K[:, None] ** 2) * proj ** 2
    _, uE, EMAP = igl.unique_edge_map(F)[:3]
    m, ne = F.shape[0], uE.shape[0]
    flat = np.sqrt(np.maximum(l2, 0.0)).T.ravel()  # half-edge f + m * c (libigl's order)
    lu = np.bincount(EMAP, weights=flat, minlength=ne) / np.bincount(EMAP, minlength=ne)
    return _fatten(lu, EMAP.reshape(3, m).T)


def _fatten(lu, emap, slack=1e-2, passes=20):
    """Lengthen the two shorter edges of faces that violate ``l_max <= (l_a + l_b) / (1 + slack)``.

    Edges are shared, so this repeats (each edge takes the largest demand of its
    faces).  libigl's intrinsic Delaunay flips fail on nearly degenerate faces.
    """
    rows = np.arange(emap.shape[0])[:, None]
    for _ in range(passes):
        lf = lu[emap]
        order = np.argsort(lf, axis=1)
        srt = lf[rows, order]
        bad = (1.0 + slack) * srt[:, 2] - srt[:, 0] - srt[:, 1] > 0
        if not bad.any():
            break
        scale = np.ones(emap.shape[0])
        scale[bad] = (1.0 + slack) * srt[bad, 2] / (srt[bad, 0] + srt[bad, 1])
        np.maximum.at(lu, emap[rows, order][:, :2].ravel(),
                      (srt[:, :2] * scale[:, None]).ravel())
    return lu[emap]


def operators_of_lengths(l, F, n):
    """Intrinsic Delaunay cotangent Laplacian and vertex areas of a metric given by edge lengths.

    libigl's ``intrinsic_delaunay_triangulation`` and ``cotmatrix_intrinsic``;
    with slivers (shortest / longest edge below :data:`igl_spheremap.operators.NEEDLE_RTOL`
    or triangle-inequality slack below ``CAP_RTOL``) the bounded flips of
    :mod:`igl_spheremap.bounded_intrinsic_delaunay`, as for the input mesh.

    Returns
    -------
    L : (n, n) scipy.sparse.csr_matrix
    area : (n,) float64 array
        Barycentric vertex areas (``igl.massmatrix_intrinsic``), scaled to ``4 pi``.

    Raises
    ------
    MeshError
        Degenerate lengths or the flip limit (from the bounded flips).
    """
    ratio = l.min(axis=1) / l.max(axis=1)
    slack = (l.sum(axis=1) - 2 * l.max(axis=1)) / l.max(axis=1)
    if ratio.min() < NEEDLE_RTOL or slack.min() < CAP_RTOL:
        L = bounded_intrinsic_delaunay_cotmatrix_of_lengths(l, F)[0]
    else:
        ld, Fd = igl.intrinsic_delaunay_triangulation(l, F)[:2]
        L = igl.cotmatrix_intrinsic(ld, Fd)
    M = igl.massmatrix_intrinsic(l, F, igl.MASSMATRIX_TYPE_BARYCENTRIC)
    area = np.zeros(n)
    area[: M.shape[0]] = M.diagonal()
    return L.tocsr(), to_sphere_area(area)


def crowding_direction(V, F, U):
    """Unit gradient of the log conformal factor in each face ((m, 3) float64; zero where flat).

    The direction in which the map ``U`` shrinks the mesh fastest
    (:func:`igl_spheremap.metrics.conformal_factor`, ``igl.grad``).
    """
    u = 0.5 * np.log(np.maximum(conformal_factor(V, F, U), 1e-300))
    m = F.shape[0]
    g = (igl.grad(V, F) @ u).reshape(3, m).T
    norm = np.linalg.norm(g, axis=1)
    out = np.zeros_like(g)
    ok = norm > 0
    out[ok] = g[ok] / norm[ok, None]
    return out


def smooth_faces(F, x, n, steps=2):
    """A per-face quantity averaged through the vertices ``steps`` times, never lowered."""
    cnt = np.maximum(np.bincount(F.ravel(), minlength=n), 1)
    for _ in range(steps):
        xv = np.bincount(F.ravel(), weights=np.repeat(x, 3), minlength=n) / cnt
        x = np.maximum(x, xv[F].mean(axis=1))
    return x
