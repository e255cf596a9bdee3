"""Batch mapping on a local Dask cluster: outputs, failure isolation, summary, resume."""

import csv
import json
import shutil
import socket
import warnings
from pathlib import Path

import igl
import nibabel.freesurfer as fs
import numpy as np
import pytest

from conftest import make_icosphere as icosphere
from igl_spheremap import MeshError, cli, count_folds, validate_mesh
from igl_spheremap.io import read_mesh
from igl_spheremap.app.batch import SUMMARY_COLUMNS, batch_output_paths, map_batch

pytest.importorskip("distributed")

FISH = Path(__file__).parent / "data" / "fish_lowres.obj"


@pytest.fixture
def subjects(tmp_path):
    """in/fish_lowres.obj, in/A/surf/lh.white (icosphere), in/B/surf/lh.white (ellipsoid),
    in/broken.off (open: one face missing)."""
    root = tmp_path / "in"
    (root / "A" / "surf").mkdir(parents=True)
    (root / "B" / "surf").mkdir(parents=True)
    shutil.copy(FISH, root / "fish_lowres.obj")
    V, F = icosphere(1)
    fs.write_geometry(str(root / "A" / "surf" / "lh.white"), 50.0 * V, F, create_stamp="t")
    V2, F2 = icosphere(2)
    fs.write_geometry(str(root / "B" / "surf" / "lh.white"), V2 * [60.0, 45.0, 30.0], F2,
                      create_stamp="t")
    igl.write_triangle_mesh(str(root / "broken.off"), V, F[1:])
    inputs = [root / "fish_lowres.obj", root / "A" / "surf" / "lh.white",
              root / "B" / "surf" / "lh.white", root / "broken.off"]
    return inputs, {"fish": (FISH, None), "A": (V, F), "B": (V2, F2)}


def _outputs(out):
    return {"fish": out / "fish_lowres_sphere.obj",
            "A": out / "A" / "surf" / "lh.white_sphere",
            "B": out / "B" / "surf" / "lh.white_sphere"}


def test_output_names_do_not_collide(tmp_path):
    a, b = tmp_path / "subjects/A/surf/lh.white", tmp_path / "subjects/B/surf/lh.white"
    paths = batch_output_paths([a, b, tmp_path / "subjects/dino.obj"], tmp_path / "o")
    assert [p.sphere for p in paths] == [tmp_path / "o/A/surf/lh.white_sphere",
                                         tmp_path / "o/B/surf/lh.white_sphere",
                                         tmp_path / "o/dino_sphere.obj"]
    assert paths[0].report == tmp_path / "o/A/surf/lh.white_sphere.json"
    single = batch_output_paths([a], tmp_path / "o")[0]
    assert single.sphere == tmp_path / "o/lh.white_sphere"


def test_a_batch_beside_a_running_dashboard_is_silent(tmp_path):
    """Port 8787 held (a Jupyter Dask dashboard, another cluster): the LocalCluster's scheduler
    warned "Port 8787 is already in use ... Hosting the HTTP server on port ... instead"."""
    held = socket.socket()
    try:
        held.bind(("0.0.0.0", 8787))
        held.listen()
    except OSError:
        pass  # already held by something else: the case itself
    V, F = icosphere(1)
    mesh = tmp_path / "lh.white"
    fs.write_geometry(str(mesh), 50.0 * V, F, create_stamp="t")
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            rows = map_batch([mesh], tmp_path / "out", n_workers=1)
    finally:
        held.close()
    assert [r["status"] for r in rows] == ["ok"]
    assert not [w for w in caught if "already in use" in str(w.message)]


def test_exit_codes_of_a_batch():
    ok = {"status": "ok", "success": True}
    folds = {"status": "warning", "success": False}
    skipped_ok = {"status": "skipped", "success": True}
    failed = {"status": "failed", "success": False}
    assert cli.batch_exit_code([ok, skipped_ok]) == 0
    assert cli.batch_exit_code([ok, folds]) == 3
    assert cli.batch_exit_code([ok, folds], allow_folds=True) == 0
    assert cli.batch_exit_code([ok, folds, failed]) == 4
    assert cli.batch_exit_code([failed, failed]) == 1


def test_batch_partial_failure_then_resume(tmp_path, subjects):
    from dask.distributed import LocalCluster

    inputs, meshes = subjects
    out = tmp_path / "out"
    code = cli.main(["batch", *map(str, inputs), "-o", str(out), "--workers", "2",
                     "--max-iter", "2000", "--no-progress", "-q"])
    assert code == 4  # one mesh failed, the others finished

    spheres = _outputs(out)
    for key, path in spheres.items():
        assert path.is_file(), key
        report = out / "fish_lowres_sphere.json" if key == "fish" else Path(f"{path}.json")
        rep = json.loads(report.read_text())
        assert rep["complete"] is True and rep["outputs"]["sphere"] == str(path)
    for key in ("A", "B"):  # FreeSurfer in, FreeSurfer out: radius 100, same faces, fold-free
        S, F = fs.read_geometry(str(spheres[key]))
        np.testing.assert_array_equal(F, meshes[key][1])
        np.testing.assert_allclose(np.linalg.norm(S, axis=1), 100.0, rtol=1e-6)
        det = np.linalg.det(np.stack([S[F[:, k]] for k in range(3)], axis=1))
        assert np.all(det > 0), key
    U, F = igl.read_triangle_mesh(str(spheres["fish"]))
    assert count_folds(F, U) == 0
    assert not list(out.glob("broken*")) and not list(out.rglob(".tmp-*"))

    with open(out / "summary.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == list(SUMMARY_COLUMNS)
    assert [Path(r["mesh"]).name for r in rows] == ["fish_lowres.obj", "lh.white", "lh.white",
                                                    "broken.off"]
    status = [r["status"] for r in rows]
    assert status == ["ok", "ok", "ok", "failed"]
    assert [r["folds"] for r in rows[:3]] == ["0", "0", "0"]
    with pytest.raises(MeshError) as info:
        validate_mesh(*read_mesh(inputs[3])[:2])
    assert info.value.problem == "boundary"
    # the icosphere with one face removed: 3 boundary edges in one loop
    assert rows[3]["message"].startswith("invalid mesh: the mesh is open: 3 boundary edges in "
                                         "1 boundary loop")
    assert [r["vertices"] for r in rows[:3]] == ["945", str(len(meshes["A"][0])),
                                                 str(len(meshes["B"][0]))]
    md = (out / "summary.md").read_text().strip().splitlines()
    assert len(md) == 2 + len(rows) and md[0].startswith("| mesh | vertices |")

    # Rerun: finished meshes are skipped (outputs untouched), the broken one fails again.
    mtimes = {k: p.stat().st_mtime_ns for k, p in spheres.items()}
    code = cli.main(["batch", *map(str, inputs), "-o", str(out), "--max-iter", "2000",
                     "--no-progress", "-q"])
    assert code == 4
    with open(out / "summary.csv", newline="") as fh:
        assert [r["status"] for r in csv.DictReader(fh)] == ["skipped"] * 3 + ["failed"]
    assert {k: p.stat().st_mtime_ns for k, p in spheres.items()} == mtimes

    # A missing output, or changed options, means "not done": recomputed, here on a
    # cluster that was already running (--scheduler).
    spheres["A"].unlink()
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster:
        rows = map_batch(inputs[:3], out, scheduler=cluster.scheduler_address, max_iter=2000)
        rows_b = map_batch(inputs[:3], out, scheduler=cluster.scheduler_address, max_iter=1000,
                           resume=True)
    assert [r["status"] == "skipped" for r in rows] == [True, False, True]
    assert spheres["A"].is_file()
    assert not any(r["status"] == "skipped" for r in rows_b)

    # An input replaced by another mesh, or an output damaged since, means "not done" too:
    # the report records both files' SHA-256 digests, and a rerun compares them.
    V3, F3 = icosphere(2)
    igl.write_triangle_mesh(str(inputs[0]), V3 * [2.0, 1.0, 1.0], F3)
    spheres["B"].write_bytes(b"damaged")
    code = cli.main(["batch", *map(str, inputs[:3]), "-o", str(out), "--max-iter", "1000",
                     "--no-progress", "-q"])
    assert code == 0
    with open(out / "summary.csv", newline="") as fh:
        assert [r["status"] for r in csv.DictReader(fh)] == ["ok", "skipped", "ok"]
    U, F = igl.read_triangle_mesh(str(spheres["fish"]))
    assert U.shape[0] == V3.shape[0] and count_folds(F, U) == 0
    S, F = fs.read_geometry(str(spheres["B"]))
    np.testing.assert_array_equal(F, meshes["B"][1])
