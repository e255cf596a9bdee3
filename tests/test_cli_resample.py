"""igl-spheremap resample without a registered sphere: the atlas's vertex order is not its
correspondence, and the report and terminal say so."""

import json

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
