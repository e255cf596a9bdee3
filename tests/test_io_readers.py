"""Readers say what is wrong: every OBJ / OFF / ASCII STL / VRML / GIfTI / FreeSurfer problem with
its count and line.

The accepted files are compared with libigl's own reader (and, for relative OBJ
indices and polygons, with indices resolved by hand).
"""

import gzip
import subprocess
import sys

import igl
import nibabel as nib
import nibabel.freesurfer as fs
import numpy as np
import pytest
from nibabel.gifti import GiftiDataArray, GiftiImage

from conftest import make_icosphere
from igl_spheremap.io import check_mesh, check_obj, check_off, check_stl, check_wrl, read_mesh

TET_V = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
TET_F = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
OFF_V = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
OFF_F = "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_bytes(text.encode() if isinstance(text, str) else text)
    return path


def same_as_libigl(path):
    V, F, _ = read_mesh(path)
    V1, F1 = igl.read_triangle_mesh(str(path))
    np.testing.assert_array_equal(V, V1)
    np.testing.assert_array_equal(F, F1)
    return V, F


# --------------------------------------------------------------------------- OBJ


@pytest.mark.parametrize("body, message", [
    (TET_V + "f 1.5 3 2\nf 1 2 4.0\nf 1 4 3\nf 2 3 4x\n",
     r"face indices that are not integers: 3 \(first on line 5: 'f 1.5 3 2'\)"),
    (TET_V + "f 1 3 2\nf 0 2 4\nf 1 4 9\nf 2 3 4\n",
     r"face indices out of range \(valid: 1 to 4.*\): 2 \(first on line 6: 'f 0 2 4'\)"),
    (TET_V + "f 1 3 2\nf 1 2 4294967297\nf 1 4 3\nf 2 3 4\n",
     r"out of range .*: 1 \(first on line 6"),
    ("v 0 0 0\nv 1 0 0\nf -3 -2 -1\n" + "v 0 1 0\nv 0 0 1\n" + TET_F,
     r"out of range .*: 1 \(first on line 3: 'f -3 -2 -1'\)"),  # only 2 vertices before line 3
    ("v nan 0 0\nv 1 inf 0\nv 0 1 1e999\nv 0 0 1\n" + TET_F,
     r"non-finite coordinates \(nan, inf or overflow\): 3 \(first on line 1: 'v nan 0 0'\)"),
    ("v 0 0 0\nv abc 0 0\nv 0 1.2.3 0\nv 0 0 1\n" + TET_F,
     r"non-numeric vertex coordinates: 2 \(first on line 2: 'v abc 0 0'\)"),
    ("v 0 0 0\nv 1 0\nv 0 1 0\nv 0 0 1\n" + TET_F,
     r"vertex lines with fewer than 3 coordinates: 1 \(first on line 2: 'v 1 0'\)"),
    (TET_V + "f 1 3\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 1\n",
     r"faces with fewer than 3 vertices: 2 \(first on line 5: 'f 1 3'\)"),
    ("  v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + TET_F,
     r"leading whitespace.*: 1 \(first on line 1"),
    ("v 0 0 0 " + "0 " * 1100 + "\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + TET_F,
     r"longer than 2046 characters.*: 1 \(first on line 1"),
    ("v 0 0 \\\n0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + TET_F,
     r"continued with '\\'.*: 1 \(first on line 1"),
    (TET_V, r"no triangles: 4 vertex lines \('v x y z'\) and 0 face lines"),
    ("# only a comment\n", r"no triangles: 0 vertex lines"),
    (TET_V + "f 1 2 3\x00\n" + TET_F, r"not a text OBJ file .* control bytes: 1 \(first on line 5"),
])
def test_obj_problems_are_named_with_count_and_line(tmp_path, body, message):
    path = write(tmp_path, "m.obj", body)
    with pytest.raises(ValueError, match=message):
        read_mesh(path)


def test_obj_problem_counts_across_parser_blocks(tmp_path):
    """Errors far apart (parsed block by block after numpy's parser refuses) keep their lines."""
    V, F = make_icosphere(4)  # 2562 vertices, 5120 faces: more than one 4096-line block
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in V] + [f"f {a + 1} {b + 1} {c + 1}"
                                                         for a, b, c in F]
    bad = [len(V) + 10, len(V) + 4500, len(V) + 5000]  # face lines, 0-based line index
    for i in bad:
        lines[i] = lines[i].replace("f ", "f 1.25 ", 1)
    lines[7000 - 1] += " junk"  # a face line further on, as a non-integer token
    path = write(tmp_path, "m.obj", "\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=rf"not integers: 4 \(first on line {bad[0] + 1}:"):
        check_obj(path)


def test_obj_accepted_variants_match_libigl(tmp_path):
    body = ("# comment\r\nv 0 0 0 1\r\nv\t1 0 0\r\nv 0 1 0 0.5 0.5 0.5\r\nv +0 -0 1e0\r\n"
            "vt 0 0\r\nvn 0 0 1\r\ng group\r\nusemtl m\r\n"
            "f 1/1/1 3/1/1 2/1/1\r\nf 1//1 2//1 4//1\r\nf -4 -1 -2\r\nf 2/1 3/1 4/1\r\n")
    path = write(tmp_path, "m.obj", body)
    V, F = same_as_libigl(path)
    np.testing.assert_array_equal(F, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    np.testing.assert_array_equal(V, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])


def test_obj_polygons_are_split_into_fans_like_libigl(tmp_path):
    body = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 1 4 3 2\nf 1 2 5\nf 2 3 5\nf 3 4 5\n" \
           "f 4 1 5\n"
    path = write(tmp_path, "pyramid.obj", body)
    V, F = same_as_libigl(path)
    np.testing.assert_array_equal(F[:2], [[0, 3, 2], [0, 2, 1]])
    assert read_mesh(path, return_metadata=True)[3]["polygons"] == 1
    assert check_obj(path).polygons == 1


def test_obj_check_equals_libigl_on_a_real_mesh(mesh):
    V, F = mesh("goathead.obj")
    from conftest import DATA

    parsed = check_obj(DATA / "goathead.obj")
    np.testing.assert_array_equal(parsed.V, V)
    np.testing.assert_array_equal(parsed.F, F)


# --------------------------------------------------------------------------- OFF


@pytest.mark.parametrize("body, message", [
    ("OFF\n3 4 0\n" + OFF_V + OFF_F, r"announces 3 vertices and 4 faces, 7 element lines, but 8"),
    ("OFF\n4 3 0\n" + OFF_V + OFF_F, r"announces 4 vertices and 3 faces, 7 element lines, but 8"),
    ("OFF\n4 5 0\n" + OFF_V + OFF_F, r"announces 4 vertices and 5 faces, 9 element lines, but 8"),
    ("4 4 0\n" + OFF_V + OFF_F, r"first line must be OFF, COFF or NOFF, not '4 4 0'"),
    ("OFF\nfour 4 0\n" + OFF_V + OFF_F, r"counts line \(line 2: 'four 4 0'\) must hold"),
    ("OFF\n4 4 0\nnan 0 0\n1 0 0\n0 1 0\n0 0 inf\n" + OFF_F,
     r"non-finite coordinates .*: 2 \(first on line 3: 'nan 0 0'\)"),
    ("OFF\n4 4 0\n0 0 0\nx 0 0\n0 1 0\n0 0 1\n" + OFF_F,
     r"vertex lines with non-numeric values: 1 \(first on line 4: 'x 0 0'\)"),
    ("OFF\n4 4 0\n0 0 0\n1 0\n0 1 0\n0 0 1\n" + OFF_F,
     r"fewer than 3 coordinates: 1 \(first on line 4"),
    ("OFF\n4 4 0\n" + OFF_V + "3 0 2 1\n3 0.5 1 3\n3 0 3 2\n3 1 2 3\n",
     r"indices that are not integers: 1 \(first on line 8: '3 0.5 1 3'\)"),
    ("OFF\n4 4 0\n" + OFF_V + "3 0 2 4\n3 -1 1 3\n3 0 3 2\n3 1 2 3\n",
     r"out of range \(valid: 0 to 3\): 2 \(first on line 7: '3 0 2 4'\)"),
    ("OFF\n4 4 0\n" + OFF_V + "2 0 2\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
     r"fewer than 3 vertices: 1 \(first on line 7: '2 0 2'\)"),
    ("OFF\n4 4 0\n" + OFF_V + "4 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
     r"fewer indices than their count: 1 \(first on line 7"),
    ("OFF\n4 4 0\n" + OFF_V + "three 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
     r"not starting with an integer vertex count: 1"),
    ("OFF\n0 0 0\n", r"no triangles: the header announces 0 vertices and 0 faces"),
    ("# nothing\n\n", r"no content"),
])
def test_off_problems_are_named(tmp_path, body, message):
    """Includes the header that crashes libigl 2.6.3 (fewer vertices than the body has)."""
    path = write(tmp_path, "m.off", body)
    with pytest.raises(ValueError, match=message):
        read_mesh(path)


def test_off_accepted_variants_match_libigl(tmp_path):
    body = ("COFF\n# comment\n4 5 0\n\n0 0 0 255 0 0 255\n1 0 0 255 0 0 255\n"
            "  0 1 0 255 0 0 255\n0 0 1 255 0 0 255\n# faces\n3 0 2 1 0.5 0.5 0.5\n"
            "3 0 1 3\n3 0 3 2\n3 1 2 3\n")
    body = body.replace("4 5 0", "4 4 0")
    V, F = same_as_libigl(write(tmp_path, "c.off", body))
    np.testing.assert_array_equal(F, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    quad = "OFF 5 5 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n4 0 3 2 1\n3 0 1 4\n3 1 2 4\n" \
           "3 2 3 4\n3 3 0 4\n"
    path = write(tmp_path, "q.off", quad)
    V, F = same_as_libigl(path)
    assert check_off(path).polygons == 1
    np.testing.assert_array_equal(F[:2], [[0, 3, 2], [0, 2, 1]])


# --------------------------------------------------------------------------- ASCII STL

TET_CORNERS = [((0, 0, 0), (0, 1, 0), (1, 0, 0)), ((0, 0, 0), (1, 0, 0), (0, 0, 1)),
               ((0, 0, 0), (0, 0, 1), (0, 1, 0)), ((1, 0, 0), (0, 1, 0), (0, 0, 1))]


def ascii_stl(newline="\n", corners=TET_CORNERS, indent=" "):
    out = ["solid tet"]
    for triangle in corners:
        out += ["facet normal 0 0 0", indent + "outer loop"]
        out += [2 * indent + "vertex {} {} {}".format(*v) for v in triangle]
        out += [indent + "endloop", "endfacet"]
    return newline.join(out + ["endsolid tet", ""])


@pytest.mark.parametrize("body, message", [
    (ascii_stl().replace("\n", "\r", 7), r"7 line ends are a carriage return alone"),
    (ascii_stl()[:ascii_stl().index("facet normal", 200)],
     r"the last line is not 'endsolid' but 'endfacet' \(line 22: a cut file\?\)"),
    (ascii_stl().replace("  vertex 0 0 1\n", "", 1),
     r"facets without exactly 3 vertex lines \(a cut or joined file\?\): 1 \(first on line 9"),
    (ascii_stl().replace("vertex 1 0 0", "vertex nan 0 0", 1),
     r"vertices with non-finite coordinates \(nan, inf or overflow\): 1 \(first on line 6"),
    (ascii_stl().replace("vertex 1 0 0", "vertex 1 zero 0", 1),
     r"vertex lines with non-numeric coordinates: 1 \(first on line 6"),
    (ascii_stl().replace("vertex 1 0 0", "vertex 1 0", 1),
     r"vertex lines with fewer than 3 coordinates: 1 \(first on line 6"),
    (ascii_stl().replace("facet normal 0 0 0", "facet 0 0 0", 2),
     r"facet lines without 'normal nx ny nz': 2 \(first on line 2"),
    (ascii_stl().replace("endfacet", "end facet", 1), r"facets without 'endfacet': 1"),
    ("solid empty\nendsolid empty\n", r"no triangles: no 'facet' line"),
    (b"solid " + bytes(range(1, 9)) * 9 + b"\x01\x02" + b"\x05\x00\x00\x00" + bytes(50 * 4),
     r"is not a text ASCII STL .*binary STL whose triangle count disagrees"),
])
def test_stl_problems_are_named(tmp_path, body, message):
    """Includes files libigl 2.6.3's ASCII reader reads short (a cut file, a joined line)."""
    path = write(tmp_path, "m.stl", body)
    with pytest.raises(ValueError, match=message):
        read_mesh(path)


@pytest.mark.parametrize("body, message", [
    (ascii_stl("\r"), "30 line ends are a carriage return alone"),
    (ascii_stl().replace("solid tet\n", "solid " + "x" * 300 + "\n", 1),
     "lines longer than 255 characters, on which libigl's reader never returns: 1 (first on "
     "line 1"),
])
def test_stl_files_libigl_never_returns_on_are_refused(tmp_path, body, message):
    """libigl 2.6.3's ASCII STL reader loops forever on these (its getline fails short of the
    file's end); read in a child process, so that a regression fails here instead of hanging
    the test run."""
    out = read_in_child(write(tmp_path, "m.stl", body))
    assert message in out and "(exit 0)" in out, out


@pytest.mark.parametrize("newline, indent", [("\n", " "), ("\r\n", " "), ("\n", "\t")])
def test_stl_accepted_variants_match_libigl(tmp_path, newline, indent):
    path = write(tmp_path, "t.stl", ascii_stl(newline, indent=indent))
    parsed = check_stl(path)
    V, F = igl.read_triangle_mesh(str(path))
    np.testing.assert_array_equal(parsed.V, V)
    np.testing.assert_array_equal(parsed.F, F)
    V, F, _ = read_mesh(path)  # the corners merged: the tetrahedron's 4 vertices
    assert V.shape == (4, 3) and F.shape == (4, 3)
    np.testing.assert_array_equal(V[F].reshape(-1, 3), np.reshape(TET_CORNERS, (-1, 3)))


def test_binary_stl_is_left_to_libigl(tmp_path):
    """libigl's binary reader checks sizes and coordinates itself: nothing parsed here, even
    when the 80-byte header starts with 'solid' (the size tells binary from text)."""
    V, F = make_icosphere(2)
    path = tmp_path / "ico.stl"
    igl.writeSTL(str(path), V, F, True)  # binary
    data = path.read_bytes()
    path.write_bytes(b"solid" + data[5:])
    assert check_stl(path) is None
    assert read_mesh(path)[1].shape == F.shape


# --------------------------------------------------------------------------- other formats


def test_gifti_and_freesurfer_contents_are_checked(tmp_path):
    V, F = make_icosphere(1)
    V = V.astype(np.float32)
    V[5] = np.nan
    img = GiftiImage(darrays=[GiftiDataArray(V, intent="NIFTI_INTENT_POINTSET"),
                              GiftiDataArray(F.astype(np.int32), intent="NIFTI_INTENT_TRIANGLE")])
    nib.save(img, str(tmp_path / "nan.surf.gii"))
    with pytest.raises(ValueError, match=r"1 vertex with non-finite coordinates \(first: "
                                         r"vertex 5"):
        read_mesh(tmp_path / "nan.surf.gii")
    G = F.astype(np.int32).copy()
    G[7, 2] = len(V)
    G[9, 0] = -1
    img = GiftiImage(darrays=[GiftiDataArray(np.nan_to_num(V), intent="NIFTI_INTENT_POINTSET"),
                              GiftiDataArray(G, intent="NIFTI_INTENT_TRIANGLE")])
    nib.save(img, str(tmp_path / "range.surf.gii"))
    with pytest.raises(ValueError, match=r"2 faces with vertex indices outside 0..41 \(first: "
                                         r"face 7"):
        read_mesh(tmp_path / "range.surf.gii")
    fs.write_geometry(str(tmp_path / "lh.bad"), V.astype(np.float64), F)
    with pytest.raises(ValueError, match=r"1 vertex with non-finite"):
        read_mesh(tmp_path / "lh.bad")


def test_files_that_cannot_be_read_at_all(tmp_path):
    write(tmp_path, "empty.ply", b"")
    with pytest.raises(ValueError, match=r"'.*empty.ply' is empty \(0 bytes\)"):
        read_mesh(tmp_path / "empty.ply")
    (tmp_path / "folder.obj").mkdir()
    with pytest.raises(IsADirectoryError, match="is a folder"):
        read_mesh(tmp_path / "folder.obj")
    write(tmp_path, "junk.ply", b"not a ply file\n")  # libigl returns nothing, without error
    with pytest.raises(ValueError, match=r"cannot read '.*junk.ply' as PLY: line 1: expected "
                                         r"'ply'"):
        read_mesh(tmp_path / "junk.ply")


def test_binary_ply_contents_are_checked(tmp_path):
    from plyfile import PlyData, PlyElement

    V, F = make_icosphere(1)
    vertex = np.empty(len(V), dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8")])
    vertex["x"], vertex["y"], vertex["z"] = V.T
    vertex["y"][[3, 8]] = np.inf
    face = np.empty(len(F), dtype=[("vertex_indices", "<i4", (3,))])
    face["vertex_indices"] = F
    PlyData([PlyElement.describe(vertex, "vertex"), PlyElement.describe(face, "face")],
            text=False).write(str(tmp_path / "inf.ply"))
    with pytest.raises(ValueError, match=r"2 vertices with non-finite coordinates \(first: "
                                         r"vertex 3"):
        read_mesh(tmp_path / "inf.ply")


# --------------------------------------------------------------------------- PLY

PYRAMID_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1.0]])
PYRAMID_F = [[0, 3, 2, 1], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]  # a quad and 4 triangles


def write_ply(path, V, faces, text):
    from plyfile import PlyData, PlyElement

    vertex = np.empty(len(V), dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8")])
    vertex["x"], vertex["y"], vertex["z"] = np.asarray(V, dtype=np.float64).T
    face = np.empty(len(faces), dtype=[("vertex_indices", "O")])
    face["vertex_indices"] = [np.asarray(f, dtype=np.int32) for f in faces]
    PlyData([PlyElement.describe(vertex, "vertex"), PlyElement.describe(face, "face")],
            text=text).write(str(path))
    return path


def read_in_child(path):
    """``read_mesh(path)`` in a child process: its ValueError's message, or what killed it."""
    code = ("import sys\nfrom igl_spheremap.io import read_mesh\ntry:\n    read_mesh(sys.argv[1])\n"
            "except ValueError as exc:\n    print(exc)\n")
    out = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True,
                         timeout=120)
    return f"{out.stdout}{out.stderr} (exit {out.returncode})"


@pytest.mark.parametrize("text", [True, False])
def test_ply_polygons_are_split_into_fans_like_obj(tmp_path, text):
    """libigl 2.6.3 aborts the process on this file (face lists of 4 and 3 vertices); the
    reference is libigl's own reading of the same mesh as OBJ, which splits polygons into fans."""
    path = write_ply(tmp_path / "pyramid.ply", PYRAMID_V, PYRAMID_F, text)
    obj = "".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in PYRAMID_V) + "".join(
        "f " + " ".join(str(i + 1) for i in f) + "\n" for f in PYRAMID_F)
    V1, F1 = igl.read_triangle_mesh(str(write(tmp_path, "pyramid.obj", obj)))
    V, F, _, meta = read_mesh(path, return_metadata=True)
    np.testing.assert_array_equal(V, V1)
    np.testing.assert_array_equal(F, F1)
    assert meta["polygons"] == 1


@pytest.mark.parametrize("text", [True, False])
def test_triangle_ply_reads_as_libigl_does(tmp_path, text):
    V, F = make_icosphere(2)
    path = write_ply(tmp_path / "ico.ply", V, F, text)
    V1, F1 = igl.read_triangle_mesh(str(path))
    V2, F2, _ = read_mesh(path)
    np.testing.assert_array_equal(V2, V1)
    np.testing.assert_array_equal(F2, F1)


@pytest.mark.parametrize("text, where, message", [
    (True, 0.3, "element 'vertex': row "), (True, 0.8, "element 'face': row "),
    (False, 0.8, "element 'face': row "),
])
def test_cut_ply_is_refused(tmp_path, text, where, message):
    """A PLY file cut short: libigl 2.6.3 aborts the process on a cut ASCII file and reads a
    cut binary one as faces of index 0; here the error names the element and row."""
    V, F = make_icosphere(2)
    data = write_ply(tmp_path / "ico.ply", V, F, text).read_bytes()
    path = write(tmp_path, "cut.ply", data[:int(where * len(data))])
    out = read_in_child(path)
    assert "cannot read" in out and message in out and "(exit 0)" in out, out


def test_ply_faces_with_fewer_than_3_vertices(tmp_path):
    path = write_ply(tmp_path / "short.ply", PYRAMID_V, PYRAMID_F + [[0, 1]], True)
    with pytest.raises(ValueError, match=r"faces with fewer than 3 vertices: 1 \(first: face 5, "
                                         r"\[0, 1\]\)"):
        read_mesh(path)


# --------------------------------------------------------------------------- VRML

CUBE_V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
CUBE_F = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]


def vrml(V=CUBE_V, F=CUBE_F, point="point [", index="coordIndex ["):
    points = ",\n".join("{} {} {}".format(*v) for v in V)
    faces = "\n".join(",".join(str(i) for i in f) + ",-1," for f in F)
    return ("#VRML V2.0 utf8\nShape { geometry IndexedFaceSet {\n"
            f"coord Coordinate {{ {point}\n{points}\n] }}\n{index}\n{faces}\n] }} }}\n")


def test_wrl_written_by_libigl_reads_as_libigl_does(tmp_path):
    V, F = make_icosphere(2)
    path = tmp_path / "ico.wrl"
    igl.write_triangle_mesh(str(path), V, F)
    V1, F1 = same_as_libigl(path)
    assert F1.shape == F.shape and np.abs(V1 - V).max() < 1e-12


def test_wrl_polygons_are_split_into_fans_like_obj(tmp_path):
    """The reference is libigl's reading of the same cube as OBJ (and, inside ``read_mesh``, its
    own VRML reader, which must agree with the strict parse)."""
    obj = "".join("v {} {} {}\n".format(*v) for v in CUBE_V) + "".join(
        "f " + " ".join(str(i + 1) for i in f) + "\n" for f in CUBE_F)
    V1, F1 = igl.read_triangle_mesh(str(write(tmp_path, "cube.obj", obj)))
    V, F, _, meta = read_mesh(write(tmp_path, "cube.wrl", vrml()), return_metadata=True)
    np.testing.assert_array_equal(V, V1)
    np.testing.assert_array_equal(F, F1)
    assert meta["polygons"] == 6


@pytest.mark.parametrize("body, message", [
    (vrml(point="point [ 0 0 0,"), r"values after 'point \[' on its own line, which libigl's "
                                   r"reader skips: .* \(line 3: 'coord Coordinate"),
    (vrml(index="coordIndex [ 0,1,2,-1,"), r"values after 'coordIndex \[' on its own line"),
    (vrml().replace("1 1 0,", "1 1,", 1), r"coordinate triple 3 has fewer than 3 numbers"),
    (vrml().replace("1 1 0,", "1 1 0 ,", 1),
     r"the 'point' list stops after 3 coordinate triples at ',', not at its '\]'"),
    (vrml().replace("0 1 1\n]", "0 1 nan\n]", 1), r"1 vertex with non-finite coordinates"),
    (vrml().replace("4,5,6,7,-1,", "4,5,6,7,-2,", 1), r"1 face end other than -1"),
    (vrml().replace("4,5,6,7,-1,", "4,5,6,7,8,-1,", 1),
     r"1 index out of range \(valid: 0 to 7\)"),
    (vrml().replace("3,0,4,7,-1,", "3,0,4,7,", 1),
     r"the last face is not closed by -1 \(libigl's reader drops it\)"),
    (vrml().replace("4,5,6,7,-1,", "4,5,6,7,x,-1,", 1),
     r"the 'coordIndex' list stops after 9 indices at 'x,-1,'"),
    (vrml() + vrml(), r"1 more 'point \[' list \(more shapes\): libigl reads the first only"),
    ("texCoord TextureCoordinate { point [\n0 0, 1 0\n] }\n" + vrml(),
     r"the first 'point \[' list is a TextureCoordinate node"),
    (vrml(F=[]), r"no faces"),
    (vrml()[:vrml().index("point")], r"no 'point \[' line"),
    (vrml().replace("3,0,4,7,-1,", "3,0,-1,", 1), r"1 face of fewer than 3 vertices"),
    (gzip.compress(vrml().encode()), r"gzip-compressed VRML file: decompress it first"),
    (vrml().replace("\n", "\r"), r"values after 'point \[' on its own line, .*line ends that "
                                   r"are a carriage return alone\?"),
])
def test_wrl_problems_are_named(tmp_path, body, message):
    """Includes what libigl 2.6.3's VRML reader reads short or wrongly without a word: values on
    a keyword line, a list ended by a stray token, an unclosed last face, a second shape."""
    with pytest.raises(ValueError, match=message):
        read_mesh(write(tmp_path, "m.wrl", body))


@pytest.mark.parametrize("body, message", [
    (vrml()[:vrml().index("coordIndex")],
     "no 'coordIndex [' line after the coordinates (line 12): a cut file?"),
    (vrml().replace("4,5,6,7,-1,", "4,5,6,7,-1,-1,", 1), "1 face of fewer than 3 vertices"),
    (vrml().replace("4,5,6,7,-1,", "4,5,6,7,-1,4,-1,", 1), "1 face of fewer than 3 vertices"),
])
def test_wrl_files_libigl_never_returns_on_or_aborts_on_are_refused(tmp_path, body, message):
    """libigl 2.6.3's VRML reader loops forever on a file cut before ``coordIndex [`` and aborts
    the process on a face of no or one vertex; read in a child process, so that a regression
    fails here instead of hanging or killing the test run."""
    out = read_in_child(write(tmp_path, "m.wrl", body))
    assert message in out and "(exit 0)" in out, out


def test_wrl_texture_coordinates_after_the_faces_are_ignored(tmp_path):
    body = vrml().replace("] } }\n", "]\ntexCoord DEF uv TextureCoordinate { point [\n0 0, 1 0\n] }"
                          "\n} }\n")
    assert "TextureCoordinate" in body
    same_as_libigl(write(tmp_path, "uv.wrl", body))


def test_wrl_check_returns_the_parse():
    parsed = check_wrl("cube.wrl", vrml().encode())
    np.testing.assert_array_equal(parsed.V, np.array(CUBE_V, dtype=float))
    assert parsed.F.shape == (12, 3) and parsed.polygons == 6


# --------------------------------------------------------------------------- Gmsh


def gmsh_ascii(V, F, element_line="{k} 2 2 1 1 {a} {b} {c}"):
    nodes = "".join(f"{i + 1} {x:.17g} {y:.17g} {z:.17g}\n" for i, (x, y, z) in enumerate(V))
    elements = "".join(element_line.format(k=k + 1, a=a + 1, b=b + 1, c=c + 1) + "\n"
                       for k, (a, b, c) in enumerate(F))
    return (f"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n{len(V)}\n{nodes}$EndNodes\n"
            f"$Elements\n{len(F)}\n{elements}$EndElements\n")


@pytest.mark.parametrize("binary", [False, True])
def test_msh_reads_as_libigl_does(tmp_path, binary):
    V, F = make_icosphere(2)
    path = tmp_path / "ico.msh"
    if binary:
        igl.writeMSH(str(path), V, F, np.zeros((0, 4), np.int64), np.ones(len(F), np.int64),
                     np.zeros(0, np.int64))
    else:
        path.write_text(gmsh_ascii(V, F))
    V1, F1 = same_as_libigl(path)
    np.testing.assert_array_equal(V1, V)
    np.testing.assert_array_equal(F1, F)


def test_msh_that_libigl_never_returns_on_is_refused(tmp_path):
    """A negative tag count (a damaged element line): libigl 2.6.3's Gmsh reader loops
    forever on it; read in a child process, so that a regression fails here instead of
    hanging the test run."""
    V, F = make_icosphere(1)
    body = gmsh_ascii(V, F).replace("\n21 2 2 1 1 ", "\n21 2-12 1 1 ", 1)
    out = read_in_child(write(tmp_path, "m.msh", body))
    assert "as a Gmsh file: invalid literal for int() with base 10: '2-12'" in out, out
    assert "(exit 0)" in out, out


@pytest.mark.parametrize("element_line, message", [
    ("{k} 3 2 1 1 {a} {b} {c} {a}", r"surface elements other than 3-node triangles, which would be "
                                    r"lost: 20 quad"),
    ("{k} 1 2 1 1 {a} {b}", r"holds no 3-node triangles \(its elements: 20 line\)"),
])
def test_msh_without_plain_triangles_is_refused(tmp_path, element_line, message):
    V, F = make_icosphere(0)
    with pytest.raises(ValueError, match=message):
        read_mesh(write(tmp_path, "m.msh", gmsh_ascii(V, F, element_line)))


# --------------------------------------------------------------------------- MEDIT


def medit(V=CUBE_V, F=((0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7)), tets=()):
    rows = "".join("{} {} {} 1\n".format(*v) for v in V)
    tris = "".join("{} {} {} 1\n".format(*(i + 1 for i in f)) for f in F)
    tet_rows = "".join("{} {} {} {} 1\n".format(*(i + 1 for i in t)) for t in tets)
    return (f"MeshVersionFormatted 1\nDimension 3\nVertices\n{len(V)}\n{rows}Triangles\n"
            f"{len(F)}\n{tris}Tetrahedra\n{len(tets)}\n{tet_rows}End\n")


def test_mesh_file_reads_its_triangles_as_libigl_readMESH_does(tmp_path):
    """``igl.read_triangle_mesh`` returns the boundary of a MEDIT file's tetrahedra (none for
    a surface: before, ``read_mesh`` said this file held no triangles); its triangles are
    what ``igl.readMESH`` reads."""
    V, F = make_icosphere(2)
    path = tmp_path / "ico.mesh"
    igl.write_triangle_mesh(str(path), V, F)
    V1, F1, _ = read_mesh(path)
    V2, _, F2 = igl.readMESH(str(path))
    np.testing.assert_array_equal(V1, V2)
    np.testing.assert_array_equal(F1, F2)
    np.testing.assert_array_equal(F1, F)
    assert np.abs(V1 - V).max() < 1e-15


@pytest.mark.parametrize("body, message", [
    (medit().replace("Vertices\n8\n", "Vertices 8\n", 1),
     r"values after 'Vertices' on its line, which libigl's reader skips: put the count on the "
     r"next line \(line 3"),
    (medit()[:medit().index("5 6 7 1") + 4],
     r"expected triangle \(a number\), found the end of the file"),
    (medit()[:medit().index("Tetrahedra")], r"the file ends before 'Tetrahedra' \(a cut file\?\)"),
    (medit().replace("MeshVersionFormatted 1", "MeshVersionFormatted 2", 1),
     r"'MeshVersionFormatted' must be 1 for libigl's reader, not 2"),
    (medit().replace("\n", "\r\n"), r"expected 'Triangles' here \(a Windows line end"),
    (medit().replace("0 1 1 1", "0 1 nan 1", 1), r"1 vertex with non-finite coordinates"),
    (medit().replace("5 6 7 1", "5 6 9 1", 1), r"1 triangle with indices out of range \(valid: 1 "
                                               r"to 8; first: triangle 3\)"),
    (medit(F=()), r"no triangles"),
    (medit().replace("Triangles", "Edges", 1), r"expected 'Triangles' here \(line 13: 'Edges'"),
])
def test_mesh_problems_are_named(tmp_path, body, message):
    """Includes what libigl 2.6.3's MEDIT reader misreads: a count on its keyword's line, and
    a file cut in its rows, read with uninitialised indices that differ from run to run."""
    with pytest.raises(ValueError, match=message):
        read_mesh(write(tmp_path, "m.mesh", body))


def test_mesh_check_keeps_comments_and_tetrahedra_apart():
    body = "# made by hand\n\n" + medit(tets=[(0, 1, 2, 4)]).replace("Dimension 3", "Dimension\n3")
    parsed = check_mesh("c.mesh", body.encode())
    np.testing.assert_array_equal(parsed.V, np.array(CUBE_V, dtype=float))
    np.testing.assert_array_equal(parsed.F, [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7)])
