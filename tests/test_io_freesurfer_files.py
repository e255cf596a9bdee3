"""FreeSurfer's per-vertex files (curv, .mgh/.mgz, .annot, .label) where surfaces, data, labels
or masks are expected, and labels written as labels."""

import nibabel as nib
import nibabel.freesurfer as fs
import numpy as np
import pytest
from nibabel.gifti import GiftiDataArray, GiftiImage, GiftiLabel

from conftest import make_icosphere as icosphere
from igl_spheremap.app.batch import batch_inputs
from igl_spheremap.cli import main
from igl_spheremap.io import mesh_format, read_mesh, read_vertex_data, write_vertex_data


# ------------------------------------------------------------ curv files are not surfaces

def surf_folder(tmp_path):
    """A FreeSurfer surf/ folder: lh.white (triangles) and lh.sulc / lh.thickness (curv) and a
    report beside them."""
    surf = tmp_path / "surf"
    surf.mkdir()
    V, F = icosphere(2)
    fs.write_geometry(str(surf / "lh.white"), 50.0 * V, F, create_stamp="t")
    fs.write_morph_data(str(surf / "lh.sulc"), np.linspace(-1, 1, len(V)).astype(np.float32))
    fs.write_morph_data(str(surf / "lh.thickness"), np.full(len(V), 2.5, np.float32))
    (surf / "lh.sphere.reg.json").write_text("{}")
    return surf, len(V)


def test_a_curv_file_read_as_a_surface_is_named(tmp_path):
    """lh.sulc starts with ff ff ff, a quad surface's magic: it was read as a quad surface
    ("cannot reshape array of size ... into shape (..., 4)")."""
    surf, n = surf_folder(tmp_path)
    assert mesh_format(surf / "lh.sulc") is None and mesh_format(surf / "lh.white") == "freesurfer"
    with pytest.raises(ValueError, match=rf"'.*lh.sulc' is a FreeSurfer per-vertex data file "
                                         rf"\(curv format: {n} values\), not a surface"):
        read_mesh(surf / "lh.sulc")


def test_the_curv_layout_is_recognised_exactly(tmp_path):
    """Magic ff ff ff and a size of exactly 15 + 4 N k bytes; one byte short is no curv file
    (the surface reader then names it)."""
    from igl_spheremap.io import curv_layout

    surf, n = surf_folder(tmp_path)
    assert curv_layout(surf / "lh.sulc") == (n, 1)
    assert curv_layout(surf / "lh.white") is None and curv_layout(tmp_path / "none") is None
    cut = tmp_path / "lh.cut"
    cut.write_bytes((surf / "lh.sulc").read_bytes()[:-1])
    assert curv_layout(cut) is None
    with pytest.raises(ValueError, match="cannot read FreeSurfer surface"):
        read_mesh(cut)


def test_a_surf_folder_expands_to_its_surfaces_only(tmp_path):
    """`batch subj/surf` mapped lh.sulc, lh.thickness and lh.sphere.reg.json as surfaces too
    (failed rows, exit 4); files given one by one are kept, to fail with their reason."""
    surf, _ = surf_folder(tmp_path)
    assert batch_inputs([surf]) == [str(surf / "lh.white")]
    assert batch_inputs([surf / "lh.sulc"]) == [str(surf / "lh.sulc")]


# ------------------------------------------------------------------ labels written as labels

def atlas(tmp_path):
    """lh.sphere: an icosphere of radius 100 (162 vertices), the template, the subject and its
    registered sphere at once, so that --from-template --label-method nearest is the identity."""
    V, F = icosphere(2)
    fs.write_geometry(str(tmp_path / "lh.sphere"), 100.0 * V, F, create_stamp="t")
    return tmp_path / "lh.sphere", len(V)


def from_template(tmp_path, labels, out, *more):
    sphere, _ = atlas(tmp_path)
    return main(["resample", str(sphere), "--sphere", str(sphere), "--template", str(sphere),
                 "--from-template", "--labels", str(labels), "--label-method", "nearest",
                 "-o", str(tmp_path / out), "-q", *more])


TABLE = {0: ("???", (0.0, 0.0, 0.0, 0.0)), 7: ("precentral", (0.25, 0.5, 0.75, 1.0)),
         1000: ("cuneus", (1.0, 0.0, 0.5, 1.0))}


def label_gifti(path, labels):
    """A .label.gii as Workbench writes it: int32, NIFTI_INTENT_LABEL, a label table."""
    img = GiftiImage(darrays=[GiftiDataArray(labels.astype(np.int32), intent="NIFTI_INTENT_LABEL",
                                             datatype="NIFTI_TYPE_INT32")])
    for key, (name, rgba) in TABLE.items():
        img.labeltable.labels.append(GiftiLabel(key, *rgba))
        img.labeltable.labels[-1].label = name
    nib.save(img, str(path))


def table_of(img):
    return {lab.key: (lab.label, (lab.red, lab.green, lab.blue, lab.alpha))
            for lab in img.labeltable.labels}


def test_a_label_gifti_output_holds_int32_labels_and_the_input_table(tmp_path):
    """It held float32 data, intent NONE and an empty label table (names, colours lost)."""
    _, n = atlas(tmp_path)
    labels = np.array(list(TABLE))[np.arange(n) % 3]
    label_gifti(tmp_path / "atlas.label.gii", labels)
    assert from_template(tmp_path, tmp_path / "atlas.label.gii", "on_subject.label.gii") == 0
    img = nib.load(str(tmp_path / "on_subject.label.gii"))
    (arr,) = img.darrays
    assert arr.intent == nib.nifti1.intent_codes["NIFTI_INTENT_LABEL"]
    assert arr.data.dtype == np.int32 and np.array_equal(arr.data, labels)
    assert table_of(img) == TABLE  # colours exact in binary: 0.25, 0.5, ...


def test_labels_beyond_float32_precision_are_written_exactly(tmp_path):
    """Labels 2**24 + 1 + 2k came back rounded to even numbers (none in the input set)."""
    _, n = atlas(tmp_path)
    labels = 2 ** 24 + 1 + 2 * (np.arange(n) % 5)
    np.save(tmp_path / "big.npy", labels)
    assert from_template(tmp_path, tmp_path / "big.npy", "big.func.gii") == 0
    (arr,) = nib.load(str(tmp_path / "big.func.gii")).darrays
    assert arr.data.dtype == np.int32 and np.array_equal(arr.data, labels)
    assert from_template(tmp_path, tmp_path / "big.npy", "big.npz") == 0
    with np.load(tmp_path / "big.npz") as z:  # it was float64
        assert np.issubdtype(z["labels"].dtype, np.integer)
        assert np.array_equal(z["labels"], labels)


def test_labels_beyond_int32_are_refused_for_gifti_and_kept_in_npz(tmp_path, capsys):
    """GIfTI stores int32: 3 labels of 2**31 + k were silently corrupted; now the count is named
    and nothing is written (.npz keeps them, int64)."""
    _, n = atlas(tmp_path)
    labels = np.arange(n) % 4
    labels[[5, 9, 11]] = 2 ** 31 + np.arange(3)
    np.save(tmp_path / "huge.npy", labels)
    assert from_template(tmp_path, tmp_path / "huge.npy", "huge.func.gii") == 1
    assert "3 labels of 'labels' are outside the int32 range" in capsys.readouterr().err
    assert not list(tmp_path.glob("huge.func.gii*")) and not list(tmp_path.glob(".tmp-*"))
    assert from_template(tmp_path, tmp_path / "huge.npy", "huge.npz") == 0
    with np.load(tmp_path / "huge.npz") as z:
        assert np.array_equal(z["labels"], labels)


def test_resampled_labels_go_next_to_the_data_as_int32_labels(tmp_path):
    """resample (subject -> template) wrote labels as a float32 column of the .func.gii."""
    sphere, n = atlas(tmp_path)
    labels = np.array(list(TABLE))[np.arange(n) % 3]
    label_gifti(tmp_path / "subject.label.gii", labels)
    np.save(tmp_path / "x.npy", np.linspace(0.0, 1.0, n))
    assert main(["resample", str(sphere), "--sphere", str(sphere), "--template", str(sphere),
                 "--data", str(tmp_path / "x.npy"), "--labels", str(tmp_path / "subject.label.gii"),
                 "--label-method", "nearest", "-o", str(tmp_path / "out.surf.gii"), "-q"]) == 0
    img = nib.load(str(tmp_path / "out.func.gii"))
    x, lab = img.darrays
    assert x.data.dtype == np.float32 and x.intent == 0
    assert lab.data.dtype == np.int32 and np.array_equal(lab.data, labels)
    assert lab.intent == nib.nifti1.intent_codes["NIFTI_INTENT_LABEL"]
    assert set(table_of(img)) == set(TABLE)


def test_values_are_refused_in_a_label_gifti(tmp_path):
    with pytest.raises(ValueError, match=r"holds labels only, but 1 array is values \(x\)"):
        write_vertex_data(tmp_path / "a.label.gii", {"l": np.arange(4), "x": np.ones(4)})
    assert not list(tmp_path.iterdir())


# --------------------------------------------------- FreeSurfer .mgh/.mgz, .annot and .label

def test_mgh_and_mgz_overlays_are_per_vertex_data(tmp_path):
    """Read as curv files before: 'holds an array of shape (0,)', '... rows but the mesh has'."""
    n = 162
    x = np.linspace(-2.0, 3.0, n).astype(np.float32)
    nib.save(nib.MGHImage(x.reshape(n, 1, 1), np.eye(4)), str(tmp_path / "lh.t.fsaverage.mgh"))
    X, names = read_vertex_data(tmp_path / "lh.t.fsaverage.mgh", n)
    assert X.shape == (n,) and np.array_equal(X, x) and names == ["lh.t.fsaverage.mgh"]
    y = np.arange(3 * n, dtype=np.float32).reshape(n, 1, 1, 3)
    nib.save(nib.MGHImage(y, np.eye(4)), str(tmp_path / "lh.y.mgz"))
    assert np.array_equal(read_vertex_data(tmp_path / "lh.y.mgz", n)[0], y.reshape(n, 3))
    nib.save(nib.MGHImage(np.zeros((6, 9, 3), np.float32), np.eye(4)), str(tmp_path / "vol.mgz"))
    with pytest.raises(ValueError, match=r"'.*vol.mgz': it holds a volume of shape \(6, 9, 3\), "
                                         r"not per-vertex values"):
        read_vertex_data(tmp_path / "vol.mgz")


CTAB = np.array([[25, 5, 25, 0, 1639705], [25, 100, 40, 0, 2647065], [220, 20, 100, 0, 6558940]])
NAMES = [b"unknown", b"bankssts", b"cuneus"]


def test_an_annotation_is_labels_with_its_colour_table(tmp_path):
    """--labels lh.x.annot: 'has 40 rows' before; now the annotation's indices are carried and
    its names and colours are the output's label table."""
    _, n = atlas(tmp_path)
    index = np.arange(n) % 3
    index[:4] = -1  # in no entry of the table
    fs.write_annot(str(tmp_path / "lh.x.annot"), index, CTAB, NAMES, fill_ctab=False)
    assert from_template(tmp_path, tmp_path / "lh.x.annot", "x.label.gii") == 0
    img = nib.load(str(tmp_path / "x.label.gii"))
    assert np.array_equal(img.darrays[0].data, index)
    table = table_of(img)
    for i, (name, rgbt) in enumerate(zip(NAMES, CTAB)):
        assert table[i][0] == name.decode()
        assert table[i][1] == pytest.approx(tuple(rgbt[:3] / 255) + (1.0,))
    with pytest.raises(ValueError, match=r"is a FreeSurfer annotation .*: pass it as labels"):
        read_vertex_data(tmp_path / "lh.x.annot", n)


def write_label(path, vertices):
    """A FreeSurfer ASCII label (cortex.label): a vertex index and its x y z value per line."""
    rows = "".join(f"{v} 0.0 0.0 0.0 0.0\n" for v in vertices)
    path.write_text(f"#!ascii label  , from subject  vox2ras=TkReg\n{len(vertices)}\n{rows}")


def test_a_label_file_is_a_mask(tmp_path):
    """--mask lh.cortex.label: 'has N rows' before; its vertices are the mask, as 0/1."""
    sphere, n = atlas(tmp_path)
    inside = np.arange(0, n, 2)
    write_label(tmp_path / "lh.cortex.label", inside)
    x = np.linspace(1.0, 2.0, n)
    np.save(tmp_path / "x.npy", x)
    assert main(["resample", str(sphere), "--sphere", str(sphere), "--template", str(sphere),
                 "--from-template", "--data", str(tmp_path / "x.npy"), "--mask",
                 str(tmp_path / "lh.cortex.label"), "-o", str(tmp_path / "x.func.gii"),
                 "-q"]) == 0
    y = nib.load(str(tmp_path / "x.func.gii")).darrays[0].data
    np.testing.assert_allclose(y[inside], x[inside], rtol=1e-6)
    from igl_spheremap.io import read_vertex_mask

    mask = read_vertex_mask(tmp_path / "lh.cortex.label", n)
    assert mask.dtype == bool and np.array_equal(np.flatnonzero(mask), inside)
    with pytest.raises(ValueError, match=r"is a FreeSurfer label file .*: pass it as a mask"):
        read_vertex_data(tmp_path / "lh.cortex.label", n)
    write_label(tmp_path / "other.label", [0, n, n + 5])
    with pytest.raises(ValueError, match=rf"lists 2 vertex indices outside 0..{n - 1} "
                                         rf"\(first: {n}\)"):
        read_vertex_mask(tmp_path / "other.label", n)


def test_a_truncated_label_file_is_refused_not_read_as_a_smaller_mask(tmp_path):
    """nibabel reads whatever rows a .label has; FreeSurfer's second line states how many."""
    from igl_spheremap.io import read_vertex_mask

    path = tmp_path / "lh.cortex.label"
    write_label(path, np.arange(10))
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(lines[:-3]))  # cut after the 7th vertex
    with pytest.raises(ValueError, match=r"states '10' vertices but it lists 7"):
        read_vertex_mask(path, 12)
    write_label(path, [4])  # one vertex: nibabel returns a 0-d array
    assert np.flatnonzero(read_vertex_mask(path, 12)).tolist() == [4]
