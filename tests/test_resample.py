"""igl_spheremap.resample: a surface and its data on a template's connectivity."""

import igl
import numpy as np
import pytest

import igl_spheremap

from igl_spheremap.mesh.shapes import icosphere
from igl_spheremap.uses.resampling import Resampled, resample


def test_icosphere_onto_itself_is_the_identity(rng):
    V, F = icosphere(4)
    data = rng.normal(size=(V.shape[0], 2))
    out = resample(V, F, V, V, F, data)
    assert isinstance(out, Resampled)
    assert np.abs(out.V - V).max() < 1e-12
    assert np.abs(out.data - data).max() < 1e-12
    assert np.array_equal(out.F, F) and out.F.dtype == np.int64
    # Every template vertex lands on its own vertex with weight 1.
    assert out.F is not F
    hit = np.take_along_axis(F[out.face], np.argmax(out.bary, axis=1)[:, None], axis=1).ravel()
    assert np.array_equal(hit, np.arange(V.shape[0]))


def test_real_mesh_onto_icosphere_lies_on_the_input_surface(conformal_map):
    V, F, result, _ = conformal_map("hippocampus.obj")
    T, FT = icosphere(4)
    a, c = np.array([0.5, -2.0, 1.0]), 3.0
    out = resample(V, F, result.U, T, FT, data=V @ a + c)
    assert np.array_equal(out.F, FT)
    assert out.V.shape == T.shape and out.data.shape == (T.shape[0],)
    diag = np.linalg.norm(V.max(axis=0) - V.min(axis=0))
    sqrD = igl.point_mesh_squared_distance(out.V, V, F)[0]
    assert np.sqrt(sqrD.max()) < 1e-12 * diag
    # Linear data follows the positions exactly (same barycentric weights).
    assert np.abs(out.data - (out.V @ a + c)).max() < 1e-10 * diag
    # The resampled points are where the template directions cut the input's spherical image.
    Q = np.einsum("kc,kcx->kx", out.bary, result.U[F[out.face]])
    assert np.abs(Q / np.linalg.norm(Q, axis=1, keepdims=True) - T).max() < 1e-9


def test_resampled_volume_converges_to_the_input_volume(conformal_map):
    V, F, result, _ = conformal_map("hippocampus.obj")
    vol = lambda X, G: np.linalg.det(X[G]).sum() / 6.0  # noqa: E731
    gaps = []
    for level in (4, 5, 6):
        T, FT = icosphere(level)
        out = resample(V, F, result.U, T, FT)
        assert vol(out.V, FT) > 0  # outward oriented like the input
        gaps.append(abs(vol(out.V, FT) / vol(V, F) - 1.0))
    assert gaps[0] > gaps[1] > gaps[2]


def test_data_shapes_and_none(rng):
    V, F = icosphere(2)
    T, FT = icosphere(3)
    X = V * np.array([1.0, 2.0, 3.0])  # an ellipsoid with the sphere as its map
    assert resample(X, F, V, T, FT).data is None
    d1 = resample(X, F, V, T, FT, data=V[:, 0]).data
    d2 = resample(X, F, V, T, FT, data=V).data
    assert d1.shape == (T.shape[0],) and d2.shape == T.shape
    assert np.array_equal(d1, d2[:, 0])


def test_bad_inputs_are_refused():
    V, F = icosphere(2)
    T, FT = icosphere(1)
    cases = [
        ((V[:-1], F, V, T, FT), "V must be"),
        ((np.where(np.arange(V.shape[0])[:, None] == 0, np.inf, V), F, V, T, FT), "V has 1 row"),
        ((V, F, V, T, FT[:, :2]), "F_template must be"),
        ((V, F, V, T, FT + 1), "F_template has 6 vertex"),
        ((V, F, V, T, FT, np.ones(3)), "data must be"),
        ((V, F, V, T, FT, np.where(np.arange(V.shape[0]) < 2, np.nan, 1.0)), "data has 2 rows"),
        ((V, F, V * 2.0, T, FT), "off the unit sphere"),
        ((V, F[:, ::-1], V, T, FT), "folded"),
    ]
    for args, msg in cases:
        with pytest.raises(ValueError, match=msg):
            resample(*args)


def test_a_short_map_is_named_and_a_template_must_be_a_sphere():
    """U with a row missing is blamed on U (not V); a torus or a non-convex surface is no
    template sphere (its faces do not tile the sphere from the origin)."""
    import igl

    V, F = icosphere(2)
    T, FT = icosphere(1)
    with pytest.raises(ValueError, match="^U must be the spherical map"):
        resample(V, F, V[:-1], T, FT)
    R, r = 1.0, 0.3  # a torus: genus 1
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 12, endpoint=False),
                       np.linspace(0, 2 * np.pi, 8, endpoint=False), indexing="ij")
    P = np.column_stack([((R + r * np.cos(v)) * np.cos(u)).ravel(),
                         ((R + r * np.cos(v)) * np.sin(u)).ravel(), (r * np.sin(v)).ravel()])
    idx = np.arange(96).reshape(12, 8)
    a, b = idx, np.roll(idx, -1, axis=0)
    c, d = np.roll(idx, -1, axis=1), np.roll(np.roll(idx, -1, axis=0), -1, axis=1)
    FT_torus = np.vstack([np.column_stack([a.ravel(), b.ravel(), d.ravel()]),
                          np.column_stack([a.ravel(), d.ravel(), c.ravel()])])
    with pytest.raises(ValueError, match="not a sphere.*genus"):
        resample(V, F, V, P, FT_torus)
    D, FD = igl.read_triangle_mesh(igl_spheremap.example_mesh())  # genus 0, not star-shaped
    D = D - D.mean(axis=0)
    with pytest.raises(ValueError, match=r"not a sphere: \d+ of \d+ vertices are more than 1% off"):
        resample(V, F, V, D, FD)  # a surface passed for its sphere
    with pytest.raises(ValueError, match=r"not a sphere: \d+ of \d+ faces fold"):
        resample(V, F, V, D / np.linalg.norm(D, axis=1, keepdims=True), FD)
    # an ellipsoid tiles the sphere under central projection, yet it is no template sphere
    with pytest.raises(ValueError, match=r"not a sphere: \d+ of \d+ vertices .*\(radii 0\.5 to 2"):
        resample(V, F, V, V * [1.0, 0.5, 2.0], F)


@pytest.mark.parametrize("method", ["barycentric", "adap_bary_area"])
def test_nan_data_outside_the_mask_is_ignored(method):
    """A medial wall's NaN with a mask leaving it out was refused ("data has 166 rows with
    non-finite values"): the masked vertices' values cannot matter, whatever they are."""
    T, TF = icosphere(3)
    S, SF = icosphere(2)
    V = T * [1.0, 1.2, 0.9]
    mask = (T[:, 2] < 0.5).astype(float)
    data = np.linspace(0.0, 1.0, len(T))
    walled = np.where(mask > 0, data, np.nan)
    other = np.where(mask > 0, data, 123.0)
    a = resample(V, TF, T, S, SF, data=walled, mask=mask, method=method).data
    b = resample(V, TF, T, S, SF, data=other, mask=mask, method=method).data
    np.testing.assert_array_equal(a, b)
    assert np.isfinite(a).sum() > len(S) // 2
    with pytest.raises(ValueError, match="166 rows with non-finite values .*leave those"):
        resample(V, TF, T, S, SF, data=walled, method=method)
