"""Slivers (issue #15): libigl's intrinsic Delaunay edge flips can run away on them.

On an icosphere with edges split very close to one end, ``igl.intrinsic_delaunay_cotmatrix``
can flip forever (a NaN edge length from rounding) and grow its flip stack until memory
runs out.  ``laplacian(..., "intrinsic_delaunay")`` sends meshes with slivers to
``bounded_intrinsic_delaunay_cotmatrix`` (the same flips, bounded).  No test here calls
libigl's intrinsic Delaunay on such a mesh: where the routing is under test, libigl is
replaced by a function that fails.
"""

import warnings

import igl
import numpy as np
import pytest

import igl_spheremap
from igl_spheremap import count_folds
from conftest import load_mesh, make_icosphere
from igl_spheremap.mesh.intrinsic_delaunay import bounded_intrinsic_delaunay_cotmatrix
from igl_spheremap.mesh.intrinsic_delaunay import CAP_RTOL, NEEDLE_RTOL, sliver_statistics
from igl_spheremap.mesh.mollify import mollified_edge_lengths
from igl_spheremap.mesh.operators import laplacian


def split_icosphere(level, n_edges, t, seed=0):
    """``make_icosphere(level)`` with ``n_edges`` edges, no two on one face, each split by a
    new vertex at ``t`` times its length from one end; both faces of the edge are split in two.

    Of the four faces of each split, the two at that end are needles whose height ratio is
    about ``t`` (their area is ``t`` times the original's, their longest edge the original
    one); the other two keep the icosphere's shape.
    """
    V, F = make_icosphere(level)
    m = F.shape[0]
    _, uE, _, uEC, uEE = igl.unique_edge_map(F)
    used = np.zeros(m, bool)
    V, new = list(V), []
    for e in np.random.default_rng(seed).permutation(uE.shape[0]):
        h1, h2 = uEE[uEC[e]], uEE[uEC[e] + 1]  # half-edge h = f + m c, opposite corner c
        f1, f2 = h1 % m, h2 % m
        if used[f1] or used[f2]:
            continue
        used[[f1, f2]] = True
        c1, c2 = h1 // m, h2 // m
        a, b, x, y = F[f1, (c1 + 1) % 3], F[f1, (c1 + 2) % 3], F[f1, c1], F[f2, c2]
        p = len(V)
        V.append(V[a] + t * (V[b] - V[a]))
        F[f1], F[f2] = (x, a, p), (y, p, a)  # the needles
        new += [(x, p, b), (y, b, p)]
        if len(new) == 2 * n_edges:
            break
    return np.array(V), np.vstack([F, np.array(new, np.int64)])


def cap_icosphere(level, n_faces, s, seed=0):
    """``make_icosphere(level)`` with ``n_faces`` faces ``(a, b, x)`` split 1-to-3 at
    ``p = mid(a, b) + s (x - mid(a, b))``: the face ``(a, b, p)`` is a cap (angle at ``p``
    within ~``2 s`` of 180 degrees, height ratio ~``s``), the other two are not slivers."""
    V, F = make_icosphere(level)
    V = list(V)
    new = []
    for f in np.random.default_rng(seed).choice(F.shape[0], n_faces, replace=False):
        a, b, x = F[f]
        mid = 0.5 * (V[a] + V[b])
        p = len(V)
        V.append(mid + s * (V[x] - mid))
        F[f] = (a, b, p)
        new += [(b, x, p), (x, a, p)]
    return np.array(V), np.vstack([F, np.array(new, np.int64)])


def _never_libigl(*args, **kwargs):
    raise AssertionError("igl.intrinsic_delaunay_cotmatrix must not run on this mesh")


def _check_laplacian(L, n):
    """Exact properties of a cotangent Laplacian of valid (intrinsic) triangles."""
    assert L.shape == (n, n) and np.isfinite(L.data).all()
    assert abs(L - L.T).max() == 0
    np.testing.assert_allclose(np.asarray(L.sum(axis=1)).ravel(), 0, atol=1e-9 * abs(L).max())
    lam = np.linalg.eigvalsh(L.toarray())  # negative semidefinite, one zero eigenvalue
    assert lam[-1] <= 1e-9 * abs(lam[0]) and lam[-2] < 0


def test_sliver_statistics_of_known_triangles():
    V = np.array([[0, 0, 0], [1, 0, 0], [0.5, 3 ** 0.5 / 2, 0],  # equilateral
                  [0, 0, 0], [1, 0, 0], [0, 1, 0],                # right isosceles
                  [0, 0, 0], [1, 0, 0], [2, 0, 0]], dtype=np.float64)  # collinear
    F = np.arange(9, dtype=np.int64).reshape(3, 3)
    edge_ratio, slack = sliver_statistics(V, F)
    np.testing.assert_allclose(edge_ratio, [1, 2 ** -0.5, 0.5], rtol=1e-15)
    np.testing.assert_allclose(slack, [1, 2 ** 0.5 - 1, 0], rtol=1e-15, atol=1e-16)


@pytest.mark.parametrize("name", ["fish_lowres.obj", "goathead.obj", "hippocampus.obj", "dino.obj"])
def test_real_meshes_keep_libigls_laplacian(name):
    V, F = load_mesh(name)
    edge_ratio, slack = sliver_statistics(V, F)
    assert edge_ratio.min() > NEEDLE_RTOL and slack.min() > CAP_RTOL
    assert (laplacian(V, F) != igl.intrinsic_delaunay_cotmatrix(V, F)[0]).nnz == 0


@pytest.mark.parametrize("make", [lambda: load_mesh("dino.obj"), lambda: make_icosphere(3),
                                  lambda: split_icosphere(3, 200, 1e-2),
                                  lambda: cap_icosphere(3, 50, 1e-7)])
def test_bounded_flips_equal_libigl_where_libigl_ends(make):
    V, F = make()
    L, skipped = bounded_intrinsic_delaunay_cotmatrix(V, F)
    assert skipped == 0
    assert (L != igl.intrinsic_delaunay_cotmatrix(V, F)[0]).nnz == 0


@pytest.mark.parametrize("t", [1e-7, 1e-11])
def test_split_icosphere_gets_bounded_flips(t, monkeypatch):
    V, F = split_icosphere(3, 200, t, seed=2)  # libigl's flips diverge on these (scratch/)
    igl_spheremap.validate_mesh(V, F)
    assert sliver_statistics(V, F)[0].min() < NEEDLE_RTOL
    L, _ = bounded_intrinsic_delaunay_cotmatrix(V, F)
    _check_laplacian(L, V.shape[0])
    monkeypatch.setattr(igl, "intrinsic_delaunay_cotmatrix", _never_libigl)
    assert (laplacian(V, F) != L).nnz == 0
    with warnings.catch_warnings():  # it may not converge; it must end
        warnings.simplefilter("ignore", igl_spheremap.SphericalMapWarning)
        r = igl_spheremap.spherical_conformal_map(V, F, max_rounds=1, max_iter=200)
    np.testing.assert_allclose(np.linalg.norm(r.U, axis=1), 1, atol=1e-12)
    assert r.success == (r.folds == 0 and r.converged)


def test_flip_limit():
    V, F = split_icosphere(3, 200, 1e-2)  # needs a few hundred flips
    with pytest.raises(igl_spheremap.MeshError, match="did not end within 5 flips") as err:
        bounded_intrinsic_delaunay_cotmatrix(V, F, max_flips=5)
    assert err.value.problem == "slivers" and err.value.count == 5


def test_degenerate_caps_get_the_laplacian_of_the_mollified_metric(monkeypatch):
    """Caps whose lengths meet the triangle inequality within rounding have no finite
    cotangent; the Laplacian is then that of the intrinsically mollified lengths (Sharp,
    Crane 2020), here against libigl's own flips of those lengths, and the mesh maps."""
    V, F = cap_icosphere(3, 50, 1e-9)
    with pytest.raises(igl_spheremap.MeshError, match="slivers") as err:
        bounded_intrinsic_delaunay_cotmatrix(V, F)  # the raw lengths stay refused
    assert err.value.count == 50
    ld, Fd = igl.intrinsic_delaunay_triangulation(mollified_edge_lengths(V, F)[0], F)[:2]
    expected = igl.cotmatrix_intrinsic(ld, Fd)
    monkeypatch.setattr(igl, "intrinsic_delaunay_cotmatrix", _never_libigl)
    L = laplacian(V, F)
    _check_laplacian(L, V.shape[0])
    assert abs(L - expected).max() <= 1e-12 * abs(expected).max()
    r = igl_spheremap.spherical_conformal_map(V, F)
    assert r.success and count_folds(F, r.U) == 0


@pytest.mark.parametrize("t", [1e-11, 1e-2])
def test_cotan_laplacian_is_libigls_on_slivers(t):
    V, F = split_icosphere(3, 200, t)
    L = laplacian(V, F, "cotan")
    assert (L != igl.cotmatrix(V, F)).nnz == 0
    assert np.isfinite(L.data).all()


def test_tutte_cotangent_weights_stay_positive_and_finite_next_to_degenerate_caps():
    """Tutte's theorem needs positive finite weights: a cotangent that is not finite (a face of
    zero area) gets the floor of the non-positive ones, and the lifted embedding is fold-free."""
    from igl_spheremap.folding.tutte_start import tutte_sphere_map, tutte_weights

    V, F = cap_icosphere(3, 50, 1e-9)
    assert not np.isfinite(igl.cotmatrix(V, F).data).all()
    E = igl.edges(F)
    w = tutte_weights(V, F, E, "cotan_positive")
    assert np.isfinite(w).all() and (w > 0).all()
    U, _ = tutte_sphere_map(V, F, "cotan_positive")
    assert np.isfinite(U).all() and count_folds(F, U) == 0
