"""The public functions of igl_spheremap.viz refuse bad input with a ValueError or TypeError that
names the argument and counts the offending elements, instead of a numpy/matplotlib error from
deep inside (or, worse, a silent picture of nonsense)."""

import numpy as np
import pytest

import igl_spheremap as sm
from igl_spheremap import viz
from igl_spheremap.mesh.shapes import icosphere


@pytest.fixture(scope="module")
def sphere():
    V, F = icosphere(2)
    V = np.asarray(V, np.float64)
    return V / np.linalg.norm(V, axis=1, keepdims=True), np.asarray(F, np.int64)


def test_u_colors_counts_nan_values():
    u = np.linspace(-1.0, 1.0, 20)
    u[[3, 7, 11]] = np.nan
    with pytest.raises(ValueError, match=r"u has 3 NaN or infinite values of 20 \(first: index 3\)"):
        viz.u_colors(u)
    with pytest.raises(ValueError, match=r"u has shape \(4, 3\)"):
        viz.u_colors(np.zeros((4, 3)))


def test_part_colors_names_shape_and_nan_rows():
    P = np.random.default_rng(0).normal(size=(30, 3))
    with pytest.raises(ValueError, match=r"P has shape \(30, 2\)"):
        viz.part_colors(P[:, :2])
    P[[0, 5]] = np.nan
    with pytest.raises(ValueError, match="P has 2 rows with NaN"):
        viz.part_colors(P)


def test_mercator_chart_refuses_non_spherical_maps_and_bad_poles(sphere):
    U, F = sphere
    n = U.shape[0]
    with pytest.raises(ValueError, match=f"U has {n} rows off the unit sphere"):
        viz.mercator_corners(2.0 * U, F, 0)            # a radius-2 sphere, not a map
    with pytest.raises(ValueError, match=f"U has {F.shape[0]} rows off the unit sphere"):
        viz.mercator_vertices(F, 0)                     # faces passed as the map
    bad = U.copy()
    bad[[1, 2]] = np.nan
    with pytest.raises(ValueError, match="U has 2 rows with NaN"):
        viz.mercator_corners(bad, F, 0)
    with pytest.raises(ValueError, match=rf"south has 1 index outside 0..{n - 1}"):
        viz.mercator_vertices(U, n)
    with pytest.raises(ValueError, match="north and south are the same vertex"):
        viz.mercator_vertices(U, 3, 3)
    with pytest.raises(ValueError, match="weights has 1 value"):
        viz.mercator_vertices(U, 0, weights=np.r_[-1.0, np.ones(n - 1)])
    # a valid chart still works: the south pole's row sits at the bottom clip
    X = viz.mercator_vertices(U, 0)
    assert X.shape == (n, 2) and X[0, 1] == X[:, 1].min()


def test_tip_vertices_and_chart_poles_check_their_inputs(sphere):
    U, F = sphere
    with pytest.raises(ValueError, match=rf"u has shape \(5,\); expected .* \({U.shape[0]}\)"):
        viz.tip_vertices(U, F, np.zeros(5))
    with pytest.raises(ValueError, match="F has shape"):
        viz.tip_vertices(U, np.c_[F, F[:, :1]], np.zeros(U.shape[0]))
    with pytest.raises(ValueError, match="anchors is empty"):
        viz.chart_poles(U, [])
    with pytest.raises(ValueError, match="anchors has 1 index outside"):
        viz.chart_poles(U, [0, U.shape[0] + 4])


def test_contact_sheet_of_no_pngs(tmp_path):
    with pytest.raises(ValueError, match="paths is empty"):
        viz.contact_sheet([], str(tmp_path / "sheet.png"))
    assert not (tmp_path / "sheet.png").exists()


def test_stage_builders_refuse_a_result_of_the_other_kind(sphere):
    V, F = sphere
    result = sm.spherical_conformal_map(V, F)
    with pytest.raises(TypeError, match="got ndarray; pass the result"):
        viz.build_stages(result.U)
    with pytest.raises(TypeError, match="expected a SurfaceMapResult .* got SphericalMapResult"):
        viz.build_registration_stages(result, V, V, [0, 1, 2], [0, 1, 2])
    with pytest.raises(ValueError, match="stages is empty"):
        viz.show(result, stages=[], screenshot_dir="unused")
    with pytest.raises(ValueError, match="stages is empty"):
        viz.show_registration([], screenshot_dir="unused")
    single = viz.build_stages(result, final_phi=False)
    with pytest.raises(ValueError, match=f"{len(single)} of {len(single)} stages are not stages "
                                         "of an inter-surface map"):
        viz.show_registration(single, screenshot_dir="unused")


def test_registration_stages_check_surfaces_landmarks_and_data(sphere):
    V, F = sphere
    n = V.shape[0]
    V2 = V * np.array([1.0, 1.2, 0.9])                  # an ellipsoid: the same triangulation
    lm = np.array([0, 1, 2, 5], dtype=np.int64)
    result = sm.surface_map(V, F, V2, F, lm, lm)
    with pytest.raises(ValueError, match=f"V2 has {n - 1} rows; expected {n}"):
        viz.build_registration_stages(result, V, V2[:-1], lm, lm)
    with pytest.raises(ValueError, match="landmarks1 has 4 vertices and landmarks2 3"):
        viz.build_registration_stages(result, V, V2, lm, lm[:3])
    with pytest.raises(ValueError, match="landmarks2 has 1 index outside"):
        viz.build_registration_stages(result, V, V2, lm, np.r_[lm[:3], n])
    data = np.linspace(0.0, 1.0, n)
    data[[4, 9]] = np.inf
    with pytest.raises(ValueError, match=f"data2 has 2 NaN or infinite values of {n}"):
        viz.build_registration_stages(result, V, V2, lm, lm, data)
    stages = viz.build_registration_stages(result, V, V2, lm, lm, np.arange(n, dtype=float))
    # the data carried through the last stage is P @ data2 (P: barycentric, rows sum to 1)
    np.testing.assert_allclose(stages[-1]["carried"], result.P @ np.arange(n, dtype=float))


def test_modules_named_in_the_package_docstring_exist():
    """Every :mod:`.name` in igl_spheremap.viz's docstring is a module of the package."""
    import importlib
    import re

    names = re.findall(r":mod:`\.([\w.]+)`", viz.__doc__)
    assert len(names) >= 10
    for name in names:
        importlib.import_module(f"igl_spheremap.viz.{name}")


def test_project_refuses_2d_points_and_projects_3d_ones():
    """project() took (k, 2) points silently (only x and y are used on screen); the scene is
    3-D and a (k, 2) array is another array passed by mistake."""
    with pytest.raises(ValueError, match=r"points has shape \(4, 2\)"):
        viz.project(np.zeros((4, 2)), (2000, 440))
    # two points a unit apart along x land the same number of pixels apart as along y
    px = viz.project(np.array([[0.0, 0, 0], [1.0, 0, 0], [0.0, 1, 0]]), (2000, 440))
    assert px[1, 0] - px[0, 0] == pytest.approx(px[0, 1] - px[2, 1])
    assert px[1, 1] == px[0, 1] and px[2, 0] == px[0, 0]
