"""Slivers (issue #15): libigl's intrinsic Delaunay edge flips can run away on them.

On an icosphere with edges split very close to one end, ``igl.intrinsic_delaunay_cotmatrix``
can flip forever (a NaN edge length from rounding) and grow its flip stack until memory
runs out.  ``laplacian(..., "intrinsic_delaunay")`` refuses such meshes before libigl
runs, so no test here ever calls libigl's intrinsic Delaunay on a refused mesh.
"""

import igl
import numpy as np
import pytest

import igl_spheremap
from conftest import make_icosphere
from igl_spheremap.operators import SLIVER_RTOL, height_ratios, laplacian


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


def test_height_ratios_of_known_triangles():
    h = 1e-9
    V = np.array([[0, 0, 0], [1, 0, 0], [0.5, 3 ** 0.5 / 2, 0],  # equilateral: sqrt(3) / 2
                  [0, 0, 0], [1, 0, 0], [0, 1, 0],                # right isosceles: 1 / 2
                  [0, 0, 0], [1, 0, 0], [0.3, h, 0],              # cap of height h under edge 1
                  [0, 0, 0], [1, 0, 0], [1 + 1e-6, h, 0]],        # needle: its long edges ~1
                 dtype=np.float64)
    F = np.arange(12, dtype=np.int64).reshape(4, 3)
    expected = [3 ** 0.5 / 2, 0.5, h, h / (1 + 1e-6) ** 2]
    np.testing.assert_allclose(height_ratios(V, F), expected, rtol=1e-6)
    # scale and translation invariant (up to the rounding of the moved input: heights of
    # 1e-12 at coordinates ~0.5 are stored to ~1e-4 relative)
    np.testing.assert_allclose(height_ratios(1e-3 * V + [0.5, -0.2, 0.1], F), expected, rtol=1e-3)


@pytest.mark.parametrize("t", [1e-7, 1e-11])
def test_intrinsic_delaunay_refuses_split_icosphere(t):
    V, F = split_icosphere(3, 200, t)
    igl_spheremap.validate_mesh(V, F)  # valid: the check belongs to the Laplacian, not the mesh
    with pytest.raises(igl_spheremap.MeshError, match="slivers") as err:
        laplacian(V, F)
    assert err.value.problem == "slivers"
    assert err.value.count == 2 * 200  # the two needles of every split
    assert "400 faces" in str(err.value) and "cotan" in str(err.value)
    # every public path to the intrinsic Delaunay Laplacian refuses it
    with pytest.raises(igl_spheremap.MeshError, match="slivers"):
        igl_spheremap.spherical_conformal_map(V, F)
    with pytest.raises(igl_spheremap.MeshError, match="slivers"):
        igl_spheremap.harmonic_map(V, F, igl_spheremap.gauss_map(V, F))


def test_intrinsic_delaunay_refuses_caps():
    V, F = cap_icosphere(3, 50, 1e-9)
    with pytest.raises(igl_spheremap.MeshError, match="slivers") as err:
        laplacian(V, F)
    assert err.value.count == 50


@pytest.mark.parametrize("t", [1e-11, 1e-2])
def test_cotan_laplacian_accepts_slivers(t):
    V, F = split_icosphere(3, 200, t)
    L = laplacian(V, F, "cotan")
    assert (L != igl.cotmatrix(V, F)).nnz == 0
    assert np.isfinite(L.data).all()


def test_mild_slivers_keep_libigls_laplacian_bit_for_bit():
    for V, F in (split_icosphere(3, 200, 1e-2), cap_icosphere(3, 50, 1e-3), make_icosphere(3)):
        assert height_ratios(V, F).min() > SLIVER_RTOL
        assert (laplacian(V, F) != igl.intrinsic_delaunay_cotmatrix(V, F)[0]).nnz == 0


@pytest.mark.parametrize("name", ["fish_lowres.obj", "goathead.obj", "hippocampus.obj", "dino.obj"])
def test_real_meshes_are_far_from_the_sliver_threshold(name):
    from conftest import load_mesh

    V, F = load_mesh(name)
    assert height_ratios(V, F).min() > 100 * SLIVER_RTOL
