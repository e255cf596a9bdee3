"""The Tutte system set up once: each solve is the weighted Laplacian's solution built from the
edge list by scipy, to the bit (to rounding with ``repeated=True``), for any weights, and
fold-free inside a convex boundary."""

import igl
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from igl_spheremap.mesh.shapes import icosphere
from igl_spheremap.sphere.chart import TutteSystem, planar_signed_areas, tutte_embedding


def icosphere_disk(level, z):
    """``(X, Fd, fixed, P)``: the part of a level-``level`` icosphere above height ``z``, its
    boundary loop on the unit circle (``X``, the other rows 0), and its vertices ``P``."""
    V, F = icosphere(level)
    Fd = F[V[F].mean(axis=1)[:, 2] > z]
    used = np.unique(Fd)
    local = np.full(V.shape[0], -1)
    local[used] = np.arange(used.size)
    Fd = local[Fd]
    loop = igl.boundary_loop(Fd)
    fixed = np.zeros(used.size, dtype=bool)
    fixed[loop] = True
    X = np.zeros((used.size, 2))
    theta = np.linspace(0.0, 2.0 * np.pi, loop.size, endpoint=False)
    X[loop] = np.column_stack([np.cos(theta), np.sin(theta)])
    return X, Fd, fixed, V[used]


@pytest.fixture(scope="module")
def disk():
    """The part of a level-3 icosphere above z = -0.3, its boundary loop on the unit circle."""
    return icosphere_disk(3, -0.3)[:3]


def reference(X, F, fixed, W):
    """``sum_j w_ij (Y_i - Y_j) = 0`` at the free vertices, assembled from the edge list."""
    n, E = X.shape[0], igl.edges(F)
    A = sp.csr_matrix((np.r_[W[:, 0], W[:, 1]], (np.r_[E[:, 0], E[:, 1]], np.r_[E[:, 1], E[:, 0]])),
                      shape=(n, n))
    L = (sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A).tocsr()
    free = ~fixed
    Y = X.copy()
    Y[free] = spsolve(L[free][:, free].tocsc(), -L[free][:, fixed] @ X[fixed])
    return Y, L


def test_each_solve_is_the_assembled_system_s_solution_to_the_bit(disk):
    X, F, fixed = disk
    E = igl.edges(F)
    rng = np.random.default_rng(3)
    system = TutteSystem(F, fixed)
    for W in (np.ones((E.shape[0], 2)), rng.uniform(0.1, 5.0, (E.shape[0], 2)),
              np.exp(rng.normal(0.0, 5.0, (E.shape[0], 2)))):
        Y, L = reference(X, F, fixed, W)
        got = system.solve(X, W)
        assert np.array_equal(got, Y)
        assert np.array_equal(got[fixed], X[fixed])
        residual = (L @ got)[~fixed]
        assert np.abs(residual).max() < 1e-9 * np.abs(L.data).max()
        assert np.array_equal(tutte_embedding(X, F, fixed, W), got)


def test_positive_weights_inside_a_convex_boundary_give_a_fold_free_embedding(disk):
    """Tutte (1963), Floater (2003): every face keeps its orientation."""
    X, F, fixed = disk
    rng = np.random.default_rng(4)
    W = rng.uniform(0.01, 100.0, (igl.edges(F).shape[0], 2))
    Y = TutteSystem(F, fixed).solve(X, W)
    area = planar_signed_areas(Y, F)
    assert np.all(area > 0) or np.all(area < 0)


def test_a_fixed_vertex_in_no_face_is_left_where_it_is(disk):
    """The punctured Tutte disk holds the puncture, which is in no face of the disk, as the last
    vertex or anywhere else."""
    X, F, fixed = disk
    W = np.random.default_rng(5).uniform(0.1, 5.0, (igl.edges(F).shape[0], 2))
    Xp = np.vstack([X, [[0.25, -0.5]]])
    Y = TutteSystem(F, np.r_[fixed, True]).solve(Xp, W)
    assert np.array_equal(Y[-1], [0.25, -0.5])
    assert np.array_equal(Y[:-1], reference(X, F, fixed, W)[0])


def test_the_solver_for_repeated_solves_gives_the_same_embedding_to_rounding(disk):
    """``repeated=True`` numbers the free vertices in a fill-reducing order and factorizes
    without pivots: the assembled system's solution to rounding, with a backward error at the
    unit roundoff, the boundary where it was."""
    X, F, fixed = disk
    E = igl.edges(F)
    rng = np.random.default_rng(6)
    system = TutteSystem(F, fixed, repeated=True)
    for W in (np.ones((E.shape[0], 2)), rng.uniform(0.1, 5.0, (E.shape[0], 2))):
        Y, L = reference(X, F, fixed, W)
        got = system.solve(X, W)
        assert np.array_equal(got[fixed], X[fixed])
        assert np.abs(got - Y).max() < 1e-12
        residual = (L @ got)[~fixed]
        assert np.abs(residual).max() < 1e-13 * np.abs(L.data).max()


def test_the_solver_for_repeated_solves_keeps_tutte_s_theorem_under_extreme_weights():
    """Positive weights inside a convex boundary give a fold-free embedding (Tutte 1963,
    Floater 2003), in floating point too when the M-matrix is factorized without pivots:
    asymmetric weights (as the mean value weights are) times a cone of low conductivity down
    to ``e^-80``, as :func:`reweighted_tutte` makes around a crowded cluster.  The plain
    sparse solve (column ordering and partial pivoting anew each time) folds faces on 14 of
    these 40 systems; the cluster inflation of float32 maps stopped at the first such fold."""
    X, Fd, fixed, P = icosphere_disk(4, 0.0)
    E = igl.edges(Fd)
    system = TutteSystem(Fd, fixed, repeated=True)
    for seed in range(40):
        rng = np.random.default_rng(seed)
        W0 = rng.uniform(0.05, 20.0, (E.shape[0], 2))
        r = np.linalg.norm(P[:, :2] - rng.uniform(-0.4, 0.4, 2), axis=1)
        g = -rng.uniform(20.0, 80.0) * np.clip(1.0 - r / rng.uniform(0.1, 0.5), 0.0, 1.0)
        W = W0 * np.exp(0.5 * (g[E[:, 0]] + g[E[:, 1]]))[:, None]
        assert np.all(planar_signed_areas(system.solve(X, W), Fd) > 0)
