"""FreeSurfer's per-vertex files (curv, .mgh/.mgz, .annot, .label) where surfaces, data, labels
or masks are expected, and labels written as labels."""

import nibabel.freesurfer as fs
import numpy as np
import pytest

from conftest import make_icosphere as icosphere
from igl_spheremap.app.batch import batch_inputs
from igl_spheremap.io import mesh_format, read_mesh


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
