"""Storage precision (issue #15): the float32 rounding margin and ``precision="float32"``.

References are independent of the library: signed volumes are ``np.linalg.det``
of the three image vertices, storage is numpy's own float32 rounding
(``astype``) or the file read back with nibabel, and the margin's bound is
checked against the change rounding actually makes.
"""

import json
import os
import subprocess
import sys
import warnings
from fractions import Fraction

import igl
import nibabel.freesurfer as fs
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import igl_spheremap
from igl_spheremap import SphericalMapWarning, spherical_conformal_map
from igl_spheremap.options import MapOptions
from igl_spheremap.sphere.folds import below_margin, rounding_margin

from conftest import load_mesh, make_capsule, make_ellipsoid

U32 = 2.0 ** -24
SHAPES = {"ellipsoid 10:1": lambda: make_ellipsoid(3, (1.0, 1.0, 10.0)),
          "ellipsoid 30:1": lambda: make_ellipsoid(3, (1.0, 1.0, 30.0)),
          "ellipsoid 100:1": lambda: make_ellipsoid(3, (1.0, 1.0, 100.0)),
          "ellipsoid 1000:1": lambda: make_ellipsoid(3, (1.0, 1.0, 1000.0)),
          "capsule 50:1": lambda: make_capsule(50.0)}


def det(F, U):
    """Signed volume ``det[U_i, U_j, U_k]`` of every face (LAPACK, not the library)."""
    return np.linalg.det(np.stack([U[F[:, 0]], U[F[:, 1]], U[F[:, 2]]], axis=1))


def exact_folds(F, U):
    """Faces whose ``det[U_i, U_j, U_k]`` is <= 0 in exact rational arithmetic (stored
    coordinates are binary fractions): LAPACK's ``det`` where it is far from 0, ``Fraction``
    where rounding could change its sign."""
    d = det(F, U)
    near = np.flatnonzero(np.abs(d) <= 1e-9 * np.abs(U).max() ** 3)
    for f in near:
        (a, b, c), (e, g, h), (i, j, k) = [[Fraction(float(x)) for x in U[v]] for v in F[f]]
        d[f] = float(a * (g * k - h * j) - b * (e * k - h * i) + c * (e * j - g * i))
    return int(np.count_nonzero(d <= 0))


def stored(U, radius, R=None):
    """``U`` (rotated by ``R``) stored as ``radius * U`` in float32 and read back, unit scale."""
    W = U if R is None else U @ R.T
    return (radius * W).astype(np.float32).astype(np.float64) / radius


def folds_stored(F, U, radius, R=None):
    return int(np.count_nonzero(det(F, stored(U, radius, R)) <= 0))


def random_triangles(rng, m, scale):
    """``m`` small triangles on the unit sphere; the third corner often near the first (slivers)."""
    c = rng.normal(size=(m, 3))
    c /= np.linalg.norm(c, axis=1, keepdims=True)
    U = np.vstack([c + scale * rng.normal(size=(m, 3)) * rng.uniform(0, 1, size=(m, 1)) ** k
                   for k in (0, 0, 3)])
    U /= np.linalg.norm(U, axis=1, keepdims=True)
    return np.arange(3 * m).reshape(3, m).T, U


def map_quietly(V, F, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SphericalMapWarning)
        return spherical_conformal_map(V, F, **kw)


# --------------------------------------------------------------------------- the margin


@pytest.mark.parametrize("scale", [1e-7, 1e-5, 1e-2])
def test_margin_bounds_the_change_of_float32_rounding(scale):
    """|det(stored) - det| <= margin at several radii and in random rotations."""
    rng = np.random.default_rng(7)
    F, U = random_triangles(rng, 20_000, scale)
    margin = rounding_margin(F, U, "float32")
    worst = 0.0
    for seed in range(4):
        R = Rotation.random(random_state=seed).as_matrix()
        s = det(F, U @ R.T)
        for radius in (1.0, 100.0, 0.37, 3.0e4):
            change = np.abs(det(F, stored(U, radius, R)) - s)
            assert np.all(change <= margin)
            worst = max(worst, float(np.max(change / margin)))
    assert worst > 0.1  # the bound is not loose by orders of magnitude


def test_margin_matches_its_formula_and_ignores_rotation():
    rng = np.random.default_rng(5)
    F, U = random_triangles(rng, 1000, 1e-4)
    a, b, c = U[F[:, 0]], U[F[:, 1]], U[F[:, 2]]
    P = (np.linalg.norm(a - b, axis=1) + np.linalg.norm(b - c, axis=1)
         + np.linalg.norm(c - a, axis=1))
    expected = 1.25 * (U32 * P + 3 * U32 ** 2 + U32 ** 3)
    np.testing.assert_allclose(rounding_margin(F, U, "float32"), expected, rtol=1e-12)
    R = Rotation.random(random_state=1).as_matrix()
    np.testing.assert_allclose(rounding_margin(F, U @ R.T, "float32"), expected, rtol=1e-9)


def test_faces_above_the_margin_never_fold_when_stored():
    """Axis permutations and sign flips (all 48) and random rotations, four radii."""
    rng = np.random.default_rng(3)
    F, U = random_triangles(rng, 20_000, 3e-7)
    above = det(F, U) > rounding_margin(F, U, "float32")
    assert np.array_equal(above, ~below_margin(F, U, "float32"))
    assert 0 < above.sum() < F.shape[0]  # both sides are exercised
    cube = [np.diag(signs)[:, list(perm)] for perm in
            [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
            for signs in np.array(np.meshgrid(*[[1, -1]] * 3)).T.reshape(-1, 3)]
    rotations = cube + [Rotation.random(random_state=s).as_matrix() for s in range(4)]
    folded_below = 0
    for R in rotations:
        sign = np.sign(np.linalg.det(R))  # a reflection reverses every orientation
        for radius in (1.0, 100.0, 0.37, 3.0e4):
            s = sign * det(F, stored(U, radius, R))
            assert np.count_nonzero(s[above] <= 0) == 0
            folded_below += np.count_nonzero(s[~above] <= 0)
    assert folded_below > 0  # faces below the margin do fold: it is not vacuous


def test_float64_margin_is_the_fold_test():
    rng = np.random.default_rng(1)
    F, U = random_triangles(rng, 1000, 1e-3)
    U[F[:10, 1]] = U[F[:10, 2]]  # ten collapsed faces
    assert np.array_equal(rounding_margin(F, U, "float64"), np.zeros(F.shape[0]))
    s = det(F, U)
    clear = np.abs(s) > 1e-12  # away from ties the test is the sign of det
    assert np.array_equal(below_margin(F, U, "float64")[clear], (s <= 0)[clear])
    assert below_margin(F, U, "float64")[:10].all()


def test_unknown_precision_and_conflicts_raise():
    F, U = random_triangles(np.random.default_rng(0), 10, 1e-2)
    with pytest.raises(ValueError, match="precision"):
        rounding_margin(F, U, "float16")
    with pytest.raises(ValueError, match="precision"):
        MapOptions(precision="float16")
    with pytest.raises(ValueError, match="fold_barrier"):
        MapOptions(method="paper", precision="float32")
    assert MapOptions().precision == "float64"


# --------------------------------------------------------------------------- the map


def test_float64_default_is_the_plain_fold_test(conformal_map):
    """The default is float64: no margin kept, no repair, same map as asking for float64."""
    V, F, r, _ = conformal_map("fish_lowres.obj")
    r64 = spherical_conformal_map(V, F, precision="float64")
    assert r.options.precision == "float64" and r.repair is None and r.success
    assert np.array_equal(r.U, r64.U) and r.message == r64.message
    assert r.below_margin == r.folds == int(np.count_nonzero(det(r.F, r.U) <= 0)) == 0


@pytest.fixture(scope="module")
def dino32():
    V, F = load_mesh("dino.obj")
    with warnings.catch_warnings():
        warnings.simplefilter("error", SphericalMapWarning)
        return V, F, spherical_conformal_map(V, F, precision="float32")


def test_dino_float32_map_survives_float32_storage(dino32, conformal_map):
    V, F, r = dino32
    s, (a, b, c) = det(r.F, r.U), (r.U[r.F[:, k]] for k in range(3))
    P = np.linalg.norm(a - b, axis=1) + np.linalg.norm(b - c, axis=1) + np.linalg.norm(c - a, axis=1)
    assert r.success and r.below_margin == 0 and r.repair is not None
    assert np.all(s > 1.25 * (U32 * P + 3 * U32 ** 2))
    R = Rotation.random(random_state=2).as_matrix()
    for radius, rot in ((100.0, None), (1.0, None), (100.0, R)):
        assert folds_stored(r.F, r.U, radius, rot) == 0
    # the reason for the setting: the float64 map folds once stored at radius 100
    _, _, r64, _ = conformal_map("dino.obj")
    assert r64.folds == 0 and folds_stored(r64.F, r64.U, 100.0) > 100


def test_dino_float32_timings_are_the_parts_of_its_seconds(dino32):
    """With a repair, every stage's seconds are non-negative and together within the call's."""
    _, _, r = dino32
    assert {"rounds", "repair", "finish"} <= set(r.timings)
    assert min(r.timings.values()) >= 0.0
    assert sum(r.timings.values()) <= r.seconds


def test_dino_float32_costs_bounded_angle_distortion(dino32, conformal_map):
    V, F, r = dino32
    _, _, r64, _ = conformal_map("dino.obj")
    a32 = igl_spheremap.angle_distortion(V, r.F, r.U).mean()
    a64 = igl_spheremap.angle_distortion(V, r64.F, r64.U).mean()
    assert a64 <= a32 < 3.0 * a64  # README: the margin costs distortion on thin features


@pytest.mark.parametrize("shape", SHAPES)
def test_elongated_shapes_stay_fold_free(shape):
    """float64: fold-free, not collapsed; float32: also fold-free once stored at radius 100."""
    V, F = SHAPES[shape]()
    with warnings.catch_warnings():
        warnings.simplefilter("error", SphericalMapWarning)  # folds or no convergence warn
        r64 = spherical_conformal_map(V, F)
        r32 = spherical_conformal_map(V, F, precision="float32")
    assert np.count_nonzero(det(r64.F, r64.U) <= 0) == 0
    assert r64.energy > 0.5 * 4 * np.pi
    assert r32.success and r32.below_margin == 0
    R = Rotation.random(random_state=4).as_matrix()
    assert folds_stored(r32.F, r32.U, 100.0) == folds_stored(r32.F, r32.U, 1.0, R) == 0


def test_a_map_far_from_conformal_says_how_far():
    """1000:1 ellipsoid: no near-conformal map is representable; the guaranteed path's
    fold-free map (conformal descent, nothing frozen) is the answer, and its message gives
    E/4pi as libigl's intrinsic Delaunay Laplacian measures it, far above 1."""
    V, F = SHAPES["ellipsoid 1000:1"]()
    r = map_quietly(V, F)
    L = igl.intrinsic_delaunay_cotmatrix(V, F)[0]
    energy = -0.5 * np.trace(r.U.T @ (L @ r.U)) / (4 * np.pi)
    assert r.success and r.folds == 0 and energy > 2.0
    assert np.count_nonzero(det(r.F, r.U) <= 0) == 0
    assert "guaranteed path" in r.message and f"E/4pi = {energy:.3f}" in r.message


def test_a_forced_collapse_is_detected_and_reverted():
    """30:1 ellipsoid without the fold barrier: the star round collapses the map
    (harmonic energy far below 4 pi, with libigl's intrinsic Delaunay Laplacian: the
    plain cotangent one has negative weights on this mesh); the earlier round is returned."""
    V, F = make_ellipsoid(3, (1.0, 1.0, 30.0))
    L = igl.intrinsic_delaunay_cotmatrix(V, F)[0]

    def energy(U):
        return -0.5 * np.trace(U.T @ (L @ U)) / (4 * np.pi)

    with pytest.warns(SphericalMapWarning, match="collapsed"):
        r = spherical_conformal_map(V, F, fold_barrier=False)
    collapsed = [rnd for rnd in r.rounds if energy(rnd.U) < 0.5]
    assert collapsed and "collapsed" in r.message and not r.success
    assert energy(r.U) > 0.9
    earlier = [rnd for rnd in r.rounds if rnd.index < collapsed[0].index]
    assert r.folds == np.count_nonzero(det(r.F, r.U) <= 0) == min(
        np.count_nonzero(det(r.F, rnd.U) <= 0) for rnd in earlier)


def _without_repairs(monkeypatch):
    from igl_spheremap.precision import repair as representable

    for name in list(representable.REPAIRS):
        monkeypatch.setitem(representable.REPAIRS, name, lambda *a: "disabled by the test")


def test_a_failed_repair_is_reported_not_hidden(monkeypatch):
    """With every repair and the guaranteed path disabled, the faces left below the margin
    are counted and warned."""
    _without_repairs(monkeypatch)
    V, F = load_mesh("dino.obj")
    with pytest.warns(SphericalMapWarning) as caught:
        r = spherical_conformal_map(V, F, precision="float32", guaranteed_path=False)
    s, (a, b, c) = det(r.F, r.U), (r.U[r.F[:, k]] for k in range(3))
    P = np.linalg.norm(a - b, axis=1) + np.linalg.norm(b - c, axis=1) + np.linalg.norm(c - a, axis=1)
    margin = 1.25 * (U32 * P + 3 * U32 ** 2 + U32 ** 3)
    below = int(np.count_nonzero(s <= margin))
    assert below > 0 and r.below_margin == below and r.folds == 0 and not r.success
    assert f"{below} faces below their float32 rounding margin" in str(caught[0].message)


def test_without_repairs_the_guaranteed_path_stores_dino_in_float32(monkeypatch):
    """The rounds' map has faces below the float32 margin and no repair runs: the guaranteed
    path starts from a Tutte embedding above the margin and keeps every face above it."""
    _without_repairs(monkeypatch)
    V, F = load_mesh("dino.obj")
    r = map_quietly(V, F, precision="float32")
    s, (a, b, c) = det(r.F, r.U), (r.U[r.F[:, k]] for k in range(3))
    P = np.linalg.norm(a - b, axis=1) + np.linalg.norm(b - c, axis=1) + np.linalg.norm(c - a, axis=1)
    assert np.all(s > 1.25 * (U32 * P + 3 * U32 ** 2 + U32 ** 3))
    assert r.success and r.below_margin == 0 and "guaranteed path" in r.message


# --------------------------------------------------------------------------- the CLI


def run_cli(*args, cwd):
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    return subprocess.run([sys.executable, "-m", "igl_spheremap", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, env=env, timeout=600)


def test_cli_maps_float32_for_freesurfer_output_unless_told(tmp_path):
    """lh.* output (FreeSurfer, float32 at radius 100): float32 by default, fold-free in the
    file read back; --precision float64 overrides it, and that file folds."""
    V, F = load_mesh("dino.obj")
    igl.write_triangle_mesh(str(tmp_path / "dino.obj"), V, F)
    for flag, out in (((), "lh.auto"), (("--precision", "float64"), "lh.f64"),
                      ((), "dino_sphere.obj")):
        r = run_cli("dino.obj", "-o", out, "--json", f"{out}.json", "--no-progress", "-q",
                    "--allow-folds", *flag, cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        rep = json.loads((tmp_path / f"{out}.json").read_text())
        S, T = (fs.read_geometry(str(tmp_path / out)) if out.startswith("lh.")
                else igl.read_triangle_mesh(str(tmp_path / out)))
        folds = exact_folds(T, S)
        assert rep["folds_stored"] == folds
        if out == "lh.auto":
            assert rep["options"]["precision"] == "float32" and folds == 0 and rep["success"]
        elif out == "lh.f64":
            assert rep["options"]["precision"] == "float64" and folds > 0
            assert not rep["success"] and "as stored" in rep["message"]
        else:
            assert rep["options"]["precision"] == "float64" and folds == 0
