"""Polyscope view of Algorithm 2, stage by stage (the folding-removal demo).

``import igl_spheremap`` does not import this module, and this module imports
polyscope (and matplotlib, for the contact sheet) only inside the functions
that draw, so the core package works without a display or OpenGL.

A *stage* is one spherical map produced while :func:`spherical_conformal_map`
runs: the Gauss map, the map after Algorithm 1, then for each folding-removal
round ``k`` the star map and the map after Algorithm 1 again.  For each stage
the view shows, in one row (left to right):

1. the input surface with the faces that are folded in this stage's map in red,
2. the spherical image, folded faces in red, turned so that the folded faces
   face the viewer (no turn once nothing is folded),
3. the same spherical image turned by 180 degrees (its far side); a grey circle
   outlines the unit sphere behind both views,
4. the input surface coloured by the log conformal factor ``u`` (paper Fig. 3,
   third row; ``u = 0.5 log e^{2u}``, Eq. 14),
5. the weighted Laplace-Beltrami eigenfunctions ``Phi^u = (phi_1, phi_2, phi_3)``
   drawn as a surface scaled to unit size (paper Fig. 9, right column):
   an ellipsoid while the conformal factor is wrong, a round sphere once the
   map is conformal and folding free.

Folded image triangles are often tiny slivers, so on the sphere every folded
face is also marked by a red dot (its centroid pushed onto the sphere), and
small clusters of folded faces are circled in red.
"""

import os

import numpy as np

from .metrics import angle_distortion, conformal_factor, folded_faces, harmonic_energy
from .operators import SPHERE_AREA, laplacian, vertex_areas

__all__ = ["build_stages", "register_stage", "show", "StageView", "contact_sheet",
           "COLUMN_LABELS", "HEADLESS_PACKAGES"]

#: Debian/Ubuntu packages that give polyscope a headless OpenGL (Mesa EGL) backend.
HEADLESS_PACKAGES = ("libegl1", "libegl-mesa0", "libgl1-mesa-dri", "libgl1", "libglx-mesa0",
                     "libx11-6")

#: Titles of the five columns of a stage view, left to right.
COLUMN_LABELS = ("input surface, folded faces red", "spherical image, folds facing you",
                 "spherical image, far side", "input coloured by u (log conformal factor)",
                 "Φ^u = (φ1, φ2, φ3), centred, unit size")

_SPACING = 2.7          # distance between column centres (objects have radius ~1)
_COLUMN_X = _SPACING * np.arange(-2, 3)
_WINDOW = (2000, 440)            # screenshots
_WINDOW_INTERACTIVE = (1700, 800)
_LENGTH_SCALE = 16.0
_RED = np.array([0.86, 0.08, 0.08])
_INPUT_COLOR = np.array([0.80, 0.78, 0.72])
_SPHERE_COLOR = np.array([0.62, 0.74, 0.88])
_PHI_COLOR = np.array([0.93, 0.70, 0.40])
_TURN = np.diag([-1.0, 1.0, -1.0])   # 180 degrees about the screen's vertical axis

_NAMES = dict(input="input: folded faces", front="sphere (front)", back="sphere (back)",
              u="input: conformal factor u", phi="Phi^u (unit size)",
              dots_front="folded faces (front)", rings_front="fold clusters (front)",
              rings_back="fold clusters (back)", outline="unit sphere outline",
              dots_back="folded faces (back)")


# --------------------------------------------------------------------------- stages

def _stage(name, index, kind, mesh, L, U, nit, Phi, phi_note, eigenvalues):
    V, F = mesh.V, mesh.F
    folded = folded_faces(F, U)
    e2u = conformal_factor(V, F, U)
    u = 0.5 * np.log(np.maximum(e2u, 1e-300))
    with np.errstate(invalid="ignore"):
        ang = float(np.nanmean(angle_distortion(V, F, U)))
    return dict(name=name, round=index, kind=kind, V=V, F=F, U=U, folded=folded,
                folds=int(np.count_nonzero(folded)), nit=nit,
                energy_over_4pi=harmonic_energy(V, F, U, L) / SPHERE_AREA,
                mean_angle_distortion_deg=ang, u=u, Phi=Phi, phi_note=phi_note,
                eigenvalues=eigenvalues, extra=[])


def build_stages(result, *, final_phi=True):
    """The maps of a :func:`spherical_conformal_map` run as a list of display stages.

    Parameters
    ----------
    result : SphericalMapResult
        The run's result; its validated mesh (``result.mesh``) is what is drawn.
    final_phi : bool
        Also solve the weighted eigenproblem for the last map so the last stage
        can show its ``Phi^u`` (one extra sparse eigensolve).

    Returns
    -------
    stages : list of dict
        In order "Gauss map", "after Algorithm 1", then for each round ``k >= 1``
        "star map k" (or "untangled map k" for a local repair round), "after
        Algorithm 1, round k".  Keys:

        ``name`` (str), ``round`` (int), ``kind`` ("gauss", "star", "local" or "alg1"),
        ``V``, ``F`` the validated mesh (``result.mesh``),
        ``U`` (k, 3) float64 map on the validated vertices,
        ``folded`` (m,) bool mask from :func:`igl_spheremap.folded_faces`,
        ``folds`` (int), ``nit`` (Algorithm 1 iterations, None for initial maps),
        ``energy_over_4pi`` (harmonic energy with the run's Laplacian / 4 pi; 1 for a
        conformal bijection), ``mean_angle_distortion_deg`` (mean over corners of
        :func:`igl_spheremap.angle_distortion`, degrees), ``u`` (k,) float64 log
        conformal factor, ``Phi`` (k, 3) float64 or None, ``phi_note`` (str),
        ``eigenvalues`` (3,) or None, ``extra`` (list of str: further notes for the panel).

    Raises
    ------
    ValueError
        If the result carries no rounds.
    """
    mesh, rounds = result.mesh, result.rounds
    if not rounds:
        raise ValueError("the result has no rounds to show")
    ours = mesh.from_input
    L = laplacian(mesh.V, mesh.F, result.options.laplacian_kind)
    stages = []
    for k, rnd in enumerate(rounds):
        if k == 0:
            stages.append(_stage("Gauss map", 0, "gauss", mesh, L, ours(rnd.U_init), None, None,
                                 "", None))
        elif rnd.kind == "local":
            stages.append(_stage(f"untangled map {k}", k, "local", mesh, L, ours(rnd.U_init),
                                 None, None, "", None))
            stages[-1]["extra"].append(
                f"local repair of {rounds[k - 1].folds_after} folded faces; Algorithm 1 "
                f"then moves {rnd.region} vertices")
        else:
            stages.append(_stage(f"star map {k}", k, "star", mesh, L, ours(rnd.U_init), None,
                                 ours(rnd.Phi),
                                 f"Φ^u of the previous map (normalized: star map {k})",
                                 rnd.eigenvalues))
            raw = getattr(rnd, "folds_star", None)
            if raw is not None and raw != stages[-1]["folds"]:
                stages[-1]["extra"].append(f"star map before local untangling: {raw} "
                                           "folded faces")
        if k + 1 < len(rounds):
            Phi, lam = rounds[k + 1].Phi, rounds[k + 1].eigenvalues
            Phi = None if Phi is None else ours(Phi)
            note = f"Φ^u of this map (gives star map {k + 1})"
        elif final_phi:
            Phi, lam = _final_phi(mesh, L, ours(rnd.U))
            note = "Φ^u of this map (final)" if Phi is not None else "eigensolver failed"
        else:
            Phi, lam, note = None, None, ""
        name = "after Algorithm 1" + (f", round {k}" if k else "")
        stages.append(_stage(name, k, "alg1", mesh, L, ours(rnd.U), rnd.nit, Phi, note, lam))
    return stages


def _final_phi(mesh, L, U):
    from .eigen_projection import star_map_of
    try:
        _, Phi, lam, _ = star_map_of(mesh.F, U, L, vertex_areas(mesh.V, mesh.F))
    except RuntimeError:
        return None, None
    return Phi, lam


def _phi_shape(Phi, area):
    """Centre ``Phi`` like the star map does; scale it to unit largest radius.

    Returns the scaled points and the radius spread: area-weighted standard
    deviation / mean of ``|Phi - c|`` (0 for a round sphere).
    """
    c = (area @ Phi) / area.sum()
    X = Phi - c
    r = np.linalg.norm(X, axis=1)
    mean_r = float(area @ r / area.sum())
    spread = float(np.sqrt(area @ (r - mean_r) ** 2 / area.sum()) / mean_r)
    return X / float(r.max()), spread


# --------------------------------------------------------------------------- layout

def _display_frame(V):
    """Rotation taking the input to the screen frame: long axis horizontal, thin axis to the viewer.

    The vertical axis stays ``y`` unless ``y`` is the thinnest extent.
    """
    ext = np.ptp(V, axis=0)
    depth = int(np.argmin(ext))
    up = 1 if depth != 1 else int(np.argsort(ext)[1])
    horiz = 3 - depth - up
    R = np.zeros((3, 3))
    R[0, horiz] = R[1, up] = R[2, depth] = 1.0
    if np.linalg.det(R) < 0:
        R[2] *= -1.0
    return R


def _layout(V):
    R = _display_frame(V)
    P = V @ R.T
    lo, hi = P.min(0), P.max(0)
    scale = 2.2 / float(np.max(hi - lo))
    return dict(R=R, input=(P - 0.5 * (lo + hi)) * scale)


# --------------------------------------------------------------------------- polyscope

def _facing_rotation(S, F, folded):
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


def _fold_rings(S, F, folded, *, max_rings=12, segments=48):
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
    colors = dict(input=_INPUT_COLOR, front=_SPHERE_COLOR, back=_SPHERE_COLOR)
    for key, P in views.items():
        name = _NAMES[key]
        if ps.has_surface_mesh(name):
            m = ps.get_surface_mesh(name)
            m.update_vertex_positions(P)
        else:
            m = ps.register_surface_mesh(name, P, F, smooth_shade=False, material="clay")
            if key in ("front", "back"):
                m.set_edge_width(0.6)
                m.set_edge_color((0.35, 0.42, 0.52))
            if key in colors:
                m.set_color(colors[key])
                m.set_back_face_policy("identical")
        if key in colors:
            m.add_color_quantity("folded faces (red)", _face_colors(folded, colors[key]),
                                 defined_on="faces", enabled=True)
            m.add_scalar_quantity("folded", folded.astype(np.float64), defined_on="faces",
                                  datatype="categorical")
        else:
            u = stage["u"]
            a = float(np.percentile(np.abs(u - np.median(u)), 98)) or 1.0
            m.add_scalar_quantity("u (log conformal factor)", u, defined_on="vertices",
                                  cmap="coolwarm", vminmax=(np.median(u) - a, np.median(u) + a),
                                  enabled=True)
            m.add_scalar_quantity("e^{2u}", np.exp(2 * u), defined_on="vertices")
    if not ps.has_curve_network(_NAMES["outline"]):
        t = np.linspace(0, 2 * np.pi, 128, endpoint=False)
        ring = 1.03 * np.stack([np.cos(t), np.sin(t), np.zeros_like(t)], 1)
        nodes = np.vstack([ring + [x[1], 0, 0], ring + [x[2], 0, 0]])
        e = np.stack([np.arange(128), (np.arange(128) + 1) % 128], 1)
        cn = ps.register_curve_network(_NAMES["outline"], nodes, np.vstack([e, e + 128]),
                                       color=(0.6, 0.6, 0.6), enabled=True)
        cn.set_radius(0.004, relative=False)
    radius = 0.018
    dots = _dots(ps, _NAMES["dots_front"], S, [x[1], 0, 0], F, folded, radius)
    _dots(ps, _NAMES["dots_back"], S @ _TURN.T, [x[2], 0, 0], F, folded, radius)
    nodes, edges = _fold_rings(S, F, folded)
    for key, Rot in (("rings_front", np.eye(3)), ("rings_back", _TURN)):
        shift = [x[1] if key == "rings_front" else x[2], 0, 0]
        if nodes.shape[0]:
            cn = ps.register_curve_network(_NAMES[key], nodes @ Rot.T + shift, edges,
                                           color=_RED, enabled=True)
            cn.set_radius(0.014, relative=False)
        elif ps.has_curve_network(_NAMES[key]):
            ps.remove_curve_network(_NAMES[key])
    spread = None
    name = _NAMES["phi"]
    if stage["Phi"] is not None:
        X, spread = _phi_shape(stage["Phi"], vertex_areas(V, F))
        P = X @ R.T + [x[4], 0, 0]
        if ps.has_surface_mesh(name):
            m = ps.get_surface_mesh(name)
            m.update_vertex_positions(P)
        else:
            m = ps.register_surface_mesh(name, P, F, color=_PHI_COLOR, smooth_shade=True,
                                         material="clay", back_face_policy="identical")
        r = np.linalg.norm(X, axis=1)
        m.add_scalar_quantity("radius - 1", r - 1.0, datatype="symmetric", cmap="coolwarm",
                              vminmax=(-0.5, 0.5))
        m.set_enabled(True)
    elif ps.has_surface_mesh(name):
        ps.get_surface_mesh(name).set_enabled(False)
    return dict(layout=layout, face_folded=folded, dots=dots, phi_spread=spread)


def _look(ps, window_size, left_px=0, center_from_top=0.5):
    """Orthographic front view framing the five columns.

    The row is fitted into the window minus ``left_px`` pixels on the left
    (polyscope's own panels in a window), with its centre at the fraction
    ``center_from_top`` of the height.  Polyscope's orthographic half-height is
    ``2 * length_scale * tan(fov / 2)``.
    """
    w, h = window_size
    half_w = _COLUMN_X[-1] + 1.4
    px_per_unit = min((w - left_px) / (2 * half_w), h / (2 * 1.45))
    half_h = 0.5 * h / px_per_unit
    dx = -(0.5 * left_px) / px_per_unit
    dy = (center_from_top - 0.5) * h / px_per_unit
    ps.set_view_projection_mode("orthographic")
    ps.set_vertical_fov_degrees(float(np.degrees(2 * np.arctan(half_h / (2 * _LENGTH_SCALE)))))
    ps.look_at((dx, dy, 12.0), (dx, dy, 0.0))


def _stage_lines(stage, phi_spread=None):
    nit = "-" if stage["nit"] is None else str(stage["nit"])
    lines = [f"folded faces: {stage['folds']} of {stage['folded'].size}",
             f"Algorithm 1 iterations: {nit}",
             f"harmonic energy / 4π: {stage['energy_over_4pi']:.4f}",
             f"mean angle distortion: {stage['mean_angle_distortion_deg']:.2f}°"]
    lines += stage["extra"]
    if stage["Phi"] is not None:
        lines.append(stage["phi_note"])
        if phi_spread is not None:
            lines.append(f"  radius spread (std/mean): {phi_spread:.4f}")
        if stage["eigenvalues"] is not None:
            lines.append("  eigenvalues (2 on a round sphere): "
                         + ", ".join(f"{v:.4g}" for v in stage["eigenvalues"]))
    return lines


class StageView:
    """State of the stage viewer: which stage is shown, and the polyscope user callback.

    Attributes
    ----------
    stages : list of dict
        From :func:`build_stages`.
    index : int
        The stage on screen.
    registered : dict
        What :func:`register_stage` drew for it.
    screenshots : list of str
        PNG per stage (screenshot mode only).
    contact_sheet : str or None
        The contact sheet PNG (screenshot mode only).
    """

    def __init__(self, stages):
        self.stages = stages
        self.index = 0
        self.layout = _layout(stages[0]["V"])
        self.registered = None
        self.screenshots = []
        self.contact_sheet = None
        self.frames = 0

    def set_stage(self, i):
        """Show stage ``i`` (clipped to the valid range)."""
        self.index = int(np.clip(i, 0, len(self.stages) - 1))
        self.registered = register_stage(self.stages[self.index], self.layout)
        return self.registered

    def lines(self):
        """The per-stage numbers shown in the UI panel, as text lines."""
        return _stage_lines(self.stages[self.index], self.registered["phi_spread"])

    def callback(self):
        """Polyscope user callback (imgui panel); runs inside a polyscope frame."""
        import polyscope.imgui as psim

        self.frames += 1
        n = len(self.stages)
        changed, i = psim.SliderInt("stage", self.index + 1, v_min=1, v_max=n)
        i -= 1
        if psim.Button("< previous"):
            changed, i = True, self.index - 1
        psim.SameLine()
        if psim.Button("next >"):
            changed, i = True, self.index + 1
        if changed and i != self.index and 0 <= i < n:
            self.set_stage(i)
        psim.Separator()
        psim.TextUnformatted(f"{self.index + 1}/{n}: {self.stages[self.index]['name']}")
        for line in self.lines():
            psim.TextUnformatted(line)
        psim.Separator()
        if psim.TreeNode("what the columns show"):
            for j, label in enumerate(COLUMN_LABELS):
                psim.TextUnformatted(f"{j + 1}. {label}")
            psim.TreePop()


def _init_polyscope(backend, headless):
    import polyscope as ps

    if ps.is_initialized():     # the caller's own structures stay; ours have fixed names
        return ps
    if headless:
        ps.set_allow_headless_backends(True)
        ps.set_verbosity(0)     # no GLFW-then-EGL fallback chatter; failures still raise
    ps.set_program_name("igl_spheremap: folding removal")
    ps.set_use_prefs_file(False)
    try:
        ps.init(backend or "auto")
    except RuntimeError as err:
        hint = (" No display? Render to files instead (show(..., screenshot_dir=DIR), "
                "demos/folding_removal.py --screenshots DIR).")
        if headless:
            hint = (" Headless rendering needs Mesa's EGL; on Debian/Ubuntu: apt-get install -y "
                    + " ".join(HEADLESS_PACKAGES) + ".")
        raise RuntimeError(f"polyscope could not initialize an OpenGL backend "
                           f"({backend or 'auto'}): {str(err).rstrip('.')}.{hint}") from err
    return ps


def _setup_scene(ps):
    ps.set_ground_plane_mode("none")
    ps.set_automatically_compute_scene_extents(False)
    ps.set_bounding_box((-8.0, -1.5, -1.5), (8.0, 1.5, 1.5))
    ps.set_length_scale(_LENGTH_SCALE)
    ps.set_SSAA_factor(2)


def show(result, *, screenshot_dir=None, interactive=True, backend=None, stages=None,
         window_size=None, sheet_width=2000):
    """Open the stage-by-stage view of a :func:`spherical_conformal_map` result.

    Parameters
    ----------
    result : SphericalMapResult
    screenshot_dir : str or path, optional
        Render headless (polyscope's Mesa EGL backend when there is no display):
        one PNG per stage ``stage_XX.png`` and ``contact_sheet.png`` in this
        directory, then return without opening a window.
    interactive : bool
        Without ``screenshot_dir``: enter polyscope's main loop (blocks until the
        window is closed).  ``False`` registers everything, runs a single frame
        (so the user callback runs once) and returns with the callback still
        installed, for scripts that drive ``polyscope.frame_tick()`` themselves.
    backend : str, optional
        Polyscope backend ("openGL3_glfw", "openGL3_egl", "openGL_mock"); default auto.
    stages : list of dict, optional
        Precomputed :func:`build_stages` output.
    window_size : (int, int), optional
        Pixels; default 2000 x 440 for screenshots, 1700 x 800 for a window.
    sheet_width : int
        Width in pixels of ``contact_sheet.png`` (screenshot mode).

    Returns
    -------
    StageView
        ``.screenshots`` and ``.contact_sheet`` hold the PNG paths in screenshot mode.

    Raises
    ------
    RuntimeError
        If polyscope cannot create an OpenGL context; in screenshot mode the
        message lists the Debian packages that provide headless EGL.
    """
    stage_list = build_stages(result) if stages is None else stages
    ps = _init_polyscope(backend, headless=screenshot_dir is not None)
    if window_size is None:
        window_size = _WINDOW if screenshot_dir is not None else _WINDOW_INTERACTIVE
    ps.set_window_size(*window_size)
    _setup_scene(ps)
    view = StageView(stage_list)
    view.set_stage(len(stage_list) - 1 if screenshot_dir is None else 0)
    if screenshot_dir is None:
        _look(ps, window_size, left_px=330, center_from_top=0.66)
    else:
        _look(ps, window_size)
    ps.set_user_callback(view.callback)
    if screenshot_dir is not None:
        os.makedirs(screenshot_dir, exist_ok=True)
        for i in range(len(stage_list)):
            view.set_stage(i)
            path = os.path.join(os.fspath(screenshot_dir), f"stage_{i:02d}.png")
            ps.screenshot(path, transparent_bg=False)
            view.screenshots.append(path)
        view.contact_sheet = contact_sheet(view.screenshots, stage_list,
                                           os.path.join(os.fspath(screenshot_dir),
                                                        "contact_sheet.png"),
                                           width_px=sheet_width)
        ps.clear_user_callback()
    elif interactive:
        ps.show()
        ps.clear_user_callback()
    else:
        ps.frame_tick()     # the stage panel stays installed for the caller's own frame_tick()s
    return view


def contact_sheet(paths, stages, out_path, *, title=None, width_px=2000):
    """Stack the stage screenshots into one annotated PNG (matplotlib, no pyplot).

    Parameters
    ----------
    paths : list of str
        One screenshot per stage, as written by :func:`show`.
    stages : list of dict
        The matching :func:`build_stages` entries (for the captions).
    out_path : str
    title : str, optional
    width_px : int
        Width of the PNG in pixels (the height follows from the number of stages).

    Returns
    -------
    str
        ``out_path``.
    """
    from matplotlib.figure import Figure
    from matplotlib.image import imread

    imgs = [imread(p) for p in paths]
    h, w = imgs[0].shape[:2]
    fig_w = 16.0
    row_h = fig_w * h / w
    cap_h = 0.55
    top = 0.45 + (0.35 if title else 0.0)
    fig_h = top + len(imgs) * (row_h + cap_h)
    fig = Figure(figsize=(fig_w, fig_h), dpi=width_px / fig_w)  # leaves pyplot's backend alone
    if title:
        fig.text(0.5, 1 - 0.3 / fig_h, title, ha="center", va="center", fontsize=14)
    for j, label in enumerate(COLUMN_LABELS):
        fig.text((0.5 + j) / 5, 1 - (top - 0.2) / fig_h, label, ha="center", va="center",
                 fontsize=10, color="0.25")
    for i, (img, st) in enumerate(zip(imgs, stages)):
        y0 = fig_h - top - (i + 1) * (row_h + cap_h)
        ax = fig.add_axes((0, y0 / fig_h, 1, row_h / fig_h))
        ax.imshow(img)
        ax.set_axis_off()
        nit = "" if st["nit"] is None else f", {st['nit']} iterations"
        cap = (f"{i + 1}. {st['name']}: {st['folds']} folded faces{nit}, "
               f"E/4π = {st['energy_over_4pi']:.3f}, "
               f"mean angle distortion {st['mean_angle_distortion_deg']:.1f}°")
        if st["Phi"] is not None:
            _, spread = _phi_shape(st["Phi"], vertex_areas(st["V"], st["F"]))
            cap += f"; Φ^u radius spread {spread:.3f}"
        color = "#b00000" if st["folds"] else "#006400"
        fig.text(0.01, (y0 + row_h + 0.5 * cap_h) / fig_h, cap, ha="left", va="center",
                 fontsize=11, color=color, weight="bold")
    fig.savefig(out_path, facecolor="white")
    return out_path
