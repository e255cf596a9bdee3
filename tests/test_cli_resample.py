"""igl-spheremap resample without a registered sphere: the atlas's vertex order is not its
correspondence, and the report and terminal say so."""

import json

import igl
import nibabel as nib
import numpy as np

from igl_spheremap import icosphere
from igl_spheremap.cli import main


def test_an_atlas_order_without_a_registration_is_noted(tmp_path, capsys):
    """--order freesurfer or --template without --sphere resampled the subject's own conformal
    map, unregistered, with exit 0 and nothing said (the help called the output
    fsaverage-ordered)."""
    T, TF = icosphere(3)
    mesh = tmp_path / "lh.white"
    nib.freesurfer.write_geometry(str(mesh), 50.0 * T * [1.0, 1.3, 0.8], TF.astype(np.int32))
    template = tmp_path / "lh.sphere"
    nib.freesurfer.write_geometry(str(template), 100.0 * T, TF.astype(np.int32))
    runs = {"fs": ["--ico", "2", "--order", "freesurfer"], "igl": ["--ico", "2"],
            "template": ["--template", str(template)],
            "registered": ["--template", str(template), "--sphere", str(template)]}
    notes = {}
    for name, args in runs.items():
        out = tmp_path / name / "lh.white"
        assert main(["resample", str(mesh), *args, "-o", str(out)]) == 0
        notes[name] = json.loads((tmp_path / name / "lh.white.json").read_text())["notes"]
        printed = capsys.readouterr().out
        assert ("note: the mesh's own conformal map" in printed) == bool(notes[name])
    assert "fsaverage's vertex order" in notes["fs"][0]
    assert "the template sphere: it is not registered" in notes["template"][0]
    assert notes["igl"] == [] and notes["registered"] == []


def test_a_surface_passed_for_a_sphere_is_named(tmp_path, capsys):
    """The subject's white surface given as --sphere was "the spherical map has 6875 folded
    faces", and a surface as --template with --from-template "current_U is not a sphere"
    (a Python argument's name)."""
    T, TF = icosphere(3)
    mesh = tmp_path / "lh.white"
    nib.freesurfer.write_geometry(str(mesh), 50.0 * T * [1.0, 1.3, 0.8], TF.astype(np.int32))
    sphere = tmp_path / "lh.sphere"
    nib.freesurfer.write_geometry(str(sphere), 100.0 * T, TF.astype(np.int32))
    np.save(tmp_path / "thick.npy", np.linspace(1.0, 3.0, len(T)))
    assert main(["resample", str(mesh), "--ico", "2", "--sphere", str(mesh),
                 "-o", str(tmp_path / "a" / "lh.white")]) == 1
    err = capsys.readouterr().err
    assert f"the sphere '{mesh}' is not a sphere" in err and "pass the surface's sphere" in err
    assert main(["resample", str(mesh), "--sphere", str(sphere), "--template", str(mesh),
                 "--from-template", "--data", str(tmp_path / "thick.npy"),
                 "-o", str(tmp_path / "b.func.gii")]) == 1
    assert f"the template '{mesh}' is not a sphere" in capsys.readouterr().err
    assert not (tmp_path / "b.func.gii").exists() and not (tmp_path / "a").exists()


def test_nan_data_is_refused_with_the_way_to_a_mask(tmp_path, capsys):
    """NaN on a medial wall: "263 rows with NaN" and no word of --mask before."""
    T, TF = icosphere(2)
    mesh = tmp_path / "lh.white"
    nib.freesurfer.write_geometry(str(mesh), 50.0 * T, TF.astype(np.int32))
    data = np.where(T[:, 2] > 0.8, np.nan, 1.0)
    np.save(tmp_path / "thick.npy", data)
    assert main(["resample", str(mesh), "--ico", "1", "--data", str(tmp_path / "thick.npy"),
                 "-o", str(tmp_path / "o" / "lh.white")]) == 1
    err = capsys.readouterr().err
    assert f"has {int(np.isnan(data).sum())} rows with NaN" in err and "--mask" in err


def test_an_unwritable_data_name_is_refused_before_the_work(tmp_path, capsys, monkeypatch):
    """--from-template -o labels.thickness located every vertex, carried the data and only
    then refused the name."""
    import igl_spheremap.app.resampling as app

    T, TF = icosphere(2)
    mesh, sphere = tmp_path / "lh.white", tmp_path / "lh.sphere"
    nib.freesurfer.write_geometry(str(mesh), 50.0 * T, TF.astype(np.int32))
    nib.freesurfer.write_geometry(str(sphere), 100.0 * T, TF.astype(np.int32))
    np.save(tmp_path / "thick.npy", np.linspace(1.0, 3.0, len(T)))
    read = []

    def read_mesh(path, *args, **kwargs):  # counts the meshes read before the refusal
        read.append(path)
        raise ValueError("read before the output name was checked")

    monkeypatch.setattr(app, "read_mesh", read_mesh)
    assert main(["resample", str(mesh), "--sphere", str(sphere), "--template", str(sphere),
                 "--from-template", "--data", str(tmp_path / "thick.npy"),
                 "-o", str(tmp_path / "labels.thickness")]) == 1
    assert "or .npz file, not 'labels.thickness'" in capsys.readouterr().err and read == []


def test_options_that_would_be_ignored_are_refused(tmp_path, capsys):
    """--template-surface without --from-template and --order with --template change nothing
    the help describes; they are refused before any work, naming the option, and no output is
    written."""
    mesh = tmp_path / "ico.obj"
    V, F = icosphere(2)
    igl.write_triangle_mesh(str(mesh), V, F)
    cases = [(["--ico", "1", "--template-surface", str(mesh)], "--template-surface is used only"),
             (["--template", str(mesh), "--order", "freesurfer"], "--order freesurfer orders")]
    for extra, words in cases:
        out = tmp_path / "out.obj"
        assert main(["resample", str(mesh), *extra, "-o", str(out)]) == 1
        assert words in capsys.readouterr().err
        assert not out.exists()
