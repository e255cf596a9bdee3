"""The polyscope structures of one registration stage (two rows, four columns)."""

import os
import tempfile

import numpy as np

from ..fields import face_colors
from .layout import (COLUMN_X, DISTORTION_CMAP, DISTORTION_RANGE, ROW_Y, colormap_rgb,
                     marker_points, placed, target_rings)

_SURFACE = ("parts", "sphere front", "sphere back", "data")
_CMAPS = {}          # colour map -> its name in polyscope (loaded once per process)
_FACES = {}          # surface mesh name -> the faces registered under it


def structure_name(row, col):
    """Polyscope name of the surface drawn in ``(row, col)``."""
    return f"surface {row + 1}: {_SURFACE[col]}"


def marker_name(row, col, part):
    """Polyscope name of the landmark markers in ``(row, col)``; ``part`` "ring" or "dot"."""
    return f"landmarks {row + 1} ({_SURFACE[col]}, {part})"


def _colormap(ps, data):
    """Polyscope name of the data's colour map, loaded once per process from a 256 x 4 PNG."""
    key = data["cmap"]
    if key not in _CMAPS:
        from matplotlib.image import imsave

        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "cmap.png")
            imsave(path, np.repeat(colormap_rgb(data)[None], 4, axis=0))
            _CMAPS[key] = f"igl_spheremap {key}"
            ps.load_color_map(_CMAPS[key], path)
    return _CMAPS[key]


def _mesh(ps, name, P, F):
    """The surface mesh ``name``, moved to ``P``; registered anew for other faces."""
    if ps.has_surface_mesh(name):
        if np.array_equal(_FACES.get(name), F):
            m = ps.get_surface_mesh(name)
            m.update_vertex_positions(P)
            return m
        ps.remove_surface_mesh(name)
    _FACES[name] = np.array(F)
    return ps.register_surface_mesh(name, P, F, smooth_shade=True, material="clay",
                                    back_face_policy="identical")


def register_registration_stage(stage, layout):
    """Register (or update) the polyscope structures of one stage.

    Polyscope must be initialized.  Names are fixed, so another stage replaces
    this one in place.

    Parameters
    ----------
    stage : dict
        One entry of :func:`igl_spheremap.viz.registration.stages.build_registration_stages`.
    layout : dict
        From :func:`igl_spheremap.viz.registration.layout.registration_layout`.

    Returns
    -------
    dict
        ``positions`` ``{(row, col): (n, 3)}`` world positions of the eight
        surfaces; ``markers`` ``{(row, col): (k, 3)}`` landmark dots;
        ``marker_colors`` ``{(row, col): (k, 3)}`` their colours; ``face_colors``
        ``{row: (m, 3)}`` the part colours of each row's first three columns
        (folded faces red; surface 1's own column shows ``stage["distortion"]``
        instead, the parts a quantity to switch on); ``data_values`` ``{row: (n,)}`` the scalar drawn in
        column 3 (row 0: surface 2's data carried, ``stage["carried"]``; row 1:
        ``pair["data2"]``); ``data`` the colour range; ``rings`` the target
        rings' world nodes (by column); ``layout``; ``faces`` the two rows' faces.
    """
    import polyscope as ps

    pair = stage["pair"]
    pos = placed(stage, layout)
    cmap = _colormap(ps, layout["data"])
    data = layout["data"]
    faces = (pair["F1"], pair["F2"])
    folded = (stage["folded"], np.zeros(len(pair["F2"]), bool))
    values = {0: stage["carried"], 1: pair["data2"]}
    fcolors = {}
    for row in (0, 1):
        fcolors[row] = face_colors(layout["surfaces"][row]["parts"], faces[row], folded[row])
        for col in (0, 1, 2):
            m = _mesh(ps, structure_name(row, col), pos[row, col], faces[row])
            shown = not (row == 0 and col == 0)
            m.add_color_quantity("parts (folded faces red)", fcolors[row], defined_on="faces",
                                 enabled=shown)
            if not shown:  # surface 1: the distortion of the map onto surface 2
                m.add_scalar_quantity("distortion of the map onto surface 2",
                                      stage["distortion"], defined_on="faces",
                                      cmap=DISTORTION_CMAP, vminmax=DISTORTION_RANGE,
                                      enabled=True)
        m = _mesh(ps, structure_name(row, 3), pos[row, 3], faces[row])
        m.add_scalar_quantity("data", values[row], defined_on="vertices", cmap=cmap,
                              vminmax=(data["vmin"], data["vmax"]), enabled=True)
    markers = marker_points(stage, layout, pos)
    colors = {}
    for key, X in markers.items():
        colors[key] = _register_markers(ps, key, X, layout["colors"])
    rings = _register_rings(ps, stage, layout)
    _register_outlines(ps)
    return dict(positions=pos, markers=markers, marker_colors=colors, face_colors=fcolors,
                data_values=values, data=data, rings=rings, layout=layout, faces=faces)


#: Radius of a landmark's dot (scene units); its black ring is 1.35 times wider.
MARKER_RADIUS = 0.045


def _register_markers(ps, key, X, colors, radius=MARKER_RADIUS):
    """A dot in the pair's colour in front of a black ring, at each landmark."""
    for part, P, r in (("ring", X, radius * 1.35), ("dot", X + [0, 0, 0.035], radius)):
        pc = ps.register_point_cloud(marker_name(*key, part), P, radius=r,
                                     color=(0.05, 0.05, 0.05), enabled=True)
        pc.set_radius(r, relative=False)
        if part == "dot":
            pc.add_color_quantity("pair colour", colors, enabled=True)
    return colors


def _register_rings(ps, stage, layout):
    """Target rings and landmark-to-target arcs on surface 1's sphere, front and back."""
    nodes, edges, owner = target_rings(stage, layout)
    S = nodes @ layout["turn"].T
    out = {}
    for col, X in ((1, S), (2, S * [-1.0, 1.0, -1.0])):
        W = X + [COLUMN_X[col], ROW_Y[0], 0.0]
        cn = ps.register_curve_network(f"targets ({_SURFACE[col]})", W, edges,
                                       color=(0.1, 0.1, 0.1), enabled=True)
        cn.set_radius(0.012, relative=False)
        cn.add_color_quantity("pair colour", layout["colors"][owner], defined_on="nodes",
                              enabled=True)
        out[col] = W
    return out


def _register_outlines(ps):
    """Grey circles behind the four sphere views."""
    if ps.has_curve_network("sphere outlines"):
        return
    t = np.linspace(0, 2 * np.pi, 128, endpoint=False)
    ring = 1.03 * np.stack([np.cos(t), np.sin(t), np.zeros_like(t)], 1)
    e = np.stack([np.arange(128), (np.arange(128) + 1) % 128], 1)
    centres = [(COLUMN_X[c], ROW_Y[r], 0.0) for r in (0, 1) for c in (1, 2)]
    nodes = np.vstack([ring + c for c in centres])
    cn = ps.register_curve_network("sphere outlines", nodes,
                                   np.vstack([e + 128 * i for i in range(4)]),
                                   color=(0.6, 0.6, 0.6), enabled=True)
    cn.set_radius(0.004, relative=False)
