"""README.md's Python examples run as written, in order, and do what their comments say.

The blocks of the "Python" section are executed one after the other in one
namespace (they build on each other), in a temporary folder holding a FreeSurfer
surface ``lh.white`` (the bundled dinosaur written by nibabel) for the GIfTI and
FreeSurfer example.  Then the namespace is checked against independent
references: libigl's mesh reader, nibabel's readers and exact identities.
"""

import pathlib
import re

import igl
import nibabel as nib
import numpy as np
import pytest

README = pathlib.Path(__file__).resolve().parents[1] / "README.md"


def _python_blocks():
    text = README.read_text(encoding="utf-8")
    section = text.split("\n## Python\n", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```python\n(.*?)```", section, flags=re.S)


@pytest.fixture(scope="module")
def namespace(tmp_path_factory):
    if not README.is_file():
        pytest.skip("README.md is not next to the tests (tests run from an sdist-less copy)")
    import igl_spheremap as sm

    folder = tmp_path_factory.mktemp("readme")
    V, F = igl.read_triangle_mesh(sm.example_mesh())
    nib.freesurfer.write_geometry(str(folder / "lh.white"), V, F.astype(np.int32))
    blocks = _python_blocks()
    assert len(blocks) >= 4, "the Python section lost its examples"
    ns = {}
    import os

    cwd = os.getcwd()
    os.chdir(folder)
    try:
        for block in blocks:
            exec(compile(block, str(README), "exec"), ns)
    finally:
        os.chdir(cwd)
    ns["_folder"] = folder
    return ns


def test_first_example_maps_the_bundled_dinosaur_fold_free(namespace):
    import igl_spheremap as sm

    V, F = igl.read_triangle_mesh(sm.example_mesh())
    U = namespace["result"].U
    assert U.shape == V.shape == (6013, 3)
    np.testing.assert_allclose(np.linalg.norm(U, axis=1), 1.0, atol=1e-12)
    assert sm.count_folds(namespace["result"].F, U) == 0
    assert namespace["ad"].shape == (F.shape[0], 3)


def test_written_spheres_read_back_at_radius_100(namespace):
    folder = namespace["_folder"]
    U = namespace["result"].U
    for name in ("lh.sphere.surf.gii", "lh.sphere"):
        path = str(folder / name)
        if name.endswith(".gii"):
            X = nib.load(path).agg_data("pointset")
        else:
            X = nib.freesurfer.read_geometry(path)[0]
        assert np.array_equal(X, np.asarray(X, np.float32))  # both formats store float32
        np.testing.assert_allclose(X, 100 * U, atol=1e-4)


def test_transfer_is_the_barycentric_interpolation_of_surface_2(namespace):
    reg, V1, V2, F2 = namespace["reg"], namespace["V1"], namespace["V2"], namespace["F2"]
    assert reg.success
    corners = V2[F2[reg.face]]                         # (n1, 3, 3)
    z = np.einsum("ij,ij->i", reg.bary, corners[:, :, 2])
    np.testing.assert_allclose(namespace["z_on_1"], z, atol=1e-12)
    # landmark pairs correspond exactly: each landmark of 1 lands on its partner of 2
    l1, l2 = namespace["l1"], namespace["l2"]
    np.testing.assert_allclose(reg.transfer(V2)[l1], V2[l2], atol=1e-9)


def test_resampled_surface_has_the_icosphere_connectivity(namespace):
    res, ico_F = namespace["res"], namespace["ico_F"]
    assert res.V.shape == (40962, 3) and np.array_equal(res.F, ico_F)
    assert res.data.shape == (40962,)


def test_atlas_registration_example_recovers_the_turned_sphere(namespace):
    from igl_spheremap.sphere.folds import folds_after_rounding

    reg, ab, F = namespace["atlas_reg"], namespace["ab"], namespace["F"]
    assert reg.U.shape == ab.U.shape and reg.success
    # the subject is the area-balanced sphere turned by 0.5 rad about z: registered, it comes back
    error = np.degrees(np.arccos(np.clip((reg.U * ab.U).sum(1), -1, 1)))
    assert np.median(error) < 2.0
    assert folds_after_rounding(F, reg.U, 100.0) == 0
    assert namespace["on_subject"].shape == (len(ab.U),)


def test_new_energy_recipe_reaches_the_cotangent_harmonic_energy(namespace):
    """The recipe of "The pieces, and adding an energy": a converged fold-free map whose energy
    is libigl's -1/2 tr(U^T L U) with the cotangent Laplacian of the mesh scaled to area 4 pi."""
    import igl_spheremap as sm

    Ve, Fe, run = namespace["Ve"], namespace["Fe"], namespace["run"]
    assert run.converged and sm.count_folds(Fe, run.U) == 0
    L = igl.cotmatrix(Ve, Fe)  # the energy is invariant to the scale of the mesh
    assert run.energy == pytest.approx(-0.5 * np.trace(run.U.T @ (L @ run.U)), rel=1e-10)
    assert run.energy == pytest.approx(sm.harmonic_energy(Ve, Fe, run.U), rel=1e-10)
