"""Awkward inputs a newcomer tried (issue #21, items 5 and 6): each gets a clear refusal that
names the problem (and the count, file and line where there are some), or the right answer;
no file is left behind."""

import os
import subprocess
import sys
from pathlib import Path

import igl
import nibabel as nib
import nibabel.freesurfer as fs
import numpy as np
import pytest

from igl_spheremap import count_folds
from igl_spheremap.app.batch import map_batch
from igl_spheremap.io import read_landmarks, read_vertex_data, write_mesh
from igl_spheremap.mesh.shapes import icosphere

DATA = Path(__file__).parent / "data"


def run(*args, cwd):
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    return subprocess.run([sys.executable, "-m", "igl_spheremap", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, env=env, timeout=600)


# ------------------------------------------------------------------------- landmarks

def test_landmark_points_far_from_the_surface_are_refused_with_file_and_line(tmp_path):
    V, F = icosphere(3)
    path = tmp_path / "l.txt"
    diag = np.linalg.norm(V.max(axis=0) - V.min(axis=0))
    far = V[7] + 0.25 * diag * V[7]  # a quarter of the model away, outward
    path.write_text(f"# three points\n{V[3][0]} {V[3][1]} {V[3][2]}\n12\n"
                    f"{far[0]} {far[1]} {far[2]}\n")
    with pytest.raises(ValueError, match=r"1 'x y z' row .* not on the surface.*line 4.*vertex 7"):
        read_landmarks(path, V, F)
    near = V[7] + 1e-3 * V[7]
    path.write_text(f"{V[3][0]} {V[3][1]} {V[3][2]}\n12\n{near[0]} {near[1]} {near[2]}\n")
    lm, d = read_landmarks(path, V, F, return_distances=True)
    assert lm.tolist() == [3, 12, 7]
    assert d[0] == 0.0 and d[1] == 0.0 and d[2] == pytest.approx(1e-3 * np.linalg.norm(V[7]))


def test_landmark_files_with_a_bom_are_read_and_binary_ones_named(tmp_path):
    V, F = icosphere(2)
    path = tmp_path / "bom.txt"
    path.write_bytes("\ufeff5\n9\n".encode("utf-8"))
    assert read_landmarks(path, V, F).tolist() == [5, 9]
    path = tmp_path / "bin.txt"
    path.write_bytes(np.arange(5, dtype=np.int64).tobytes())
    with pytest.raises(ValueError, match="binary file"):
        read_landmarks(path, V, F)


def test_a_landmark_file_that_lists_no_landmark_is_refused(tmp_path):
    """An empty list is a wrong or truncated file, not a request for a map without landmarks
    (which leaves the files out): `register` used to run one without a word."""
    V, F = icosphere(1)
    path = tmp_path / "l.txt"
    path.write_text("# no rows yet\n\n")
    with pytest.raises(ValueError, match=r"'.*l\.txt' lists no landmarks"):
        read_landmarks(path, V, F)
    mesh = tmp_path / "ico.obj"
    igl.write_triangle_mesh(str(mesh), V, F)
    r = run("register", mesh, mesh, "--landmarks", path, path, "-o", tmp_path / "out", "-q",
            cwd=tmp_path)
    assert r.returncode == 1 and "lists no landmarks" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ico.obj", "l.txt"]


def test_a_landmark_index_beyond_int64_is_out_of_range(tmp_path):
    """'1e30' reads as an integer-valued float: an out-of-range index, not an OverflowError."""
    V, F = icosphere(1)
    path = tmp_path / "l.txt"
    path.write_text("0\n5\n1e30\n")
    with pytest.raises(ValueError, match=r"1 landmark index in .* outside 0..41 \(first: "
                                         r"line 3\)"):
        read_landmarks(path, V, F)


def damaged_data_files(tmp_path):
    """A per-vertex function of 42 vertices in three formats, each damaged as a cut or garbled
    file would be: ``(path, the exception its third-party reader raised before)``."""
    x = np.linspace(-1.0, 1.0, 42)
    np.savez(tmp_path / "f.npz", a=x)
    data = (tmp_path / "f.npz").read_bytes()
    (tmp_path / "cut.npz").write_bytes(data[:len(data) // 2])
    import nibabel.gifti as gifti
    nib.save(gifti.GiftiImage(darrays=[gifti.GiftiDataArray(x.astype(np.float32))]),
             str(tmp_path / "f.func.gii"))
    text = (tmp_path / "f.func.gii").read_text()
    (tmp_path / "cut.func.gii").write_text(text[:len(text) // 2])
    fs.write_morph_data(str(tmp_path / "lh.f"), x.astype(np.float32))
    (tmp_path / "lh.cut").write_bytes((tmp_path / "lh.f").read_bytes()[:6])
    return [(tmp_path / "cut.npz", "BadZipFile"), (tmp_path / "cut.func.gii", "ExpatError"),
            (tmp_path / "lh.cut", "IndexError")]


def test_damaged_per_vertex_data_is_a_value_error_naming_the_file(tmp_path):
    """numpy, zipfile, expat and nibabel raised their own exception types here, which the
    command line showed as a traceback."""
    for path, raised_before in damaged_data_files(tmp_path):
        with pytest.raises(ValueError, match=rf"cannot read per-vertex data from '.*{path.name}': "
                                             rf"{raised_before}"):
            read_vertex_data(path, 42)


def test_a_damaged_result_file_is_a_value_error_naming_the_file(tmp_path):
    """A cut result file raised zipfile's BadZipFile; the whole one reads back the map."""
    from igl_spheremap import spherical_conformal_map
    from igl_spheremap.io import load_result, save_result
    V, F = icosphere(1)
    result = spherical_conformal_map(V, F)
    save_result(tmp_path / "r.npz", result)
    np.testing.assert_array_equal(load_result(tmp_path / "r.npz").U, result.U)
    data = (tmp_path / "r.npz").read_bytes()
    (tmp_path / "cut.npz").write_bytes(data[:len(data) // 2])
    with pytest.raises(ValueError, match=r"cannot read the result file '.*cut.npz': BadZipFile"):
        load_result(tmp_path / "cut.npz")
    with pytest.raises(FileNotFoundError):
        load_result(tmp_path / "none.npz")


def test_a_freesurfer_surface_is_not_per_vertex_data(tmp_path):
    V, F = icosphere(2)
    fs.write_geometry(str(tmp_path / "lh.white"), V, F)
    with pytest.raises(ValueError, match="FreeSurfer surface .* not per-vertex data"):
        read_vertex_data(tmp_path / "lh.white", len(V))
    fs.write_morph_data(str(tmp_path / "lh.sulc"), np.arange(len(V), dtype=np.float32))
    X, _ = read_vertex_data(tmp_path / "lh.sulc", len(V))  # morphometry still reads
    assert np.array_equal(X, np.arange(len(V)))


# ------------------------------------------------------------------------- writing

def test_float32_overflow_is_refused_and_no_file_is_left(tmp_path):
    V, F = icosphere(1)
    for name in ("lh.sphere", "x.surf.gii"):
        with pytest.raises(ValueError, match="beyond the float32 range"):
            write_mesh(tmp_path / name, 1e39 * V, F)
    assert not list(tmp_path.iterdir())
    write_mesh(tmp_path / "x.obj", 1e39 * V, F)  # float64 text stores it
    assert np.allclose(igl.read_triangle_mesh(str(tmp_path / "x.obj"))[0], 1e39 * V, rtol=1e-15)


def test_faces_that_do_not_index_the_vertices_are_refused_and_no_file_is_left(tmp_path):
    """An index past the last vertex, a negative one and a fractional one: each file would be
    refused when read back (or, for 0.5, silently hold another face); none is written."""
    V, F = icosphere(1)
    for name, G, what in (("a.obj", np.where(F == 0, 9999, F), "indices outside 0..41"),
                          ("b.ply", np.where(F == 0, -1, F), "indices outside 0..41"),
                          ("c.obj", F + 0.5, "non-integer entries")):
        with pytest.raises(ValueError, match=f"cannot write .*{name}.*{what}"):
            write_mesh(tmp_path / name, V, G)
    assert not list(tmp_path.iterdir())
    with pytest.raises(FileNotFoundError, match=r"no such folder '.*nofolder'"):
        write_mesh(tmp_path / "nofolder" / "x.obj", V, F)  # named, not the temporary file


def test_the_cli_refuses_a_radius_and_a_file_precision_before_mapping(tmp_path):
    """Refused before the mesh is even read: an open mesh (exit 2 once mapped) exits 1."""
    V, F = icosphere(2)
    mesh = tmp_path / "open.obj"
    igl.write_triangle_mesh(str(mesh), V, F[1:])
    r = run(mesh, "-o", tmp_path / "out.surf.gii", "--radius", "1e39", "--no-progress",
            cwd=tmp_path)
    assert r.returncode == 1 and "float32" in r.stderr and "radius" in r.stderr
    r = run(mesh, "-o", tmp_path / "out.obj", "--file-precision", "float32", "--no-progress",
            cwd=tmp_path)
    assert r.returncode == 1 and "stores float64" in r.stderr
    # below the smallest normal number of what the file stores: subnormal or zero coordinates
    for out, radius in (("out.surf.gii", "1e-45"), ("out.obj", "1e-320")):
        r = run(mesh, "-o", tmp_path / out, "--radius", radius, "--no-progress", cwd=tmp_path)
        assert r.returncode == 1 and "radius" in r.stderr and "in that range" in r.stderr, radius
    assert sorted(p.name for p in tmp_path.iterdir()) == ["open.obj"]


def test_stored_folds_near_the_float64_limit(tmp_path):
    """A sphere written at radius 1e308 (.obj stores every digit): its determinants would
    overflow to NaN and count no fold whatever the file holds; the count is the unit map's."""
    import warnings

    from igl_spheremap.io import stored_folds

    V, F = icosphere(2)
    U = V.copy()
    U[F[0]] *= -1.0  # reflect one face's corners: folds around them
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for X in (V, U):
            write_mesh(tmp_path / "s.obj", 1e308 * X, F)
            assert stored_folds(tmp_path / "s.obj", F) == count_folds(F, X)
    assert count_folds(F, U) > 0


def test_resample_refuses_stl_and_names_a_fractional_level(tmp_path):
    mesh = tmp_path / "fish.obj"
    mesh.write_bytes((DATA / "fish_lowres.obj").read_bytes())
    r = run("resample", mesh, "--ico", "1", "-o", tmp_path / "out.stl", cwd=tmp_path)
    assert r.returncode == 1 and "STL" in r.stderr and "resampled surface" in r.stderr
    r = run("resample", mesh, "--ico", "2.5", "-o", tmp_path / "out.obj", cwd=tmp_path)
    assert r.returncode == 1 and "whole number" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fish.obj"]


# ------------------------------------------------------------------------- batch

def test_a_batch_takes_folders_and_patterns_and_isolates_what_names_nothing(tmp_path):
    (tmp_path / "in").mkdir()
    (tmp_path / "empty").mkdir()
    (tmp_path / "in" / "fish.obj").write_bytes((DATA / "fish_lowres.obj").read_bytes())
    (tmp_path / "in" / "notes.txt").write_text("not a mesh")
    rows = map_batch([tmp_path / "in", str(tmp_path / "in" / "*.gii"), tmp_path / "empty"],
                     tmp_path / "out", n_workers=1)
    by_mesh = {Path(r["mesh"]).name: r for r in rows}
    assert by_mesh["fish.obj"]["status"] == "ok"
    assert "matches no file" in by_mesh["*.gii"]["message"]
    assert "folder with no mesh file" in by_mesh["empty"]["message"]
    assert len(rows) == 3 and (tmp_path / "out" / "summary.csv").is_file()


def test_results_print_as_summaries_not_arrays():
    from igl_spheremap import spherical_conformal_map

    V, F = icosphere(3)
    r = spherical_conformal_map(V * np.array([1.0, 1.3, 0.9]), F)
    for obj in (r, r.rounds[0], r.rounds[0].run, r.mesh):
        text = repr(obj)
        assert "array(" not in text and len(text) < 2000, text[:200]
    assert "folds=0" in repr(r) and "kind='gauss'" in repr(r.rounds[0])
    assert repr(r).startswith("SphericalMapResult(success=True, folds=0,")  # success first
    assert repr(r.rounds[0].run).startswith("Algorithm1Result(success=True, converged=True,")
    from igl_spheremap import resample
    W, T = icosphere(2)
    text = repr(resample(V, F, r.U, W, T, V[:, 0]))
    assert text == ("Resampled(V=(162, 3) float64, F=(320, 3) int64, data=(162,) float64, "
                    "face=(162,) int64, bary=(162, 3) float64)"), text


# ------------------------------------------------------------------------- GIfTI metadata

def _gifti_surface(path, V, F, meta):
    from nibabel.gifti import GiftiDataArray, GiftiImage, GiftiMetaData

    pts = GiftiDataArray(V.astype(np.float32), intent="NIFTI_INTENT_POINTSET",
                         datatype="NIFTI_TYPE_FLOAT32", meta=GiftiMetaData(meta))
    tri = GiftiDataArray(F.astype(np.int32), intent="NIFTI_INTENT_TRIANGLE",
                         datatype="NIFTI_TYPE_INT32")
    GiftiImage(darrays=[pts, tri]).to_filename(str(path))


VOLGEOM = {"VolGeomWidth": "256", "VolGeomHeight": "256", "VolGeomDepth": "256",
           "VolGeomXsize": "1", "VolGeomYsize": "1", "VolGeomZsize": "1",
           "VolGeomX_R": "-1", "VolGeomX_A": "0", "VolGeomX_S": "0",
           "VolGeomY_R": "0", "VolGeomY_A": "0", "VolGeomY_S": "-1",
           "VolGeomZ_R": "0", "VolGeomZ_A": "1", "VolGeomZ_S": "0",
           "VolGeomC_R": "1.5", "VolGeomC_A": "-17", "VolGeomC_S": "19"}


def test_a_gifti_sphere_keeps_what_describes_it_and_names_its_hemisphere(tmp_path):
    from igl_spheremap.app.map_file import map_file

    V, F = icosphere(2)
    V = V * np.array([1.0, 1.3, 0.8])
    cases = {"sub-01_hemi-R_white.surf.gii": "CortexRight",
             "100307.L.white.32k_fs_LR.surf.gii": "CortexLeft"}
    for name, structure in cases.items():
        _gifti_surface(tmp_path / name, V, F, {"Name": "/subjects/x/surf/lh.white",
                                               "UniqueID": "abc", "GeometricType": "Anatomical",
                                               "AnatomicalStructureSecondary": "GrayWhite",
                                               **VOLGEOM})
        out = tmp_path / f"out_{name}"
        map_file(tmp_path / name, out)
        pts, tri = fs_read_gifti(out)
        assert pts.meta["AnatomicalStructurePrimary"] == structure
        assert pts.meta["GeometricType"] == "Spherical"
        assert not {"Name", "UniqueID", "AnatomicalStructureSecondary"} & set(pts.meta)
        assert tri.meta["TopologicalType"] == "Closed"
    map_file(tmp_path / "sub-01_hemi-R_white.surf.gii", tmp_path / "forced.surf.gii",
             hemisphere="left")
    assert fs_read_gifti(tmp_path / "forced.surf.gii")[0].meta["AnatomicalStructurePrimary"] \
        == "CortexLeft"


def fs_read_gifti(path):
    img = nib.load(str(path))
    return (next(d for d in img.darrays if d.intent == 1008),
            next(d for d in img.darrays if d.intent == 1009))


def test_gifti_to_freesurfer_writes_the_volume_geometry(tmp_path):
    from igl_spheremap.app.map_file import map_file

    V, F = icosphere(2)
    _gifti_surface(tmp_path / "lh.white.surf.gii", V * 1.2, F, dict(VOLGEOM))
    map_file(tmp_path / "lh.white.surf.gii", tmp_path / "lh.sphere")
    *_, info = fs.read_geometry(str(tmp_path / "lh.sphere"), read_metadata=True)
    assert list(info["volume"]) == [256, 256, 256]
    assert np.allclose(info["cras"], [1.5, -17.0, 19.0])
    assert np.allclose(info["yras"], [0.0, 0.0, -1.0])
