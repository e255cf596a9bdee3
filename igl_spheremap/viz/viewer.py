"""The stage viewer (a slider over the stages) and :func:`show`, interactive or headless."""

import os

import numpy as np

from .layout import stage_layout, look
from .scene import register_stage
from .sheet import compose_stage, contact_sheet
from .stages import build_stages, check_result
from .stage_controls import stage_controls
from .style import (COLUMN_LABELS, HEADLESS_PACKAGES, LENGTH_SCALE, WINDOW,
                    WINDOW_INTERACTIVE)


def _stage_lines(stage, phi_spread=None, u_norm=None):
    nit = "-" if stage["nit"] is None else str(stage["nit"])
    lines = [f"folded faces: {stage['folds']} of {stage['folded'].size}",
             f"Algorithm 1 iterations: {nit}",
             f"harmonic energy / 4π: {stage['energy_over_4pi']:.4f}",
             f"mean angle distortion: {stage['mean_angle_distortion_deg']:.2f}°"]
    lines += stage["extra"]
    if u_norm is not None:
        lines.append(f"u colours: {u_norm.vmin:.2f} (purple) .. 0 (white) .. "
                     f"{u_norm.vmax:.2f} (green)")
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
    drawn : list of dict
        What :func:`register_stage` returned for each stage's screenshot
        (screenshot mode only), e.g. to find objects in the PNGs with
        :func:`igl_spheremap.viz.layout.project`.
    """

    def __init__(self, stages, up=None):
        self.stages = stages
        self.index = 0
        self.layout = stage_layout(stages[0]["V"], stages[0]["F"], stages[-1]["u"], up)
        self.registered = None
        self.screenshots = []
        self.contact_sheet = None
        self.drawn = []
        self.frames = 0

    def set_stage(self, i):
        """Show stage ``i`` (clipped to the valid range)."""
        self.index = int(np.clip(i, 0, len(self.stages) - 1))
        self.registered = register_stage(self.stages[self.index], self.layout)
        return self.registered

    def lines(self):
        """The per-stage numbers shown in the UI panel, as text lines."""
        reg = self.registered
        return _stage_lines(self.stages[self.index], reg["phi_spread"], reg["u_norm"])

    def callback(self):
        """Polyscope user callback (imgui panel); runs inside a polyscope frame."""
        import polyscope.imgui as psim

        stage_controls(self)
        if psim.TreeNode("what the columns show"):
            for j, label in enumerate(COLUMN_LABELS):
                psim.TextUnformatted(f"{j + 1}. {label}")
            psim.TextUnformatted("dots: the tips the final map shrinks most")
            psim.TreePop()


def init_polyscope(backend, headless, program_name="igl_spheremap: folding removal",
                    demo="demos/folding_removal.py"):
    import polyscope as ps

    if ps.is_initialized():     # the caller's own structures stay; ours have fixed names
        return ps
    if headless:
        ps.set_allow_headless_backends(True)
        ps.set_verbosity(0)     # no GLFW-then-EGL fallback chatter; failures still raise
    ps.set_program_name(program_name)
    ps.set_use_prefs_file(False)
    try:
        ps.init(backend or "auto")
    except RuntimeError as err:
        hint = (" No display? Render to files instead (show(..., screenshot_dir=DIR), "
                f"{demo} --screenshots DIR).")
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
    ps.set_length_scale(LENGTH_SCALE)
    ps.set_SSAA_factor(2)


def _screenshots(ps, view, out_dir, window_size, sheet_width):
    """Render every stage, annotate each PNG, then stack them into the contact sheet."""
    import tempfile

    os.makedirs(out_dir, exist_ok=True)
    n = len(view.stages)
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(n):
            registered = view.set_stage(i)
            view.drawn.append(registered)
            raw = os.path.join(tmp, f"render_{i:02d}.png")
            ps.screenshot(raw, transparent_bg=False)
            path = os.path.join(out_dir, f"stage_{i:02d}.png")
            compose_stage(raw, path, view.stages[i], registered, i, n, window_size)
            view.screenshots.append(path)
    view.contact_sheet = contact_sheet(view.screenshots, os.path.join(out_dir, "contact_sheet.png"),
                                       width_px=sheet_width)


def show(result, *, screenshot_dir=None, interactive=True, backend=None, stages=None,
         window_size=None, sheet_width=2000, up=None):
    """Open the stage-by-stage view of a :func:`spherical_conformal_map` result.

    Parameters
    ----------
    result : SphericalMapResult
    screenshot_dir : str or path, optional
        Render headless (polyscope's Mesa EGL backend when there is no display):
        one annotated PNG per stage ``stage_XX.png`` (title, column headers,
        colour bar of ``u``; :func:`igl_spheremap.viz.sheet.stage_png_boxes`
        says where) and ``contact_sheet.png`` (all stages stacked) in this
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
    up : int, optional
        Axis of the input drawn vertical (2 for FreeSurfer/GIfTI surfaces, whose
        ``z`` is superior); default ``y`` unless it is the thinnest extent.

    Returns
    -------
    StageView
        ``.screenshots`` and ``.contact_sheet`` hold the PNG paths in screenshot mode.

    Raises
    ------
    TypeError
        If ``result`` is not a :class:`igl_spheremap.SphericalMapResult` (as
        :func:`build_stages`).
    ValueError
        If ``stages`` is given but empty.
    RuntimeError
        If polyscope cannot create an OpenGL context; in screenshot mode the
        message lists the Debian packages that provide headless EGL.
    """
    if stages is None:
        stage_list = build_stages(result)
    else:
        check_result(result)
        stage_list = list(stages)
        if not stage_list:
            raise ValueError("stages is empty; pass build_stages(result) or leave it None")
    ps = init_polyscope(backend, headless=screenshot_dir is not None)
    if window_size is None:
        window_size = WINDOW if screenshot_dir is not None else WINDOW_INTERACTIVE
    ps.set_window_size(*window_size)
    _setup_scene(ps)
    view = StageView(stage_list, up)
    view.set_stage(len(stage_list) - 1 if screenshot_dir is None else 0)
    if screenshot_dir is None:
        look(ps, window_size, left_px=330, center_from_top=0.66)
    else:
        look(ps, window_size)
    ps.set_user_callback(view.callback)
    if screenshot_dir is not None:
        _screenshots(ps, view, os.fspath(screenshot_dir), window_size, sheet_width)
        ps.clear_user_callback()
    elif interactive:
        ps.show()
        ps.clear_user_callback()
    else:
        ps.frame_tick()     # the stage panel stays installed for the caller's own frame_tick()s
    return view
