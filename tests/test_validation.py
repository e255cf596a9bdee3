"""Tests of validate_mesh: one bad mesh per MeshError, the automatic fixes, real meshes.

Expected counts come from how each mesh is built (e.g. a cube with one quad
removed has 4 boundary edges in 1 loop), not from runs of validate_mesh.
"""

import pathlib
import re

import igl
import numpy as np
import pytest

from igl_spheremap import MeshError, validate_mesh
from igl_spheremap.mesh.topology import _fans_per_vertex, _interior_half_edges
from igl_spheremap.mesh.validate import ZERO_AREA_RTOL, _has_duplicate_rows

DATA = pathlib.Path(__file__).parent / "data"


# ---------------------------------------------------------------- mesh builders

def outward(V, F):
    """Orient the faces of a convex polyhedron (around its centroid) outward."""
    V, F = np.asarray(V, float), np.array(F, dtype=np.int64)
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    inward = np.einsum("ij,ij->i", n, V[F].mean(axis=1) - V.mean(axis=0)) < 0
    F[inward] = F[inward][:, [0, 2, 1]]
    return V, F


def tetrahedron(shift=(0.0, 0.0, 0.0)):
    V = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float) + shift
    return outward(V, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])


def octahedron(shift=(0.0, 0.0, 0.0)):
    V = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    F = [[x, y, z] for x in (0, 1) for y in (2, 3) for z in (4, 5)]
    return outward(V + shift, F)


def icosahedron():
    t = (1 + 5 ** 0.5) / 2
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
                  [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]])
    F = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    return outward(V, F)


def icosphere(level=2):
    V, F = icosahedron()
    for _ in range(level):
        V, F = igl.upsample(V, F)
    return V / np.linalg.norm(V, axis=1, keepdims=True), F


def cube():
    V = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    quads = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
    return V, quads


def cube_without(removed):
    V, quads = cube()
    F = [t for i, q in enumerate(quads) if i not in removed
         for t in ([q[0], q[1], q[2]], [q[0], q[2], q[3]])]
    return V, np.array(F)


def grid_surface(nu, nv, klein=False):
    """Torus (or Klein bottle) from an nu x nv grid of quads, two triangles each."""
    def idx(i, j):
        if i == nu and klein:  # glue the last column to the first one mirrored
            j = -j
        return (i % nu) * nv + (j % nv)
    F = []
    for i in range(nu):
        for j in range(nv):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            F += [[a, b, c], [a, c, d]]
    u, v = np.meshgrid(2 * np.pi * np.arange(nu) / nu, 2 * np.pi * np.arange(nv) / nv,
                       indexing="ij")
    V = np.stack([(2 + np.cos(v)) * np.cos(u), (2 + np.cos(v)) * np.sin(u), np.sin(v)], -1)
    return V.reshape(-1, 3), np.array(F)


def raises(V, F, problem, count):
    with pytest.raises(MeshError) as info:
        validate_mesh(V, F)
    err = info.value
    assert err.problem == problem, str(err)
    assert err.count == count, str(err)
    assert re.search(rf"\b{count}\b", str(err)), str(err)
    assert problem in str(err)
    return str(err)


# ------------------------------------------------------------ builders are right

def test_builders_are_closed_outward_genus0():
    for V, F in (tetrahedron(), octahedron(), icosahedron(), icosphere(1)):
        assert igl.euler_characteristic(F) == 2
        n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
        assert np.all(np.einsum("ij,ij->i", n, V[F].mean(axis=1)) > 0)
    V, F = grid_surface(8, 6)
    assert igl.euler_characteristic(F) == 0 and igl.is_edge_manifold(F)[0]
    V, F = grid_surface(8, 6, klein=True)
    assert igl.euler_characteristic(F) == 0 and igl.is_vertex_manifold(F).all()


# ------------------------------------------------------------------ array errors

def test_empty():
    V, F = tetrahedron()
    raises(np.zeros((0, 3)), F, "empty", 1)
    raises(V, np.zeros((0, 3), int), "empty", 1)
    raises([], [], "empty", 2)


def test_shape():
    V, F = tetrahedron()
    raises(V, np.hstack([F, F[:, :1]]), "shape", 1)  # quads
    raises(V[:, :2], F, "shape", 1)
    raises(V, F.ravel(), "shape", 1)
    raises(V[:, :2], F.ravel(), "shape", 2)
    raises(V, [[0, 1, 2], [0, 1]], "shape", 1)  # ragged


def test_dtype():
    V, F = tetrahedron()
    raises(V, F.astype(bool), "dtype", F.size)
    Ff = F.astype(float)
    Ff[0, 1] += 0.5
    Ff[2, 2] = np.nan
    raises(V, Ff, "dtype", 2)
    raises(V.astype(complex), F, "dtype", V.size)
    raises(V.astype(str), F, "dtype", V.size)
    raises(V, F.astype(str), "dtype", F.size)


def test_index_range():
    V, F = octahedron()
    F[0, 0], F[3, 1], F[5, 2] = -1, 6, 7
    msg = raises(V, F, "index_range", 3)
    assert "1 negative" in msg


def test_non_finite_counts_vertices():
    V, F = icosahedron()
    V[2, 0] = np.nan
    V[5] = np.inf
    V[7, 1:] = -np.inf
    raises(V, F, "non_finite", 3)


# ------------------------------------------------------------------ face errors

def test_degenerate_faces():
    V, F = icosahedron()
    F[4] = [F[4, 0], F[4, 0], F[4, 1]]
    F[9] = [F[9, 2], F[9, 1], F[9, 2]]
    raises(V, F, "degenerate_faces", 2)


@pytest.mark.parametrize("extra, count", [([0], 1), ([0, 0], 2), ([0, 1], 2)])
def test_duplicate_faces(extra, count):
    V, F = tetrahedron()
    raises(V, np.vstack([F, F[extra]]), "duplicate_faces", count)
    raises(V, np.vstack([F, F[extra][:, ::-1]]), "duplicate_faces", count)  # opposite orientation


@pytest.mark.parametrize("offset", [0, 3_000_000])  # the sorted-key test, and igl's above 2^21
def test_duplicate_rows_agree_with_igl_unique_simplices(offset, rng):
    for _ in range(50):
        F = rng.integers(0, 12, size=(20, 3)) + offset
        F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])]
        expected = igl.unique_simplices(F)[1].shape[0] < F.shape[0]
        assert _has_duplicate_rows(F) == expected
        assert _has_duplicate_rows(np.vstack([F, F[-1, ::-1]]))  # a reversed copy


# ------------------------------------------------------------- topology errors

def test_fin_edge():
    V, F = tetrahedron()
    a, b = F[0, 0], F[0, 1]
    V2 = np.vstack([V, [3.0, 3.0, 3.0]])
    raises(V2, np.vstack([F, [a, b, 4]]), "nonmanifold_edge", 1)  # edge ab in 3 faces
    V2, F2 = tetrahedron(shift=(5.0, 0, 0))
    F2 = F2 + 2
    F2[F2 == 2], F2[F2 == 3] = 0, 1  # second tet shares edge 01 with the first
    raises(np.vstack([V, V2]), np.vstack([F, F2]), "nonmanifold_edge", 1)  # edge 01 in 4 faces


def test_bowtie_vertex():
    V, F = tetrahedron()
    V2, F2 = tetrahedron(shift=(2.0, 2.0, 2.0))  # its vertex 0 lands on (3, 3, 3)
    V2 = np.vstack([V, V2[1:]])
    F2 = np.where(F2 == 0, 0, F2 + 3)
    F2 = np.vstack([F, F2])
    raises(V2, F2, "nonmanifold_vertex", 1)
    assert np.count_nonzero(~igl.is_vertex_manifold(F2)) == 1  # libigl agrees


def test_two_pinched_vertices():
    V, F = octahedron()
    V2, F2 = octahedron(shift=(3.0, 0, 0))
    F2 = F2 + 6
    F2[F2 == 10], F2[F2 == 11] = 4, 5  # the second octahedron's poles are the first one's
    V2 = np.vstack([V, V2[:4]])
    F2 = np.vstack([F, F2])
    raises(V2, F2, "nonmanifold_vertex", 2)
    assert np.count_nonzero(~igl.is_vertex_manifold(F2)) == 2


@pytest.mark.parametrize("seed", range(10))
def test_fan_count_agrees_with_libigl_vertex_manifold(seed):
    V, F = icosphere(1)
    F = F[np.random.default_rng(seed).random(F.shape[0]) < 0.6]  # random patches: pinched vertices
    V, F, _, _ = igl.remove_unreferenced(V, F)
    fans = _fans_per_vertex(F, *_interior_half_edges(*igl.unique_edge_map(F)[3:]), V.shape[0])
    ok = igl.is_vertex_manifold(F)
    assert np.array_equal(fans == 1, ok)
    if not ok.all():
        raises(V, F, "nonmanifold_vertex", np.count_nonzero(~ok))


def test_open_cube():
    V, F = cube_without({0})
    msg = raises(V, F, "boundary", 4)
    assert "in 1 boundary loop " in msg
    V, F = cube_without({0, 1})  # a tube: two opposite quads removed
    msg = raises(V, F, "boundary", 8)
    assert "in 2 boundary loops" in msg and "per loop: 4, 4" in msg
    assert "close the holes" in msg and "remove_duplicate_vertices" not in msg  # real holes


def test_a_triangle_soup_or_a_seam_is_told_to_merge_vertices_not_to_fill_holes():
    """An STL read by igl.read_triangle_mesh (every triangle its own 3 corners) and a surface
    split along a seam were told to "close the holes ... a triangle fan per loop": the wrong
    repair.  The message counts the boundary vertices that share a position, and its repair,
    taken as written, gives the closed mesh back."""
    V, F = icosphere(2)
    m = F.shape[0]
    soup_V, soup_F = V[F].reshape(-1, 3), np.arange(3 * m).reshape(-1, 3)
    msg = raises(soup_V, soup_F, "boundary", 3 * m)
    assert f"in {m} boundary loops" in msg
    assert f"{3 * m} of its {3 * m} boundary vertices share their position" in msg
    assert "close the holes" not in msg
    assert "V, _, _, F = igl.remove_duplicate_vertices(V, F, 0.0)" in msg
    V2, _, _, F2 = igl.remove_duplicate_vertices(soup_V, soup_F, 0.0)
    res = validate_mesh(V2, F2)
    assert res.V.shape == V.shape and res.notes == []
    # a seam: the faces above z = 0 on copies of their vertices
    up = V[F].mean(axis=1)[:, 2] > 0
    seam_F = np.where(up[:, None], F + len(V), F)
    seam_V = np.vstack([V, V])
    used_both = np.intersect1d(F[up], F[~up])  # the vertices on the seam, each split in two
    E = np.sort(F[up][:, [[1, 2], [2, 0], [0, 1]]].reshape(-1, 2), axis=1)
    rim = int(np.count_nonzero(np.unique(E, axis=0, return_counts=True)[1] == 1))
    msg = raises(seam_V, seam_F, "boundary", 2 * rim)  # the rim of each half
    k = 2 * used_both.size
    assert f"{k} of its {k} boundary vertices share their position" in msg


def test_open_cube_mixed_orientation_counts_loops():
    V, F = cube_without({0})
    F[3] = F[3, [0, 2, 1]]
    msg = raises(V, F, "boundary", 4)
    assert "in 1 boundary loop " in msg


def test_components():
    V, F = tetrahedron()
    V2, F2 = tetrahedron(shift=(5.0, 0, 0))
    msg = raises(np.vstack([V, V2]), np.vstack([F, F2 + 4]), "components", 2)
    assert "faces: 4, 4" in msg and "vertices: 4, 4" in msg
    V2, F2 = octahedron(shift=(5.0, 0, 0))
    V3, F3 = tetrahedron(shift=(0, 5.0, 0))
    msg = raises(np.vstack([V, V2, V3]), np.vstack([F, F2 + 4, F3 + 10]), "components", 3)
    assert "faces: 8, 4, 4" in msg and "vertices: 6, 4, 4" in msg


def test_torus_genus_1():
    V, F = grid_surface(8, 6)
    raises(V, F, "genus", 1)


def test_double_torus_genus_2():
    # connected sum of two tori: remove one face from each and glue in a triangular tube
    V1, F1 = grid_surface(8, 6)
    V2, F2 = grid_surface(8, 6)
    V2 = V2 + [7.0, 0, 0]
    n = V1.shape[0]
    a, b = F1[0], F2[0] + n
    tube = [[a[0], b[0], a[1]], [a[1], b[0], b[2]], [a[1], b[2], a[2]],
            [a[2], b[2], b[1]], [a[2], b[1], a[0]], [a[0], b[1], b[0]]]
    F = np.vstack([F1[1:], F2[1:] + n, tube])
    assert igl.euler_characteristic(F) == -2 and igl.is_edge_manifold(F)[0]
    raises(np.vstack([V1, V2]), F, "genus", 2)


def test_klein_bottle_non_orientable():
    V, F = grid_surface(8, 6, klein=True)
    raises(V, F, "non_orientable", 2)


# ------------------------------------------------------------- geometry errors

def test_zero_length_edge():
    V, F = icosahedron()
    assert {0, 1} <= set(F[1])  # vertices 0 and 1 share an edge
    V[1] = V[0]
    raises(V, F, "zero_length_edge", 1)


def test_zero_area_face():
    V, F = octahedron()
    V[4] = [0.5, 0.5, 0.0]  # +z onto the segment from +x to +y: face (+x, +y, +z) collapses
    raises(V, F, "zero_area", 1)
    V[4, 2] = 1e-15  # area ~1e-15 lbar^2, below ZERO_AREA_RTOL
    raises(V, F, "zero_area", 1)
    V[4, 2] = 1e3 * ZERO_AREA_RTOL  # thin but not degenerate: accepted
    assert validate_mesh(V, F).notes == []


def test_zero_volume_orientation_error():
    # a tetrahedron squashed flat: two triangulations of one square, back to back
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    assert igl.euler_characteristic(F) == 2
    raises(V, F, "orientation", 4)


# ------------------------------------------------------------ accepted oddities

def test_duplicate_position_without_edge_is_accepted_with_note():
    V, F = icosphere(2)
    A = igl.adjacency_matrix(F)
    two_ring = (A @ A).tocsr()
    a = 0
    b = next(j for j in two_ring[a].indices if j != a and A[a, j] == 0)
    V[b] = V[a]
    res = validate_mesh(V, F)
    assert np.array_equal(res.F, F) and np.array_equal(res.V, V * res.scale)
    assert any("2 vertices share 1 position " in note for note in res.notes), res.notes


def test_float_integral_F_and_other_dtypes_are_converted():
    V, F = icosphere(1)
    res = validate_mesh(V.astype(np.float32), np.asfortranarray(F.astype(np.float64)))
    assert np.array_equal(res.F, F)
    assert np.array_equal(res.V, V.astype(np.float32).astype(np.float64) * res.scale)
    assert any("converted to int64" in note for note in res.notes)
    for Vi, Fi in ((V, F.astype(np.int32)), (np.asfortranarray(V), F.astype(np.uint16)),
                   (np.round(V * 100).astype(np.int64), F)):
        res = validate_mesh(Vi, Fi)
        assert res.V.dtype == np.float64 and res.V.flags.c_contiguous
        assert res.F.dtype == np.int64 and res.F.flags.c_contiguous
        assert res.vertex_index.dtype == np.int64 and res.unreferenced.dtype == np.int64


# -------------------------------------------------------------- automatic fixes

def test_unreferenced_vertices_are_dropped():
    V, F = icosphere(1)
    n = V.shape[0]
    extra_at = np.array([0, 10, n + 2])  # rows of the padded input that no face uses
    keep = np.setdiff1d(np.arange(n + 3), extra_at)
    V_in = np.full((n + 3, 3), 7.0)
    V_in[keep] = V
    V_in[extra_at[0]] = np.nan  # an unreferenced NaN vertex is still an error
    raises(V_in, keep[F], "non_finite", 1)
    V_in[extra_at[0]] = 7.0
    res = validate_mesh(V_in, keep[F])
    assert np.array_equal(res.V, V * res.scale) and np.array_equal(res.F, F)
    assert np.array_equal(res.vertex_index, keep)
    assert np.array_equal(res.unreferenced, extra_at)
    assert any("3 unreferenced" in note for note in res.notes)


def test_inward_orientation_is_flipped():
    V, F = icosphere(2)
    res = validate_mesh(V, F[:, [0, 2, 1]])
    assert res.orientation_flipped and res.faces_reoriented == 0
    assert np.array_equal(res.F, F)
    assert len(res.notes) == 1 and "inward" in res.notes[0]


@pytest.mark.parametrize("inward", [False, True])
def test_mixed_orientation_is_repaired(inward):
    V, F = icosphere(2)
    rng = np.random.default_rng(0)
    bad = np.r_[0, rng.choice(np.arange(1, F.shape[0]), size=16, replace=False)]  # incl. face 0
    F_in = F[:, [0, 2, 1]] if inward else F.copy()
    F_in[bad] = F_in[bad][:, [0, 2, 1]]
    res = validate_mesh(V, F_in)
    assert np.array_equal(res.F, F)
    assert res.faces_reoriented == 17 and res.orientation_flipped == inward
    assert any("flipped 17 faces" in note for note in res.notes), res.notes


def test_outward_mesh_is_unchanged():
    V, F = icosphere(2)
    res = validate_mesh(V, F)
    assert np.array_equal(res.V, V * res.scale) and np.array_equal(res.F, F)
    assert not res.orientation_flipped and res.notes == [] and res.unreferenced.size == 0
    assert np.array_equal(res.vertex_index, np.arange(V.shape[0]))


# ----------------------------------------------------------------- real meshes

def check_real_mesh(path):
    V, F = igl.read_triangle_mesh(str(path))
    res = validate_mesh(V, F)
    assert np.array_equal(res.V, V * res.scale) and np.array_equal(res.F, F)
    assert res.notes == [] and not res.orientation_flipped
    assert res.V.dtype == np.float64 and res.V.flags.c_contiguous
    assert res.F.dtype == np.int64 and res.F.flags.c_contiguous
    # the vertex-manifold check agrees with libigl's
    assert igl.is_vertex_manifold(F).all()


@pytest.mark.parametrize("path", sorted(DATA.glob("*.obj")), ids=lambda p: p.name)
def test_real_meshes_in_tests_data_pass_unchanged(path):
    check_real_mesh(path)


# ------------------------------------------------------------ coordinate range

@pytest.mark.parametrize("factor", [1e-200, 1e-100, 3.0, 1e100, 1e200])
def test_extreme_coordinates_are_scaled_exactly_by_a_power_of_two(factor):
    """Areas of a mesh at 1e200 overflow float64 (and at 1e-200 underflow): the
    validated vertices are the input times a power of two, with the bounding-box
    diagonal in [1, 2), and the checks give what they give on the unscaled mesh."""
    V, F = icosphere(2)
    res = validate_mesh(V * factor, F)
    mantissa, _ = np.frexp(res.scale)
    assert mantissa == 0.5  # a power of two: the scaling is exact
    assert np.array_equal(res.V, (V * factor) * res.scale)
    diag = np.linalg.norm(res.V.max(axis=0) - res.V.min(axis=0))
    assert 1.0 <= diag < 2.0
    assert np.array_equal(res.F, F) and res.notes == []
    flipped = validate_mesh(V * factor, F[:, [0, 2, 1]])
    assert flipped.orientation_flipped and np.array_equal(flipped.F, F)


def test_to_input_fills_unreferenced_rows_with_the_nearest_vertex():
    V, F = icosphere(1)
    extra = V[5] * 1.01  # unreferenced, next to vertex 5
    V_in = np.vstack([V, extra])
    res = validate_mesh(V_in, F)
    X = np.arange(3 * V.shape[0], dtype=float).reshape(-1, 3)
    Y = res.to_input(X)
    assert Y.shape == (V.shape[0] + 1, 3)
    assert np.array_equal(Y[:-1], X) and np.array_equal(Y[-1], X[5])
    assert np.array_equal(res.from_input(Y), X)
    assert np.array_equal(res.F_input, F)


# ----------------------------------------------------- repairs reported by the maps' results

def test_a_maps_result_reports_the_faces_validation_flipped(mesh):
    """Fish with every 7th face flipped: validate_mesh's note said so, but the map's
    ``notes`` were empty and its message silent, while ``result.F`` differs from the input
    in those rows: count_folds(F_input, U) saw them as folds of a successful map."""
    from igl_spheremap import count_folds, spherical_conformal_map

    V, F = mesh("fish_lowres.obj")
    Fm = F.copy()
    Fm[::7] = Fm[::7, ::-1]
    k, m = len(F[::7]), len(F)
    res = spherical_conformal_map(V, Fm)
    assert res.success
    assert np.count_nonzero((res.F != Fm).any(axis=1)) == k
    assert count_folds(res.F, res.U) == 0 and count_folds(Fm, res.U) == k
    assert validate_mesh(V, Fm).notes[0] in res.notes
    assert res.message.endswith(f"; F re-oriented: {k} of {m} faces flipped, use result.F")
    outward = spherical_conformal_map(V, F)
    assert outward.notes == [] and "re-oriented" not in outward.message


def test_inward_input_is_reported_by_every_map_built_on_the_conformal_map(ellipsoid):
    """All faces inward: ``orientation_flipped`` was set, the message and notes were silent.
    Said once, also where a message quotes the conformal map's (area-balanced, landmarks)."""
    import igl_spheremap as sm

    V, F = ellipsoid(2)
    Fi = F[:, ::-1]
    say = f"F re-oriented: all {len(F)} faces flipped (the input was oriented inward)"
    res = sm.spherical_conformal_map(V, Fi)
    assert res.orientation_flipped and np.array_equal(res.F, Fi[:, [0, 2, 1]])
    assert sm.count_folds(Fi, res.U) == len(F) and sm.count_folds(res.F, res.U) == 0
    assert any("oriented inward" in note for note in res.notes)
    balanced = sm.spherical_conformal_map(V, Fi, kind="area_balanced")
    lm = sm.landmark_map(V, Fi, [0, 7], res.U[[0, 7]])
    for r in (res, balanced, lm):
        assert r.message.count(say) == 1, r.message
        assert r.message.count(f"{say}, use result.F") == 1
    harmonic = sm.harmonic_map(V, Fi, res.U)
    assert say in harmonic.message and harmonic.folds == 0
