"""Tests of the polyscope demo (igl_spheremap.viz, demos/folding_removal.py) and demos/figures.py.

Polyscope keeps one global OpenGL context per process, so everything that
initializes it (headless EGL screenshots, the mock backend) runs in a
subprocess.  Headless rendering needs Mesa EGL; when it is missing the test
fails with the list of Debian packages to install instead of being skipped.
"""

import dataclasses
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
import folding_removal  # noqa: E402

from igl_spheremap import viz  # noqa: E402
from igl_spheremap.result_io import load_result, save_result  # noqa: E402

STAGE_LINE = re.compile(r"^stage (\d+): (.+): (\d+) folded faces$")


def _fish():
    V, F = igl.read_triangle_mesh(str(FISH))
    return np.asarray(V, np.float64), np.asarray(F, np.int64)


def _run(args, tmp_path, env_extra=None, timeout=300):
    env = dict(os.environ, MPLBACKEND="Agg")
    env.update(env_extra or {})
    # cwd=tmp_path: imgui writes imgui.ini into the working directory
    return subprocess.run([sys.executable, *map(str, args)], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def fish_run():
    """Fish through Algorithm 2 with Algorithm 1 cut to 2 iterations.

    Two iterations leave folds behind whatever the optimizer does, so the run
    has a Gauss-map round and one star-map round: four stages, with folds.
    """
    V, F = _fish()
    result = sm.spherical_conformal_map(V, F, max_rounds=1, max_iter=2)
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
    import matplotlib.pyplot as plt
    for name in ("energy.png", "grad_norm.png", "angle_histograms.png"):
        path = tmp_path / "fig" / name
        assert str(path) in proc.stdout
        img = plt.imread(path)
        assert img.ndim == 3 and img.shape[0] > 200 and img.shape[1] > 400
        assert img[..., :3].std() > 0.05          # axes, lines, bars: not an empty canvas


# --------------------------------------------------------------------- polyscope

def _strips(img):
    """The five columns of a stage screenshot (equal vertical strips)."""
    w = img.shape[1]
    return [img[:, j * w // 5:(j + 1) * w // 5] for j in range(5)]


def _foreground(img):
    bg = img[0, 0, :3]
    return np.abs(img[..., :3] - bg).max(axis=-1) > 0.06


def _red(img):
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    return (r > 0.45) & (g < 0.3) & (b < 0.3) & (r - g > 0.3)


def test_headless_screenshots(tmp_path):
    """Real pipeline on the fish, rendered with polyscope's EGL backend."""
    shots, npz = tmp_path / "shots", tmp_path / "fish.npz"
    proc = _run([DEMOS / "folding_removal.py", FISH, "--max-rounds", "1", "--max-iter", "400",
                 "--screenshots", shots, "--save-result", npz], tmp_path)
    if proc.returncode != 0:
        pytest.fail("headless polyscope demo failed (does this machine have Mesa EGL? "
                    f"apt-get install -y {' '.join(viz.HEADLESS_PACKAGES)}):\n"
                    f"{proc.stdout[-2000:]}\n{proc.stderr[-4000:]}")
    printed = [STAGE_LINE.match(line) for line in proc.stdout.splitlines()]
    printed = [(m.group(2), int(m.group(3))) for m in printed if m]
    result = load_result(npz)
    V, F = _fish()
    Fv = sm.validate_mesh(V, F).F
    expected = _expected_maps(result)
    # the folds the demo reports per stage == count_folds of that stage's map, computed here
    assert printed == [(name, sm.count_folds(Fv, U)) for name, U in expected]
    assert printed[0][1] > 0                     # the fish's Gauss map folds
    import matplotlib.pyplot as plt
    for i, (name, folds) in enumerate(printed):
        path = shots / f"stage_{i:02d}.png"
        assert str(path) in proc.stdout
        img = plt.imread(path)[..., :3]
        assert img.shape[:2] == (440, 2000)
        assert img.std() > 0.05
        fg = _foreground(img)
        assert 0.05 < fg.mean() < 0.8
        strips = _strips(img)
        for j in range(4):                       # input, sphere x2, conformal factor
            assert _foreground(strips[j]).mean() > 0.05, (name, j)
        phi_drawn = _foreground(strips[4]).mean()  # every stage but the first shows Phi^u
        if name == "Gauss map":
            assert phi_drawn == 0
        else:
            assert phi_drawn > 0.003, name
        red_on_spheres = int(_red(strips[1]).sum() + _red(strips[2]).sum())
        red_anywhere = int(sum(_red(s).sum() for s in strips[:3]))
        if folds:
            assert red_on_spheres > 20, (name, folds)
        else:
            assert red_anywhere == 0, name
    sheet = shots / "contact_sheet.png"
    assert str(sheet) in proc.stdout
    img = plt.imread(sheet)
    assert img.shape[1] >= 1500 and img.shape[0] > len(printed) * 250


def test_headless_failure_names_packages(fish_npz, tmp_path):
    """Without a usable EGL the demo stops with the Debian packages to install."""
    env = {"__EGL_VENDOR_LIBRARY_FILENAMES": str(tmp_path / "no_such_vendor.json"),
           "DISPLAY": "", "WAYLAND_DISPLAY": ""}
    proc = _run([DEMOS / "folding_removal.py", "--load-result", fish_npz,
                 "--screenshots", tmp_path / "shots"], tmp_path, env)
    assert proc.returncode == 2
    assert "apt-get install -y " + " ".join(viz.HEADLESS_PACKAGES) in proc.stderr
    assert not (tmp_path / "shots" / "stage_00.png").exists()


MOCK_SCRIPT = textwrap.dedent("""
    import json, sys
    import polyscope as ps
    from igl_spheremap import viz
    from igl_spheremap.result_io import load_result
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
            phi_enabled=ps.has_surface_mesh("Phi^u (unit size)")
                        and ps.get_surface_mesh("Phi^u (unit size)").is_enabled(),
            spheres=[ps.has_surface_mesh(n) for n in ("sphere (front)", "sphere (back)")]))
    out["frames"] = view.frames
    print("JSON" + json.dumps(out))
""")


def test_interactive_view_mock_backend(fish_run, fish_npz, tmp_path):
    V, F, result = fish_run
    script = tmp_path / "mock_show.py"
    script.write_text(MOCK_SCRIPT)
    proc = _run([script, fish_npz, DEMOS], tmp_path)
    assert proc.returncode == 0, proc.stderr[-4000:]
    out = json.loads(proc.stdout.split("JSON", 1)[1])
    assert out["backend"] == "openGL_mock"
    assert out["frames_after_show"] == 1                 # show(interactive=False) ran one frame
    assert out["frames"] == 1 + len(out["stages"])       # and the callback ran in every tick
    assert out["shown_first"] == len(out["stages"]) - 1  # the window opens on the final map
    Fv = sm.validate_mesh(V, F).F
    expected = _expected_maps(result)
    assert [s["name"] for s in out["stages"]] == [name for name, _ in expected]
    for st, (_, U) in zip(out["stages"], expected):
        folds = sm.count_folds(Fv, U)
        assert st["marked"] == st["dots"] == folds
        assert st["lines"][0] == f"folded faces: {folds} of {F.shape[0]}"
        assert st["spheres"] == [True, True]
        assert st["phi_enabled"] == (st["name"] != "Gauss map")
