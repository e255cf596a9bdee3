"""The registration viewer (a slider over the stages) and :func:`show_registration`."""

import os

import numpy as np

from ..layout import look
from .layout import (HALF_SIZE, ROW_LABELS, WINDOW, WINDOW_INTERACTIVE,
                                  registration_layout)
from .scene import register_registration_stage
from .sheet import compose_registration_stage, registration_sheet
from ..stage_controls import stage_controls
from ..style import LENGTH_SCALE
from ..viewer import init_polyscope


def registration_lines(stage):
    """The per-stage numbers of the panel, as text lines."""
    pair = stage["pair"]
    errs = ", ".join(f"{e:.2f}" for e in stage["landmark_errors"])
    return [f"largest landmark error: {stage['max_error']:.4f}°",
            f"landmark errors (°, pairs 1-{len(errs.split(', '))}): {errs}",
            f"folded faces of surface 1's map: {stage['folds']} of {stage['folded'].size}",
            f"mean angle distortion: {stage['mean_angle_distortion_deg']:.2f}°",
            f"harmonic energy / 4π: {stage['energy_over_4pi']:.4f}",
            f"median distortion of the map onto surface 2: {stage['median_distortion']:.4f}",
            f"stage: {stage['note']}",
            f"data: {pair['data_name']}",
            f"result: {pair['message']}"]


class RegistrationView:
    """State of the registration viewer: the stage shown and the polyscope user callback.

    Attributes
    ----------
    stages : list of dict
        From :func:`build_registration_stages`.
    layout : dict
        From :func:`registration_layout`.
    index : int
    registered : dict
        What :func:`register_registration_stage` drew for the stage shown.
    screenshots, drawn : list
        Screenshot mode: the PNG of each stage and what was drawn for it.
    contact_sheet : str or None
    frames : int
        How many times the callback ran.
    """

    def __init__(self, stages, up=None):
        self.stages = stages
        self.layout = registration_layout(stages[0]["pair"], up)
        self.index = 0
        self.registered = None
        self.screenshots, self.drawn = [], []
        self.contact_sheet = None
        self.frames = 0

    def set_stage(self, i):
        """Show stage ``i`` (clipped to the valid range); returns what was drawn."""
        self.index = int(np.clip(i, 0, len(self.stages) - 1))
        self.registered = register_registration_stage(self.stages[self.index], self.layout)
        return self.registered

    def lines(self):
        return registration_lines(self.stages[self.index])

    def callback(self):
        """Polyscope user callback: slider, previous/next, the stage's numbers, the legend."""
        import polyscope.imgui as psim

        stage_controls(self)
        if psim.TreeNode("what the rows and columns show"):
            for row, labels in enumerate(ROW_LABELS):
                for j, label in enumerate(labels):
                    psim.TextUnformatted(f"row {row + 1}, column {j + 1}: {label}")
            psim.TextUnformatted("dots: landmark pairs, pair i in the same colour everywhere")
            psim.TextUnformatted("rings: the targets of surface 1's landmarks")
            psim.TreePop()


def _screenshots(ps, view, out_dir, window_size, sheet_width):
    import tempfile

    os.makedirs(out_dir, exist_ok=True)
    n = len(view.stages)
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(n):
            view.drawn.append(view.set_stage(i))
            raw = os.path.join(tmp, f"render_{i:02d}.png")
            ps.screenshot(raw, transparent_bg=False)
            path = os.path.join(out_dir, f"stage_{i:02d}.png")
            compose_registration_stage(raw, path, view.stages[i], view.drawn[-1], i, n,
                                       window_size)
            view.screenshots.append(path)
    view.contact_sheet = registration_sheet(view.screenshots,
                                            os.path.join(out_dir, "contact_sheet.png"),
                                            window_size, width_px=sheet_width)


def show_registration(stages, *, screenshot_dir=None, interactive=True, backend=None,
                      window_size=None, sheet_width=1800, up=None):
    """Open the stage-by-stage view of an inter-surface map, or render it to PNGs.

    Parameters
    ----------
    stages : list of dict
        From :func:`igl_spheremap.viz.registration.stages.build_registration_stages`.
    screenshot_dir : str or path, optional
        Render headless (Mesa EGL when there is no display): ``stage_XX.png`` per
        stage (title, column headers, legend) and ``contact_sheet.png`` (surface 1's
        row of every stage above surface 2's row,
        :func:`igl_spheremap.viz.registration.sheet.registration_sheet`); no window.
    interactive : bool
        Without ``screenshot_dir``: enter polyscope's main loop; ``False`` runs
        one frame and returns with the callback installed.
    backend : str, optional
        Polyscope backend ("openGL3_glfw", "openGL3_egl", "openGL_mock"); default auto.
    window_size : (int, int), optional
        Default 1800 x 980 for screenshots, 1700 x 900 for a window.
    sheet_width : int
        Width of ``contact_sheet.png`` in pixels.
    up : int, optional
        Axis of the surfaces drawn vertical (2 for FreeSurfer/GIfTI surfaces).

    Returns
    -------
    RegistrationView

    Raises
    ------
    ValueError
        If ``stages`` is empty or not stages of :func:`build_registration_stages`
        (e.g. :func:`igl_spheremap.viz.build_stages`' stages of a single map).
    RuntimeError
        If polyscope cannot create an OpenGL context (headless: the message
        lists the Debian packages of Mesa EGL).
    """
    stages = list(stages)
    if not stages:
        raise ValueError("stages is empty; pass build_registration_stages(result, V1, V2, l1, l2)")
    wrong = sum(not isinstance(st, dict) or "pair" not in st for st in stages)
    if wrong:
        raise ValueError(f"{wrong} of {len(stages)} stages are not stages of an inter-surface "
                         "map (no 'pair'); build them with build_registration_stages (a "
                         "single map's stages are shown by viz.show)")
    ps = init_polyscope(backend, headless=screenshot_dir is not None,
                         program_name="igl_spheremap: registration",
                         demo="demos/registration.py")
    if window_size is None:
        window_size = WINDOW if screenshot_dir is not None else WINDOW_INTERACTIVE
    ps.set_window_size(*window_size)
    ps.set_ground_plane_mode("none")
    ps.set_automatically_compute_scene_extents(False)
    ps.set_bounding_box((-HALF_SIZE[0], -HALF_SIZE[1], -1.5), (HALF_SIZE[0], HALF_SIZE[1], 1.5))
    ps.set_length_scale(LENGTH_SCALE)
    ps.set_SSAA_factor(2)
    view = RegistrationView(stages, up)
    view.set_stage(len(stages) - 1 if screenshot_dir is None else 0)
    if screenshot_dir is None:
        look(ps, window_size, left_px=330, center_from_top=0.55, half_size=HALF_SIZE)
    else:
        look(ps, window_size, half_size=HALF_SIZE)
    ps.set_user_callback(view.callback)
    if screenshot_dir is not None:
        _screenshots(ps, view, os.fspath(screenshot_dir), window_size, sheet_width)
        ps.clear_user_callback()
    elif interactive:
        ps.show()
        ps.clear_user_callback()
    else:
        ps.frame_tick()
    return view
