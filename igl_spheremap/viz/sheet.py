"""The contact sheet: every stage's screenshot in one annotated PNG (matplotlib)."""

from ..operators import vertex_areas
from .stages import _phi_shape
from .style import COLUMN_LABELS

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
