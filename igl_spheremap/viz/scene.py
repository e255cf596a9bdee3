"""The polyscope structures that show one stage."""

import numpy as np

from ..mesh.operators import vertex_areas
from .fields import chart_poles, checker_size, face_colors, mercator_corners, u_colors
from .layout import facing_rotation, fold_rings, stage_layout
from .stages import phi_shape
from .style import CHECKER_COLORS, COLUMN_X, NAMES, RED, TURN


def _dots(ps, name, S, shift, F, folded, radius):
    """Red dots at the folded faces' centroids, pushed out onto the unit sphere ``S``."""
    pts = S[F[folded]].mean(axis=1) if folded.any() else np.zeros((0, 3))
    r = np.linalg.norm(pts, axis=1, keepdims=True)
    pts = np.where(r > 1e-9, pts / np.maximum(r, 1e-300), pts) + shift
    pc = ps.register_point_cloud(name, pts, color=RED, radius=radius, enabled=True)
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
        From :func:`igl_spheremap.viz.layout.stage_layout` (computed from ``stage["V"]``
        and ``stage["u"]`` when omitted).

    Returns
    -------
    registered : dict
        What was drawn: ``layout``; ``face_folded`` (m,) bool (the faces drawn red
        on the input and both sphere views); ``face_colors`` (m, 3) float64 (the
        colours of those three views); ``dots`` (k, 3) red dots on the front sphere
        view (folded faces' centroids pushed onto the sphere); ``positions``, a dict
        of the (n, 3) world positions of the five columns ("input", "front",
        "back", "checker", "u"); ``u_norm``, the matplotlib normalization of the
        u colours (its ``vmin``/``vmax`` are the colour bar's ends); ``phi_spread``
        (radius standard deviation / mean of ``Phi^u``, 0 for a round sphere;
        None without ``Phi``).
    """
    import polyscope as ps

    V, F = stage["V"], stage["F"]
    if layout is None:
        layout = stage_layout(V, F, stage["u"])
    x = COLUMN_X
    folded = np.asarray(stage["folded"], dtype=bool)
    S = stage["U"] @ layout["R"].T
    S = S @ facing_rotation(S, F, folded).T
    pos = {"input": layout["input"] + [x[0], 0, 0], "front": S + [x[1], 0, 0],
           "back": S @ TURN.T + [x[2], 0, 0], "checker": layout["input"] + [x[3], 0, 0],
           "u": layout["input"] + [x[4], 0, 0]}
    colors = face_colors(layout["parts"], F, folded)
    areas = vertex_areas(V, F)
    for key in ("input", "front", "back"):
        m = _mesh(ps, key, pos[key], F)
        m.add_color_quantity("parts (folded faces red)", colors, defined_on="faces",
                             enabled=True)
        m.add_scalar_quantity("folded", folded.astype(np.float64), defined_on="faces",
                              datatype="categorical")
    m = _mesh(ps, "checker", pos["checker"], F)
    chart = mercator_corners(stage["U"], F, *chart_poles(stage["U"], layout["anchors"]),
                             weights=areas)
    m.add_parameterization_quantity("Mercator checks", chart, defined_on="corners",
                                    coords_type="unit", viz_style="checker",
                                    checker_colors=CHECKER_COLORS,
                                    checker_size=checker_size(), enabled=True)
    m = _mesh(ps, "u", pos["u"], F)
    ucol, norm, _ = u_colors(stage["u"])
    m.add_color_quantity("u (log conformal factor)", ucol, defined_on="vertices", enabled=True)
    m.add_scalar_quantity("u", stage["u"], defined_on="vertices")
    _register_outline(ps)
    radius = 0.018
    dots = _dots(ps, NAMES["dots_front"], S, [x[1], 0, 0], F, folded, radius)
    _dots(ps, NAMES["dots_back"], S @ TURN.T, [x[2], 0, 0], F, folded, radius)
    _register_fold_rings(ps, S, F, folded)
    _register_tips(ps, pos, layout["tips"], layout["parts"])
    spread = None
    if stage["Phi"] is not None:
        spread = phi_shape(stage["Phi"], areas)[1]
    return dict(layout=layout, face_folded=folded, face_colors=colors, dots=dots,
                positions=pos, u_norm=norm, phi_spread=spread)


def _mesh(ps, key, P, F):
    """The surface mesh of column ``key``, registered or moved to ``P``."""
    name = NAMES[key]
    if ps.has_surface_mesh(name):
        m = ps.get_surface_mesh(name)
        m.update_vertex_positions(P)
        return m
    m = ps.register_surface_mesh(name, P, F, smooth_shade=True, material="clay",
                                 back_face_policy="identical")
    return m


def _register_outline(ps):
    """Grey circles behind both sphere views (the unit sphere's outline)."""
    if ps.has_curve_network(NAMES["outline"]):
        return
    x = COLUMN_X
    t = np.linspace(0, 2 * np.pi, 128, endpoint=False)
    ring = 1.03 * np.stack([np.cos(t), np.sin(t), np.zeros_like(t)], 1)
    nodes = np.vstack([ring + [x[1], 0, 0], ring + [x[2], 0, 0]])
    e = np.stack([np.arange(128), (np.arange(128) + 1) % 128], 1)
    cn = ps.register_curve_network(NAMES["outline"], nodes, np.vstack([e, e + 128]),
                                   color=(0.6, 0.6, 0.6), enabled=True)
    cn.set_radius(0.004, relative=False)


def _register_tips(ps, pos, tips, parts):
    """Tip markers: a dot in the tip's part colour, ringed in black, on the input and both spheres.

    On the spheres the markers sit just outside the unit sphere; with no tips
    any markers of an earlier call are removed.
    """
    for key, column in (("input", None), ("front", 1), ("back", 2)):
        X = pos[key][tips]
        if column is not None:
            c = np.array([COLUMN_X[column], 0.0, 0.0])
            X = (X - c) * 1.01 + c
        for suffix, P, color, radius in (("ring", X, None, 0.05),
                                         ("dot", X + [0, 0, 0.035], parts[tips], 0.037)):
            name = f"tips ({key}, {suffix})"
            if not len(tips):
                if ps.has_point_cloud(name):
                    ps.remove_point_cloud(name)
                continue
            pc = ps.register_point_cloud(name, P, radius=radius, color=(0.05, 0.05, 0.05),
                                         enabled=True)
            pc.set_radius(radius, relative=False)
            if color is not None:
                pc.add_color_quantity("part colour", color, enabled=True)


def _register_fold_rings(ps, S, F, folded):
    nodes, edges = fold_rings(S, F, folded)
    for key, Rot in (("rings_front", np.eye(3)), ("rings_back", TURN)):
        shift = [COLUMN_X[1] if key == "rings_front" else COLUMN_X[2], 0, 0]
        if nodes.shape[0]:
            cn = ps.register_curve_network(NAMES[key], nodes @ Rot.T + shift, edges,
                                           color=RED, enabled=True)
            cn.set_radius(0.014, relative=False)
        elif ps.has_curve_network(NAMES[key]):
            ps.remove_curve_network(NAMES[key])
