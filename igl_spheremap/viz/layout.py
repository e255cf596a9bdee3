"""Where things go on screen: the display frame of the input, the turn of the spheres, fold rings."""

import numpy as np

from ..mesh.arrays import as_points
from .fields import part_colors, tip_vertices
from .style import COLUMN_X, LENGTH_SCALE


def _display_frame(V, up=None):
    """Rotation taking the input to the screen frame: ``up`` vertical, thin axis to the viewer.

    Without ``up`` the vertical axis is ``y`` (the usual convention of OBJ/PLY
    models) unless ``y`` is the thinnest extent; then the middle one.  With
    ``up`` (0, 1 or 2; e.g. 2 for FreeSurfer and GIfTI surfaces, whose ``z`` is
    superior) that axis is vertical and the thinner of the other two points to
    the viewer.
    """
    ext = np.ptp(V, axis=0)
    if up is None:
        depth = int(np.argmin(ext))
        up = 1 if depth != 1 else int(np.argsort(ext)[1])
    else:
        others = [k for k in range(3) if k != up]
        depth = min(others, key=lambda k: ext[k])
    horiz = 3 - depth - up
    R = np.zeros((3, 3))
    R[0, horiz] = R[1, up] = R[2, depth] = 1.0
    if np.linalg.det(R) < 0:
        R[2] *= -1.0
    return R


def stage_layout(V, F, u=None, up=None):
    """Where the input goes on screen, its part colours, its tips and the checks' pole candidates.

    Parameters
    ----------
    V : (n, 3) float array
    F : (m, 3) int array
    u : (n,) float array, optional
        Log conformal factor of a map (the last one shown).  The tips marked
        on the input and the spheres are
        :func:`igl_spheremap.viz.fields.tip_vertices` of ``u`` (none without).
        They are also the candidate poles of the checkerboard chart
        (:func:`igl_spheremap.viz.fields.chart_poles`); without tips the vertex
        of smallest ``u``, without ``u`` the vertex farthest from the centroid.
    up : int, optional
        Axis of ``V`` drawn vertical (see :func:`_display_frame`).

    Returns
    -------
    dict
        ``R`` (3, 3) display rotation, ``input`` (n, 3) the input in the display
        frame centred and scaled to width 2.2, ``parts`` (n, 3) RGB part colours
        (:func:`igl_spheremap.viz.fields.part_colors`), ``tips`` (k,) int64,
        ``anchors`` (k >= 1,) int64 pole candidates.
    """
    R = _display_frame(V, up)
    P = V @ R.T
    lo, hi = P.min(0), P.max(0)
    scale = 2.2 / float(np.max(hi - lo))
    P = (P - 0.5 * (lo + hi)) * scale
    tips = np.zeros(0, np.int64) if u is None else tip_vertices(P, F, u)
    if tips.size:
        anchors = tips
    elif u is None:
        anchors = np.array([np.argmax(np.linalg.norm(V - V.mean(axis=0), axis=1))])
    else:
        anchors = np.array([np.argmin(u)])
    return dict(R=R, input=P, parts=part_colors(P), tips=tips, anchors=anchors)


def facing_rotation(S, F, folded):
    """Rotation turning the mean direction of the folded image faces towards the viewer (+z).

    Identity when nothing is folded or the folds are spread evenly over the sphere.
    """
    if not folded.any():
        return np.eye(3)
    d = S[F[folded]].mean(axis=1)
    d = d.sum(axis=0)
    n = np.linalg.norm(d)
    if n < 1e-9 * folded.sum():
        return np.eye(3)
    d = d / n
    z = np.array([0.0, 0.0, 1.0])
    c = float(d @ z)
    if c < -1 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])
    v = np.cross(d, z)
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + K + K @ K / (1.0 + c)


def fold_rings(S, F, folded, *, max_rings=12, segments=48):
    """Red circles around small clusters of folded faces on the unit sphere.

    Only when the folded faces cover less than 1% of the sphere (otherwise
    the red faces are visible by themselves).  Folded faces are grouped into
    clusters (faces sharing a vertex); each of the ``max_rings`` largest
    clusters whose image fits in a cap of angular radius 0.3 gets a circle a bit
    wider than the cap, so folds crushed into a few pixels still stand out.

    Returns
    -------
    nodes : (p, 3) float64 array
    edges : (q, 2) int64 array
    """
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    idx = np.flatnonzero(folded)
    Ff = F[idx]
    area = 0.5 * np.linalg.norm(np.cross(S[Ff[:, 1]] - S[Ff[:, 0]], S[Ff[:, 2]] - S[Ff[:, 0]]),
                                axis=1).sum()
    if idx.size == 0 or area > 0.01 * 4 * np.pi:
        return np.zeros((0, 3)), np.zeros((0, 2), np.int64)
    A = sp.csr_matrix((np.ones(Ff.size), (np.repeat(np.arange(idx.size), 3), Ff.ravel())),
                      shape=(idx.size, S.shape[0]))
    _, label = connected_components(A @ A.T, directed=False)
    sizes = np.bincount(label)
    nodes, edges = [], []
    t = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    for c in np.argsort(-sizes)[:max_rings]:
        verts = np.unique(Ff[label == c])
        d = S[verts].sum(axis=0)
        if np.linalg.norm(d) < 1e-12:
            continue
        d /= np.linalg.norm(d)
        rho = float(np.arccos(np.clip(S[verts] @ d, -1, 1)).max())
        if rho > 0.3:
            continue
        theta = 1.3 * rho + 0.1
        e1 = np.cross(d, [1.0, 0, 0] if abs(d[0]) < 0.9 else [0, 1.0, 0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(d, e1)
        ring = (np.cos(theta) * d + np.sin(theta) * (np.outer(np.cos(t), e1)
                                                      + np.outer(np.sin(t), e2))) * 1.004
        base = len(nodes) * segments
        nodes.append(ring)
        edges.append(base + np.stack([np.arange(segments), (np.arange(segments) + 1) % segments], 1))
    if not nodes:
        return np.zeros((0, 3)), np.zeros((0, 2), np.int64)
    return np.vstack(nodes), np.vstack(edges)



def _camera(window_size, left_px=0, center_from_top=0.5, half_size=None):
    """Scale and centre of the orthographic front view: (pixels per unit, dx, dy).

    The scene's box of half width and half height ``half_size`` (default: the
    row of five columns, ``(COLUMN_X[-1] + 1.4, 1.45)``) centred on the origin
    is fitted into the window minus ``left_px`` pixels on the left (polyscope's
    own panels in a window), with its centre at the fraction
    ``center_from_top`` of the height; ``(dx, dy)`` is the scene point at the
    window's centre.
    """
    w, h = window_size
    half_w, half_h = (COLUMN_X[-1] + 1.4, 1.45) if half_size is None else half_size
    px_per_unit = min((w - left_px) / (2 * half_w), h / (2 * half_h))
    dx = -(0.5 * left_px) / px_per_unit
    dy = (center_from_top - 0.5) * h / px_per_unit
    return px_per_unit, dx, dy


def look(ps, window_size, left_px=0, center_from_top=0.5, half_size=None):
    """Set polyscope's camera to the orthographic front view of :func:`_camera`.

    Polyscope's orthographic half-height is ``2 * length_scale * tan(fov / 2)``.
    """
    px_per_unit, dx, dy = _camera(window_size, left_px, center_from_top, half_size)
    half_h = 0.5 * window_size[1] / px_per_unit
    ps.set_view_projection_mode("orthographic")
    ps.set_vertical_fov_degrees(float(np.degrees(2 * np.arctan(half_h / (2 * LENGTH_SCALE)))))
    ps.look_at((dx, dy, 12.0), (dx, dy, 0.0))


def project(points, window_size, left_px=0, center_from_top=0.5, half_size=None):
    """Pixel positions of scene points in a screenshot taken with :func:`look`.

    Parameters
    ----------
    points : (k, 3) float array
        Scene (world) positions, e.g. ``register_stage(...)["positions"]["front"]``.
    window_size : (int, int)
        Width and height in pixels.
    left_px, center_from_top, half_size
        As given to :func:`look` (``half_size``: the scene box fitted into the
        window, default the five-column row of the folding demo).

    Returns
    -------
    (k, 2) float64 array
        Column and row (from the top-left corner) of each point, in pixels.

    Raises
    ------
    ValueError
        ``points`` is not (k, 3) or has rows with NaN or infinite values (their count).
    """
    P = as_points(points, "points")
    px_per_unit, dx, dy = _camera(window_size, left_px, center_from_top, half_size)
    w, h = window_size
    return np.column_stack([0.5 * w + (P[:, 0] - dx) * px_per_unit,
                            0.5 * h - (P[:, 1] - dy) * px_per_unit])
