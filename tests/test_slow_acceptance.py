"""Acceptance runs on the shared meshes that are regression checks: slow, opt-in.

They need the 14 shared meshes next to the repository (``../shared/meshes``) and take
minutes, so they are marked ``slow``, which the default run deselects (pyproject's
``addopts``); without the meshes they skip.  Run them with::

    python -m pytest -m slow                                   # all of them
    IGL_SPHEREMAP_BEFORE=/path/to/other/checkout python -m pytest -m slow -k identical

* every sphere the command line writes in a float32 format (GIfTI ``.surf.gii``,
  FreeSurfer ``lh.X``) is fold-free as stored: the file read back with nibabel and its
  faces' determinants counted with numpy (issue #15's acceptance run, formerly
  ``benchmarks/cli_outputs.py``);
* the intrinsic Delaunay Laplacian takes libigl's path on every shared mesh and equals
  ``igl.intrinsic_delaunay_cotmatrix`` bit for bit (the sliver routing changes nothing
  on real meshes; ``benchmarks/sliver_statistic.py`` has the numbers);
* dino -> horse (``../shared/registration``, same connectivity, the identity as ground truth)
  with 32 landmarks: the horse's conformal map crowds its legs so much that a landmark pair
  the dino's map holds apart lands micro-radians apart; every landmark is placed all the same
  (on both maps relaxed toward area balance) and ``success`` is True;
* the default float64 map is bit-identical to the one of another checkout of the
  library, named by ``IGL_SPHEREMAP_BEFORE`` (skipped without it): the check
  ``benchmarks/float64_before_after.py`` reports, run after a change that should not
  alter the maps.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "meshes"
REGISTRATION = ROOT.parent / "shared" / "registration"
MESHES = sorted(SHARED.glob("*.obj"), key=lambda p: (p.stat().st_size, p.name)) if SHARED.is_dir() else []
FAMILIES = {"gifti": "{stem}.sphere.surf.gii", "freesurfer": "lh.{stem}_sphere"}

pytestmark = pytest.mark.slow

shared_mesh = pytest.mark.parametrize(
    "mesh", MESHES or [pytest.param(None, marks=pytest.mark.skip(reason=f"no meshes in {SHARED}"))],
    ids=lambda p: p.stem if p else "none")


def stored_folds(path, family):
    """Folded faces of the sphere stored in ``path``, counted with numpy alone.

    ``det[X_i, X_j, X_k] <= 0`` on the stored float32 coordinates (radius 100, centred at
    the origin, faces as stored), read back with nibabel.
    """
    import nibabel as nib
    if family == "gifti":
        img = nib.load(str(path))
        X, F = img.agg_data("pointset"), img.agg_data("triangle")
    else:
        X, F = nib.freesurfer.read_geometry(str(path))[:2]
    X = np.asarray(X, dtype=np.float64)
    det = np.linalg.det(np.stack([X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]], axis=1))
    return int(np.count_nonzero(det <= 0))


@shared_mesh
@pytest.mark.parametrize("family", list(FAMILIES))
def test_cli_float32_sphere_is_fold_free_as_stored(mesh, family, tmp_path):
    """``igl-spheremap MESH -o X`` with default options, as a user runs it (a fresh process)."""
    out = tmp_path / FAMILIES[family].format(stem=mesh.stem)
    report = tmp_path / "report.json"
    proc = subprocess.run([sys.executable, "-m", "igl_spheremap", str(mesh), "-o", str(out),
                           "--json", str(report), "--no-progress", "-q"],
                          capture_output=True, text=True, timeout=1800)
    assert proc.returncode == 0, proc.stderr[-2000:]
    rep = json.loads(report.read_text())
    assert rep["options"]["precision"] == "float32"
    assert rep["success"] and rep["folds"] == 0 and rep["folds_stored"] == 0
    assert stored_folds(out, family) == 0


@pytest.mark.skipif(not (REGISTRATION / "isoblend_horse.obj").is_file(),
                    reason=f"no isoblend_horse.obj in {REGISTRATION}")
def test_dino_to_horse_places_32_landmarks_the_conformal_maps_crowd_together():
    """32 Euclidean farthest-point landmarks on the dino, partners the same vertices of the horse
    (the true correspondence): on the conformal maps at least one cannot be placed without folds,
    on the relaxed maps all are (landmark stages only: ``iterations=0``, no coarse levels)."""
    import igl
    import igl_spheremap
    from igl_spheremap import surface_map

    V1, F1 = igl.read_triangle_mesh(str(SHARED / "dino.obj"))[:2]
    V2, F2 = igl.read_triangle_mesh(str(REGISTRATION / "isoblend_horse.obj"))[:2]
    assert np.array_equal(F1, F2)
    picks = [int(np.argmax(np.linalg.norm(V1 - V1[0], axis=1)))]
    d = np.linalg.norm(V1 - V1[picks[0]], axis=1)
    while len(picks) < 32:
        picks.append(int(np.argmax(d)))
        d = np.minimum(d, np.linalg.norm(V1 - V1[picks[-1]], axis=1))
    lm = np.array(picks)
    said = []
    res = surface_map(V1, F1, V2, F2, lm, lm, iterations=0, coarse_levels=(), reverse=False,
                      on_stage=said.append)
    assert "landmarks placed on the conformal maps" in res.message, res.message
    assert "finishing the run on the conformal maps" not in said  # not needed: all 32 placed
    assert res.success and res.landmark_distances.max() <= 1e-9
    assert res.map2.rounds[-1].kind == "area_balanced"
    assert igl_spheremap.count_folds(F1, res.map1.U) == 0


@shared_mesh
def test_intrinsic_delaunay_laplacian_is_libigls_on_real_meshes(mesh):
    import igl

    from igl_spheremap import validate_mesh
    from igl_spheremap.mesh.intrinsic_delaunay import CAP_RTOL, NEEDLE_RTOL, sliver_statistics
    from igl_spheremap.mesh.operators import laplacian
    from igl_spheremap.io import read_mesh

    checked = validate_mesh(*read_mesh(mesh)[:2])
    V, F = checked.V, checked.F
    edge_ratio, slack = sliver_statistics(V, F)
    assert edge_ratio.min() >= NEEDLE_RTOL and slack.min() >= CAP_RTOL
    assert (laplacian(V, F) != igl.intrinsic_delaunay_cotmatrix(V, F)[0]).nnz == 0


@shared_mesh
def test_default_map_is_identical_to_the_reference_checkout(mesh, tmp_path, monkeypatch):
    before = os.environ.get("IGL_SPHEREMAP_BEFORE")
    if not before:
        pytest.skip("set IGL_SPHEREMAP_BEFORE to the root of the checkout to compare with")
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    from float64_before_after import compare

    row = compare(mesh, Path(before), ROOT, tmp_path, calls=1)
    assert row["library_before"] != row["library_after"]
    assert row["identical"], row
