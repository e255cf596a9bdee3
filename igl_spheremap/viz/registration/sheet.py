"""Annotated PNG of one registration stage (matplotlib, no pyplot).

The polyscope screenshot is cut into its two rows; above each goes a band of
column headers, above all a title (stage, largest landmark error, folds, and
a line on how surface 1's map was made), below all a legend of the landmark
markers and the data (the checkerboard's two colours or the colour bar of a
field), the same for every stage.  The landmarks are numbered next to their
markers where they face the viewer.  :func:`registration_png_boxes` says where
each part is.  The contact sheet stacks surface 1's row of every stage above
surface 2's row (which no stage changes) and the legend.
"""

import textwrap

import numpy as np

from ...errors import plural
from ..layout import project
from .layout import COLUMN_X, DISTORTION_RANGE, HALF_SIZE, ROW_LABELS, colormap_rgb
from .scene import MARKER_RADIUS

_TITLE_PX, _HEADER_PX, _FOOTER_PX = 64, 30, 92
_DPI = 100


def registration_png_boxes(window_size):
    """Where the parts of a stage PNG are, in pixels ``(top, bottom, left, right)``.

    Returns
    -------
    dict
        ``title``, ``headers`` (a pair, one band per row), ``render`` (a pair:
        the screenshot's top and bottom halves, unscaled), ``footer``,
        ``legend`` (the checker swatches or the colour bar, under column 4),
        ``size`` (height, width), and ``split`` (the screenshot row where its
        halves meet).
    """
    w, h = window_size
    split = h // 2
    t1 = _TITLE_PX + _HEADER_PX
    t2 = t1 + split + _HEADER_PX
    bottom = t2 + h - split
    x4 = project(np.array([[COLUMN_X[3], 0.0, 0.0]]), window_size, half_size=HALF_SIZE)[0, 0]
    half = 0.5 * (w / 4.0) * 0.8
    return dict(title=(0, _TITLE_PX, 0, w),
                headers=((_TITLE_PX, t1, 0, w), (t1 + split, t2, 0, w)),
                render=((t1, t1 + split, 0, w), (t2, bottom, 0, w)),
                footer=(bottom, bottom + _FOOTER_PX, 0, w),
                legend=(bottom + 10, bottom + 30, int(x4 - half), int(x4 + half)),
                size=(bottom + _FOOTER_PX, w), split=split)


def registration_title(stage, index, count):
    """Stage name, largest landmark error, folds, distortion onto surface 2: one line."""
    return (f"{index + 1}/{count}. {stage['name']}: largest landmark error "
            f"{stage['max_error']:.2f}°, {plural(stage['folds'], 'folded face')}, median "
            f"distortion onto surface 2 {stage['median_distortion']:.3f}")


def compose_registration_stage(render_path, out_path, stage, registered, index, count,
                               window_size):
    """Write the annotated PNG of one stage around its polyscope screenshot (``out_path``)."""
    from matplotlib.figure import Figure
    from matplotlib.image import imread

    img = imread(render_path)[..., :3]
    boxes = registration_png_boxes(window_size)
    H, W = boxes["size"]
    split = boxes["split"]
    fig = Figure(figsize=(W / _DPI, H / _DPI), dpi=_DPI)
    for part, (top, bottom, _, _) in zip((img[:split], img[split:]), boxes["render"]):
        fig.figimage(part, xo=0, yo=H - bottom, origin="upper")

    def y(px):
        return 1.0 - px / H

    failed = index == count - 1 and not stage["pair"]["success"]
    color = "#b00000" if stage["folds"] or failed else "#006400"
    fig.text(0.006, y(22), registration_title(stage, index, count), ha="left",
             va="center", fontsize=15, weight="bold", color=color)
    note = (textwrap.shorten(f"failed: {stage['pair']['message']}", 220) if failed else
            f"surface 1's map: {stage['note']}")
    fig.text(0.006, y(48), note, ha="left", va="center", fontsize=11,
             color="#b00000" if failed else "0.25")
    xs = project(np.column_stack([COLUMN_X, np.zeros(4), np.zeros(4)]), window_size,
                 half_size=HALF_SIZE)[:, 0]
    for row, (top, bottom, _, _) in enumerate(boxes["headers"]):
        for x, label in zip(xs, ROW_LABELS[row]):
            fig.text(x / W, y(0.5 * (top + bottom)), label, ha="center", va="center",
                     fontsize=11.5, color="0.15", weight="bold" if row == 0 else "normal")
    _numbers(fig, registered, window_size, boxes, H)
    _footer(fig, stage, registered, boxes, H, W)
    fig.savefig(out_path, dpi=_DPI, facecolor="white")
    return out_path


def visible_markers(registered, key, window_size, tol=0.08):
    """Which landmark markers of view ``key`` face the viewer: (k,) bool.

    On a sphere view, those on its near half; on a surface, those of which the
    centre or a point of the rim (up, down, left or right, at the black ring's
    radius) is covered by no face of that surface more than ``tol`` nearer the
    viewer than the landmark (depth interpolated over the projected triangle;
    the default is the dot's offset towards the viewer plus its radius, so a
    dot that pokes out in front of the surface counts, and so does one half
    hidden behind the surface's outline).
    """
    X = registered["markers"][key]
    if key[1] in (1, 2):
        return X[:, 2] > 0.0
    P = registered["positions"][key]
    F = registered["faces"][key[0]]
    q = project(P, window_size, half_size=HALF_SIZE)
    a, b, c = q[F[:, 0]], q[F[:, 1]], q[F[:, 2]]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    ok = np.abs(det) > 1e-12
    rim = 1.35 * MARKER_RADIUS * np.array([[0, 0, 0], [0, 1, 0], [0, -1, 0], [1, 0, 0],
                                           [-1, 0, 0]], dtype=np.float64)
    out = np.zeros(len(X), dtype=bool)
    for k, x in enumerate(X):
        for p in project(x + rim, window_size, half_size=HALF_SIZE):
            s = ((b[:, 0] - p[0]) * (c[:, 1] - p[1]) - (b[:, 1] - p[1]) * (c[:, 0] - p[0]))
            t = ((c[:, 0] - p[0]) * (a[:, 1] - p[1]) - (c[:, 1] - p[1]) * (a[:, 0] - p[0]))
            s, t = np.divide(s, det, where=ok, out=np.zeros_like(s)), np.divide(
                t, det, where=ok, out=np.zeros_like(t))
            inside = ok & (s >= 0) & (t >= 0) & (s + t <= 1)
            depth = (s * P[F[:, 0], 2] + t * P[F[:, 1], 2] + (1 - s - t) * P[F[:, 2], 2])[inside]
            if not depth.size or depth.max() <= x[2] + tol:
                out[k] = True
                break
    return out


def _numbers(fig, registered, window_size, boxes, H):
    """Numbers next to the visible landmark markers (1-based, as in the legend)."""
    from matplotlib import patheffects

    split = boxes["split"]
    for key, X in registered["markers"].items():
        px = project(X, window_size, half_size=HALF_SIZE)
        top = boxes["render"][key[0]][0] - (split if key[0] == 1 else 0)
        for k in np.flatnonzero(visible_markers(registered, key, window_size)):
            fig.text((px[k, 0] + 10) / window_size[0], 1.0 - (top + px[k, 1] - 10) / H,
                     str(k + 1), fontsize=12, weight="bold", color="black", ha="left",
                     va="center",
                     path_effects=[patheffects.withStroke(linewidth=3, foreground="white")])


def _footer(fig, stage, registered, boxes, H, W):
    """The landmark legend (left) and the data legend under column 4."""
    from matplotlib.colors import ListedColormap, Normalize
    from matplotlib.colorbar import ColorbarBase

    top = boxes["footer"][0]
    k = len(stage["pair"]["l1"])
    text = (f"dots 1-{k}: the {plural(k, 'landmark pair')}, pair i in the same colour and number "
            "on both surfaces and spheres; rings on surface 1's sphere: the targets,\na line joins "
            "a landmark to its target while they differ; red on the spheres: folded.  Surface 1, "
            "column 1: distortion of its map onto surface 2\n(symmetric Dirichlet; white: 1, "
            f"isometric; red: {DISTORTION_RANGE[1]:g} or more).  "
            f"Data (column 4): {stage['pair']['data_name']}.")
    fig.text(0.006, 1.0 - (top + 42) / H, text, ha="left", va="center", fontsize=10.5,
             color="0.15", linespacing=1.6)
    data = registered["data"]
    t, b, l, r = boxes["legend"]
    ax = fig.add_axes((l / W, 1.0 - b / H, (r - l) / W, (b - t) / H))
    cmap = ListedColormap(colormap_rgb(data))
    cb = ColorbarBase(ax, cmap=cmap, norm=Normalize(data["vmin"], data["vmax"]),
                      orientation="horizontal")
    if data["cmap"] == "checker":
        cb.set_ticks([0.25, 0.75], labels=["even check", "odd check"])
        label = "the checks, on both surfaces"
    else:
        ticks = [data["vmin"], 0.5 * (data["vmin"] + data["vmax"]), data["vmax"]]
        cb.set_ticks(ticks, labels=[f"{v:.3g}" for v in ticks])
        label = "the data, same colours on both surfaces"
    cb.ax.tick_params(labelsize=10)
    cb.set_label(label, fontsize=10)


def registration_sheet(paths, out_path, window_size, *, width_px=1800):
    """Contact sheet: each stage's title and surface-1 row, then surface 2's row and the legend.

    Parameters
    ----------
    paths : list of str
        The stage PNGs of :func:`compose_registration_stage`, in order.
    out_path : str
    window_size : (int, int)
        The screenshots' size.
    width_px : int

    Returns
    -------
    str
        ``out_path``.
    """
    import os
    import tempfile

    from matplotlib.image import imread, imsave

    from ..sheet import contact_sheet

    boxes = registration_png_boxes(window_size)
    imgs = [imread(p)[..., :3] for p in paths]
    parts = [img[:boxes["render"][0][1]] for img in imgs]
    parts.append(imgs[-1][boxes["headers"][1][0]:])
    if width_px == parts[0].shape[1]:            # pixel for pixel, no resampling
        imsave(out_path, np.ascontiguousarray(np.concatenate(parts, axis=0)))
        return out_path
    with tempfile.TemporaryDirectory() as tmp:
        names = [os.path.join(tmp, f"part_{i:02d}.png") for i in range(len(parts))]
        for name, part in zip(names, parts):
            imsave(name, np.ascontiguousarray(part))
        return contact_sheet(names, out_path, width_px=width_px)
