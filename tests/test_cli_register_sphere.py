"""igl-spheremap register-sphere and resample end to end on constructed data: a blobby subject
surface (a permuted icosphere pushed out by a smooth bump field) with features known on the
target sphere.  The outputs are read back with nibabel (independent of our writers)."""

import json

import igl
import nibabel as nib
import numpy as np
import pytest

from igl_spheremap import count_folds, icosphere
from igl_spheremap.cli import main

from test_sphere_field import bumps


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    root = tmp_path_factory.mktemp("register_sphere")
    (root / "subj").mkdir()
    (root / "atlas").mkdir()
    T, TF = icosphere(4, order="freesurfer")
    sulc, curv = bumps(T, seed=3, k=40, width=0.4), bumps(T, seed=5, k=120, width=0.2)
    perm = np.random.default_rng(0).permutation(len(T))
    inv = np.argsort(perm)
    V = 50.0 * T[perm] * (1.0 + 0.15 * bumps(T[perm], seed=9, width=0.9))[:, None]
    F = inv[TF]
    fs = nib.freesurfer
    fs.write_geometry(str(root / "subj" / "lh.white"), V, F.astype(np.int32))
    fs.write_morph_data(str(root / "subj" / "lh.sulc"), sulc[perm].astype(np.float32))
    fs.write_morph_data(str(root / "subj" / "lh.curv"), curv[perm].astype(np.float32))
    fs.write_geometry(str(root / "atlas" / "lh.sphere"), 100.0 * T, TF.astype(np.int32))
    fs.write_morph_data(str(root / "atlas" / "lh.sulc"), sulc.astype(np.float32))
    fs.write_morph_data(str(root / "atlas" / "lh.curv"), curv.astype(np.float32))
    np.save(root / "subj" / "sulc.npy", sulc[perm])
    np.save(root / "atlas" / "sulc.npy", sulc)
    return dict(root=root, T=T, TF=TF, perm=perm, F=F, n=len(T))


def angles(A, B):
    A = A / np.linalg.norm(A, axis=1, keepdims=True)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(A, B), axis=1), (A * B).sum(1)))


def test_freesurfer_output_is_the_subjects_sphere_on_the_target(case):
    root = case["root"]
    out = root / "subj" / "lh.sphere.reg"
    code = main(["register-sphere", str(root / "subj" / "lh.white"), "--target",
                 str(root / "atlas" / "lh.sphere"), "-o", str(out), "-q"])
    assert code == 0
    V, F = nib.freesurfer.read_geometry(str(out))
    assert V.shape == (case["n"], 3)
    np.testing.assert_array_equal(F, case["F"])  # the subject's faces, in its order
    np.testing.assert_allclose(np.linalg.norm(V, axis=1), 100.0, rtol=1e-6)  # target's radius
    assert count_folds(F.astype(np.int64), V.astype(np.float64)) == 0  # as stored (float32)
    error = angles(V.astype(np.float64), case["T"][case["perm"]])
    assert error.mean() < 2.0 and np.percentile(error, 90) < 4.0  # vertex spacing ~4 degrees
    rep = json.loads((root / "subj" / "lh.sphere.reg.json").read_text())
    assert rep["success"] and rep["folds_stored"] == 0 and rep["radius"] == pytest.approx(100.0)
    assert len(rep["correlation_after"]) == 2  # ?h.sulc then ?h.curv by default
    assert all(b > a for a, b in zip(rep["correlation_before"], rep["correlation_after"]))


def test_gifti_output_from_npy_features_and_a_given_sphere(case, tmp_path):
    root = case["root"]
    first = root / "subj" / "first.sphere.surf.gii"
    assert main(["map", str(root / "subj" / "lh.white"), "--kind", "area_balanced", "-o",
                 str(first), "-q"]) == 0
    out = tmp_path / "lh.sphere.reg.surf.gii"
    code = main(["register-sphere", str(first), "--sphere", "--features",
                 str(root / "subj" / "sulc.npy"), "--target", str(root / "atlas" / "lh.sphere"),
                 "--target-features", str(root / "atlas" / "sulc.npy"), "-o", str(out), "-q"])
    assert code == 0
    img = nib.load(str(out))
    V, F = img.agg_data("pointset"), img.agg_data("triangle")
    assert V.shape == (case["n"], 3) and F.shape == case["F"].shape
    assert count_folds(F.astype(np.int64), V.astype(np.float64)) == 0
    np.testing.assert_allclose(np.linalg.norm(V, axis=1), 100.0, rtol=1e-6)
    meta = img.darrays[0].meta
    assert meta["GeometricType"] == "Spherical" and meta["AnatomicalStructurePrimary"] == "CortexLeft"
    assert img.darrays[1].meta["TopologicalType"] == "Closed"


def test_resample_through_the_registration_both_ways(case, tmp_path):
    root = case["root"]
    reg = root / "subj" / "lh.sphere.reg"
    if not reg.exists():
        pytest.skip("needs the registration of the first test")
    labels = np.argmax(case["T"] @ case["T"][::97].T, axis=1)
    np.save(tmp_path / "atlas_labels.npy", labels)
    to_subject = tmp_path / "labels_on_subject.npz"
    assert main(["resample", str(root / "subj" / "lh.white"), "--sphere", str(reg),
                 "--template", str(root / "atlas" / "lh.sphere"), "--from-template", "--labels",
                 str(tmp_path / "atlas_labels.npy"), "--label-method", "nearest", "-o",
                 str(to_subject), "-q"]) == 0
    on_subject = np.load(to_subject)["labels"].astype(np.int64)
    np.save(tmp_path / "subject_labels.npy", on_subject)
    back = tmp_path / "lh.white.atlas.surf.gii"
    assert main(["resample", str(root / "subj" / "lh.white"), "--sphere", str(reg),
                 "--template", str(root / "atlas" / "lh.sphere"), "--labels",
                 str(tmp_path / "subject_labels.npy"), "--method", "adap_bary_area", "-o",
                 str(back), "-q"]) == 0
    kept = nib.load(str(tmp_path / "lh.white.atlas.func.gii")).darrays[-1].data
    assert (kept.astype(np.int64) == labels).mean() > 0.95


def test_a_surface_passed_as_the_target_sphere_is_refused(case, tmp_path, capsys):
    """The subject's white surface given as --target (its own sulc and curv beside it): its
    vertices are not at one radius, so it is refused, naming the file and the count, before
    any work and without an output (the registration would otherwise run on its central
    projection, which is fold-free for this blobby surface, and write it at its mean radius)."""
    root = case["root"]
    out = tmp_path / "lh.sphere.reg"
    assert main(["register-sphere", str(root / "subj" / "lh.white"), "--target",
                 str(root / "subj" / "lh.white"), "-o", str(out)]) == 1
    out_text, err = capsys.readouterr()
    assert "lh.white' is not a sphere:" in err and "vertices are more than 1% off" in err
    assert "sphere of the subject" not in out_text + err  # refused before that stage
    assert not list(tmp_path.iterdir())


def test_a_constant_feature_is_refused_before_any_work(case, tmp_path, capsys):
    """A feature file that does not vary (all ones): no correlation is defined and nothing can
    be matched; refused naming the file, without an output."""
    root = case["root"]
    flat = tmp_path / "flat.npy"
    np.save(flat, np.ones(case["n"]))
    out = tmp_path / "lh.sphere.reg"
    assert main(["register-sphere", str(root / "subj" / "lh.white"), "--features", str(flat),
                 "--target", str(root / "atlas" / "lh.sphere"), "--target-features",
                 str(root / "atlas" / "sulc.npy"), "-o", str(out)]) == 1
    out_text, err = capsys.readouterr()
    assert "1 of the 1 columns of the features" in err and "flat.npy" in err
    assert "sphere of the subject" not in out_text + err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["flat.npy"]


def test_a_given_sphere_is_checked_against_the_surface_passed(case, tmp_path, capsys):
    """register-sphere --sphere had no way to pass the surface: a conformal sphere of a long
    subject, a poor start, was registered as a success without a word."""
    root = case["root"]
    V, F = nib.freesurfer.read_geometry(str(root / "subj" / "lh.white"))
    long = tmp_path / "lh.white"
    nib.freesurfer.write_geometry(str(long), V * [1.0, 1.0, 4.0], F)
    sphere = tmp_path / "lh.sphere"
    assert main(["map", str(long), "--kind", "conformal", "-o", str(sphere), "-q"]) == 0
    U = nib.freesurfer.read_geometry(str(sphere))[0].astype(np.float64)
    A = igl.doublearea(V * [1.0, 1.0, 4.0], F.astype(np.int64))
    B = igl.doublearea(U, F.astype(np.int64))
    crushed = np.abs(np.log(B / B.sum()) - np.log(A / A.sum())).mean()
    assert crushed > 0.45
    args = ["register-sphere", str(sphere), "--sphere", "--features", str(root / "subj" / "sulc.npy"),
            "--target", str(root / "atlas" / "lh.sphere"), "--target-features",
            str(root / "atlas" / "sulc.npy")]
    main([*args, "-o", str(tmp_path / "a" / "lh.sphere.reg")])
    rep = json.loads((tmp_path / "a" / "lh.sphere.reg.json").read_text())
    assert rep["start_area_log"] is None and "not checked against the subject's surface" in rep["notes"][0]
    assert "note: the given sphere was not checked" in capsys.readouterr().out
    code = main([*args, "--surface", str(long), "-o", str(tmp_path / "b" / "lh.sphere.reg"), "-q"])
    rep = json.loads((tmp_path / "b" / "lh.sphere.reg.json").read_text())
    assert code == 3 and not rep["success"] and "poor start" in rep["warnings"][0]
    assert rep["start_area_log"] == pytest.approx(crushed, rel=1e-6) and "notes" not in rep
    # the surface must be the sphere's: another mesh is refused before any work
    other = tmp_path / "rh.white"
    T, TF = icosphere(2)
    nib.freesurfer.write_geometry(str(other), 50.0 * T, TF.astype(np.int32))
    assert main([*args, "--surface", str(other), "-o", str(tmp_path / "c" / "lh.sphere.reg")]) == 1
    assert "pass the surface the sphere was made from" in capsys.readouterr().err
    assert not (tmp_path / "c" / "lh.sphere.reg").exists()


def test_unmatched_feature_counts_are_refused_before_the_sphere(case, tmp_path):
    """Two subject features against one target feature were refused only after the subject's
    area-balanced sphere had been computed."""
    from igl_spheremap.app.sphere_registration import register_sphere_file

    root, stages = case["root"], []
    with pytest.raises(ValueError, match="2 subject features but 1 target feature"):
        register_sphere_file(root / "subj" / "lh.white", root / "atlas" / "lh.sphere",
                             tmp_path / "lh.sphere.reg",
                             features=[root / "subj" / "lh.sulc", root / "subj" / "lh.curv"],
                             target_features=[root / "atlas" / "lh.sulc"], on_stage=stages.append)
    assert stages == [] and not (tmp_path / "lh.sphere.reg").exists()
