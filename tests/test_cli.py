"""The igl-spheremap command line, end to end in subprocesses (python -m igl_spheremap)."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import igl
import nibabel as nib
import nibabel.freesurfer as fs
import numpy as np
import pytest

from igl_spheremap import MeshError, count_folds, validate_mesh
from igl_spheremap import cli
from igl_spheremap.cli import version_text
from igl_spheremap.io import read_mesh

FISH = Path(__file__).parent / "data" / "fish_lowres.obj"


def run(*args, cwd=None):
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    return subprocess.run([sys.executable, "-m", "igl_spheremap", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, env=env, timeout=600)


@pytest.fixture(scope="module")
def fish():
    return igl.read_triangle_mesh(str(FISH))


def _outward(V, F, report):
    return F[:, ::-1] if report["orientation_flipped"] else F


def test_map_fish_end_to_end(tmp_path, fish):
    V, F = fish
    out, rep_path = tmp_path / "fish_sphere.obj", tmp_path / "report.json"
    # no subcommand: "map" is implied when the first argument is a mesh path
    r = run(FISH, "-o", out, "--json", rep_path, "--data", "--no-progress")
    assert r.returncode == 0, r.stderr  # the fish maps fold-free (README results table)
    rep = json.loads(rep_path.read_text())
    assert rep["complete"] is True and rep["success"] is True
    assert (rep["vertices"], rep["faces"]) == (len(V), len(F))
    assert rep["input"] == str(FISH.absolute())
    assert rep["outputs"]["sphere"] == str(out.absolute())
    assert {"read", "map", "write", "total"} <= set(rep["timings"])
    assert {"libigl", "numpy", "nibabel"} <= set(rep["versions"])
    assert rep["options"]["method"] == "folding_free"

    U, F2 = igl.read_triangle_mesh(str(out))
    np.testing.assert_array_equal(F2, F)
    np.testing.assert_allclose(np.linalg.norm(U, axis=1), 1.0, atol=1e-9)
    # an independent look at the written sphere: fold-free (numpy determinants), and
    # conformal (the fish's Gauss map is not: its mean angle error is ~4x larger)
    det = np.linalg.det(np.stack([U[F[:, k]] for k in range(3)], axis=1))
    assert rep["folds"] == int(np.count_nonzero(det <= 0)) == 0
    angles = np.degrees(np.abs(igl.internal_angles(U, F) - igl.internal_angles(V, F)))
    assert angles.mean() == pytest.approx(rep["angle_distortion_mean_deg"], rel=1e-9)
    assert angles.mean() < 8.0
    assert len(rep["rounds"]) >= 1
    assert [r["round"] for r in rep["rounds"]] == list(range(len(rep["rounds"])))

    with np.load(tmp_path / "fish_sphere.npz") as d:
        np.testing.assert_allclose(d["theta"], np.arccos(np.clip(U[:, 2], -1, 1)), atol=1e-7)
        assert int(d["folded"].sum()) == rep["folded_vertices"]
        assert d["log_conformal_factor"].shape == (len(V),)

    lines = r.stdout.strip().splitlines()
    assert lines[0].split()[:2] == ["round", "kind"]
    assert len(lines) == 1 + len(rep["rounds"]) + 1  # header, one per round, summary
    assert str(out.absolute()) in lines[-1] and f"folds {rep['folds']}" in lines[-1]


def test_default_output_name_and_exit_code_3(tmp_path, fish):
    V, F = fish
    shutil.copy(FISH, tmp_path / "fish.obj")
    # the paper's method with no iterations at all: the Gauss map of the fish has folds and
    # nothing converged (the default would return a start fold-free by construction)
    r = run("map", "fish.obj", "--method", "paper", "--max-rounds", "0", "--max-iter", "0",
            "--json", "r.json", cwd=tmp_path)
    assert r.returncode == 3, r.stderr
    out = tmp_path / "fish_sphere.obj"
    assert out.is_file()
    rep = json.loads((tmp_path / "r.json").read_text())
    U, _ = igl.read_triangle_mesh(str(out))
    assert rep["folds"] == count_folds(_outward(V, F, rep), U) > 0
    assert rep["converged"] is False and rep["success"] is False
    err = r.stderr.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("igl-spheremap: warning:")
    assert f"{rep['folds']} folded faces" in err[0] and "Traceback" not in r.stderr

    r = run("fish.obj", "--method", "paper", "--max-rounds", "0", "--max-iter", "0",
            "--allow-folds", "-q", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout == ""
    assert "folded faces" in r.stderr  # still said, but not an error


def test_freesurfer_and_gifti_outputs(tmp_path, fish):
    V, F = fish
    fs.write_geometry(str(tmp_path / "lh.fish"), 60.0 * V, F, create_stamp="test")
    common = ("--max-rounds", "0", "--max-iter", "0", "--allow-folds", "--data", "-q")
    r = run("lh.fish", *common, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    S, F2 = fs.read_geometry(str(tmp_path / "lh.fish_sphere"))
    np.testing.assert_array_equal(F2, F)
    np.testing.assert_allclose(np.linalg.norm(S, axis=1), 100.0, rtol=1e-6)  # ?h.sphere radius
    img = nib.load(str(tmp_path / "lh.fish_sphere.func.gii"))
    assert [a.meta["Name"] for a in img.darrays] == ["log_conformal_factor", "theta", "phi",
                                                     "tex_u", "tex_v", "folded"]
    theta = img.darrays[1].data
    np.testing.assert_allclose(theta, np.arccos(np.clip(S[:, 2] / 100.0, -1, 1)), atol=1e-5)

    r = run("lh.fish", "-o", "sphere.surf.gii", "--radius", "1", *common, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    img = nib.load(str(tmp_path / "sphere.surf.gii"))
    pts = img.get_arrays_from_intent("NIFTI_INTENT_POINTSET")[0]
    np.testing.assert_array_equal(img.get_arrays_from_intent("NIFTI_INTENT_TRIANGLE")[0].data, F)
    np.testing.assert_allclose(np.linalg.norm(pts.data, axis=1), 1.0, rtol=1e-6)
    assert pts.meta["AnatomicalStructurePrimary"] == "CortexLeft"
    assert (tmp_path / "sphere.func.gii").is_file()
    # without --radius a GIfTI sphere has radius 100, like FreeSurfer's and the HCP's
    r = run("lh.fish", "-o", "sphere100.surf.gii", *common, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    img = nib.load(str(tmp_path / "sphere100.surf.gii"))
    pts = img.get_arrays_from_intent("NIFTI_INTENT_POINTSET")[0].data
    np.testing.assert_allclose(np.linalg.norm(pts, axis=1), 100.0, rtol=1e-6)


def test_gzipped_gifti_input_as_nilearn_ships_it(tmp_path, fish):
    """``white_left.gii.gz`` (nilearn's fsaverage files): mapped, the sphere an uncompressed
    ``.surf.gii`` with the input's faces; an explicit ``.surf.gii.gz`` output is gzipped."""
    from nibabel.gifti import GiftiDataArray, GiftiImage

    V, F = fish
    nib.save(GiftiImage(darrays=[
        GiftiDataArray((60.0 * V).astype(np.float32), intent="NIFTI_INTENT_POINTSET"),
        GiftiDataArray(F.astype(np.int32), intent="NIFTI_INTENT_TRIANGLE")]),
        str(tmp_path / "white_left.gii.gz"))
    r = run("white_left.gii.gz", "--no-progress", "-q", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    img = nib.load(str(tmp_path / "white_left_sphere.surf.gii"))
    np.testing.assert_array_equal(img.get_arrays_from_intent("NIFTI_INTENT_TRIANGLE")[0].data, F)
    S = img.get_arrays_from_intent("NIFTI_INTENT_POINTSET")[0].data.astype(np.float64)
    assert count_folds(F, S) == 0
    r = run("white_left.gii.gz", "-o", "s.surf.gii.gz", "--no-progress", "-q", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "s.surf.gii.gz").read_bytes()[:2] == b"\x1f\x8b"
    np.testing.assert_array_equal(nib.load(str(tmp_path / "s.surf.gii.gz")).darrays[1].data, F)


def test_missing_file_is_one_line_exit_1(tmp_path):
    r = run("map", tmp_path / "nothere.obj")
    assert r.returncode == 1
    assert r.stdout == ""
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("igl-spheremap: error:")
    assert "nothere.obj" in lines[0] and "Traceback" not in r.stderr


def test_control_bytes_of_a_damaged_file_are_escaped_in_the_message(tmp_path):
    """The message quotes the offending line; its terminal escape codes (clear screen, colour)
    must reach the terminal as text, not act on it."""
    bad = tmp_path / "esc.obj"
    bad.write_bytes(b"v 0 0 0\x1b[2J\x1b[31mHELLO\n")
    r = run(bad, "-o", tmp_path / "s.obj")
    assert r.returncode == 1 and "\x1b" not in r.stderr
    assert "'v 0 0 0\\x1b[2J\\x1b[31mHELLO'" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_open_mesh_is_one_line_exit_2(tmp_path, fish):
    V, F = fish
    igl.write_triangle_mesh(str(tmp_path / "open.obj"), V, F[:-1])
    with pytest.raises(MeshError) as info:  # what the library says about this mesh
        validate_mesh(*read_mesh(tmp_path / "open.obj")[:2])
    assert info.value.problem == "boundary"
    r = run(tmp_path / "open.obj", cwd=tmp_path)
    assert r.returncode == 2
    # one face removed from a closed mesh: its 3 edges become 1 boundary loop
    assert r.stderr.startswith("igl-spheremap: invalid mesh: the mesh is open: 3 boundary edges "
                               "in 1 boundary loop (edges per loop: 3); close the holes")
    assert len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "open_sphere.obj").exists()


def test_io_error_on_output_is_exit_1(tmp_path):
    (tmp_path / "file").write_text("")
    r = run(FISH, "-o", tmp_path / "file" / "x.obj", "--max-iter", "0", "--max-rounds", "0")
    assert r.returncode == 1
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("igl-spheremap: error:")
    assert "Traceback" not in r.stderr


def test_usage_errors_exit_1_and_help(tmp_path):
    r = run("map", FISH, "--max-rounds", "-3")
    assert r.returncode == 1 and "--max-rounds" in r.stderr
    r = run("batch", FISH)  # -o OUTDIR is required
    assert r.returncode == 1 and "outdir" in r.stderr
    r = run("--help")
    assert r.returncode == 0
    assert "batch" in r.stdout and "exit codes" in r.stdout


def test_no_mesh_maps_the_bundled_dino(monkeypatch, tmp_path):
    """`igl-spheremap` alone and `igl-spheremap -o x.obj` reach map with the bundled mesh
    (the mapping itself is replaced: the full dino run is too slow for the unit tests)."""
    import igl_spheremap.app.map_file as mf

    calls = []

    def fake_map_file(mesh, output, **kwargs):
        calls.append((Path(mesh), output))
        V, F = igl.read_triangle_mesh(str(mesh))
        raise MeshError("test", 0, f"read {len(V)} vertices")

    monkeypatch.setattr(mf, "map_file", fake_map_file)
    monkeypatch.chdir(tmp_path)
    assert cli.main([]) == 2
    assert cli.main(["-o", "x.obj"]) == 2
    assert [(p.name, o) for p, o in calls] == [("dino.obj", None), ("dino.obj", "x.obj")]
    assert calls[0][0].parent.name == "data"


def test_import_does_not_pull_polyscope_or_dask():
    code = ("import sys, igl_spheremap, igl_spheremap.cli, igl_spheremap.app.batch, "
            "igl_spheremap.io, igl_spheremap.app.map_file; "
            "bad = [m for m in ('polyscope', 'dask', 'distributed') if m in sys.modules]; "
            "assert not bad, bad")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_version_names_the_libraries_and_the_solver():
    r = run("--version")
    assert r.returncode == 0
    import numpy
    import scipy
    from importlib.metadata import version
    lines = r.stdout.strip().splitlines()
    assert lines[0] == f"igl-spheremap {version('igl-spheremap')}"
    assert f"libigl {version('libigl')}" in lines[1]
    assert f"numpy {numpy.__version__}" in lines[1] and f"scipy {scipy.__version__}" in lines[1]
    assert lines[2].startswith("H1 solver: direct = ")
    assert r.stdout.strip() == version_text()


def test_an_stl_input_without_o_gets_an_obj_sphere(tmp_path, fish):
    """STL cannot store the sphere (``-o x.stl`` is refused, below), so the default name after
    an STL input is ``<stem>_sphere.obj``: the map runs, and the file holds the merged STL
    vertices in the order ``read_mesh`` gives them, fold-free as stored."""
    V, F = fish
    igl.write_triangle_mesh(str(tmp_path / "part.stl"), V, F, igl.FileEncoding.Binary)
    r = run("part.stl", "--no-progress", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["part.stl", "part_sphere.obj"]
    Vin, Fin = read_mesh(tmp_path / "part.stl")[:2]
    U, G = igl.read_triangle_mesh(str(tmp_path / "part_sphere.obj"))
    assert U.shape == Vin.shape == V.shape and np.array_equal(G, Fin)
    assert np.allclose(np.linalg.norm(U, axis=1), 1.0) and count_folds(G, U) == 0


@pytest.mark.parametrize("args, message", [
    (["-o", "/no_such_folder_igl/x.obj"], "at the file system root"),
    (["-o", "{input}"], "would overwrite the input"),
    (["-o", "x.stl"], "STL"),
    (["--json", "{here}/file/r.json"], "Not a directory|not a folder|is a file"),
])
def test_bad_outputs_are_refused_before_the_map_runs(tmp_path, args, message):
    shutil.copy(FISH, tmp_path / "fish.obj")
    (tmp_path / "file").write_text("")
    args = [a.format(input=tmp_path / "fish.obj", here=tmp_path) for a in args]
    r = run("fish.obj", *args, "--no-progress", cwd=tmp_path)
    assert r.returncode == 1, r.stderr
    assert r.stdout == ""  # the round table never started: nothing was mapped
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("igl-spheremap: error:")
    import re
    assert re.search(message, lines[0]), lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file", "fish.obj"]
    assert not pathlib_exists("/no_such_folder_igl")


def pathlib_exists(path):
    return Path(path).exists()


def test_a_file_that_stores_folds_exits_3_and_says_why(tmp_path):
    """An icosphere with one vertex 1e-9 from a neighbour maps fold-free (float64 asked
    for), but float32 (GIfTI) rounding flips its crowded image triangles: the report
    and the exit code describe the file, counted here from the file read back."""
    from conftest import make_icosphere
    V, F = make_icosphere(3)
    a, b = F[0, 0], F[0, 1]
    V[a] = V[b] + 1e-9 * (V[a] - V[b]) / np.linalg.norm(V[a] - V[b])
    igl.write_triangle_mesh(str(tmp_path / "crowded.obj"), V, F)
    r = run("crowded.obj", "-o", "crowded.surf.gii", "--json", "r.json", "--no-progress",
            "--precision", "float64", cwd=tmp_path)  # the explicit flag overrides GIfTI's float32
    rep = json.loads((tmp_path / "r.json").read_text())
    img = nib.load(str(tmp_path / "crowded.surf.gii"))
    S = img.get_arrays_from_intent("NIFTI_INTENT_POINTSET")[0].data.astype(np.float64)
    T = img.get_arrays_from_intent("NIFTI_INTENT_TRIANGLE")[0].data
    det = np.linalg.det(np.stack([S[T[:, k]] for k in range(3)], axis=1))
    stored = int(np.count_nonzero(det <= 0))
    assert rep["folds"] == 0 and rep["folds_stored"] == stored
    if stored:
        assert r.returncode == 3 and rep["success"] is False
        assert "as stored" in rep["message"] and "float32" in rep["message"]
        assert "folded faces in the file written" in r.stderr
    else:
        assert r.returncode == 0


def test_polish_reaches_the_map_and_a_conflict_is_refused_before_writing(tmp_path):
    out, rep_path = tmp_path / "fish_sphere.obj", tmp_path / "report.json"
    r = run(FISH, "-o", out, "--json", rep_path, "--polish", "always", "--no-progress")
    assert r.returncode == 0, r.stderr
    rep = json.loads(rep_path.read_text())
    assert rep["options"]["polish"] == "always" and rep["rounds"][-1]["kind"] == "polish"
    assert "polished by the conformal descent" in rep["message"]
    bad = tmp_path / "paper.obj"
    r = run(FISH, "-o", bad, "--method", "paper", "--polish", "always", "--no-progress")
    assert r.returncode != 0 and "polish='always' needs guaranteed_path=True" in r.stderr
    assert not bad.exists()


def test_repair_line_compares_the_map_written_with_the_rounds_map():
    """The float32 repair runs on the rounds' map and the polish (a round of its own, after
    the repair) runs from the repaired map: the line's "rounds' map" is the round the map came
    from, or the last round before the polish, never the polished map the file holds."""
    from igl_spheremap.cli.map_command import repair_line

    def row(kind, angle):
        return {"kind": kind, "angle_distortion_mean_deg": angle}

    rep = {"precision": "float32", "repair": {"summary": "2047 faces were below"},
           "timings": {"map_repair": 0.2}, "angle_distortion_mean_deg": 5.723,
           "rounds": [row("gauss", 15.059), row("star", 4.763), row("polish", 5.723)], "chosen": 2}
    line = repair_line(rep)
    assert "map written 5.723 deg (the rounds' map: 4.763 deg)" in line
    # a futile last round: the map came from round 1
    rep.update(rounds=[row("gauss", 15.059), row("star", 4.763), row("star", 4.9)], chosen=1,
               angle_distortion_mean_deg=4.8)
    assert "map written 4.800 deg (the rounds' map: 4.763 deg)" in repair_line(rep)


def test_polygons_split_by_the_reader_are_reported(tmp_path):
    """An OBJ cube of six quads: the reader splits each into two triangles (libigl's fan);
    the run says so on the terminal and in the report instead of mapping silently."""
    lines = ["v 0 0 0", "v 1 0 0", "v 1 1 0", "v 0 1 0", "v 0 0 1", "v 1 0 1", "v 1 1 1",
             "v 0 1 1", "f 1 4 3 2", "f 5 6 7 8", "f 1 2 6 5", "f 2 3 7 6", "f 3 4 8 7",
             "f 4 1 5 8"]
    (tmp_path / "cube.obj").write_text("\n".join(lines) + "\n")
    r = run(tmp_path / "cube.obj", "-o", tmp_path / "c.obj", "--json", tmp_path / "c.json",
            "--no-progress")
    assert r.returncode == 0, r.stderr
    assert "note: 6 faces of the file with more than three corners were split" in r.stdout
    rep = json.loads((tmp_path / "c.json").read_text())
    assert rep["input_polygons"] == 6 and rep["faces"] == 12


def test_faces_reoriented_by_validation_are_said_on_the_terminal(tmp_path, fish):
    """Every 7th face of the fish flipped: the written sphere has the faces re-oriented
    (read back, 270 rows differ from the file's), and only the JSON said so."""
    V, F = fish
    G = F.copy()
    G[::7] = G[::7, ::-1]
    igl.write_triangle_mesh(str(tmp_path / "mixed.obj"), V, G)
    r = run(tmp_path / "mixed.obj", "-o", tmp_path / "s.obj", "--json", tmp_path / "s.json",
            "--no-progress")
    assert r.returncode == 0, r.stderr
    U, F2 = igl.read_triangle_mesh(str(tmp_path / "s.obj"))
    differ = int(np.count_nonzero((F2 != G).any(axis=1)))
    assert differ == len(G[::7])
    assert f"note: F re-oriented: {differ} of {len(G)} faces flipped" in r.stdout
    assert json.loads((tmp_path / "s.json").read_text())["reorientation"].startswith(
        f"F re-oriented: {differ} of")
