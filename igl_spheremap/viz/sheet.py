"""Annotated PNGs (matplotlib, no pyplot): one per stage, and the contact sheet of all stages.

A stage PNG is the polyscope screenshot, pixel for pixel, with a title band and
column headers above it and a band below it holding the legend of the tip
markers and the colour bar of ``u``; the tips are numbered on the input and on
the sphere views.  :func:`stage_png_boxes` says where each part is.
"""

import numpy as np

from ..errors import plural
from .layout import project
from .style import COLUMN_LABELS, U_CMAP

_TITLE_PX, _HEADER_PX, _FOOTER_PX = 44, 30, 84
_DPI = 100


def stage_png_boxes(window_size):
    """Where the parts of a stage PNG are, in pixels ``(top, bottom, left, right)``.

    Parameters
    ----------
    window_size : (int, int)
        The screenshot's width and height.

    Returns
    -------
    dict
        ``title``, ``headers``, ``render`` (the screenshot itself, unscaled),
        ``footer`` and ``colorbar`` (the colour bar of ``u``, under the fifth
        column), plus ``size`` (height, width) of the whole PNG.
    """
    w, h = window_size
    top = _TITLE_PX + _HEADER_PX
    col = w // 5
    return dict(title=(0, _TITLE_PX, 0, w), headers=(_TITLE_PX, top, 0, w),
                render=(top, top + h, 0, w), footer=(top + h, top + h + _FOOTER_PX, 0, w),
                colorbar=(top + h + 8, top + h + 26, 4 * col + col // 8, 5 * col - col // 8),
                size=(top + h + _FOOTER_PX, w))


def stage_title(stage, index, count):
    """One line: the stage's name, folds, iterations, energy and angle distortion."""
    nit = "" if stage["nit"] is None else ", " + plural(stage["nit"], "iteration")
    return (f"{index + 1}/{count}. {stage['name']}: {plural(stage['folds'], 'folded face')}{nit}, "
            f"E/4π = {stage['energy_over_4pi']:.3f}, "
            f"mean angle distortion {stage['mean_angle_distortion_deg']:.1f}°")


def compose_stage(render_path, out_path, stage, registered, index, count, window_size):
    """Write the annotated PNG of one stage around its polyscope screenshot.

    Parameters
    ----------
    render_path : str
        The polyscope screenshot (``window_size`` pixels).
    out_path : str
    stage : dict
        The :func:`build_stages` entry.
    registered : dict
        What :func:`register_stage` returned for it (positions, tips, u_norm).
    index, count : int
        Stage number (0-based) and number of stages, for the title.
    window_size : (int, int)

    Returns
    -------
    str
        ``out_path``.
    """
    from matplotlib.figure import Figure
    from matplotlib.image import imread

    img = imread(render_path)[..., :3]
    boxes = stage_png_boxes(window_size)
    H, W = boxes["size"]
    fig = Figure(figsize=(W / _DPI, H / _DPI), dpi=_DPI)
    fig.figimage(img, xo=0, yo=H - boxes["render"][1], origin="upper")

    def y(px):          # figure fraction of a pixel row counted from the top
        return 1.0 - px / H

    color = "#b00000" if stage["folds"] else "#006400"
    fig.text(0.006, y(_TITLE_PX / 2), stage_title(stage, index, count), ha="left",
             va="center", fontsize=15, weight="bold", color=color)
    for j, label in enumerate(COLUMN_LABELS):
        fig.text((j + 0.5) / 5, y(_TITLE_PX + _HEADER_PX / 2), label, ha="center",
                 va="center", fontsize=11, color="0.2")
    _number_tips(fig, registered, window_size, boxes["render"][0], H)
    _footer(fig, registered, boxes, H, W)
    fig.savefig(out_path, dpi=_DPI, facecolor="white")
    return out_path


def _number_tips(fig, registered, window_size, top, H):
    """Numbers next to the tip markers: on the input, and on the sphere views where they face you."""
    from matplotlib import patheffects

    tips = registered["layout"]["tips"]
    for key in ("input", "front", "back"):
        X = registered["positions"][key][tips]
        px = project(X, window_size)
        for k, (p, z) in enumerate(zip(px, X[:, 2])):
            if key != "input" and z < -0.02:     # on the far half of the sphere
                continue
            fig.text((p[0] + 9) / window_size[0], 1.0 - (top + p[1] - 9) / H, str(k + 1),
                     fontsize=11, weight="bold", color="black", ha="left", va="center",
                     path_effects=[patheffects.withStroke(linewidth=3, foreground="white")])


def _footer(fig, registered, boxes, H, W):
    """Legends of the first four columns and the colour bar of ``u`` under the fifth."""
    from matplotlib import colormaps
    from matplotlib.colorbar import ColorbarBase

    top = boxes["footer"][0]
    n_tips = len(registered["layout"]["tips"])
    tips = {0: "", 1: "dot 1: the point the final map shrinks most, numbered alike on the "
                       "input and the sphere views"}.get(
        n_tips, f"dots 1-{n_tips}: the {n_tips} tips the final map shrinks most, numbered "
                "alike on the input and the sphere views")
    left = "red: folded faces (red dots and rings mark tiny ones);  " + tips
    fig.text(0.006, 1.0 - (top + 16) / H, left, ha="left", va="center", fontsize=10.5,
             color="0.15")
    poles = "poles at tip 1 and a tip far from it" if n_tips else "pole at the most shrunk point"
    fig.text(3.5 / 5, 1.0 - (top + 20) / H, "squares where the map is conformal;\n"
             "a limb the map shrinks holds few, large checks\n"
             f"(Mercator chart, {poles})", ha="center", va="center", fontsize=10, color="0.15")
    t, b, l, r = boxes["colorbar"]
    ax = fig.add_axes((l / W, 1.0 - b / H, (r - l) / W, (b - t) / H))
    norm = registered["u_norm"]
    cb = ColorbarBase(ax, cmap=colormaps[U_CMAP], norm=norm, orientation="horizontal")
    ticks = [float(norm.vmin), 0.0, float(norm.vmax)]   # ticks outside the range break the bar
    cb.set_ticks(ticks, labels=[f"{v:.2f}" if v else "0" for v in ticks])
    cb.ax.tick_params(labelsize=10)
    cb.set_label("u: 1st to 99th percentile, 0 = area kept", fontsize=10)


def contact_sheet(paths, out_path, *, title=None, width_px=2000):
    """Stack the stage PNGs into one PNG (matplotlib, no pyplot).

    Parameters
    ----------
    paths : list of str
        The annotated stage PNGs written by :func:`compose_stage`.
    out_path : str
    title : str, optional
    width_px : int
        Width of the PNG in pixels (the height follows).

    Returns
    -------
    str
        ``out_path``.

    Raises
    ------
    ValueError
        ``paths`` is empty.
    OSError
        A PNG cannot be read.
    """
    from matplotlib.figure import Figure
    from matplotlib.image import imread

    if not len(paths):
        raise ValueError("contact_sheet needs at least one stage PNG; paths is empty")
    imgs = [imread(p)[..., :3] for p in paths]
    stack = np.concatenate(imgs, axis=0)
    h, w = stack.shape[:2]
    title_in = 0.5 if title else 0.0
    fig_w = 16.0
    fig_h = fig_w * h / w + title_in
    fig = Figure(figsize=(fig_w, fig_h), dpi=width_px / fig_w)
    if title:
        fig.text(0.5, 1 - 0.25 / fig_h, title, ha="center", va="center", fontsize=14)
    ax = fig.add_axes((0, 0, 1, (fig_h - title_in) / fig_h))
    ax.imshow(stack, interpolation="antialiased")
    ax.set_axis_off()
    fig.savefig(out_path, facecolor="white")
    return out_path
