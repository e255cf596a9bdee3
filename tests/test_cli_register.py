"""igl-spheremap register and resample, end to end in subprocesses."""

import json
import os
import subprocess
import sys
from pathlib import Path

import igl
import nibabel as nib
import nibabel.freesurfer as fs
import numpy as np

FISH = Path(__file__).parent / "data" / "fish_lowres.obj"


def run(*args, cwd=None):
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    return subprocess.run([sys.executable, "-m", "igl_spheremap", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, env=env, timeout=600)


def test_register_a_retriangulation_carries_freesurfer_data(tmp_path):
    """A = upsample(B) (the hippocampus) as FreeSurfer surfaces (B's vertices come first in
    A); landmarks of A
    as 'x y z' rows snapped to A's vertices, of B as indices; B's thickness file carried
    to A is written as .func.gii and matches A's own values at the shared vertices."""
    V2, F2 = igl.read_triangle_mesh(str(Path(__file__).parent / "data" / "hippocampus.obj"))
    V1, F1 = igl.upsample(V2, F2)
    fs.write_geometry(str(tmp_path / "lh.a"), 50 * V1, F1)
    fs.write_geometry(str(tmp_path / "lh.b"), 50 * V2, F2)
    lm = np.arange(0, len(V2), 600)
    np.savetxt(tmp_path / "a.txt", 50 * V1[lm] + 1e-4)       # points near the vertices
    (tmp_path / "b.txt").write_text("# fish landmarks\n" + "\n".join(map(str, lm)) + "\n")
    thickness = 2.0 + V2[:, 0] / np.ptp(V2[:, 0])
    fs.write_morph_data(str(tmp_path / "lh.b.thickness"), thickness.astype(np.float32))
    r = run("register", "lh.a", "lh.b", "--landmarks", "a.txt", "b.txt", "--data",
            "lh.b.thickness", "-o", "out/ab", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    rep = json.loads((tmp_path / "out" / "ab.json").read_text())
    assert rep["success"] and rep["map1"]["folds"] == rep["map2"]["folds"] == 0
    assert rep["landmark_error_max_deg"] < 1e-9
    corr = np.load(tmp_path / "out" / "ab.npz")
    assert corr["face"].shape == (len(V1),) and corr["bary"].shape == (len(V1), 3)
    assert np.array_equal(corr["landmarks1"], lm) and np.array_equal(corr["landmarks2"], lm)
    carried = nib.load(str(tmp_path / "out" / "ab.func.gii")).darrays[0].data
    assert carried.shape == (len(V1),)
    assert np.abs(carried[:len(V2)] - thickness).max() < 0.01  # 1% of its range


def test_register_without_landmarks_and_with_two(tmp_path):
    """Landmarks are optional: none, or fewer than 3 pairs, register (the rotation search aligns);
    the stages are printed; the report says how many were met; a bad landmark line is an error.
    Without landmarks --descriptor-weight 0 (the term off, as it is there by default) is
    accepted."""
    r = run("register", FISH, FISH, "--descriptor-weight", "0", "-o", "none", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "aligning surface 1's map" in r.stdout and "no landmarks" in r.stdout
    rep = json.loads((tmp_path / "none.json").read_text())
    assert rep["success"] and rep["landmark_errors_deg"] == []
    assert rep["map1"]["folds"] == rep["map2"]["folds"] == 0
    (tmp_path / "a.txt").write_text("0\n5\n")
    r = run("register", FISH, FISH, "--landmarks", "a.txt", "a.txt", "-o", "two", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    rep = json.loads((tmp_path / "two.json").read_text())
    assert len(rep["landmark_errors_deg"]) == 2 and rep["landmark_error_max_deg"] < 1e-6
    (tmp_path / "b.txt").write_text("0\n5\nseven\n")
    r = run("register", FISH, FISH, "--landmarks", "b.txt", "b.txt", "-o", "x", cwd=tmp_path)
    assert r.returncode == 1 and "1 line of" in r.stderr and "line 3" in r.stderr
    assert "Traceback" not in r.stderr and not (tmp_path / "x.json").exists()


def test_resample_puts_the_surface_on_an_icosphere(tmp_path):
    V, F = igl.read_triangle_mesh(str(FISH))
    np.save(tmp_path / "x.npy", V[:, 1])
    r = run("resample", FISH, "--ico", "3", "--data", "x.npy", "-o", "fish_ico3.obj",
            cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    W, T = igl.read_triangle_mesh(str(tmp_path / "fish_ico3.obj"))
    assert W.shape == (642, 3) and T.shape == (1280, 3)
    d2, _, _ = igl.point_mesh_squared_distance(W, V, F)
    assert np.sqrt(d2.max()) < 1e-9 * np.ptp(V, axis=0).max()   # on the input surface
    y = np.load(tmp_path / "fish_ico3_data.npz")["x"]
    assert np.abs(y - W[:, 1]).max() < 1e-9                      # a linear function: exact


def _fish_onto_itself_with(tmp_path, option, good, bad, refusal):
    """The fish onto itself with 8 landmarks and ``option good...`` stays the identity (each
    vertex lands on itself); ``option bad`` is refused by the parser with ``refusal``, before
    anything is read or written."""
    (tmp_path / "a.txt").write_text("\n".join(map(str, range(0, 945, 118))) + "\n")
    r = run("register", FISH, FISH, "--landmarks", "a.txt", "a.txt", option, *good, "-o", "d",
            cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    corr = np.load(tmp_path / "d.npz")
    V, F = igl.read_triangle_mesh(str(FISH))
    X = np.einsum("ij,ijk->ik", corr["bary"], V[F[corr["face"]]])
    assert np.abs(X - V).max() < 1e-6 * np.ptp(V, axis=0).max()
    r = run("register", FISH, FISH, option, bad, "-o", "e", cwd=tmp_path)
    assert r.returncode == 1 and refusal in r.stderr
    assert not any(tmp_path.glob("e.*"))


def test_register_with_the_descriptor_term(tmp_path):
    """--descriptor-weight turns the harmonic landmark descriptors on; a negative weight is refused."""
    _fish_onto_itself_with(tmp_path, "--descriptor-weight", ["300"], "-1",
                           "--descriptor-weight: must be >= 0")


def test_register_with_the_robust_penalty(tmp_path):
    """--robust-scale charges the last stage's distortion by the robust penalty, 'auto' where the
    map is near-isometric, 'off' never (the identity stays the identity: its distortion is 0
    either way); a scale of 0 or below is refused."""
    _fish_onto_itself_with(tmp_path, "--robust-scale", ["0.01"], "0",
                           "--robust-scale: must be > 0")
    for value in ("auto", "off"):
        _fish_onto_itself_with(tmp_path, "--robust-scale", [value], "-1",
                               "--robust-scale: must be > 0")


def test_register_with_coarse_levels(tmp_path):
    """--coarse-levels runs the distortion stage on coarse versions of A first; a level of 0
    vertices is refused."""
    _fish_onto_itself_with(tmp_path, "--coarse-levels", ["100", "300"], "0",
                           "--coarse-levels: must be >= 1")


def test_register_in_one_process(tmp_path):
    """--workers 1 runs every stage in the command's own process (the identity as with the
    default); 0 workers are refused."""
    _fish_onto_itself_with(tmp_path, "--workers", ["1"], "0", "--workers: must be >= 1")


def test_register_defaults_and_no_coarse_levels(tmp_path):
    """By default (8 landmark pairs) register runs the coarse levels and the descriptor term,
    then a stage without it; --no-coarse-levels runs none; --descriptor-weight 0 no term.  The
    help states the library's defaults."""
    from igl_spheremap.uses.coarse_to_fine import LEVELS
    from igl_spheremap.uses.correspondence import DESCRIPTOR_MIN_LANDMARKS, DESCRIPTOR_WEIGHT
    (tmp_path / "a.txt").write_text("\n".join(map(str, range(0, 945, 118))) + "\n")
    messages = {}
    for name, extra in (("d", []), ("n", ["--no-coarse-levels", "--descriptor-weight", "0"])):
        r = run("register", FISH, FISH, "--landmarks", "a.txt", "a.txt", *extra, "-o", name,
                cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        messages[name] = json.loads((tmp_path / f"{name}.json").read_text())["message"]
    assert "vertices of surface 1: energy" in messages["d"]
    assert "descriptor term off" in messages["d"]
    assert "vertices of surface 1" not in messages["n"] and "descriptor" not in messages["n"]
    text = " ".join(run("register", "--help").stdout.split())
    assert f"(default: {' '.join(map(str, LEVELS))})" in text
    assert (f"default: {DESCRIPTOR_WEIGHT:g} with at least {DESCRIPTOR_MIN_LANDMARKS} landmark "
            "pairs") in text


def test_of_two_surfaces_the_invalid_one_is_named(tmp_path):
    """register and register-sphere read two meshes; an open one (the fish without a face)
    is exit 2 with the validation's message, prefixed by which input and which file it is."""
    V, F = igl.read_triangle_mesh(str(FISH))
    good, open_ = tmp_path / "good.obj", tmp_path / "holed.obj"
    igl.write_triangle_mesh(str(good), V, F)
    igl.write_triangle_mesh(str(open_), V, F[1:])
    r = run("register", good, open_, "-o", tmp_path / "reg", cwd=tmp_path)
    assert r.returncode == 2
    assert f"surface 2 '{open_}': invalid mesh" in r.stderr and "3 boundary edges" in r.stderr
    r = run("register", open_, good, "-o", tmp_path / "reg", cwd=tmp_path)
    assert r.returncode == 2 and f"surface 1 '{open_}': invalid mesh" in r.stderr
    np.save(tmp_path / "f.npy", V[:, 0])
    r = run("register-sphere", good, "--features", tmp_path / "f.npy", "--target", open_,
            "--target-features", tmp_path / "f.npy", "-o", tmp_path / "reg.surf.gii", cwd=tmp_path)
    assert r.returncode == 2 and f"the target sphere '{open_}': invalid mesh" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.npy", "good.obj", "holed.obj"]


def test_weight_with_hard_mode_is_refused_in_the_options_words(tmp_path):
    """--weight is the spring stiffness of --mode soft; with the default --mode hard it is
    refused naming the CLI's options (not the library's landmark_tol or mode='soft'), before
    any output is written."""
    proc = run("register", FISH, FISH, "-o", tmp_path / "out", "--weight", "5")
    assert proc.returncode == 1
    assert "--weight" in proc.stderr and "--mode soft" in proc.stderr, proc.stderr
    assert "landmark_tol" not in proc.stderr
    assert not list(tmp_path.iterdir())


def test_descriptor_weight_without_landmarks_is_refused(tmp_path):
    """The descriptor term is built from the --landmarks pairs alone (not from the pairs the
    alignment finds), so without landmarks a weight above 0 would change nothing: it is refused
    naming both options, before any output is written, and the help says so.  0 (off) is what
    happens anyway and stays accepted (test_register_without_landmarks_and_with_two)."""
    proc = run("register", FISH, FISH, "-o", tmp_path / "out", "--descriptor-weight", "300")
    assert proc.returncode == 1, proc.stderr
    assert "--descriptor-weight" in proc.stderr and "--landmarks" in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr
    assert not list(tmp_path.iterdir())
    text = " ".join(run("register", "--help").stdout.split())
    assert "refused above 0 without --landmarks" in text


def test_coarse_levels_too_large_for_surface_1_are_refused(tmp_path):
    """--coarse-levels 5000 on the fish (945 vertices) used to be skipped without a word; the
    library's refusal is reported like the command's other errors (exit 1, one line naming the
    count of offending levels and the largest allowed), before any output is written."""
    proc = run("register", FISH, FISH, "-o", tmp_path / "out", "--coarse-levels", "100", "5000")
    assert proc.returncode == 1, proc.stderr
    assert "1 coarse level above half of surface 1's 945 vertices" in proc.stderr, proc.stderr
    assert "at most 472" in proc.stderr and "Traceback" not in proc.stderr
    assert not list(tmp_path.iterdir())
    text = " ".join(run("register", "--help").stdout.split())
    assert "each from 4 to half of A's vertices" in text


def _symmetric_dirichlet(V1, F1, X):
    """Per face of ``(V1, F1)``, ``(s1^2 + s2^2 + s1^-2 + s2^-2) / 4`` of the affine map onto the
    triangle of ``X`` (images of the corners), from the two first fundamental forms: the
    ``s^2`` are the eigenvalues of ``G1^-1 G2``, so the sum is ``tr(G1^-1 G2) + tr(G2^-1 G1)``."""
    def gram(P):
        E = np.stack([P[F1[:, 1]] - P[F1[:, 0]], P[F1[:, 2]] - P[F1[:, 0]]], axis=2)  # (m, 3, 2)
        return np.einsum("mki,mkj->mij", E, E)
    G1, G2 = gram(V1), gram(X)
    return (np.trace(np.linalg.solve(G1, G2), axis1=1, axis2=2)
            + np.trace(np.linalg.solve(G2, G1), axis1=1, axis2=2)) / 4.0


def test_register_reports_the_median_distortion_of_the_map_between_the_surfaces(tmp_path):
    """The fish onto a stretched copy, no landmarks: the report's median, 90th percentile and
    largest distortion are those of the written correspondence (computed here from the first
    fundamental forms, both surfaces at equal area), and the printed line gives the median, not
    the mean that a few crushed faces can dominate."""
    V, F = igl.read_triangle_mesh(str(FISH))
    W = V * np.array([1.3, 1.0, 0.8])
    igl.write_triangle_mesh(str(tmp_path / "stretched.obj"), W, F)
    r = run("register", FISH, "stretched.obj", "-o", "s", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    rep = json.loads((tmp_path / "s.json").read_text())
    corr = np.load(tmp_path / "s.npz")
    X = np.einsum("ij,ijk->ik", corr["bary"], W[F[corr["face"]]])
    scale = np.sqrt(igl.doublearea(V, F).sum() / igl.doublearea(W, F).sum())
    d = _symmetric_dirichlet(V, F, X * scale)
    assert np.median(d) > 1.005  # a stretch: not the identity's 1
    for key, value in (("median", np.median(d)), ("p90", np.percentile(d, 90)),
                       ("max", d.max()), ("mean", d.mean())):
        assert abs(rep[f"distortion_{key}"] - value) <= 1e-6 * value, key
    assert f"median {rep['distortion_median']:.3g}," in r.stdout
    assert "mean distortion" not in r.stdout
