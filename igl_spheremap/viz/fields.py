"""What is painted on the surfaces: part colours, the Mercator checkerboard chart, the u colours.

No polyscope here; matplotlib only for the colour map of ``u``.
"""

import numpy as np

from ..mesh.arrays import (as_faces, as_points, as_weights, off_unit_sphere, vertex_indices,
                           vertex_values)
from .style import CHECKS_AROUND, MERCATOR_CLIP, PART_WHEEL, RED, U_CMAP


def part_colors(P, *, lighten=0.2, darken=0.35, core=0.25):
    """A smooth colour per vertex that tells the parts of the input apart.

    ``P`` is the input in its display frame (``x`` to the right along the long
    axis, ``y`` up, ``z`` towards the viewer).  The hue follows the direction of
    ``(x, y)`` from the centre of the bounding box (coordinates scaled to
    ``[-1, 1]``) round a colour wheel with no red in it, so that parts sticking
    out in different directions get different colours; on an animal seen from
    the side (head upper left, tail right) the head is gold, the chest pale,
    the front legs violet, the hind legs blue, the tail teal and the back
    green (stops in ``style.PART_WHEEL``).  Within ``core`` of the centre the
    colour fades to grey (the wheel's centre has no direction).  Points towards
    the viewer are lighter (by up to ``lighten``) and points away darker (by up
    to ``darken``), so near and far legs differ.  No colour is close to the red of folded faces.

    Parameters
    ----------
    P : (n, 3) float array
        Vertex positions in the display frame.
    lighten, darken : float
        Largest fraction towards white (nearest point) and towards black (farthest).
    core : float
        Radius, in scaled coordinates, of the grey centre.

    Returns
    -------
    (n, 3) float64 array
        RGB in ``[0, 1]``.

    Raises
    ------
    ValueError
        ``P`` is not (n, 3) with n >= 1, or has rows with NaN or infinite values (their count).
    """
    P = as_points(P, "P")
    if not P.shape[0]:
        raise ValueError("P has no rows; expected one point per vertex")
    lo, hi = P.min(axis=0), P.max(axis=0)
    t = 2.0 * (P - 0.5 * (lo + hi)) / np.where(hi > lo, hi - lo, 1.0)   # in [-1, 1]
    angle = np.degrees(np.arctan2(t[:, 1], t[:, 0])) % 360.0
    stops = np.array([a for a, _ in PART_WHEEL] + [PART_WHEEL[0][0] + 360.0])
    cols = np.array([c for _, c in PART_WHEEL] + [PART_WHEEL[0][1]])
    angle = np.where(angle < stops[0], angle + 360.0, angle)
    C = np.column_stack([np.interp(angle, stops, cols[:, k]) for k in range(3)])
    w = np.clip(np.hypot(t[:, 0], t[:, 1]) / core, 0.0, 1.0)[:, None]
    C = w * C + (1.0 - w) * 0.7
    z = t[:, 2:]
    C = np.where(z > 0, C + lighten * z * (1.0 - C), C * (1.0 + darken * z))
    return np.clip(C, 0.0, 1.0)


def face_colors(vertex_colors, F, folded):
    """Per-face colours: the mean of the face's vertex colours, folded faces red.

    Parameters
    ----------
    vertex_colors : (n, 3) float array
    F : (m, 3) int array
    folded : (m,) bool array

    Returns
    -------
    (m, 3) float64 array
    """
    C = np.asarray(vertex_colors, dtype=np.float64)[F].mean(axis=1)
    C[np.asarray(folded, dtype=bool)] = RED
    return C


def _stereographic(U, north):
    """Stereographic coordinate (complex) of the rows of ``U`` from the unit vector ``north``."""
    e3 = north / np.linalg.norm(north)
    a = np.array([1.0, 0, 0]) if abs(e3[0]) < 0.9 else np.array([0, 1.0, 0])
    e1 = np.cross(a, e3)
    e1 /= np.linalg.norm(e1)
    X = U @ np.stack([e1, np.cross(e3, e1), e3]).T
    with np.errstate(divide="ignore", invalid="ignore"):
        return (X[:, 0] + 1j * X[:, 1]) / (1.0 - X[:, 2])


def chart_poles(U, anchors, *, min_angle=np.radians(115.0)):
    """The poles of :func:`mercator_corners` for one map: ``(south, north or None)``.

    ``south`` is ``anchors[0]``; ``north`` the first later anchor whose image
    is at least ``min_angle`` (radians) from the image of ``south``, or None
    (then the antipode of ``south``'s image is the north pole).  Two poles close
    together would squeeze the rest of the sphere into a single check.

    Parameters
    ----------
    U : (n, 3) float array
    anchors : (k,) int array, k >= 1
        Candidate vertices, e.g. :func:`tip_vertices`, most wanted first.

    Returns
    -------
    (int, int or None)

    Raises
    ------
    ValueError
        ``anchors`` is empty or names a vertex ``U`` does not have.
    """
    anchors = vertex_indices(anchors, len(U), "anchors")
    if not anchors.size:
        raise ValueError("anchors is empty; chart_poles needs at least one vertex (the south "
                         "pole)")
    a = int(anchors[0])
    for b in anchors[1:]:
        if float(U[b] @ U[a]) <= np.cos(min_angle):
            return a, int(b)
    return a, None


def mercator_corners(U, F, south, north=None, *, weights=None, clip=MERCATOR_CLIP):
    """Conformal checkerboard coordinates of a spherical map, per face corner.

    With ``z`` the stereographic coordinate of the sphere from the image of
    vertex ``north`` (from the antipode of ``south``'s image when ``north`` is
    None) and ``w = z - z(south)``, the coordinates are ``(arg w, log |w|)``:
    Mercator's chart of the sphere after the Moebius transformation sending the
    images of ``south`` and ``north`` to the south and north poles (a plain
    rotation when ``north`` is None; ``log |w| = log cot(theta / 2)`` up to a
    constant, ``arg w`` the azimuth).  The chart is conformal (a complex
    logarithm of a Moebius map of the stereographic projection), so a
    checkerboard in these coordinates, pulled back to the input through the
    map ``U``, has square checks exactly where ``U`` is conformal.  Mercator
    rather than the bare stereographic projection: round each pole its checks
    form a log-polar target, whose checks shrink geometrically, so a thin limb
    that the map shrinks a lot and that ends at a pole still shows squares all
    along it, instead of one check or checks piling up without bound.

    ``arg w`` is unwrapped per face, so faces across the seam get continuous
    coordinates; with ``2 pi`` a whole number of check pairs
    (:func:`checker_size`) the seam is invisible.  A corner at a pole takes the
    mean ``arg w`` of the face's other corners.  ``log |w|`` is shifted so that
    its ``weights``-weighted median is 0 and clipped to ``[-clip, clip]``.

    Parameters
    ----------
    U : (n, 3) float array
        The map, unit rows.
    F : (m, 3) int array
    south : int
        Vertex whose image becomes the south pole (``log |w| = -clip``).
    north : int, optional
        Vertex whose image becomes the north pole (``log |w| = clip``); another
        vertex than ``south`` (see :func:`chart_poles`).
    weights : (n,) float array, optional
        E.g. vertex areas of the input (default: equal).
    clip : float

    Returns
    -------
    (3 m, 2) float64 array
        Corner coordinates in the order of ``F.ravel()`` (polyscope's corner order).

    Raises
    ------
    ValueError
        As :func:`mercator_vertices`, or ``F`` not (m, 3) indices of ``U``'s rows.
    """
    U = as_points(U, "U")
    F = as_faces(F, U.shape[0])
    angle, y, w = _mercator(U, south, north, weights, clip)
    at_pole = (F == south) | ~np.isfinite(w[F])
    P = angle[F]
    ref = np.take_along_axis(P, np.argmin(at_pole, axis=1)[:, None], axis=1)
    P = ref + (P - ref + np.pi) % (2 * np.pi) - np.pi
    r, c = np.nonzero(at_pole)
    n_other = 3 - at_pole[r].sum(axis=1)
    P[r, c] = np.where(at_pole[r], 0.0, P[r]).sum(axis=1) / np.maximum(n_other, 1)
    return np.column_stack([P.ravel(), y[F].ravel()])


def _mercator(U, south, north, weights, clip):
    """Per-vertex ``arg w`` (0 at the poles), ``log |w|`` (median-shifted, clipped) and ``w``;
    the arguments checked (see :func:`mercator_vertices`)."""
    U = as_points(U, "U")
    message = off_unit_sphere(U, "U")
    if message:
        raise ValueError(f"{message} (a spherical map has unit rows)")
    n = U.shape[0]
    south = int(vertex_indices([south], n, "south")[0])
    if north is not None:
        north = int(vertex_indices([north], n, "north")[0])
        if north == south:
            raise ValueError(f"north and south are the same vertex ({south}); the chart needs "
                             "two poles (north=None: the antipode of south's image)")
    if weights is not None:
        weights = as_weights(weights, n, "weights")
    z = _stereographic(U, -U[south] if north is None else U[north])
    if north is not None:
        z[north] = np.inf           # exactly, whatever rounding left in 1 - x3
    w = z - z[south]
    with np.errstate(divide="ignore", invalid="ignore"):
        y = np.log(np.abs(w))
    y = np.clip(np.nan_to_num(y - _weighted_median(y, weights), nan=clip, posinf=clip,
                              neginf=-clip), -clip, clip)
    return np.angle(np.where(np.isfinite(w), w, 0.0)), y, w


def mercator_vertices(U, south, north=None, *, weights=None, clip=MERCATOR_CLIP):
    """The chart of :func:`mercator_corners` per vertex: ``(arg w, log |w|)``, not unwrapped.

    Same poles, shift and clipping as :func:`mercator_corners`; ``arg w`` is in
    ``(-pi, pi]`` (0 at the poles), so per-vertex data computed from it must be
    periodic in ``arg w`` (e.g. a checkerboard with an even number of checks round).

    Parameters
    ----------
    U : (n, 3) float array
        The map, unit rows.
    south, north : int
        Vertices at the chart's poles (``north`` None: the antipode of ``south``'s image).
    weights : (n,) float array, optional
    clip : float

    Returns
    -------
    (n, 2) float64 array

    Raises
    ------
    ValueError
        ``U`` not (n, 3), rows with NaN or infinite values or off the unit sphere (their
        count), ``south``/``north`` not a vertex or the same vertex, ``weights`` of another
        length or with negative or non-finite values.
    """
    angle, y, _ = _mercator(U, south, north, weights, clip)
    return np.column_stack([angle, y])


def _weighted_median(y, weights):
    """Weighted median of the finite entries of ``y`` (equal weights when None)."""
    ok = np.isfinite(y)
    wts = np.ones(y.size) if weights is None else np.asarray(weights, dtype=np.float64)
    order = np.argsort(y[ok])
    cum = np.cumsum(wts[ok][order])
    return y[ok][order][np.searchsorted(cum, 0.5 * cum[-1])]


def tip_vertices(P, F, u, *, max_tips=8, radius=0.15, depth=1.0):
    """Tips of the input that the map shrinks most: where the head, tail and feet of an animal go.

    Candidates are the vertices where ``u`` is smallest within their 2-ring and
    at least ``depth`` below the median of ``u`` (lengths shrunk ``e^depth``
    times more than typical).  They are taken in increasing ``u``, skipping any
    closer than ``radius`` times the largest extent of ``P`` to a tip already
    taken (non-maximum suppression), up to ``max_tips``.

    Parameters
    ----------
    P : (n, 3) float array
        Input positions.
    F : (m, 3) int array
    u : (n,) float array
        Log conformal factor of the map.

    Returns
    -------
    (k,) int64 array
        Vertex indices, most shrunk first; ``k <= max_tips`` (0 for a map that
        shrinks nothing much).

    Raises
    ------
    ValueError
        ``P`` or ``F`` malformed, or ``u`` not one finite value per vertex (the count
        of NaN or infinite values).
    """
    import igl

    P = as_points(P, "P")
    F = as_faces(F, P.shape[0])
    u = vertex_values(u, P.shape[0], "u")
    A = igl.adjacency_matrix(F).tocsr()
    A = (A + A @ A).tocsr()
    lowest = np.minimum.reduceat(u[A.indices], A.indptr[:-1])
    cand = np.flatnonzero((u <= lowest) & (u <= np.median(u) - depth))
    cand = cand[np.argsort(u[cand], kind="stable")]
    r = radius * float(np.ptp(P, axis=0).max())
    tips = []
    for i in cand:
        if len(tips) == max_tips:
            break
        if all(np.linalg.norm(P[i] - P[j]) >= r for j in tips):
            tips.append(int(i))
    return np.asarray(tips, dtype=np.int64)


def checker_size():
    """Side of one check in Mercator units: ``2 pi / CHECKS_AROUND`` (an even count)."""
    return 2.0 * np.pi / CHECKS_AROUND


def u_colors(u, *, lo_pct=1.0, hi_pct=99.0):
    """Colours of the log conformal factor ``u``, white at ``u = 0`` (area kept).

    Two linear slopes meet at 0 (matplotlib ``TwoSlopeNorm``): the 1st percentile
    of ``u`` (or slightly below 0) is the darkest purple (shrunk on the sphere),
    the 99th (or slightly above 0) the darkest green (grown); values beyond are
    clipped.

    Parameters
    ----------
    u : (n,) float array

    Returns
    -------
    colors : (n, 3) float64 array
    norm : matplotlib.colors.Normalize
        The normalization used (for the colour bar).
    cmap : matplotlib.colors.Colormap

    Raises
    ------
    ValueError
        ``u`` is not a non-empty 1-D array, or has NaN or infinite values (their count).
    """
    from matplotlib import colormaps
    from matplotlib.colors import TwoSlopeNorm

    u = vertex_values(u, None, "u")
    lo = min(float(np.percentile(u, lo_pct)), -1e-3)
    hi = max(float(np.percentile(u, hi_pct)), 1e-3)
    norm = TwoSlopeNorm(vcenter=0.0, vmin=lo, vmax=hi)
    cmap = colormaps[U_CMAP]
    return np.asarray(cmap(norm(np.clip(u, lo, hi))))[:, :3], norm, cmap

