"""Tests of the registration demo (demos/registration.py, igl_spheremap.viz.registration).

The pair: the fish of tests/data as surface 2 and, as surface 1, the fish
decimated, Loop-subdivided and bent by the demo's own recipe (8 landmark
pairs).  Everything that initializes polyscope runs in a subprocess (one
OpenGL context per process); the headless tests skip, naming the Debian
packages, where Mesa EGL is missing.  They check facts that do not depend on
one run's pixels: each landmark pair has one colour on both surfaces (in the
renders, with the unlit material), the data drawn on surface 1 is surface 2's
data interpolated at the point of surface 2 that its spherical maps put under
each vertex (located here by brute force), every cell draws something, and
the printed and panel numbers are those of the maps.
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
from igl_spheremap.mesh.operators import vertex_areas
from igl_spheremap.viz.fields import chart_poles, mercator_vertices
from igl_spheremap.viz.registration.layout import HALF_SIZE, WINDOW, landmark_colors
from igl_spheremap.viz.registration.sheet import registration_png_boxes
from igl_spheremap.viz.registration.stages import CHECKS_AROUND, checker_values
from igl_spheremap.viz.style import HEADLESS_PACKAGES
from igl_spheremap.viz.layout import project

ROOT = Path(__file__).resolve().parents[1]
DEMOS = ROOT / "demos"
FISH = ROOT / "tests" / "data" / "fish_lowres.obj"
sys.path.insert(0, str(DEMOS))

import registration as demo  # noqa: E402

STAGE_LINE = re.compile(r"^stage (\d+): (.+): largest landmark error ([\d.]+) deg, "
                        r"(\d+) folded faces, median distortion ([\d.]+)$")


def _run(args, cwd, env_extra=None, timeout=300):
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [env.get("PYTHONPATH")] if p])
    env.update(env_extra or {})
    return subprocess.run([sys.executable, *map(str, args)], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    """Surface 1 (fish decimated to 1,200 faces, Loop-subdivided, bent) and surface 2 (fish),
    as files with their landmark files; the demo's own command line reads them."""
    tmp = tmp_path_factory.mktemp("pair")
    V2, F2, _ = sm.read_mesh(FISH)
    V1, F1, l1, l2 = demo.deformed_pair(V2, F2, faces=1200, k=8)
    igl.write_triangle_mesh(str(tmp / "a.obj"), V1, F1)
    V1, F1, _ = sm.read_mesh(tmp / "a.obj")            # as the demo will read it
    np.savetxt(tmp / "a.txt", l1, fmt="%d")
    np.savetxt(tmp / "b.txt", l2, fmt="%d")
    argv = [str(tmp / "a.obj"), str(FISH), "--landmarks", str(tmp / "a.txt"), str(tmp / "b.txt")]
    return dict(V1=V1, F1=F1, V2=V2, F2=F2, l1=l1, l2=l2, argv=argv, dir=tmp)


def _angles(A, B):
    return np.degrees(np.arccos(np.clip(np.sum(A * B, axis=1), -1.0, 1.0)))


def _median_distortion(V1, F1, X, V2, F2):
    """Area-weighted mean over the triangles of (V1, F1) of (s1^2 + s2^2 + s1^-2 + s2^-2) / 4, the
    singular values of the linear map of each triangle onto its images X on surface 2 (V2, F2),
    both surfaces scaled to area 4 pi; the singular values from the Gram matrices of the edges
    (no shared code)."""
    def areas(P, F):
        return 0.5 * np.linalg.norm(np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]]),
                                    axis=1)

    a = areas(V1, F1)
    V = V1 * np.sqrt(4 * np.pi / a.sum())
    Y = X * np.sqrt(4 * np.pi / areas(V2, F2).sum())
    E = np.stack([V[F1[:, 1]] - V[F1[:, 0]], V[F1[:, 2]] - V[F1[:, 0]]], axis=2)  # (m, 3, 2)
    G = np.stack([Y[F1[:, 1]] - Y[F1[:, 0]], Y[F1[:, 2]] - Y[F1[:, 0]]], axis=2)
    M1, M2 = np.transpose(E, (0, 2, 1)) @ E, np.transpose(G, (0, 2, 1)) @ G
    C = np.linalg.solve(M1, M2)                     # J^T J in the edge basis: eigenvalues s^2
    tr, det = np.trace(C, axis1=1, axis2=2), np.linalg.det(C)
    with np.errstate(divide="ignore"):           # a collapsed image: infinite distortion
        d = 0.25 * (tr + tr / det)                  # s1^2 + s2^2 and 1/s1^2 + 1/s2^2
    order = np.argsort(d)
    half = np.flatnonzero(np.cumsum(a[order]) >= 0.5 * a.sum())[0]
    return float(d[order][half])


# ----------------------------------------------------------------- no polyscope

def test_printed_stage_numbers_are_those_of_the_maps(pair, capsys):
    """One line per stage of surface_map (aligned, landmarks placed, distortion lowered): the
    landmark errors, folds and median distortion onto surface 2 of that stage's map, recomputed
    here (the distortion by locating the map's vertices on surface 2 by brute force)."""
    args = demo._parser().parse_args(pair["argv"])
    result, stages, _ = demo.compute(args)
    printed = [STAGE_LINE.match(line) for line in capsys.readouterr().out.splitlines()]
    printed = [(int(m.group(1)), m.group(2), float(m.group(3)), int(m.group(4)),
                float(m.group(5))) for m in printed if m]
    assert result.success, result.message
    l1, l2 = pair["l1"], pair["l2"]
    Q = result.map2.U[l2]
    assert [p[0] for p in printed] == list(range(1, len(result.stages) + 1))
    assert [p[1] for p in printed] == [s["name"] for s in result.stages]
    for (_, name, err, folds, dist), st in zip(printed, result.stages):
        U = st["U"]
        assert err == pytest.approx(_angles(U[l1], Q).max(), abs=5e-5), name
        assert folds == sm.count_folds(result.map1.F, U), name
        face, bary = _locate_brute_force(result.map2.U, result.map2.F, U)
        X = np.einsum("pk,pkd->pd", bary, pair["V2"][result.map2.F[face]])
        want = _median_distortion(pair["V1"], pair["F1"], X, pair["V2"], result.map2.F)
        assert dist == pytest.approx(want, rel=1e-3), name
    assert printed[0][2] > 0.01          # the aligned conformal map misses the targets ...
    assert printed[2][2] < 1e-4          # ... the final map meets them (hard landmarks)
    assert printed[2][4] < printed[1][4]  # and the distortion stage lowered the distortion
    np.testing.assert_array_equal(stages[-1]["U"], result.map1.U)


def test_extremity_landmarks_are_the_tips_then_farthest_points():
    """A sphere with six bumps of different heights: its extremities are the bumps' apexes,
    highest first; two more are each the vertex farthest from those already chosen."""
    V, F = sm.icosphere(3)
    axes = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1.0]])
    apex = [int(np.argmax(V @ a)) for a in axes]
    heights = [1.0, 0.9, 0.8, 0.7, 0.6, 0.5]
    r = 1.0 + sum(h * np.exp(-np.sum((V - V[i]) ** 2, axis=1) / 0.05)
                  for i, h in zip(apex, heights))
    X = V * r[:, None]
    X -= X.mean(axis=0)
    got = demo.extremity_landmarks(X, F, k=8)
    assert list(got[:6]) == apex
    for j in (6, 7):
        gap = np.min(np.linalg.norm(X[:, None] - X[got[:j]][None], axis=2), axis=1)
        assert gap[got[j]] == pytest.approx(gap.max())


def test_checker_values_are_the_parity_of_the_conformal_chart():
    """On the unit sphere with ``north`` None the chart's second coordinate is
    ``log tan(theta / 2)`` of the angle ``theta`` from the south pole (stereographic
    projection from its antipode), shifted to median 0; the checks are the parity of
    ``floor`` of both coordinates over ``2 pi / CHECKS_AROUND``."""
    V, _ = sm.icosphere(4)
    south = 7
    X = mercator_vertices(V, south)
    theta = np.arccos(np.clip(V @ V[south], -1, 1))
    ok = (theta > 1e-9) & (theta < np.pi - 1e-9)
    y = np.log(np.tan(theta[ok] / 2))
    np.testing.assert_allclose(X[ok, 1] - np.median(X[ok, 1]), y - np.median(y), atol=1e-9)
    s = 2 * np.pi / CHECKS_AROUND
    k = np.floor(X / s).astype(int)
    np.testing.assert_array_equal(checker_values(V, south), (k.sum(axis=1) % 2).astype(float))
    assert set(np.unique(checker_values(V, south))) == {0.0, 1.0}


def test_landmark_colors_are_distinct_and_not_red():
    C = landmark_colors(16)
    d = np.linalg.norm(C[:, None] - C[None], axis=-1)
    assert d[~np.eye(16, dtype=bool)].min() > 0.05
    assert not ((C[:, 0] > 0.6) & (C[:, 1] < 0.3) & (C[:, 2] < 0.3)).any()


def test_demo_needs_landmark_files_for_two_meshes(tmp_path):
    proc = _run([DEMOS / "registration.py", FISH, FISH], tmp_path)
    assert proc.returncode == 1
    assert proc.stderr.startswith("error: give two meshes and --landmarks")
    assert "Traceback" not in proc.stderr


# ----------------------------------------------------------------- polyscope

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
    proc = _run(["-c", EGL_PROBE], tmp_path_factory.mktemp("egl"))
    if "EGL OK" not in proc.stdout:
        pytest.skip(f"{proc.stdout.strip()} {proc.stderr.strip()[-500:]}".strip())


SHOT_SCRIPT = textwrap.dedent("""
    import sys
    import numpy as np
    sys.path.insert(0, sys.argv[1])
    import registration as demo
    import polyscope as ps
    from igl_spheremap.viz.registration.view import show_registration
    from igl_spheremap.viz.registration.scene import marker_name

    out = sys.argv[2]
    result, stages, up = demo.compute(demo._parser().parse_args(sys.argv[3:]))
    view = show_registration(stages, screenshot_dir=out)
    for i, reg in enumerate(view.drawn):
        arrays = dict(carried=reg["data_values"][0], data2=reg["data_values"][1],
                      U=stages[i]["U"])
        for (r, c), X in reg["markers"].items():
            arrays[f"markers_{r}{c}"] = X
            arrays[f"colors_{r}{c}"] = reg["marker_colors"][r, c]
        np.savez(f"{out}/drawn_{i:02d}.npz", **arrays)
    np.savez(f"{out}/maps.npz", U2=result.map2.U, F2=result.map2.F, U1=result.map1.U)
    for i in range(len(stages)):            # unlit landmark dots: their colours exactly
        view.set_stage(i)
        for key in view.drawn[i]["markers"]:
            ps.get_point_cloud(marker_name(*key, "dot")).set_material("flat")
        ps.screenshot(f"{out}/flat_{i:02d}.png", transparent_bg=False)
""")


@pytest.fixture(scope="module")
def shots(headless, pair):
    tmp = pair["dir"]
    (tmp / "shot.py").write_text(SHOT_SCRIPT)
    proc = _run([tmp / "shot.py", DEMOS, tmp / "out", *pair["argv"]], tmp)
    assert proc.returncode == 0, proc.stderr[-4000:]
    return tmp / "out"


def _locate_brute_force(U2, F2, X):
    """Face of the spherical mesh (U2, F2) whose cone contains each direction of X, and the
    central-projection barycentric coordinates, by testing every face: the face whose
    smallest signed volume det[x, U_j, U_k] (over the sum of the three) is largest, which
    is >= 0 only in a cone containing x."""
    A, B, C = (U2[F2[:, j]] for j in range(3))
    face, bary = np.empty(len(X), np.int64), np.empty((len(X), 3))
    for s in range(0, len(X), 128):
        x = X[s:s + 128]
        vols = np.stack([np.einsum("pj,fj->pf", x, np.cross(B, C)),
                         np.einsum("pj,fj->pf", x, np.cross(C, A)),
                         np.einsum("pj,fj->pf", x, np.cross(A, B))], axis=-1)
        total = vols.sum(axis=-1)
        score = np.where(total > 0, vols.min(axis=-1) / np.where(total > 0, total, 1), -np.inf)
        f = np.argmax(score, axis=1)
        assert (score[np.arange(len(x)), f] > -1e-9).all()
        w = np.clip(vols[np.arange(len(x)), f], 0, None)
        face[s:s + 128], bary[s:s + 128] = f, w / w.sum(axis=1, keepdims=True)
    return face, bary


def test_surface_1_shows_surface_2s_checks_where_the_maps_meet(pair, shots):
    """Surface 2 is drawn with the checkerboard of its chart (poles: chart_poles of its
    landmarks), and each vertex of surface 1 with that checkerboard interpolated at the point
    of surface 2's spherical mesh under the vertex's image, at every stage."""
    maps = np.load(shots / "maps.npz")
    U2, F2 = maps["U2"], maps["F2"]
    poles = chart_poles(U2, pair["l2"])
    X = mercator_vertices(U2, *poles, weights=vertex_areas(pair["V2"], F2))
    k = np.floor(X / (2 * np.pi / CHECKS_AROUND)).astype(int)
    checks = (k.sum(axis=1) % 2).astype(float)
    for i in range(3):
        drawn = np.load(shots / f"drawn_{i:02d}.npz")
        np.testing.assert_array_equal(drawn["data2"], checks)
        face, bary = _locate_brute_force(U2, F2, drawn["U"])
        want = np.einsum("pk,pk->p", bary, checks[F2[face]])
        # the sub-volumes are triple products known to ~1e-18 absolute, so in the fish's
        # crushed fins (image faces of volume ~1e-11) two correct computations of the
        # barycentric coordinates differ by ~1e-7; a wrong face is off by up to 1 (a check)
        np.testing.assert_allclose(drawn["carried"], want, atol=1e-6)
    last = sorted(shots.glob("drawn_*.npz"))[-1]                # the last stage is the result
    np.testing.assert_array_equal(np.load(last)["U"], maps["U1"])


#: Radius in pixels of a landmark marker's ring (0.045 * 1.35 scene units) in the screenshots.
MARKER_PX = 0.045 * 1.35 * min(WINDOW[0] / (2 * HALF_SIZE[0]), WINDOW[1] / (2 * HALF_SIZE[1]))


def test_each_landmark_pair_is_drawn_in_one_colour(pair, shots):
    """In every view the k-th marker has the k-th colour (the same on both surfaces and
    spheres), and where a marker's centre is in view in the unlit rendering its pixel has
    that colour."""
    from matplotlib.image import imread
    k = len(pair["l1"])
    want = landmark_colors(k)
    assert np.linalg.norm(want[:, None] - want[None], axis=-1)[~np.eye(k, dtype=bool)].min() > 0.05
    for i in range(3):
        drawn = np.load(shots / f"drawn_{i:02d}.npz")
        flat = imread(shots / f"flat_{i:02d}.png")[..., :3]
        for r in (0, 1):
            for c in range(4):
                np.testing.assert_array_equal(drawn[f"colors_{r}{c}"], want)
                px = np.round(project(drawn[f"markers_{r}{c}"], WINDOW,
                                      half_size=HALF_SIZE)).astype(int)
                got = flat[px[:, 1], px[:, 0]]
                hit = np.abs(got - want).max(axis=1) < 3 / 255
                other = np.abs(got[:, None] - want[None]).max(axis=-1) < 3 / 255
                # no marker shows another pair's colour, unless that marker covers it
                gap = np.linalg.norm(px[:, None] - px[None], axis=-1) + 1e9 * np.eye(k)
                alone = gap.min(axis=1) > 2 * MARKER_PX
                assert not (other & ~np.eye(k, dtype=bool))[alone].any(), (i, r, c)
                if c in (1, 2):          # on a sphere: every marker on the near half shows
                    near = drawn[f"markers_{r}{c}"][:, 2] > 0.05
                    assert hit[near & alone].all(), (i, r, c, hit, near, alone)
                else:                    # on a surface: most (the tips are on its outline)
                    assert hit.sum() >= k // 2, (i, r, c, hit)


def test_every_cell_draws_and_the_pngs_are_annotated(shots):
    from matplotlib.image import imread
    boxes = registration_png_boxes(WINDOW)
    for i in range(3):
        img = imread(shots / f"stage_{i:02d}.png")[..., :3]
        assert img.shape[:2] == boxes["size"]
        for r in (0, 1):
            t, b, l, rr = boxes["render"][r]
            cells = np.array_split(img[t:b, l:rr], 4, axis=1)
            for c, cell in enumerate(cells):
                fg = np.abs(cell - 1.0).max(axis=-1) > 0.06
                assert fg.mean() > 0.03, (i, r, c, fg.mean())
        t, b, l, rr = boxes["title"]
        assert (img[t:b, l:rr].max(axis=-1) < 0.5).mean() > 0.01      # the title's text
        t, b, l, rr = boxes["legend"]
        bar = img[t:b, l:rr]
        assert np.unique(np.round(bar.reshape(-1, 3), 1), axis=0).shape[0] >= 2
    sheet = imread(shots / "contact_sheet.png")
    assert sheet.shape[1] == 1800
    # the stages' surface-1 rows, then surface 2's row and the legend
    count = len(list(shots.glob("stage_*.png")))
    h = boxes["render"][0][1] * count + boxes["size"][0] - boxes["headers"][1][0]
    assert sheet.shape[0] == pytest.approx(h * 1800 / WINDOW[0], abs=3)


def test_headless_failure_names_packages(pair, tmp_path):
    env = {"__EGL_VENDOR_LIBRARY_FILENAMES": str(tmp_path / "no_such_vendor.json"),
           "DISPLAY": "", "WAYLAND_DISPLAY": ""}
    proc = _run([DEMOS / "registration.py", *pair["argv"], "--screenshots", tmp_path / "s"],
                tmp_path, env)
    assert proc.returncode == 2
    assert "apt-get install -y " + " ".join(HEADLESS_PACKAGES) in proc.stderr
    assert not (tmp_path / "s" / "stage_00.png").exists()
    assert "surface_map:" not in proc.stdout          # it stopped before computing the maps


MOCK_SCRIPT = textwrap.dedent("""
    import json, sys
    import numpy as np
    sys.path.insert(0, sys.argv[1])
    import registration as demo
    import polyscope as ps
    from igl_spheremap.viz.registration.view import show_registration
    from igl_spheremap.viz.registration.scene import marker_name, structure_name

    result, stages, up = demo.compute(demo._parser().parse_args(sys.argv[3:]))
    view = show_registration(stages, backend="openGL_mock", interactive=False)
    out = dict(backend=ps.get_render_engine_backend_name(), frames_after_show=view.frames,
               shown_first=view.index, stages=[])
    ps.set_frame_tick_limit_fps_mode("ignore_limits")
    for i in range(len(stages)):
        reg = view.set_stage(i)
        ps.frame_tick()
        np.savez(f"{sys.argv[2]}/mock_{i}.npz", U=stages[i]["U"], carried=reg["data_values"][0])
        out["stages"].append(dict(
            name=stages[i]["name"], lines=view.lines(),
            meshes=[ps.has_surface_mesh(structure_name(r, c)) for r in (0, 1) for c in range(4)],
            markers=[ps.has_point_cloud(marker_name(r, c, p)) for r in (0, 1) for c in range(4)
                     for p in ("ring", "dot")]))
    out["frames"] = view.frames
    np.savez(f"{sys.argv[2]}/mock_maps.npz", U2=result.map2.U, F2=result.map2.F)
    print("JSON" + json.dumps(out))
""")


def test_interactive_panel_mock_backend(pair):
    """The window's panel, on polyscope's mock backend, with --data: the slider's stages, the
    numbers of each stage's map, surface 2's data file on surface 2 and carried to surface 1."""
    tmp = pair["dir"]
    data = pair["V2"][:, 2] ** 2 - pair["V2"][:, 0]          # any smooth field of surface 2
    np.save(tmp / "field.npy", data)
    (tmp / "mock.py").write_text(MOCK_SCRIPT)
    proc = _run([tmp / "mock.py", DEMOS, tmp, *pair["argv"], "--data", tmp / "field.npy"], tmp)
    assert proc.returncode == 0, proc.stderr[-4000:]
    out = json.loads(proc.stdout.split("JSON", 1)[1])
    assert out["backend"] == "openGL_mock"
    assert out["frames_after_show"] == 1 and out["frames"] == 1 + len(out["stages"])
    assert out["shown_first"] == len(out["stages"]) - 1          # opens on the final map
    assert [s["name"] for s in out["stages"]] == [
        "conformal map of surface 1, aligned", "landmarks moved onto their targets",
        "distortion lowered on coarse levels of surface 1",
        "distortion between the surfaces lowered, with descriptors",
        "distortion between the surfaces lowered"]
    maps = np.load(tmp / "mock_maps.npz")
    Q = maps["U2"][pair["l2"]]
    for i, st in enumerate(out["stages"]):
        assert all(st["meshes"]) and all(st["markers"])
        mock = np.load(tmp / f"mock_{i}.npz")
        U = mock["U"]
        err = _angles(U[pair["l1"]], Q)
        assert st["lines"][0] == f"largest landmark error: {err.max():.4f}°"
        folds = sm.count_folds(pair["F1"], U)
        assert st["lines"][2].startswith(f"folded faces of surface 1's map: {folds} of ")
        assert any(line.startswith("data: field of surface 2") for line in st["lines"])
        face, bary = _locate_brute_force(maps["U2"], maps["F2"], U)
        np.testing.assert_allclose(mock["carried"],
                                   np.einsum("pk,pk->p", bary, data[maps["F2"][face]]),
                                   atol=1e-6 * np.abs(data).max())     # see above


def test_every_distortion_stage_has_the_kind_distortion(pair):
    """build_registration_stages documents kinds "aligned", "deformed", "distortion"; the
    stages that lower the distortion (coarse levels, with descriptors, the last) are all
    "distortion", the one stage before the landmarks move is "aligned", and "deformed" is the
    stage whose landmarks first meet their targets (hard mode)."""
    from igl_spheremap.viz import build_registration_stages

    result = sm.surface_map(pair["V1"], pair["F1"], pair["V2"], pair["F2"], pair["l1"],
                            pair["l2"])
    stages = build_registration_stages(result, pair["V1"], pair["V2"], pair["l1"], pair["l2"])
    assert len(stages) >= 4, "premise: the pair runs the coarse levels or the descriptors"
    Q = result.map2.U[pair["l2"]]
    met = [_angles(st["U"][pair["l1"]], Q).max() < 1e-4 for st in stages]
    assert met == [False] + [True] * (len(stages) - 1)
    kinds = [st["kind"] for st in stages]
    assert kinds == ["aligned", "deformed"] + ["distortion"] * (len(stages) - 2)


def test_a_landmark_half_hidden_behind_the_outline_is_numbered():
    """A dot whose centre is behind a surface but whose rim shows above the surface's outline
    is seen in the PNG, so it gets its number; a dot wholly behind the surface does not, and one
    in front of it does. The surface: a flat square x in [-1, 1], y in [-1, 0] at z = 0, facing
    the viewer (+z); the dots 0.2 behind it or 0.2 in front."""
    from igl_spheremap.viz.registration.layout import WINDOW
    from igl_spheremap.viz.registration.scene import MARKER_RADIUS
    from igl_spheremap.viz.registration.sheet import visible_markers

    P = np.array([[-1.0, -1, 0], [1, -1, 0], [1, 0, 0], [-1, 0, 0]])
    F = np.array([[0, 1, 2], [0, 2, 3]])
    edge = -0.5 * MARKER_RADIUS          # centre under the top edge, rim above it
    X = np.array([[0.0, edge, -0.2], [0.0, -0.5, -0.2], [0.0, -0.5, 0.2], [0.0, 0.5, -0.2]])
    key = (0, 0)
    registered = dict(markers={key: X}, positions={key: P}, faces={0: F})
    assert visible_markers(registered, key, WINDOW).tolist() == [True, False, True, True]
