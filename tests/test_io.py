"""Mesh and per-vertex data I/O: round trips through libigl, GIfTI and FreeSurfer via nibabel."""

import json
from collections import OrderedDict
from pathlib import Path

import igl
import nibabel as nib
import nibabel.freesurfer as fs
import numpy as np
import pytest

from conftest import make_icosphere as icosphere
from igl_spheremap import conformal_factor
from igl_spheremap.io import (check_sphere_output, mesh_format, output_paths, read_mesh,
                              read_vertex_data, write_mesh, write_report, write_vertex_data)
from igl_spheremap.app.vertex_data import vertex_data

FISH = Path(__file__).parent / "data" / "fish_lowres.obj"


@pytest.fixture(scope="module")
def fish():
    return igl.read_triangle_mesh(str(FISH))


# --------------------------------------------------------------------------- formats


def test_mesh_format_rules(tmp_path, fish):
    V, F = fish
    fs.write_geometry(str(tmp_path / "plain_name"), V, F, create_stamp="t")
    (tmp_path / "README").write_text("not a mesh\n")
    assert mesh_format(tmp_path / "plain_name") == "freesurfer"  # magic bytes, no name rule
    assert mesh_format(tmp_path / "README") is None
    assert mesh_format("x.surf.gii", must_exist=False) == "gifti"
    assert mesh_format("X.GII", must_exist=False) == "gifti"
    assert mesh_format("x.OBJ", must_exist=False) == "mesh"
    assert mesh_format("rh.pial", must_exist=False) == "freesurfer"
    assert mesh_format("lh.sphere.reg", must_exist=False) == "freesurfer"
    assert mesh_format("notes.txt", must_exist=False) is None
    with pytest.raises(FileNotFoundError):
        mesh_format(tmp_path / "missing.obj")


def test_gifti_round_trip(tmp_path, fish):
    V, F = fish
    path = tmp_path / "fish.surf.gii"
    write_mesh(path, V, F, metadata={"gifti_meta": {"GeometricType": "Spherical"}})
    img = nib.load(str(path))  # nibabel directly
    pts = img.get_arrays_from_intent("NIFTI_INTENT_POINTSET")
    tris = img.get_arrays_from_intent("NIFTI_INTENT_TRIANGLE")
    assert len(pts) == 1 and len(tris) == 1 and len(img.darrays) == 2
    assert pts[0].data.dtype == np.float32
    np.testing.assert_array_equal(pts[0].data, V.astype(np.float32))
    np.testing.assert_array_equal(tris[0].data, F)
    assert pts[0].meta["GeometricType"] == "Spherical"

    V2, F2, family, meta = read_mesh(path, return_metadata=True)  # our reader
    assert family == "gifti"
    assert V2.dtype == np.float64 and V2.shape == V.shape
    assert F2.dtype == np.int64 and F2.shape == F.shape
    np.testing.assert_array_equal(V2, V.astype(np.float32).astype(np.float64))
    np.testing.assert_allclose(V2, V, rtol=0, atol=1e-6 * np.abs(V).max())
    np.testing.assert_array_equal(F2, F)
    assert meta["gifti_meta"]["GeometricType"] == "Spherical"


def test_gzipped_gifti_as_nilearn_ships_it(tmp_path, fish):
    """nilearn ships FreeSurfer's fsaverage as ``white_left.gii.gz``, ``sulc_left.gii.gz``:
    written here by nibabel alone, read by ours; ours written compressed, read by nibabel."""
    from nibabel.gifti import GiftiDataArray, GiftiImage

    V, F = fish
    V32 = V.astype(np.float32)
    surf = GiftiImage(darrays=[GiftiDataArray(V32, intent="NIFTI_INTENT_POINTSET"),
                               GiftiDataArray(F.astype(np.int32), intent="NIFTI_INTENT_TRIANGLE")])
    nib.save(surf, str(tmp_path / "white_left.gii.gz"))
    assert (tmp_path / "white_left.gii.gz").read_bytes()[:2] == b"\x1f\x8b"  # gzip
    assert mesh_format(tmp_path / "white_left.gii.gz") == "gifti"
    V2, F2, family = read_mesh(tmp_path / "white_left.gii.gz")
    assert family == "gifti"
    np.testing.assert_array_equal(V2, V32.astype(np.float64))
    np.testing.assert_array_equal(F2, F)

    sulc = np.linspace(-1.0, 1.0, len(V)).astype(np.float32)
    nib.save(GiftiImage(darrays=[GiftiDataArray(sulc)]), str(tmp_path / "sulc_left.gii.gz"))
    values, _ = read_vertex_data(tmp_path / "sulc_left.gii.gz", len(V))
    np.testing.assert_array_equal(values, sulc.astype(np.float64))

    write_mesh(tmp_path / "s.surf.gii.gz", V, F)
    assert (tmp_path / "s.surf.gii.gz").read_bytes()[:2] == b"\x1f\x8b"
    img = nib.load(str(tmp_path / "s.surf.gii.gz"))
    np.testing.assert_array_equal(img.get_arrays_from_intent("NIFTI_INTENT_POINTSET")[0].data, V32)
    write_vertex_data(tmp_path / "d.func.gii.gz", {"sulc": sulc})
    np.testing.assert_array_equal(nib.load(str(tmp_path / "d.func.gii.gz")).darrays[0].data, sulc)


def test_freesurfer_round_trip(tmp_path, fish):
    V, F = fish
    V = 80.0 * V  # millimetre-sized, like a cortical surface
    info = OrderedDict(head=np.array([2, 0, 20], dtype=np.int32), valid="1  # volume info valid",
                       filename="orig.mgz", volume=np.array([256, 256, 256]),
                       voxelsize=np.array([1.0, 1.0, 1.0]), xras=np.array([-1.0, 0, 0]),
                       yras=np.array([0, 0, -1.0]), zras=np.array([0, 1.0, 0]),
                       cras=np.array([1.5, -2.0, 3.25]))
    path = tmp_path / "lh.fish"
    write_mesh(path, V, F, metadata={"volume_info": info})
    V1, F1, info1 = fs.read_geometry(str(path), read_metadata=True)  # nibabel directly
    np.testing.assert_array_equal(V1, V.astype(np.float32))
    np.testing.assert_array_equal(F1, F)
    np.testing.assert_array_equal(info1["cras"], info["cras"])

    V2, F2, family, meta = read_mesh(path, return_metadata=True)  # our reader
    assert family == "freesurfer"
    assert V2.dtype == np.float64 and F2.dtype == np.int64
    np.testing.assert_array_equal(V2, V.astype(np.float32).astype(np.float64))
    np.testing.assert_allclose(V2, V, rtol=1e-6)
    np.testing.assert_array_equal(F2, F)
    np.testing.assert_array_equal(meta["volume_info"]["cras"], info["cras"])


@pytest.mark.parametrize("ext", [".obj", ".off", ".ply"])
def test_libigl_formats_round_trip(tmp_path, fish, ext):
    V, F = fish
    path = tmp_path / f"fish{ext}"
    write_mesh(path, V, F)
    V1, F1 = igl.read_triangle_mesh(str(path))
    V2, F2, family = read_mesh(path)
    assert family == "mesh"
    for Vr, Fr in ((V1, F1), (V2, F2)):
        np.testing.assert_allclose(Vr, V, rtol=0, atol=1e-12)
        np.testing.assert_array_equal(Fr, F)


def test_stl_corners_are_merged(tmp_path, fish):
    V, F = fish
    path = tmp_path / "fish.stl"
    igl.write_triangle_mesh(str(path), V, F)
    soup_V, _ = igl.read_triangle_mesh(str(path))
    assert len(soup_V) == 3 * len(F)  # libigl alone returns one vertex per corner
    V2, F2, family = read_mesh(path)
    assert family == "mesh"
    assert len(V2) == len(np.unique(V.astype(np.float32), axis=0))
    assert F2.shape == F.shape
    # same triangles, corner by corner (STL stores float32)
    np.testing.assert_allclose(V2[F2], V[F], rtol=0, atol=1e-6)


def test_read_errors_are_clear_and_quiet(tmp_path, capfd):
    with pytest.raises(FileNotFoundError, match="missing.obj"):
        read_mesh(tmp_path / "missing.obj")
    (tmp_path / "garbage.obj").write_text("hello world\n")
    with pytest.raises(ValueError, match="no triangles"):
        read_mesh(tmp_path / "garbage.obj")
    (tmp_path / "notes.txt").write_text("hello\n")
    with pytest.raises(ValueError, match="cannot tell the mesh format"):
        read_mesh(tmp_path / "notes.txt")
    write_vertex_data(tmp_path / "data.func.gii", {"a": np.zeros(3)})
    with pytest.raises(ValueError, match="POINTSET"):
        read_mesh(tmp_path / "data.func.gii")
    # the checks raise before libigl prints anything of its own on stderr
    assert capfd.readouterr().err == ""


def test_failed_write_leaves_old_file_and_no_temporary(tmp_path, fish, monkeypatch):
    V, F = fish
    path = tmp_path / "lh.sphere"
    path.write_bytes(b"old")

    def broken_write(filepath, *args, **kwargs):
        Path(filepath).write_bytes(b"\xff\xff\xfe partial")
        raise OSError("disk full")

    monkeypatch.setattr(fs, "write_geometry", broken_write)
    with pytest.raises(OSError, match="disk full"):
        write_mesh(path, V, F)
    assert path.read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lh.sphere"]

    with pytest.raises(ValueError, match="cannot write"):
        write_mesh(tmp_path / "fish.xyz", V, F, family="mesh")  # libigl refuses .xyz
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lh.sphere"]


# --------------------------------------------------------------------------- per-vertex data


def test_vertex_data_quantities():
    V, F = icosphere(2)
    U = V.copy()
    # swap the images of two adjacent vertices: the faces around them flip
    a, b = F[0, 0], F[0, 1]
    U[[a, b]] = U[[b, a]]
    d = vertex_data(V, F, U)
    assert list(d) == ["log_conformal_factor", "theta", "phi", "tex_u", "tex_v", "folded"]
    # independent fold test: sign of det[U_i, U_j, U_k]
    det = np.linalg.det(np.stack([U[F[:, 0]], U[F[:, 1]], U[F[:, 2]]], axis=1))
    expected = np.zeros(len(V), bool)
    expected[F[det <= 0].ravel()] = True
    assert expected.any()
    np.testing.assert_array_equal(d["folded"], expected)
    np.testing.assert_allclose(d["log_conformal_factor"], 0.5 * np.log(conformal_factor(V, F, U)))
    np.testing.assert_allclose(d["theta"], np.arccos(np.clip(U[:, 2], -1, 1)), atol=1e-12)
    d0 = vertex_data(V, F, V)
    assert not d0["folded"].any()


def test_log_conformal_factor_of_identity_map():
    """Identity map of an inscribed polyhedron: the image is the input itself, so with the
    input scaled to area 4 pi the factor is the same at every vertex, area(V) / (4 pi)."""
    V, F = icosphere(2)
    u = vertex_data(V, F, V)["log_conformal_factor"]
    area = igl.doublearea(V, F).sum() / 2.0
    np.testing.assert_allclose(np.exp(2.0 * u), area / (4.0 * np.pi), rtol=1e-12)


def test_vertex_data_files(tmp_path):
    V, F = icosphere(1)
    d = vertex_data(V, F, V)
    write_vertex_data(tmp_path / "d.func.gii", d, metadata={"AnatomicalStructurePrimary": "X"})
    img = nib.load(str(tmp_path / "d.func.gii"))
    assert [a.meta["Name"] for a in img.darrays] == list(d)
    assert img.meta["AnatomicalStructurePrimary"] == "X"
    for arr, (key, val) in zip(img.darrays, d.items()):
        assert arr.data.dtype == np.float32 and arr.data.shape == (len(V),)
        np.testing.assert_array_equal(arr.data, np.asarray(val, np.float32), err_msg=key)

    write_vertex_data(tmp_path / "d.npz", d)
    with np.load(tmp_path / "d.npz") as z:
        assert sorted(z.files) == sorted(d)
        assert z["folded"].dtype == bool
        for key, val in d.items():
            np.testing.assert_array_equal(z[key], val)

    with pytest.raises(ValueError, match="one length"):
        write_vertex_data(tmp_path / "e.npz", {"a": np.zeros(3), "b": np.zeros(4)})
    with pytest.raises(ValueError, match="npz"):
        write_vertex_data(tmp_path / "e.csv", {"a": np.zeros(3)})


def test_report_is_strict_json(tmp_path):
    write_report(tmp_path / "r.json", {"a": np.float64(np.nan), "b": np.arange(3),
                                       "c": np.int64(7), "d": [np.inf, 1.5], "e": tmp_path})
    text = (tmp_path / "r.json").read_text()
    rep = json.loads(text, parse_constant=lambda c: pytest.fail(f"non-standard JSON {c}"))
    assert rep == {"a": None, "b": [0, 1, 2], "c": 7, "d": [None, 1.5], "e": str(tmp_path)}


# --------------------------------------------------------------------------- output names


@pytest.mark.parametrize("name, family, sphere, data", [
    ("dino.obj", "mesh", "dino_sphere.obj", "dino_sphere.npz"),
    ("bunny.PLY", "mesh", "bunny_sphere.PLY", "bunny_sphere.npz"),
    ("lh.white", "freesurfer", "lh.white_sphere", "lh.white_sphere.func.gii"),
    ("sub-01_hemi-L_white.surf.gii", "gifti", "sub-01_hemi-L_white_sphere.surf.gii",
     "sub-01_hemi-L_white_sphere.func.gii"),
    ("cortex.gii", "gifti", "cortex_sphere.surf.gii", "cortex_sphere.func.gii"),
    ("white_left.gii.gz", "gifti", "white_left_sphere.surf.gii", "white_left_sphere.func.gii"),
    ("lh.white.surf.gii.gz", "gifti", "lh.white_sphere.surf.gii", "lh.white_sphere.func.gii"),
    # formats that cannot store the sphere (check_sphere_output refuses them): .obj instead
    ("part.stl", "mesh", "part_sphere.obj", "part_sphere.npz"),
    ("PART.STL", "mesh", "PART_sphere.obj", "PART_sphere.npz"),
    ("scene.wrl", "mesh", "scene_sphere.obj", "scene_sphere.npz"),
    ("volume.mesh", "mesh", "volume_sphere.obj", "volume_sphere.npz"),
    ("gmsh.msh", "mesh", "gmsh_sphere.obj", "gmsh_sphere.npz"),
])
def test_default_output_names(name, family, sphere, data):
    p = output_paths(Path("in") / name, input_family=family, outdir="out")
    assert p.family == family
    assert p.sphere == Path("out") / sphere
    assert p.data == Path("out") / data
    assert p.report == Path("out") / (sphere.split("_sphere")[0] + "_sphere.json")
    assert check_sphere_output(p.sphere) == family  # the default name is one the map can take


def test_explicit_output_names():
    p = output_paths("lh.white", "spheres/lh.sphere", input_family="freesurfer")
    assert (p.family, p.data.name, p.report.name) == ("freesurfer", "lh.sphere.func.gii",
                                                      "lh.sphere.json")
    assert output_paths("lh.white", "x.surf.gii", input_family="freesurfer").family == "gifti"
    p = output_paths("lh.white", "x.surf.gii.gz", input_family="freesurfer")
    assert (p.family, p.data.name, p.report.name) == ("gifti", "x.func.gii", "x.json")
    assert output_paths("lh.white", "x.obj", input_family="freesurfer").family == "mesh"
    assert output_paths("lh.white", "out_sphere", input_family="freesurfer").family == \
        "freesurfer"
    assert output_paths("a.obj", "rh.sphere", input_family="mesh").family == "freesurfer"
    with pytest.raises(ValueError, match="output format"):
        output_paths("a.obj", "a_sphere", input_family="mesh")
    # another tool's extension after a FreeSurfer input: a FreeSurfer binary named .vtk before
    assert output_paths("lh.white", "sub01.sphere", input_family="freesurfer").family == \
        "freesurfer"
    for name in ("subj_sphere.vtk", "subj.NII", "subj_sphere.json"):
        with pytest.raises(ValueError, match="cannot tell the output format"):
            output_paths("lh.white", name, input_family="freesurfer")


def test_file_digest_is_the_sha256_of_the_content(tmp_path):
    """Against hashlib on the whole content at once; the file is read in blocks, so one larger
    than a block is checked too.  A missing file has no digest."""
    import hashlib

    from igl_spheremap.io import file_digest
    from igl_spheremap.io.file_digest import CHUNK

    for size in (0, 7, 2 * CHUNK + 3):
        data = np.random.default_rng(size).integers(0, 256, size, dtype=np.uint8).tobytes()
        path = tmp_path / f"f{size}.bin"
        path.write_bytes(data)
        assert file_digest(path) == hashlib.sha256(data).hexdigest()
    assert file_digest(tmp_path / "missing.obj") is None


def test_what_is_not_per_vertex_data_is_named(tmp_path):
    """A mesh file, a GIfTI surface, strings and an empty archive passed as data: each refused
    with its cause (before: a row-count mismatch, a numpy concatenation or conversion error)."""
    V, F = igl.read_triangle_mesh(str(Path(__file__).parent / "data" / "fish_lowres.obj"))
    mesh, surf = tmp_path / "m.obj", tmp_path / "m.surf.gii"
    igl.write_triangle_mesh(str(mesh), V, F)
    write_mesh(surf, V, F)
    np.save(tmp_path / "s.npy", np.array(["a"] * len(V)))
    np.savez(tmp_path / "e.npz")
    for path, cause in ((mesh, r"is a mesh file \(\.obj\), not per-vertex data"),
                        (surf, "is a GIfTI surface"), (tmp_path / "s.npy", "holds <U1 values"),
                        (tmp_path / "e.npz", "holds no arrays")):
        with pytest.raises(ValueError, match=cause) as info:
            read_vertex_data(path, len(V))
        assert path.name in str(info.value)
