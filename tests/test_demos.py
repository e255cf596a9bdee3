"""Tests of the polyscope demo (igl_spheremap.viz, demos/folding_removal.py) and demos/figures.py.

Polyscope keeps one global OpenGL context per process, so everything that
initializes it (headless EGL screenshots, the mock backend) runs in a
subprocess.  Headless rendering needs Mesa EGL: where polyscope cannot open it
the screenshot tests are skipped with the Debian packages to install.  The
screenshot tests check facts that do not depend on one run's pixels: red
appears exactly when the stage has folds, every column draws something, the
checkerboard has two alternating colours, the sphere shows the input's part
colours at the mapped positions, the title and the colour bar are drawn.
"""

import json
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import igl
import numpy as np
import pytest

import igl_spheremap as sm

ROOT = Path(__file__).resolve().parents[1]
FISH = ROOT / "tests" / "data" / "fish_lowres.obj"
DEMOS = ROOT / "demos"
sys.path.insert(0, str(DEMOS))

import figures  # noqa: E402

from igl_spheremap import viz  # noqa: E402
from igl_spheremap.io.result_file import load_result, save_result  # noqa: E402
from igl_spheremap.viz import style  # noqa: E402

STAGE_LINE = re.compile(r"^stage (\d+): (.+): (\d+) folded faces$")


def _fish():
    V, F = igl.read_triangle_mesh(str(FISH))
    return np.asarray(V, np.float64), np.asarray(F, np.int64)


def _run(args, cwd, env_extra=None, timeout=300):
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [env.get("PYTHONPATH")] if p])
    env.update(env_extra or {})
    # cwd: imgui writes imgui.ini into the working directory
    return subprocess.run([sys.executable, *map(str, args)], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def fish_run():
    """Fish through Algorithm 2 with Algorithm 1 cut to 2 iterations.

    Two iterations leave folds behind whatever the optimizer does, so the run
    has a Gauss-map round and one star-map round: four stages, with folds (the
    guaranteed path, which would add its starts, is off).
    """
    V, F = _fish()
    result = sm.spherical_conformal_map(V, F, max_rounds=1, max_iter=2, guaranteed_path=False)
    assert len(result.rounds) == 2, "premise: 2 iterations of Algorithm 1 leave folds on the fish"
    return V, F, result


@pytest.fixture(scope="module")
def fish_npz(fish_run, tmp_path_factory):
    path = tmp_path_factory.mktemp("npz") / "fish.npz"
    save_result(path, fish_run[2])
    return path


def _expected_maps(result):
    """Stage maps straight from the rounds, in the documented stage order."""
    out = []
    for k, rnd in enumerate(result.rounds):
        out.append(("Gauss map" if k == 0 else f"star map {k}", rnd.U_init))
        out.append(("after Algorithm 1" + (f", round {k}" if k else ""), rnd.U))
    return out


# --------------------------------------------------------------------- no polyscope needed

def test_import_does_not_load_polyscope(tmp_path):
    code = ("import sys, igl_spheremap, igl_spheremap.viz; "
            "print('polyscope' in sys.modules, 'polyscope_bindings' in sys.modules)")
    proc = _run(["-c", code], tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["False", "False"]


def test_build_stages_matches_rounds(fish_run):
    V, F, result = fish_run
    stages = viz.build_stages(result)
    expected = _expected_maps(result)
    assert [s["name"] for s in stages] == [name for name, _ in expected]
    Fv = sm.validate_mesh(V, F).F
    assert any(s["folds"] > 0 for s in stages)
    for st, (_, U) in zip(stages, expected):
        assert np.array_equal(st["U"], U)
        assert np.array_equal(st["F"], Fv)
        assert st["folded"].dtype == bool and st["folded"].shape == (F.shape[0],)
        assert int(st["folded"].sum()) == st["folds"] == sm.count_folds(Fv, U)
        np.testing.assert_allclose(np.exp(2 * st["u"]), sm.conformal_factor(V, Fv, U),
                                   rtol=1e-12)
        np.testing.assert_allclose(st["mean_angle_distortion_deg"],
                                   np.nanmean(sm.angle_distortion(V, Fv, U)), rtol=1e-12)
    for k, rnd in enumerate(result.rounds):
        gauss_or_star, alg1 = stages[2 * k], stages[2 * k + 1]
        assert gauss_or_star["folds"] == rnd.folds_before
        assert alg1["folds"] == rnd.folds_after
        assert alg1["nit"] == rnd.nit and gauss_or_star["nit"] is None
        # the energy shown for an Algorithm 1 stage is the energy the run minimized
        np.testing.assert_allclose(alg1["energy_over_4pi"], rnd.energy / (4 * np.pi), rtol=1e-8)
    assert stages[0]["Phi"] is None
    assert np.array_equal(stages[2]["Phi"], result.rounds[1].Phi)   # star map 1 <- its Phi^u
    assert np.array_equal(stages[1]["Phi"], result.rounds[1].Phi)   # Phi^u of the map before
    assert stages[-1]["Phi"] is not None and stages[-1]["Phi"].shape == V.shape


def test_figures_write_pngs(fish_run, fish_npz, tmp_path):
    V, F, result = fish_run
    before, after = figures.angle_differences(result)
    Fv = sm.validate_mesh(V, F).F
    for got, U in ((before, result.rounds[0].U), (after, result.U)):
        ref = sm.angle_distortion(V, Fv, U).ravel()
        np.testing.assert_array_equal(got, ref[np.isfinite(ref)])
    proc = _run([DEMOS / "figures.py", "--load-result", fish_npz, "--out", tmp_path / "fig"],
                tmp_path)
    assert proc.returncode == 0, proc.stderr
    from matplotlib.image import imread
    for name in ("energy.png", "grad_norm.png", "angle_histograms.png"):
        path = tmp_path / "fig" / name
        assert str(path) in proc.stdout
        img = imread(path)
        assert img.ndim == 3 and img.shape[0] > 200 and img.shape[1] > 400
        assert img[..., :3].std() > 0.05          # axes, lines, bars: not an empty canvas


def _red(img):
    """Pixels of the folds' red: strong red, weak green and blue (shading keeps the ratios)."""
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    return (r > 0.45) & (g < 0.3) & (b < 0.3) & (r - g > 0.3)


def test_part_colors_tell_directions_apart_and_avoid_red():
    rng = np.random.default_rng(0)
    P = rng.uniform(-1, 1, (20000, 3)) * [2.0, 1.0, 0.5]
    C = viz.part_colors(P)
    assert C.shape == P.shape and C.min() >= 0 and C.max() <= 1
    for shade in (1.0, 0.8, 0.6, 0.4):          # shading dims colours; none turns fold-red
        assert not _red(shade * C).any()
    # smooth: a bounded change of colour per change of position (box scaled to [-1, 1])
    Q = P + rng.normal(size=P.shape) * 1e-4
    CP, CQ = np.split(viz.part_colors(np.vstack([P, Q])), 2)     # one box for both
    step = np.linalg.norm((Q - P) / (np.ptp(np.vstack([P, Q]), axis=0) / 2), axis=1)
    assert (np.linalg.norm(CQ - CP, axis=1) / step).max() < 10.0
    # eight directions on screen (head, tail, legs of an animal) get distinct colours
    ang = np.radians(np.arange(8) * 45.0 + 22.5)
    ring = np.column_stack([np.cos(ang), np.sin(ang), np.zeros(8)])
    box = np.array([[-1, -1, -1], [1, 1, 1]], float)
    Cr = viz.part_colors(np.vstack([box, ring]))[2:]
    d = np.linalg.norm(Cr[:, None] - Cr[None], axis=-1)
    assert d[~np.eye(8, dtype=bool)].min() > 0.1
    near, far = viz.part_colors(np.array([[0.9, 0, 1.0], [0.9, 0, -1.0], [-1, -1, 0],
                                          [1, 1, 0]]))[:2]
    assert near.sum() > far.sum()                # near parts lighter than far ones


def _chart_distortion(U, V, F, poles, keep_away=0.3):
    """Ratio of singular values of the linear map from each input triangle to the chart."""
    X = viz.mercator_corners(U, F, *poles).reshape(-1, 3, 2)
    e1, e2 = V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]
    a = e1 / np.linalg.norm(e1, axis=1, keepdims=True)
    b = np.cross(np.cross(e1, e2), e1)
    b /= np.linalg.norm(b, axis=1, keepdims=True)
    T = np.stack([np.stack([(e1 * a).sum(1), (e1 * b).sum(1)], 1),
                  np.stack([(e2 * a).sum(1), (e2 * b).sum(1)], 1)], 1)  # (m, 2, 2) rows
    D = np.stack([X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]], 1)
    J = np.linalg.solve(T, D)
    s = np.linalg.svd(J, compute_uv=False)
    far = np.ones(len(F), bool)
    for p in [q for q in poles if q is not None]:
        far &= (np.arccos(np.clip(U[F] @ U[p], -1, 1)) > keep_away).all(axis=1)
    return (s[:, 0] / s[:, 1])[far]


def test_checkerboard_chart_is_conformal_and_seamless():
    """Squares stay squares under a conformal map and only then; the seam does not show."""
    err = {}
    for level, north in ((3, "vertex"), (4, "vertex"), (3, None), (4, None)):
        V, F = sm.icosphere(level)
        poles = (0, int(np.argmin(V @ V[0] + 0.3 * V[:, 0])) if north else None)
        err[level, north] = _chart_distortion(V, V, F, poles) - 1.0
        stretched = V * [1.0, 1.0, 2.5]
        stretched /= np.linalg.norm(stretched, axis=1, keepdims=True)
        bad = _chart_distortion(stretched, V, F, poles) - 1.0
        assert np.median(bad) > 5 * np.median(err[level, north])   # a non-conformal map shows
    for north in ("vertex", None):
        # the identity map: distortion is only the piecewise-linear error, O(edge length)
        assert np.median(err[4, north]) < 0.6 * np.median(err[3, north])
        assert np.median(err[4, north]) < 0.05
    # 2 pi is a whole number of check pairs: the checker colour is periodic in arg w
    pairs = 2 * np.pi / (2 * viz.fields.checker_size())
    assert abs(pairs - round(pairs)) < 1e-12
    V, F = sm.icosphere(3)
    X = viz.mercator_corners(V, F, 0, 5).reshape(-1, 3, 2)
    assert np.ptp(X[..., 0], axis=1).max() < np.pi       # no face spans the seam
    y = X[..., 1]
    assert np.all(y[F == 0] == -style.MERCATOR_CLIP) and np.all(y[F == 5] == style.MERCATOR_CLIP)


def test_chart_poles_keep_the_poles_apart():
    V, _ = sm.icosphere(2)
    a = 0
    near = int(np.argsort(-(V @ V[a]))[3])       # a few degrees from vertex 0
    far = int(np.argmin(V @ V[a]))               # its antipode
    assert viz.chart_poles(V, [a, near, far]) == (a, far)
    assert viz.chart_poles(V, [a, near]) == (a, None)
    assert viz.chart_poles(V, [a]) == (a, None)


def test_tip_vertices_are_the_deepest_separate_minima_of_u():
    V, F = sm.icosphere(3)
    centres = [10, 200, 400]
    depth = [5.0, 4.0, 3.0]
    u = np.zeros(len(V))
    for c, a in zip(centres, depth):
        u -= a * np.exp(-np.sum((V - V[c]) ** 2, axis=1) / 0.05)
    assert list(viz.tip_vertices(V, F, u)) == centres
    assert viz.tip_vertices(V, F, np.zeros(len(V))).size == 0       # nothing shrunk


def test_u_colors_white_at_zero_and_percentile_ends():
    from matplotlib import colormaps
    u = np.linspace(-6.0, 2.0, 801)
    C, norm, cmap = viz.u_colors(u)
    assert cmap.name == colormaps[style.U_CMAP].name
    np.testing.assert_allclose([norm.vmin, norm.vmax], np.percentile(u, [1, 99]))
    np.testing.assert_allclose(C[np.argmin(abs(u))], cmap(0.5)[:3], atol=0.02)
    np.testing.assert_allclose(C[0], cmap(0.0)[:3])
    np.testing.assert_allclose(C[-1], cmap(1.0)[:3])


def test_demo_rejects_unreadable_mesh_without_traceback(tmp_path):
    bad = tmp_path / "lh.white"
    bad.write_bytes(b"not a surface")
    proc = _run([DEMOS / "folding_removal.py", bad], tmp_path)
    assert proc.returncode == 1
    assert proc.stderr.startswith("error: cannot read FreeSurfer surface")
    assert "Traceback" not in proc.stderr


# --------------------------------------------------------------------- polyscope

EGL_PROBE = textwrap.dedent("""
    from igl_spheremap.viz.viewer import init_polyscope
    try:
        init_polyscope(None, headless=True)
    except RuntimeError as err:
        print(err)
    else:
        print("EGL OK")
""")


@pytest.fixture(scope="module")
def headless(tmp_path_factory):
    """Skip unless polyscope can open a headless OpenGL context here (Mesa EGL)."""
    tmp = tmp_path_factory.mktemp("egl")
    proc = _run(["-c", EGL_PROBE], tmp)
    if "EGL OK" not in proc.stdout:
        pytest.skip(f"{proc.stdout.strip()} {proc.stderr.strip()[-500:]}".strip())


SHOT_SCRIPT = textwrap.dedent("""
    import sys
    import numpy as np
    from igl_spheremap import viz
    from igl_spheremap.io.result_file import load_result
    result = load_result(sys.argv[1])
    view = viz.show(result, screenshot_dir=sys.argv[2])
    for i, reg in enumerate(view.drawn):
        np.savez(f"{sys.argv[2]}/drawn_{i:02d}.npz", face_colors=reg["face_colors"],
                 folded=reg["face_folded"], tips=reg["layout"]["tips"],
                 u_range=[reg["u_norm"].vmin, reg["u_norm"].vmax],
                 **{k: v for k, v in reg["positions"].items()})
    # the same stages with unlit colours ("flat" material), to compare colours exactly
    import polyscope as ps
    from igl_spheremap.viz.style import NAMES
    for i in range(len(view.stages)):
        view.set_stage(i)
        for key in ("input", "front", "back"):
            ps.get_surface_mesh(NAMES[key]).set_material("flat")
        ps.screenshot(f"{sys.argv[2]}/flat_{i:02d}.png", transparent_bg=False)
""")


@pytest.fixture(scope="module")
def fish_shots(headless, tmp_path_factory):
    """The fish with Algorithm 1 cut to 5 iterations, rendered headless stage by stage.

    Five iterations leave folds after the first Algorithm 1 run and the star map
    removes them, so there are stages with folds and stages without.
    """
    tmp = tmp_path_factory.mktemp("shots")
    V, F = _fish()
    result = sm.spherical_conformal_map(V, F, max_rounds=1, max_iter=5)
    folds = [sm.count_folds(result.F, U) for _, U in _expected_maps(result)]
    assert min(folds) == 0 < max(folds), f"premise: some stages fold, some do not ({folds})"
    save_result(tmp / "fish.npz", result)
    (tmp / "shot.py").write_text(SHOT_SCRIPT)
    proc = _run([tmp / "shot.py", tmp / "fish.npz", tmp / "out"], tmp)
    assert proc.returncode == 0, proc.stderr[-4000:]
    return result, folds, tmp / "out"


def _stage_png(out, i):
    from matplotlib.image import imread
    return imread(out / f"stage_{i:02d}.png")[..., :3]


def _box(img, box):
    t, b, l, r = box
    return img[t:b, l:r]


def _columns(render):
    w = render.shape[1]
    return [render[:, j * w // 5:(j + 1) * w // 5] for j in range(5)]


def _foreground(img):
    return np.abs(img - 1.0).max(axis=-1) > 0.06      # the background is white


def test_screenshots_draw_every_column_and_red_iff_folds(fish_shots):
    result, folds, out = fish_shots
    boxes = viz.stage_png_boxes(style.WINDOW)
    for i, n_folds in enumerate(folds):
        img = _stage_png(out, i)
        assert img.shape[:2] == boxes["size"]
        render = _box(img, boxes["render"])
        cols = _columns(render)
        for j, col in enumerate(cols):           # polyscope drew every column
            assert _foreground(col).mean() > 0.02, (i, j)
        red_on_spheres = int(_red(cols[1]).sum() + _red(cols[2]).sum())
        if n_folds:
            assert red_on_spheres > 0, (i, n_folds)
        else:                                    # no red anywhere: part colours avoid it
            assert int(_red(render).sum()) == 0, i
        # title and headers drawn (text on white), colour bar with the u colour map
        for part, chars in (("title", 40), ("headers", 100)):
            ink = np.abs(_box(img, boxes[part]) - 1.0).max(axis=-1) > 0.3
            assert ink.sum() > 5 * chars, (i, part)          # a few pixels per character
        assert (np.abs(_box(img, boxes["title"]) - [0.69, 0, 0]).max(-1) < 0.1).any() \
            == bool(n_folds)                                 # red title iff folds
        _assert_colorbar(_box(img, boxes["colorbar"]))
    from matplotlib.image import imread
    sheet = imread(out / "contact_sheet.png")
    assert sheet.shape[1] == 2000 and sheet.shape[0] > len(folds) * boxes["size"][0] * 0.9


def _assert_colorbar(bar):
    """The bar's middle row runs through the u colour map, in order, from one end to the other."""
    from matplotlib import colormaps
    row = bar[bar.shape[0] // 2]
    ref = colormaps[style.U_CMAP](np.linspace(0, 1, 256))[:, :3]
    d = np.linalg.norm(row[:, None] - ref[None], axis=-1)
    on_map = d.min(axis=1) < 0.03               # frame and background pixels are not
    assert on_map.mean() > 0.8                   # drawn with the colour map
    idx = d.argmin(axis=1)[on_map]
    assert idx.min() < 20 and idx.max() > 235    # both ends of the map
    assert np.corrcoef(idx, np.flatnonzero(on_map))[0, 1] > 0.95   # in order, left to right


def _otsu(x):
    """Otsu's two-class split of the values ``x``: threshold and separability (between-class
    variance / total variance, 1 for two spikes, about 0.64 for a uniform spread)."""
    cuts = np.quantile(x, np.linspace(0.02, 0.98, 97))
    best = (-1.0, None)
    for c in cuts:
        lo, hi = x[x <= c], x[x > c]
        if lo.size and hi.size:
            between = lo.size * hi.size * (lo.mean() - hi.mean()) ** 2 / x.size ** 2
            best = max(best, (between, c), key=lambda t: t[0])
    return best[1], best[0] / x.var()


def test_checkerboard_column_alternates_two_colours(fish_shots):
    """Two colours, one bluer than the other like the checker colours, in alternation."""
    _, folds, out = fish_shots
    boxes = viz.stage_png_boxes(style.WINDOW)

    def blueness(x):                             # (b - r) / (r + g + b): shading cancels
        return (x[..., 2] - x[..., 0]) / np.maximum(x.sum(axis=-1), 1e-6)

    light, dark = (np.asarray(c) for c in style.CHECKER_COLORS)
    assert blueness(dark) > blueness(light)
    for i in range(len(folds)):
        col = _columns(_box(_stage_png(out, i), boxes["render"]))[3]
        fg = _foreground(col)
        cut, separability = _otsu(blueness(col[fg]))
        assert separability > 0.8, (i, separability)        # two colours dominate
        is_dark = blueness(col) > cut
        assert 0.2 < is_dark[fg].mean() < 0.8, i             # both cover a good share
        assert col[fg & is_dark].mean() < col[fg & ~is_dark].mean()   # the bluer is darker
        flips = [np.count_nonzero(np.diff(is_dark[r][fg[r]].astype(int)))
                 for r in range(col.shape[0]) if fg[r].sum() > 50]
        assert np.median(flips) >= 4, i          # and they alternate along the rows


def _visible_faces(P, F, window, min_inradius_px=2.0):
    """Faces of the surface at world positions ``P`` that face the viewer, are big enough
    to hold a pixel sample and are in front of every other face projecting near them.
    Returns the face indices and the pixel (column, row) of their centroids."""
    from scipy.spatial import cKDTree
    px = viz.project(P, window)
    a, b, c = (px[F[:, k]] for k in range(3))
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    per = (np.linalg.norm(b - a, axis=1) + np.linalg.norm(c - b, axis=1)
           + np.linalg.norm(a - c, axis=1))
    inradius = np.abs(area2) / np.maximum(per, 1e-12)
    n = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    facing = n[:, 2] / np.maximum(np.linalg.norm(n, axis=1), 1e-300) > 0.5
    cen, z = (a + b + c) / 3, P[F].mean(axis=1)[:, 2]
    tree = cKDTree(cen)
    cand = np.flatnonzero(facing & (inradius > min_inradius_px))
    keep = [f for f in cand if z[tree.query_ball_point(cen[f], 2 * inradius[f])].max() <= z[f]
            + 1e-9]
    return np.asarray(keep, dtype=np.int64), cen[keep]


def test_spheres_show_the_input_part_colours_where_the_map_sends_them(fish_shots):
    """The sphere views are the map, rotated, and the colour at the image of a face is that
    face's colour on the input: the mean part colour of its corners (red when folded).

    Compared on a rendering with the "flat" (unlit) material, where a pixel inside a face
    is the face's colour exactly."""
    from matplotlib.image import imread
    result, folds, out = fish_shots
    F = result.F
    for i, n_folds in enumerate(folds):
        drawn = np.load(out / f"drawn_{i:02d}.npz")
        U = result.mesh.from_input(_expected_maps(result)[i][1])
        S = drawn["front"] - [style.COLUMN_X[1], 0, 0]    # the front view is the map, rotated
        Q, *_ = np.linalg.lstsq(U, S, rcond=None)
        np.testing.assert_allclose(Q @ Q.T, np.eye(3), atol=1e-9)
        assert np.linalg.det(Q) > 0
        np.testing.assert_array_equal(drawn["folded"], sm.folded_faces(F, U))
        parts = viz.part_colors(drawn["input"])              # the input's colours
        want = parts[F].mean(axis=1)
        want[drawn["folded"]] = style.RED
        np.testing.assert_allclose(drawn["face_colors"], want, atol=1e-12)
        if n_folds:                              # red dots and rings cover the spheres there
            continue
        flat = imread(out / f"flat_{i:02d}.png")[..., :3]
        tips_px = np.vstack([viz.project(drawn[k][drawn["tips"]], style.WINDOW)
                             for k in ("input", "front", "back")])
        for key in ("front", "back", "input"):
            faces, px = _visible_faces(drawn[key], F, style.WINDOW)
            clear = np.min(np.linalg.norm(px[:, None] - tips_px[None], axis=-1), axis=1) > 12
            faces, px = faces[clear], px[clear]                # not under a tip marker
            assert len(faces) >= 30, (i, key, len(faces))
            got = flat[np.round(px[:, 1]).astype(int), np.round(px[:, 0]).astype(int)]
            match = np.abs(got - want[faces]).max(axis=1) < 3 / 255
            # the spheres are convex: every sample is visible; the input may hide a few
            assert match.mean() >= (1.0 if key != "input" else 0.9), (i, key, match.mean())


def test_headless_failure_names_packages(fish_npz, tmp_path):
    """Without a usable EGL the demo stops with the Debian packages to install."""
    env = {"__EGL_VENDOR_LIBRARY_FILENAMES": str(tmp_path / "no_such_vendor.json"),
           "DISPLAY": "", "WAYLAND_DISPLAY": ""}
    proc = _run([DEMOS / "folding_removal.py", "--load-result", fish_npz,
                 "--screenshots", tmp_path / "shots"], tmp_path, env)
    assert proc.returncode == 2
    assert "apt-get install -y " + " ".join(viz.HEADLESS_PACKAGES) in proc.stderr
    assert not (tmp_path / "shots" / "stage_00.png").exists()


def _write_fish(path, family):
    """The fish as a FreeSurfer surface or a GIfTI surface, written by nibabel."""
    import nibabel as nib
    from nibabel.freesurfer import write_geometry
    from nibabel.gifti import GiftiDataArray, GiftiImage
    V, F = _fish()
    if family == "freesurfer":
        write_geometry(str(path), V.astype(np.float32), F.astype(np.int32))
    else:
        nib.save(GiftiImage(darrays=[
            GiftiDataArray(V.astype(np.float32), intent="NIFTI_INTENT_POINTSET"),
            GiftiDataArray(F.astype(np.int32), intent="NIFTI_INTENT_TRIANGLE")]), str(path))
    return V, F


@pytest.mark.parametrize("name, family", [("lh.pial", "freesurfer"),
                                          ("lh.pial.surf.gii", "gifti")])
def test_demo_reads_freesurfer_and_gifti(headless, tmp_path, name, family):
    V, F = _write_fish(tmp_path / name, family)
    proc = _run([DEMOS / "folding_removal.py", tmp_path / name, "--screenshots",
                 tmp_path / "shots", "--save-result", tmp_path / "r.npz"], tmp_path)
    assert proc.returncode == 0, proc.stderr[-4000:]
    assert proc.stdout.startswith(f"{tmp_path / name} ({family}): {len(V)} vertices, "
                                  f"{len(F)} faces")
    result = load_result(tmp_path / "r.npz")
    # the mesh mapped is the file's (float32 coordinates; validation scales by a power of 2)
    Vm = result.mesh.to_input(result.mesh.V) / result.mesh.scale
    np.testing.assert_allclose(Vm, V, atol=1e-6 * np.abs(V).max())
    matches = [m for m in map(STAGE_LINE.match, proc.stdout.splitlines()) if m]
    printed = [(m.group(2), int(m.group(3))) for m in matches]
    assert printed == [(n, sm.count_folds(result.F, result.mesh.from_input(U)))
                       for n, U in _expected_maps(result)]
    # numbered as the stage PNGs' titles ("k/n. name: ...", viz.sheet.stage_title) number them
    from igl_spheremap.viz.sheet import stage_title
    stages = viz.build_stages(result, final_phi=False)
    assert [int(m.group(1)) for m in matches] == [
        int(stage_title(st, i, len(stages)).split("/")[0]) for i, st in enumerate(stages)]
    for i in range(len(printed)):
        assert (tmp_path / "shots" / f"stage_{i:02d}.png").is_file()
    assert (tmp_path / "shots" / "contact_sheet.png").is_file()


MOCK_SCRIPT = textwrap.dedent("""
    import json, sys
    import polyscope as ps
    from igl_spheremap import viz
    from igl_spheremap.viz.style import NAMES
    from igl_spheremap.io.result_file import load_result
    result = load_result(sys.argv[1])
    view = viz.show(result, backend="openGL_mock", interactive=False)
    out = dict(backend=ps.get_render_engine_backend_name(), frames_after_show=view.frames,
               shown_first=view.index, stages=[])
    ps.set_frame_tick_limit_fps_mode("ignore_limits")
    for i in range(len(view.stages)):
        reg = view.set_stage(i)
        ps.frame_tick()
        out["stages"].append(dict(
            name=view.stages[i]["name"], marked=int(reg["face_folded"].sum()),
            dots=int(reg["dots"].shape[0]), lines=view.lines(),
            u_range=[reg["u_norm"].vmin, reg["u_norm"].vmax],
            meshes=[ps.has_surface_mesh(NAMES[k])
                    for k in ("input", "front", "back", "checker", "u")]))
    out["frames"] = view.frames
    print("JSON" + json.dumps(out))
""")


def test_interactive_view_mock_backend(fish_run, fish_npz, tmp_path):
    V, F, result = fish_run
    script = tmp_path / "mock_show.py"
    script.write_text(MOCK_SCRIPT)
    proc = _run([script, fish_npz], tmp_path)
    assert proc.returncode == 0, proc.stderr[-4000:]
    out = json.loads(proc.stdout.split("JSON", 1)[1])
    assert out["backend"] == "openGL_mock"
    assert out["frames_after_show"] == 1                 # show(interactive=False) ran one frame
    assert out["frames"] == 1 + len(out["stages"])       # and the callback ran in every tick
    assert out["shown_first"] == len(out["stages"]) - 1  # the window opens on the final map
    Fv = sm.validate_mesh(V, F).F
    expected = _expected_maps(result)
    stages = viz.build_stages(result)
    assert [s["name"] for s in out["stages"]] == [name for name, _ in expected]
    for st, (_, U), ref in zip(out["stages"], expected, stages):
        folds = sm.count_folds(Fv, U)
        assert st["marked"] == st["dots"] == folds
        assert st["lines"][0] == f"folded faces: {folds} of {F.shape[0]}"
        assert st["meshes"] == [True] * 5
        u = 0.5 * np.log(sm.conformal_factor(V, Fv, U))
        lo, hi = np.percentile(u, [1, 99])
        np.testing.assert_allclose(st["u_range"], [min(lo, -1e-3), max(hi, 1e-3)])
        # Phi^u is no longer drawn: its numbers are in the panel
        has_eig = any(line.startswith("  eigenvalues") for line in st["lines"])
        assert has_eig == (ref["eigenvalues"] is not None)


def test_stages_show_the_starts_of_the_guaranteed_path():
    """A split icosphere: the rounds' map is held by the barrier, the Tutte start wins; its
    stages are the start (fold-free by construction) and Algorithm 1 after it."""
    from igl_spheremap.mesh.shapes import split_icosphere

    V, F = split_icosphere(2)
    result = sm.spherical_conformal_map(V, F)
    stages = viz.build_stages(result)
    starts = [s for s in stages if s["kind"] == "start"]
    assert [r.kind for r in result.rounds if r.kind in ("central", "tutte")]
    assert len(starts) == sum(r.kind in ("central", "tutte") for r in result.rounds)
    assert all(s["folds"] == 0 for s in starts)
    assert len(stages) == 2 * len(result.rounds)


def test_stages_show_a_restart_and_a_polish_as_starts():
    """Rounds that start from neither a star map nor the Gauss map (a restart after a collapse,
    the polish of a partly held map) are drawn as starts, their maps those of the rounds."""
    from igl_spheremap.mesh.shapes import capsule

    V, F = capsule(5.0)  # rounds: the Gauss map folds, a star round, ...
    result = sm.spherical_conformal_map(V, F, polish="always")
    assert result.rounds[-1].kind == "polish"
    stages = viz.build_stages(result)
    starts = [s for s in stages if s["kind"] == "start"]
    assert starts[-1]["name"] == "start of the polish"
    # the polish is the conformal descent, not a round of Algorithm 2
    assert stages[-1]["name"] == f"after the conformal descent, round {result.rounds[-1].index}"
    k = result.rounds[-1].index
    assert np.abs(starts[-1]["U"] - result.mesh.from_input(result.rounds[-1].U_init)).max() == 0
    assert len(stages) == 2 * len(result.rounds) and stages[-1]["round"] == k


def test_figures_name_the_polish_round_and_its_stopping_threshold(tmp_path):
    """A polish round (the conformal descent) is labelled as such, not as "star map k", its
    energy line is named the conformal distortion, and the gtol line drawn for each converged
    round is one its last RMS gradient is below (the descent stops at its own threshold)."""
    V, F = _fish()
    result = sm.spherical_conformal_map(V, F, polish="always")
    polish = [r for r in result.rounds if r.kind == "polish"]
    assert polish and polish[0].converged, "premise: the fish gets a converged polish round"
    for rnd in result.rounds:
        label = figures.round_label(rnd)
        assert ("star map" in label) == (rnd.kind == "star"), label
        if rnd.converged:
            assert rnd.grad_norm_history[-1] <= figures.round_gtol(result, rnd)
    assert "polish" in figures.round_label(polish[0])
    # the polish minimizes the conformal distortion, not the harmonic energy (libigl's cotan)
    U = polish[0].U
    harmonic = -0.5 * np.sum(U * (igl.cotmatrix(V, F) @ U))
    assert abs(polish[0].energy - harmonic) > 1e-3 * harmonic
    assert figures.is_descent(polish[0]) and not figures.is_descent(result.rounds[0])
    # the final histogram's title counts folding-removal rounds apart from the polish
    removal = sum(r.kind in ("star", "local", "restart") for r in result.rounds)
    assert figures.after_title(result) == (f"after folding removal ({removal} round"
                                           f"{'' if removal == 1 else 's'} + the polish)")


@pytest.mark.parametrize("script, args, words", [
    ("figures.py", ["--out", "OUT", "--max-iter", "-3"], "argument --max-iter: must be >= 0"),
    ("figures.py", ["--out", "OUT", "no_such_mesh.obj"], "error: "),
    ("folding_removal.py", ["--sheet-width", "0", "--screenshots", "OUT"],
     "argument --sheet-width: must be >= 1"),
    ("folding_removal.py", ["--max-rounds", "-1"], "argument --max-rounds: must be >= 0"),
    ("registration.py", ["--robust-scale", "foo"], "argument --robust-scale: expected a number"),
    ("registration.py", ["--sheet-width", "0"], "argument --sheet-width: must be >= 1"),
])
def test_demo_options_are_checked_before_the_work(tmp_path, script, args, words):
    """A wrong option value stops a demo at once with exit code 1 (the registration demo's
    docstring: 'the arguments are wrong'), one line naming the option, no traceback: not
    argparse's 'invalid <lambda> value', nor a traceback from matplotlib after the renders."""
    args = [str(tmp_path / "out") if a == "OUT" else a for a in args]
    proc = _run([DEMOS / script, *args], tmp_path, timeout=120)
    assert proc.returncode == 1, proc.stderr[-2000:]
    assert words in proc.stderr and "Traceback" not in proc.stderr, proc.stderr[-2000:]
    assert not (tmp_path / "out").exists()
