"""igl_spheremap.sphere.folds against direct computations (libigl, numpy, exact identities)."""

import igl
import numpy as np
import pytest
import scipy.sparse as sp

from igl_spheremap import (
    angle_distortion,
    area_distortion,
    conformal_factor,
    count_folds,
    folded_faces,
    gauss_map,
    harmonic_energy,
    image_centroid,
    signed_image_volumes,
)


def _unit(X):
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def _corner_angles(V, F):
    """Angle at corner c (vertex F[:, c]) of every face, radians, numpy only."""
    out = np.empty(F.shape, dtype=np.float64)
    for c in range(3):
        p, q, r = V[F[:, c]], V[F[:, (c + 1) % 3]], V[F[:, (c + 2) % 3]]
        a, b = q - p, r - p
        out[:, c] = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
    return out


def _det_signs(F, U):
    """det[U_i, U_j, U_k] per face with numpy's LU-based determinant."""
    return np.linalg.det(np.stack([U[F[:, 0]], U[F[:, 1]], U[F[:, 2]]], axis=1))


# ---------------------------------------------------------------- harmonic energy

def test_harmonic_energy_equals_trace_and_edge_sum(mesh, rng):
    V, F = mesh("fish_lowres.obj")
    L = igl.cotmatrix(V, F)
    C = igl.cotmatrix_entries(V, F)  # half cotangent of the angle opposite each edge
    W = sp.triu(L, 1).tocoo()        # off-diagonal entries w_ij, i < j
    for U in (rng.normal(size=V.shape), _unit(rng.normal(size=V.shape)), gauss_map(V, F)):
        E = harmonic_energy(V, F, U)
        trace = -0.5 * np.trace(U.T @ (L @ U))
        edges = 0.5 * np.sum(W.data * np.sum((U[W.row] - U[W.col]) ** 2, axis=1))
        faces = 0.0
        for c, (a, b) in enumerate(((1, 2), (2, 0), (0, 1))):
            faces += 0.5 * np.sum(C[:, c] * np.sum((U[F[:, a]] - U[F[:, b]]) ** 2, axis=1))
        assert E == pytest.approx(trace, rel=1e-12)
        assert E == pytest.approx(edges, rel=1e-12)
        assert E == pytest.approx(faces, rel=1e-12)


def test_harmonic_energy_uses_the_given_laplacian_and_ignores_scale(mesh, rng):
    V, F = mesh("goathead.obj")
    U = _unit(rng.normal(size=V.shape))
    Li = igl.intrinsic_delaunay_cotmatrix(V, F)[0]
    assert harmonic_energy(V, F, U, L=Li) == pytest.approx(-0.5 * np.sum(U * (Li @ U)), rel=1e-12)
    assert harmonic_energy(V, F, U, L=Li) < harmonic_energy(V, F, U)  # Delaunay minimizes it
    assert harmonic_energy(7e4 * V + 3.0, F, U) == pytest.approx(harmonic_energy(V, F, U),
                                                                  rel=1e-10)


def test_harmonic_energy_refuses_a_laplacian_of_another_mesh(icosphere):
    """A 10 x 10 Laplacian for a 162-vertex map: scipy's 'dimension mismatch' before."""
    V, F = icosphere(2)
    L = igl.cotmatrix(V, F)
    with pytest.raises(ValueError, match=r"L must be \(162, 162\).*got \(10, 10\)"):
        harmonic_energy(V, F, V, L=L[:10, :10])


def test_harmonic_energy_bounds_the_image_area(mesh, rng):
    """Per triangle, 1/2 |grad f|^2 >= |det df|: E(U) >= total flat image area, with
    equality for a similarity (the identity map has E = area of the mesh)."""
    V, F = mesh("fish_lowres.obj")
    for _ in range(4):
        U = rng.normal(size=V.shape)
        assert harmonic_energy(V, F, U) >= igl.doublearea(U, F).sum() / 2.0
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    U = 2.5 * V @ R.T - 1.0
    assert harmonic_energy(V, F, U) == pytest.approx(igl.doublearea(U, F).sum() / 2.0, rel=1e-12)


def test_identity_energy_is_the_area_and_converges_to_4pi(icosphere):
    """E(identity) = mesh area exactly; on inscribed icospheres it increases to 4 pi
    with second-order convergence (the gap shrinks ~4x per refinement)."""
    gaps = []
    for level in range(5):
        V, F = icosphere(level)
        E = harmonic_energy(V, F, V)
        area = igl.doublearea(V, F).sum() / 2.0
        assert E == pytest.approx(area, rel=1e-12)
        gaps.append(4.0 * np.pi - E)
    gaps = np.array(gaps)
    assert np.all(gaps > 0)
    ratios = gaps[:-1] / gaps[1:]
    assert np.all(ratios[1:] > 3.5), ratios  # levels 1->2->3->4: O(h^2)
    assert gaps[-1] < 0.02


# ---------------------------------------------------------------- angles, areas

def test_angle_distortion_against_direct_angles(conformal_map):
    V, F, result, _ = conformal_map("fish_lowres.obj")
    for U in (result.U, gauss_map(V, F)):
        D = angle_distortion(V, F, U)
        direct = np.degrees(np.abs(_corner_angles(U, F) - _corner_angles(V, F)))
        libigl = np.degrees(np.abs(igl.internal_angles(U, F) - igl.internal_angles(V, F)))
        assert D.shape == F.shape
        assert np.allclose(D, direct, rtol=0, atol=1e-9)
        assert np.allclose(D, libigl, rtol=0, atol=1e-12)


def test_angle_distortion_is_zero_for_a_similarity(mesh, rng):
    V, F = mesh("goathead.obj")
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    assert angle_distortion(V, F, 1e-3 * V @ R.T + 4.0).max() < 1e-9
    # A non-uniform stretch does distort: the measure is not trivially zero.
    assert angle_distortion(V, F, V * [1.0, 1.0, 2.0]).max() > 1.0


@pytest.mark.parametrize("scale", [1e300, 1e-300])
def test_measures_of_a_mesh_near_the_float64_limits_are_its_unit_measures(conformal_map, scale):
    """Coordinates near 1e300 overflow in squared edge lengths (1e-300 underflow); the map
    handles such input (validate_mesh scales it), and the measures must too: each is
    independent of the units of V, so each equals its value on the same mesh in units
    near 1 (libigl's angles as the reference)."""
    V, F, result, _ = conformal_map("fish_lowres.obj")
    U, W = result.U, V * scale
    ref = np.degrees(np.abs(igl.internal_angles(U, F) - igl.internal_angles(V, F)))
    assert np.allclose(angle_distortion(W, F, U), ref, rtol=0, atol=1e-9)
    for measure in (conformal_factor, area_distortion, image_centroid, harmonic_energy):
        got = measure(W, F, U)
        assert np.all(np.isfinite(got)), measure.__name__
        assert np.allclose(got, measure(V, F, U), rtol=1e-12, atol=1e-12), measure.__name__


def test_conformal_factor_matches_eq14_loop(icosphere, mesh):
    V, F = mesh("fish_lowres.obj")
    V = 3.7 * V  # units must not matter: the input is scaled to area 4 pi
    U = gauss_map(V, F)
    A = igl.doublearea(V, F) / 2.0
    A *= 4.0 * np.pi / A.sum()
    B = igl.doublearea(U, F) / 2.0
    num = np.zeros(V.shape[0])
    den = np.zeros(V.shape[0])
    for f in range(F.shape[0]):
        for i in F[f]:
            num[i] += B[f]
            den[i] += A[f]
    assert np.allclose(conformal_factor(V, F, U), num / den, rtol=1e-12, atol=0)
    # Identity of the unit icosphere: image area = input area, input scaled to 4 pi,
    # so e^{2u} = area / 4 pi at every vertex.
    V, F = icosphere(2)
    area = igl.doublearea(V, F).sum() / 2.0
    assert np.allclose(conformal_factor(V, F, V), area / (4.0 * np.pi), rtol=1e-12, atol=0)


def test_area_distortion_against_direct_log_ratio(mesh, rng):
    V, F = mesh("fish_lowres.obj")
    U = gauss_map(V, F)
    a = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    b = 0.5 * np.linalg.norm(np.cross(U[F[:, 1]] - U[F[:, 0]], U[F[:, 2]] - U[F[:, 0]]), axis=1)
    ref = np.log(b / b.sum()) - np.log(a / a.sum())
    assert np.allclose(area_distortion(V, F, U), ref, rtol=0, atol=1e-10)
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    assert np.abs(area_distortion(V, F, 0.01 * V @ R.T)).max() < 1e-10
    # A collapsed image face has log ratio -inf (documented).
    Uc = U.copy()
    Uc[F[0, 1]] = Uc[F[0, 0]]
    assert area_distortion(V, F, Uc)[0] == -np.inf


def test_image_centroid_uses_input_vertex_areas(mesh, icosphere, rng):
    V, F = mesh("goathead.obj")
    U = _unit(rng.normal(size=V.shape))
    M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
    assert np.allclose(image_centroid(V, F, U), M @ U / M.sum(), rtol=0, atol=1e-14)
    V, F = icosphere(3)  # centrally symmetric: centroid of the identity is 0
    assert np.linalg.norm(image_centroid(V, F, V)) < 1e-15


# ---------------------------------------------------------------- folds

def test_signed_volumes_equal_the_determinant(mesh, rng):
    V, F = mesh("fish_lowres.obj")
    U = _unit(rng.normal(size=V.shape))
    assert np.allclose(signed_image_volumes(F, U), _det_signs(F, U), rtol=0, atol=1e-14)


def test_map_degree_of_a_sphere_of_any_radius(icosphere):
    """The degree depends on the directions only: the identity map of an icosphere (its faces
    tile the sphere once) has degree 1 at radius 1, 100 (a FreeSurfer sphere) and 1e-3, the
    antipodal map (det -I < 0) degree -1; before, radius 100 gave 61.5."""
    from igl_spheremap import map_degree

    V, F = icosphere(3)
    for radius in (1.0, 100.0, 1e-3):
        assert map_degree(F, radius * V) == pytest.approx(1.0, abs=1e-12)
        assert map_degree(F, -radius * V) == pytest.approx(-1.0, abs=1e-12)
    with pytest.raises(ValueError, match="1 zero row"):
        map_degree(F, np.r_[np.zeros((1, 3)), V[1:]])


def test_count_folds_on_a_reflected_hemisphere(icosphere, rng):
    V, F = icosphere(3)
    assert count_folds(F, V) == 0
    assert count_folds(F, V * [1.0, 1.0, -1.0]) == F.shape[0]  # a reflection folds all
    # Reflect the vertices on one side of a generic plane through the origin.
    n = _unit(np.array([[0.3, -0.4, 0.86]]))[0]
    side = V @ n > 0
    U = V.copy()
    U[side] -= 2.0 * np.outer(U[side] @ n, n)
    det = _det_signs(F, U)
    assert np.abs(det).min() > 1e-8  # no face is near-degenerate: the sign is unambiguous
    inside = side[F].all(axis=1)
    outside = (~side[F]).all(axis=1)
    assert inside.sum() > 100 and outside.sum() > 100
    mask = folded_faces(F, U)
    assert np.array_equal(mask, det <= 0)
    assert count_folds(F, U) == int(np.count_nonzero(det <= 0))
    assert mask[inside].all() and not mask[outside].any()
    # Rotations do not change the count.
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    R *= np.sign(np.linalg.det(R))
    assert count_folds(F, U @ R.T) == count_folds(F, U)


@pytest.mark.parametrize("eps", [1e-9, 1e-12])
def test_fold_sign_of_tiny_crowded_triangles(icosphere, eps):
    """A spherical patch shrunk to size eps around a point p keeps its orientation;
    its mirror image is folded everywhere.  The raw triple product U_i . (U_j x U_k)
    of such nearly equal unit vectors cancels catastrophically."""
    V, F = icosphere(3)
    p = _unit(np.array([[0.3, -0.5, 0.8]]))[0]
    Fp = F[(V[F] @ p).min(axis=1) > 0.5]
    T = V - np.outer(V @ p, p)                     # tangent-plane coordinates around p
    e = _unit(T[Fp[0, :1]])[0]
    M = np.eye(3) - 2.0 * np.outer(e, e)           # reflection inside the tangent plane
    U = _unit(p + eps * T)
    Um = _unit(p + eps * T @ M)
    assert count_folds(Fp, U) == 0
    assert count_folds(Fp, Um) == Fp.shape[0]
    naive = np.einsum("ij,ij->i", U[Fp[:, 0]], np.cross(U[Fp[:, 1]], U[Fp[:, 2]]))
    assert np.count_nonzero(naive <= 0) > 0  # the naive formula gets some signs wrong here


def test_signed_volumes_in_blocks_and_index_checks(mesh, rng, monkeypatch):
    """Blocks of any size (remainder included) and any integer dtype or layout of F
    give the determinant; the public function refuses indices outside the rows of U
    with a ValueError naming their count, the internal one follows numpy's rules."""
    import igl_spheremap.mesh.operators as metrics
    V, F = mesh("fish_lowres.obj")
    U = _unit(rng.normal(size=V.shape))
    ref = _det_signs(F, U)
    for block in (1, 7, 100, F.shape[0], 1 << 14):
        monkeypatch.setattr(metrics, "CHUNK_FACES", block)
        for Fi in (F, F.astype(np.int32), np.asfortranarray(F), F.astype(np.uint16)):
            assert np.allclose(signed_image_volumes(Fi, U), ref, rtol=0, atol=1e-14)
    assert np.allclose(metrics.signed_volumes(F - V.shape[0], U), ref, rtol=0, atol=1e-14)
    assert signed_image_volumes(F[:0], U).shape == (0,)
    for bad in (V.shape[0], -1):
        G = F.copy()
        G[5, 1] = bad
        G[7, 2] = bad
        with pytest.raises(ValueError, match="2 indices outside 0..944"):
            signed_image_volumes(G, U)
    with pytest.raises(IndexError, match="out of bounds"):
        metrics.signed_volumes(G + 2 * V.shape[0], U)


def test_signed_volumes_of_a_few_faces_are_the_whole_mesh_rows_to_the_bit(mesh, rng):
    """A few faces of a large map (fewer than a third of its vertices: the fold tests of a
    blend) gather only their corners; their volumes are the rows of the whole mesh's call
    bit for bit (the same arithmetic on the same numbers), negative indices included."""
    import igl_spheremap.mesh.operators as metrics
    V, F = mesh("fish_lowres.obj")
    U = _unit(rng.normal(size=V.shape))
    whole = metrics.signed_volumes(F, U)
    assert np.allclose(whole, _det_signs(F, U), rtol=0, atol=1e-14)
    for rows in (rng.choice(F.shape[0], 5), rng.choice(F.shape[0], V.shape[0] // 3 - 1),
                 np.array([3, 3, 0])):
        assert 3 * rows.size < V.shape[0]
        assert np.array_equal(metrics.signed_volumes(F[rows], U), whole[rows])
        assert np.array_equal(metrics.signed_volumes(F[rows] - V.shape[0], U), whole[rows])


def test_unit_sphere_measures_refuse_a_map_of_another_radius(mesh):
    """A sphere of radius 100 (FreeSurfer's, GIfTI's): conformal_factor returned ~1e4 and
    image_centroid 100 times the centroid without a word, though both are measures of a map
    onto the unit sphere (mean factor ~1).  Angle and area distortion do not depend on the
    radius and still take it; a float32-stored unit map is accepted."""
    V, F = mesh("fish_lowres.obj")
    U = gauss_map(V, F)
    for measure in (conformal_factor, image_centroid):
        with pytest.raises(ValueError, match=rf"U has {len(V)} rows off the unit sphere"):
            measure(V, F, 100.0 * U)
        got = measure(V, F, U.astype(np.float32))
        assert np.allclose(got, measure(V, F, U), rtol=1e-5, atol=1e-6)
    assert np.allclose(angle_distortion(V, F, 100.0 * U), angle_distortion(V, F, U), atol=1e-9)
    assert np.allclose(area_distortion(V, F, 100.0 * U), area_distortion(V, F, U), atol=1e-9)
