"""Outputs refused before any work if they cannot be written or would do harm; nothing left behind."""

import importlib
import os
import uuid
from pathlib import Path

import pytest

from igl_spheremap.io import check_output_paths, check_sphere_output, output_paths


def tree(root):
    return sorted(str(p.relative_to(root)) for p in Path(root).rglob("*"))


@pytest.fixture
def work(tmp_path):
    (tmp_path / "in").mkdir()
    mesh = tmp_path / "in" / "dino.obj"
    mesh.write_text("v 0 0 0\n")
    return tmp_path, mesh


def refused(root, exc, match, *args, **kwargs):
    before = tree(root)
    with pytest.raises(exc, match=match):
        check_output_paths(*args, **kwargs)
    assert tree(root) == before


def test_outputs_that_would_overwrite_the_input(work, monkeypatch):
    root, mesh = work
    refused(root, ValueError, r"sphere output .* would overwrite the input ", mesh, mesh)
    monkeypatch.chdir(root / "in")
    refused(root, ValueError, "would overwrite the input", mesh, "dino.obj")  # relative name
    refused(root, ValueError, r"report output .* would overwrite the input", mesh,
            root / "s.obj", report_path=root / "in" / ".." / "in" / "dino.obj")
    refused(root, ValueError, r"data output .* would overwrite", mesh, root / "s.obj",
            data_path=mesh)
    (root / "link.obj").symlink_to(mesh)
    refused(root, ValueError, "would overwrite the input", mesh, root / "link.obj")
    os.link(mesh, root / "hard.obj")
    refused(root, ValueError, "would overwrite the input", mesh, root / "hard.obj")


def test_two_outputs_on_one_file(work):
    root, mesh = work
    refused(root, ValueError, r"the report output and the sphere output are the same file", mesh,
            root / "s.obj", report_path=root / "out" / ".." / "s.obj")
    refused(root, ValueError, r"the report output and the data output", mesh, root / "s.obj",
            data_path=root / "d.npz", report_path=root / "d.npz")


def test_output_that_is_a_folder_or_below_a_file(work):
    root, mesh = work
    (root / "taken.obj").mkdir()
    refused(root, IsADirectoryError, "sphere output .* is an existing folder", mesh,
            root / "taken.obj")
    (root / "plain").write_text("x")
    refused(root, NotADirectoryError, r"'.*plain' is not a folder", mesh,
            root / "plain" / "sub" / "s.obj")


def test_missing_folder_at_the_root_is_refused_and_not_created():
    name = f"/igl-spheremap-test-{uuid.uuid4().hex[:8]}"
    assert not Path(name).exists()
    with pytest.raises(ValueError, match=rf"would create folder {name} at the file system root; "
                                         "create it first"):
        check_output_paths("in.obj", f"{name}/deeper/x.obj")
    assert not Path(name).exists()


def test_missing_folders_below_a_writable_one_are_allowed_not_created(work):
    root, mesh = work
    paths = output_paths(mesh, root / "a" / "b" / "s.surf.gii")
    got = check_output_paths(mesh, paths, report_path=paths.report, data_path=paths.data)
    assert got == {"sphere": paths.sphere, "data": paths.data, "report": paths.report}
    assert tree(root) == ["in", "in/dino.obj"]  # no folder, no probe file


def test_unwritable_folder(work, monkeypatch):
    root, mesh = work

    def denied(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    module = importlib.import_module("igl_spheremap.io.check_output_paths")
    monkeypatch.setattr(module.tempfile, "mkstemp", denied)
    refused(root, PermissionError, rf"cannot write into folder '{root}' \(to create '{root}/out/x' "
                                   r"in\): Permission denied", mesh, root / "out" / "x" / "s.obj")
    (root / "out").mkdir()
    refused(root, PermissionError, r"cannot write into folder '.*out': Permission denied", mesh,
            root / "out" / "s.obj")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_read_only_folder_without_mocking(work):
    root, mesh = work
    (root / "ro").mkdir()
    (root / "ro").chmod(0o555)
    try:
        refused(root, PermissionError, "cannot write into folder", mesh, root / "ro" / "s.obj")
    finally:
        (root / "ro").chmod(0o755)


@pytest.mark.parametrize("name, match", [
    ("s.stl", "STL keeps no per-vertex correspondence"),
    ("s.STL", "STL keeps no per-vertex correspondence"),
    ("s.wrl", "15 significant digits"),
    ("s.mesh", "tetrahedra"),
    ("s_sphere", "cannot tell the output format"),
])
def test_sphere_formats_that_cannot_carry_the_map(work, name, match):
    root, mesh = work
    refused(root, ValueError, match + r".*use \.obj, \.off, \.ply, \.surf\.gii or a FreeSurfer",
            mesh, root / name)
    with pytest.raises(ValueError, match=match):
        check_sphere_output(name)


@pytest.mark.parametrize("name, family", [("s.obj", "mesh"), ("s.OFF", "mesh"), ("s.ply", "mesh"),
                                          ("s.surf.gii", "gifti"), ("lh.sphere", "freesurfer")])
def test_sphere_formats_accepted(name, family):
    assert check_sphere_output(name) == family
