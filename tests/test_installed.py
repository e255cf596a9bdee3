"""Which igl_spheremap the tests run against.

CI runs the suite twice: in the checkout (editable install, as README says) and
against the wheel built from it, installed in a fresh virtual environment, from a
folder outside the checkout with IGL_SPHEREMAP_EXPECT_INSTALLED=1.  Then the
package imported must be the installed one: a test run that silently imported
the source tree would not test the wheel.
"""

import os
from pathlib import Path

import pytest

import igl_spheremap

REPO = Path(__file__).resolve().parents[1]


def test_the_package_under_test_is_the_installed_one_when_required():
    if os.environ.get("IGL_SPHEREMAP_EXPECT_INSTALLED") != "1":
        pytest.skip("IGL_SPHEREMAP_EXPECT_INSTALLED=1 is set by CI for the installed wheel")
    path = Path(igl_spheremap.__file__).resolve()
    assert REPO not in path.parents, f"imported the source tree: {path}"
    assert "site-packages" in path.parts


def test_the_package_carries_its_data_files():
    from importlib import resources
    for name in ("dino.obj", "README.txt"):
        ref = resources.files("igl_spheremap") / "data" / name
        assert ref.is_file(), name
    for sub in ("mesh", "sphere", "optimize", "folding", "precision", "uses", "io", "app", "cli",
                "viz", "viz/registration"):
        assert (resources.files("igl_spheremap") / sub / "__init__.py").is_file(), sub


def test_example_mesh_is_a_path_libigl_reads():
    import igl
    V, F = igl.read_triangle_mesh(igl_spheremap.example_mesh())
    assert V.shape == (6013, 3) and F.shape[1] == 3
    # the data folder also holds its README, and the package's files are one '..' away
    for name in ("bunny.obj", "README.txt", "../__init__.py"):
        with pytest.raises(FileNotFoundError, match="bundles 'dino.obj'"):
            igl_spheremap.example_mesh(name)
