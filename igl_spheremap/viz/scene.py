"""The polyscope structures that show one stage."""

import numpy as np

from ..operators import vertex_areas
from .layout import _facing_rotation, _fold_rings, _layout
from .stages import _phi_shape
from .style import (_COLUMN_X, _INPUT_COLOR, _NAMES, _PHI_COLOR, _RED, _SPHERE_COLOR, _TURN)

def _face_colors(folded, base):
    C = np.tile(base, (folded.size, 1))
    C[folded] = _RED
    return C


def _dots(ps, name, S, shift, F, folded, radius):
    """Red dots at the folded faces' centroids, pushed out onto the unit sphere ``S``."""
    pts = S[F[folded]].mean(axis=1) if folded.any() else np.zeros((0, 3))
    r = np.linalg.norm(pts, axis=1, keepdims=True)
    pts = np.where(r > 1e-9, pts / np.maximum(r, 1e-300), pts) + shift
    pc = ps.register_point_cloud(name, pts, color=_RED, radius=radius, enabled=True)
    pc.set_radius(radius, relative=False)
    return pts


def register_stage(stage, layout=None):
    """Register (or update) the polyscope structures showing one stage.

    Polyscope must be initialized.  Structures keep fixed names, so calling this
    again with another stage replaces the previous one in place.

    Parameters
    ----------
    stage : dict
        One entry of :func:`build_stages`.
    layout : dict, optional
        From a previous call (computed from ``stage["V"]`` when omitted).

    Returns
    -------
    registered : dict
        What was drawn: ``layout``, ``face_folded`` (m,) bool (the mask given to the
        face quantity "folded" of the input and both sphere views), ``dots`` (k, 3)
        red dots on the front sphere view (folded faces' centroids pushed onto the
        sphere), ``phi_spread`` (radius standard deviation / mean of ``Phi^u``, 0 for
        a round sphere; None without ``Phi``).
    """
    import polyscope as ps

    V, F = stage["V"], stage["F"]
    if layout is None:
        layout = _layout(V)
    R = layout["R"]
    x = _COLUMN_X
    folded = np.asarray(stage["folded"], dtype=bool)
    S = stage["U"] @ R.T
    S = S @ _facing_rotation(S, F, folded).T
    views = {
        "input": layout["input"] + [x[0], 0, 0],
        "front": S + [x[1], 0, 0],
        "back": S @ _TURN.T + [x[2], 0, 0],
        "u": layout["input"] + [x[3], 0, 0],
    }
    for key, P in views.items():
        _register_view(ps, key, P, F, folded, stage["u"])
    _register_outline(ps)
    radius = 0.018
    dots = _dots(ps, _NAMES["dots_front"], S, [x[1], 0, 0], F, folded, radius)
    _dots(ps, _NAMES["dots_back"], S @ _TURN.T, [x[2], 0, 0], F, folded, radius)
    _register_fold_rings(ps, S, F, folded)
    spread = _register_phi(ps, stage, R)
    return dict(layout=layout, face_folded=folded, dots=dots, phi_spread=spread)


_COLORS = dict(input=_INPUT_COLOR, front=_SPHERE_COLOR, back=_SPHERE_COLOR)


def _register_view(ps, key, P, F, folded, u):
    """One surface column: folded faces in red, or (key "u") the log conformal factor."""
    name = _NAMES[key]
    if ps.has_surface_mesh(name):
        m = ps.get_surface_mesh(name)
        m.update_vertex_positions(P)
    else:
        m = ps.register_surface_mesh(name, P, F, smooth_shade=False, material="clay")
        if key in ("front", "back"):
            m.set_edge_width(0.6)
            m.set_edge_color((0.35, 0.42, 0.52))
        if key in _COLORS:
            m.set_color(_COLORS[key])
            m.set_back_face_policy("identical")
    if key in _COLORS:
        m.add_color_quantity("folded faces (red)", _face_colors(folded, _COLORS[key]),
                             defined_on="faces", enabled=True)
        m.add_scalar_quantity("folded", folded.astype(np.float64), defined_on="faces",
                              datatype="categorical")
        return
    a = float(np.percentile(np.abs(u - np.median(u)), 98)) or 1.0
    m.add_scalar_quantity("u (log conformal factor)", u, defined_on="vertices",
                          cmap="coolwarm", vminmax=(np.median(u) - a, np.median(u) + a),
                          enabled=True)
    m.add_scalar_quantity("e^{2u}", np.exp(2 * u), defined_on="vertices")


def _register_outline(ps):
    """Grey circles behind both sphere views (the unit sphere's outline)."""
    if ps.has_curve_network(_NAMES["outline"]):
        return
    x = _COLUMN_X
    t = np.linspace(0, 2 * np.pi, 128, endpoint=False)
    ring = 1.03 * np.stack([np.cos(t), np.sin(t), np.zeros_like(t)], 1)
    nodes = np.vstack([ring + [x[1], 0, 0], ring + [x[2], 0, 0]])
    e = np.stack([np.arange(128), (np.arange(128) + 1) % 128], 1)
    cn = ps.register_curve_network(_NAMES["outline"], nodes, np.vstack([e, e + 128]),
                                   color=(0.6, 0.6, 0.6), enabled=True)
    cn.set_radius(0.004, relative=False)


def _register_fold_rings(ps, S, F, folded):
    nodes, edges = _fold_rings(S, F, folded)
    for key, Rot in (("rings_front", np.eye(3)), ("rings_back", _TURN)):
        shift = [_COLUMN_X[1] if key == "rings_front" else _COLUMN_X[2], 0, 0]
        if nodes.shape[0]:
            cn = ps.register_curve_network(_NAMES[key], nodes @ Rot.T + shift, edges,
                                           color=_RED, enabled=True)
            cn.set_radius(0.014, relative=False)
        elif ps.has_curve_network(_NAMES[key]):
            ps.remove_curve_network(_NAMES[key])


def _register_phi(ps, stage, R):
    """The Phi^u column; returns its radius spread (None without Phi^u)."""
    name = _NAMES["phi"]
    if stage["Phi"] is None:
        if ps.has_surface_mesh(name):
            ps.get_surface_mesh(name).set_enabled(False)
        return None
    X, spread = _phi_shape(stage["Phi"], vertex_areas(stage["V"], stage["F"]))
    P = X @ R.T + [_COLUMN_X[4], 0, 0]
    if ps.has_surface_mesh(name):
        m = ps.get_surface_mesh(name)
        m.update_vertex_positions(P)
    else:
        m = ps.register_surface_mesh(name, P, stage["F"], color=_PHI_COLOR, smooth_shade=True,
                                     material="clay", back_face_policy="identical")
    r = np.linalg.norm(X, axis=1)
    m.add_scalar_quantity("radius - 1", r - 1.0, datatype="symmetric", cmap="coolwarm",
                          vminmax=(-0.5, 0.5))
    m.set_enabled(True)
    return spread
