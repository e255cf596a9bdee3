"""The part of the viewers' imgui panel that both have: the stage slider and the stage's numbers."""


def stage_controls(view):
    """Draw the stage slider, previous/next buttons and the stage's text lines (inside a frame).

    Parameters
    ----------
    view
        A viewer with ``stages`` (list of dict with a ``"name"``), ``index`` (int,
        0-based), ``set_stage(i)``, ``lines()`` (list of str) and a ``frames``
        counter, which is incremented.
    """
    import polyscope.imgui as psim

    view.frames += 1
    n = len(view.stages)
    changed, i = psim.SliderInt("stage", view.index + 1, v_min=1, v_max=n)
    i -= 1
    if psim.Button("< previous"):
        changed, i = True, view.index - 1
    psim.SameLine()
    if psim.Button("next >"):
        changed, i = True, view.index + 1
    if changed and i != view.index and 0 <= i < n:
        view.set_stage(i)
    psim.Separator()
    psim.TextUnformatted(f"{view.index + 1}/{n}: {view.stages[view.index]['name']}")
    for line in view.lines():
        psim.TextUnformatted(line)
    psim.Separator()
