"""What each output format stores of a crowded spherical map, and how many folds that has.

References are independent of the writers: folds are counted with
``count_folds`` on the exact rounding each format applies (``astype(np.float32)``
for GIfTI float32, FreeSurfer and STL; none for OBJ, OFF, PLY and GIfTI
float64), and the files are read back with libigl / nibabel / plyfile directly.
"""

import igl
import nibabel as nib
import numpy as np
import pytest
from plyfile import PlyData

from conftest import make_icosphere
from igl_spheremap import count_folds, validate_mesh
from igl_spheremap.io import STORED_PRECISION, read_mesh, stored_folds, write_mesh

EXACT = ["s.obj", "s.off", "s.ply"]
FLOAT32 = ["s.surf.gii", "lh.s", "s.stl"]


@pytest.fixture(scope="module")
def crowded():
    """Unit icosphere (level 2) with one vertex moved within 1e-9 of a neighbour, along their edge.

    The two faces on that edge keep their orientation but have areas near 5e-10;
    float32 (spacing 6e-8 near 1) merges or flips them.
    """
    V, F = make_icosphere(2)
    v = 0
    w = igl.adjacency_matrix(F).tocsr()[v].indices[0]
    V[v] = V[w] + 1e-9 * (V[v] - V[w]) / np.linalg.norm(V[v] - V[w])
    V[v] /= np.linalg.norm(V[v])
    return V, F


def test_crowded_map_folds_only_when_rounded(crowded):
    U, F = crowded
    assert count_folds(F, U) == 0
    assert igl.doublearea(U, F).min() / 2 < 1e-9
    for radius in (1.0, 100.0):
        assert count_folds(F, (radius * U).astype(np.float32).astype(np.float64)) > 0


@pytest.mark.parametrize("name", EXACT)
@pytest.mark.parametrize("radius", [1.0, 100.0])
def test_exact_formats_store_every_bit(tmp_path, crowded, name, radius):
    U, F = crowded
    W = radius * U
    path = tmp_path / name
    write_mesh(path, W, F)
    if name.endswith(".ply"):
        ply = PlyData.read(str(path))
        assert ply.text is False and ply.byte_order == "<"
        assert ply["vertex"]["x"].dtype == np.float64
        V1 = np.column_stack([ply["vertex"][c] for c in "xyz"])
        np.testing.assert_array_equal(V1, W)
    V1, F1 = igl.read_triangle_mesh(str(path))  # libigl reads what we wrote, bit for bit
    assert V1.tobytes() == W.tobytes()
    np.testing.assert_array_equal(F1, F)
    V2, F2, _ = read_mesh(path)
    assert V2.tobytes() == W.tobytes()
    assert stored_folds(path, F) == 0 == count_folds(F, W)


@pytest.mark.parametrize("name", FLOAT32)
@pytest.mark.parametrize("radius", [1.0, 100.0])
def test_float32_formats_fold_as_float32_rounding_does(tmp_path, crowded, name, radius):
    U, F = crowded
    W = radius * U
    W32 = W.astype(np.float32).astype(np.float64)
    path = tmp_path / name
    write_mesh(path, W, F)
    expected = count_folds(F, W32)
    assert expected > 0
    if name.endswith(".stl"):  # corners merged back by exact match: vertices renumbered
        V2, F2, _ = read_mesh(path)
        np.testing.assert_array_equal(V2[F2], W32[F])
        assert stored_folds(path) == expected
    else:
        V2, F2, _ = read_mesh(path)
        np.testing.assert_array_equal(V2, W32)
        np.testing.assert_array_equal(F2, F)
        assert stored_folds(path, F) == expected == stored_folds(path)


@pytest.mark.parametrize("radius", [1.0, 100.0])
def test_gifti_float64_is_exact_and_float32_by_default(tmp_path, crowded, radius):
    U, F = crowded
    W = radius * U
    write_mesh(tmp_path / "d.surf.gii", W, F)
    write_mesh(tmp_path / "e.surf.gii", W, F, precision="float64")
    default = nib.load(str(tmp_path / "d.surf.gii")).darrays[0]
    double = nib.load(str(tmp_path / "e.surf.gii")).darrays[0]
    assert default.datatype == nib.nifti1.data_type_codes["NIFTI_TYPE_FLOAT32"]
    assert double.datatype == nib.nifti1.data_type_codes["NIFTI_TYPE_FLOAT64"]
    assert double.data.tobytes() == W.tobytes()
    assert stored_folds(tmp_path / "e.surf.gii", F) == 0
    assert stored_folds(tmp_path / "d.surf.gii", F) == \
        count_folds(F, W.astype(np.float32).astype(np.float64)) > 0


def test_precision_a_format_cannot_store_is_refused(tmp_path, crowded):
    U, F = crowded
    assert STORED_PRECISION["freesurfer"] == "float32" and STORED_PRECISION[".obj"] == "float64"
    for name, precision in (("lh.s", "float64"), ("s.stl", "float64"), ("s.obj", "float32"),
                            ("s.ply", "float32"), ("s.surf.gii", "float16")):
        with pytest.raises(ValueError, match="precision|stores"):
            write_mesh(tmp_path / name, U, F, precision=precision)
    write_mesh(tmp_path / "s.obj", U, F, precision="float64")  # what it stores anyway
    write_mesh(tmp_path / "lh.s", U, F, precision="float32")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lh.s", "s.obj"]


def test_extreme_magnitudes_round_trip_in_text_formats(tmp_path, rng):
    V = rng.standard_normal((300, 3)) * 10.0 ** rng.integers(-300, 300, (300, 1))
    V[:4] = [[5e-324, -0.0, 1e308], [np.pi, 1 / 3, 0.1], [1 + 2 ** -52, 1 - 2 ** -53, 2 ** 60 + 1],
             [1e-21, -2e-21, 3e-21]]
    F = rng.integers(0, 300, (200, 3))
    for name in EXACT + ["e.surf.gii"]:
        kw = {"precision": "float64"} if name.endswith(".gii") else {}
        write_mesh(tmp_path / name, V, F, **kw)
        V2, F2, _ = read_mesh(tmp_path / name)
        assert V2.tobytes() == V.tobytes(), name
        np.testing.assert_array_equal(F2, F)


def test_libigl_text_writers_are_not_exact(tmp_path, rng):
    """Why OBJ/OFF/PLY are written here: libigl's writers lose digits (15 / 15 / 6)."""
    V = rng.standard_normal((100, 3))
    F = rng.integers(0, 100, (50, 3))
    for ext in (".obj", ".off", ".ply"):
        igl.write_triangle_mesh(str(tmp_path / f"x{ext}"), V, F)
        V1, _ = igl.read_triangle_mesh(str(tmp_path / f"x{ext}"))
        assert not np.array_equal(V1, V), ext


def test_write_refuses_non_finite_and_bad_shapes(tmp_path):
    U, F = make_icosphere(1)
    U[3, 1] = np.nan
    with pytest.raises(ValueError, match="1 vertex has non-finite"):
        write_mesh(tmp_path / "s.obj", U, F)
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        write_mesh(tmp_path / "s.obj", U[:, :2], F)
    assert list(tmp_path.iterdir()) == []


def test_stored_folds_checks_the_faces_given(tmp_path, crowded):
    U, F = crowded
    write_mesh(tmp_path / "s.obj", U, F)
    with pytest.raises(ValueError, match="do not fit"):
        stored_folds(tmp_path / "s.obj", F + len(U))
    # inward faces: every face of the stored map counts as folded
    assert stored_folds(tmp_path / "s.obj", F[:, ::-1]) == len(F)


def test_dino_map_round_trips(tmp_path, conformal_map):
    """The real crowded map of issue #15: fold-free in memory and in OBJ/OFF/PLY/GIfTI-float64."""
    V, F, result, _ = conformal_map("dino.obj")
    mesh = validate_mesh(V, F)
    F_out = mesh.vertex_index[mesh.F]
    U = np.asarray(result.U)
    assert count_folds(F_out, U) == 0
    for name in EXACT + ["e.surf.gii"]:
        kw = {"precision": "float64"} if name.endswith(".gii") else {}
        write_mesh(tmp_path / name, U, F_out, **kw)
        assert stored_folds(tmp_path / name, F_out) == 0, name
    write_mesh(tmp_path / "lh.sphere", 100 * U, F_out)
    expected = count_folds(F_out, (100 * U).astype(np.float32).astype(np.float64))
    assert stored_folds(tmp_path / "lh.sphere", F_out) == expected > 0
