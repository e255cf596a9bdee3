"""Where the registration view puts things, and its colours (no polyscope here).

Two rows, one per surface (surface 1 on top), four columns: the surface (surface
1 coloured by the distortion of its map onto surface 2, surface 2 by part), its
spherical map in part colours from the front and from behind, the surface
painted with surface 2's data.  Both spheres are turned by the same rotation,
so a point of the sphere sits at the same place in both rows.
"""

import numpy as np

from ..layout import stage_layout
from ..style import CHECKER_COLORS

SPACING = 2.7                                   # column centres, as in the stage view
COLUMN_X = SPACING * np.array([-1.5, -0.5, 0.5, 1.5])
ROW_Y = np.array([1.5, -1.5])
HALF_SIZE = (COLUMN_X[-1] + 1.4, 3.0)           # the scene box fitted into the window
WINDOW = (1800, 980)                            # screenshots
WINDOW_INTERACTIVE = (1700, 900)

#: Column headers of each row (surface 1, surface 2).
ROW_LABELS = (("surface 1: distortion onto surface 2",
               "its sphere at this stage, by part",
               "the same sphere from behind",
               "surface 1 painted with surface 2's data, carried"),
              ("surface 2, coloured by part",
               "its conformal map (the same turn)",
               "the same sphere from behind",
               "surface 2 with its data"))

#: Matplotlib colour map of a data field (purple-white-orange: no red).
DATA_CMAP = "PuOr_r"

#: Polyscope colour map and range of the per-triangle distortion of the map between the
#: surfaces (symmetric Dirichlet: 1 for an isometry; larger values are clipped).
DISTORTION_CMAP = "reds"
DISTORTION_RANGE = (1.0, 3.0)
TURN = np.diag([-1.0, 1.0, -1.0])


def landmark_colors(k):
    """``k`` distinct RGB colours for the landmark pairs (matplotlib's tab10/tab20 without red).

    Returns
    -------
    (k, 3) float64 array
        Row ``i`` is the colour of pair ``i`` on both surfaces and both spheres.
    """
    from matplotlib import colormaps

    tab10 = colormaps["tab10"].colors
    tab20 = colormaps["tab20"].colors
    base = [tab10[i] for i in (0, 1, 2, 4, 5, 6, 8, 9)]
    base += [tab20[i] for i in (1, 3, 5, 9, 11, 13, 17, 19)]
    reps = int(np.ceil(k / len(base))) if k else 0
    return np.asarray((base * max(reps, 1))[:k], dtype=np.float64).reshape(k, 3)


def sphere_turn(targets):
    """Rotation (3, 3) of both spheres: the landmarks' mean direction faces you, landmark 1 up.

    The rows are the screen axes (right, up, towards the viewer) in sphere
    coordinates, so ``U @ R.T`` is the map as drawn.  If the landmarks' mean
    direction is near 0, landmark 1 faces you instead.
    """
    Q = np.asarray(targets, dtype=np.float64)
    front = Q.mean(axis=0)
    if np.linalg.norm(front) < 0.05:
        front = Q[0]
    front = front / np.linalg.norm(front)
    up = Q[0] - (Q[0] @ front) * front
    if np.linalg.norm(up) < 1e-6:
        up = np.cross(front, [1.0, 0, 0] if abs(front[0]) < 0.9 else [0, 1.0, 0])
    up /= np.linalg.norm(up)
    return np.stack([np.cross(up, front), up, front])


def registration_layout(pair, up=None):
    """Display frames of the two surfaces, their part colours, the spheres' turn, the colours.

    Parameters
    ----------
    pair : dict
        The ``pair`` entry of :func:`build_registration_stages`.
    up : int, optional
        Axis of the inputs drawn vertical (2 for FreeSurfer / GIfTI surfaces).

    Returns
    -------
    dict
        ``surfaces``: a list of two :func:`igl_spheremap.viz.layout.stage_layout`
        dicts (``input`` positions centred and scaled to width 2.2, ``parts``);
        ``turn`` (3, 3); ``colors`` (k, 3) landmark colours; ``data`` a dict
        with the colour map (``cmap`` name, ``vmin``, ``vmax``) of the data.
    """
    surfaces = [stage_layout(pair["V1"], pair["F1"], None, up),
                stage_layout(pair["V2"], pair["F2"], None, up)]
    return dict(surfaces=surfaces, turn=sphere_turn(pair["targets"]),
                colors=landmark_colors(len(pair["l1"])), data=data_range(pair))


def data_range(pair, pct=95.0):
    """Colour range of the data: 0..1 for the checkerboard; else symmetric about 0 for a field
    of both signs (``pct`` percentile of its magnitude: curvature has long tails at tips),
    the ``100 - pct`` to ``pct`` percentiles otherwise; values beyond are clipped."""
    x = pair["data2"]
    if pair["checker"]:
        return dict(cmap="checker", vmin=0.0, vmax=1.0)
    lo, hi = np.percentile(x, [100.0 - pct, pct])
    if lo < 0 < hi:
        m = float(np.percentile(np.abs(x), pct))
        lo, hi = -m, m
    if hi <= lo:
        lo, hi = lo - 0.5, hi + 0.5
    return dict(cmap=DATA_CMAP, vmin=float(lo), vmax=float(hi))


def colormap_rgb(data):
    """(256, 3) RGB of the data's colour map (two flat halves for the checkerboard)."""
    if data["cmap"] == "checker":
        return np.repeat(np.asarray(CHECKER_COLORS, dtype=np.float64), 128, axis=0)
    from matplotlib import colormaps

    return np.asarray(colormaps[data["cmap"]](np.linspace(0, 1, 256)))[:, :3]


def placed(stage, layout):
    """World positions of every drawn surface: ``{(row, column): (n, 3) array}``.

    Rows 0 (surface 1) and 1 (surface 2); columns 0 (parts), 1 (sphere front),
    2 (sphere back), 3 (data).
    """
    pair, R = stage["pair"], layout["turn"]
    out = {}
    for row, U in ((0, stage["U"]), (1, pair["U2"])):
        P = layout["surfaces"][row]["input"]
        S = U @ R.T
        for col, X in enumerate((P, S, S @ TURN.T, P)):
            out[row, col] = X + [COLUMN_X[col], ROW_Y[row], 0.0]
    return out


def marker_points(stage, layout, positions):
    """Landmark marker positions ``{(row, column): (k, 3)}``: on the surface, or just outside
    the sphere."""
    pair = stage["pair"]
    out = {}
    for row, lm in ((0, pair["l1"]), (1, pair["l2"])):
        for col in range(4):
            X = positions[row, col][lm]
            if col in (1, 2):
                c = np.array([COLUMN_X[col], ROW_Y[row], 0.0])
                X = (X - c) * 1.012 + c
            out[row, col] = X
    return out


def target_rings(stage, layout, radius=0.1, segments=40):
    """Rings round the targets and arcs from each landmark to its target on surface 1's sphere.

    Returns
    -------
    nodes : (p, 3) float64 array
        Unit-sphere points in the sphere's own frame (not turned, not placed).
    edges : (q, 2) int64 array
    pair_of_node : (p,) int64 array
        Which landmark pair each node belongs to (its colour).
    """
    Q, A = stage["pair"]["targets"], stage["U"][stage["pair"]["l1"]]
    t = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    nodes, edges, owner = [], [], []
    for i, (q, a) in enumerate(zip(Q, A)):
        e1 = np.cross(q, [1.0, 0, 0] if abs(q[0]) < 0.9 else [0, 1.0, 0])
        e1 /= np.linalg.norm(e1)
        ring = np.cos(radius) * q + np.sin(radius) * (np.outer(np.cos(t), e1)
                                                       + np.outer(np.sin(t), np.cross(q, e1)))
        s = np.linspace(0.0, 1.0, 12)[:, None]
        arc = (1 - s) * a + s * q
        arc /= np.maximum(np.linalg.norm(arc, axis=1, keepdims=True), 1e-12)
        base = sum(len(n) for n in nodes)
        nodes += [ring, arc]
        edges += [base + np.stack([np.arange(segments), (np.arange(segments) + 1) % segments], 1),
                  base + segments + np.stack([np.arange(11), np.arange(1, 12)], 1)]
        owner.append(np.full(segments + 12, i))
    return (np.vstack(nodes) * 1.006, np.vstack(edges).astype(np.int64),
            np.concatenate(owner).astype(np.int64))
