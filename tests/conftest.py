"""Shared fixtures of the test suite: meshes built in the test and the vendored real meshes.

Meshes built here:

- ``icosphere(level)``: the regular icosahedron refined ``level`` times by
  ``igl.upsample`` (4-to-1 midpoint subdivision), vertices projected back onto
  the unit sphere after every step.  Levels 0 and 1 have the full icosahedral
  symmetry at every vertex (the identity map is then an exact critical point of
  the discrete harmonic energy); from level 2 on only up to discretisation.
- ``ellipsoid(level, axes)``: an icosphere scaled by ``axes`` (default ``(1, 1.5, 3)``).
- ``rotated_sphere(level, seed, scale, translation)``: an icosphere under a random
  rotation, scaled and translated; also returns the rotation and the unit-sphere
  points the input corresponds to.
- ``stretched``: a 3:1 ellipsoid (validated) and its central projection slightly perturbed,
  fold-free: ``(V, F, U)``, for the conformal descent's energy and metric.

Real meshes (``tests/data``, see its README.md for sources and licences):
``load_mesh("fish_lowres.obj")``, ``"goathead.obj"``, ``"hippocampus.obj"``,
``"mpl_pinky0_left.obj"``, ``"stepped_shaft.obj"``, and
``"dino.obj"`` (package data of igl_spheremap, read with importlib.resources).

``conformal_map(name)`` maps a real mesh once per test session and returns
``(V, F, result, rounds_seen_by_callback)``.
"""

import functools
import importlib.resources
import pathlib

import igl
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

DATA = pathlib.Path(__file__).parent / "data"
REAL_MESHES = ("fish_lowres.obj", "goathead.obj", "hippocampus.obj", "dino.obj")


def _icosahedron():
    t = (1.0 + 5.0 ** 0.5) / 2.0
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0],
                  [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                  [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], dtype=np.float64)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11],
                  [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
                  [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
                  [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]], dtype=np.int64)
    return V / np.linalg.norm(V, axis=1, keepdims=True), F


@functools.cache
def _icosphere_cached(level):
    V, F = _icosahedron()
    for _ in range(level):
        V, F = igl.upsample(V, F)
        V = V / np.linalg.norm(V, axis=1, keepdims=True)
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    V.flags.writeable = False
    F.flags.writeable = False
    return V, F


def drag_past_neighbor(F, U, v, factor=2.5):
    """Move vertex ``v`` along the chord to one of its neighbors, past it: local folds (a copy)."""
    w = igl.adjacency_matrix(F).tocsr()[v].indices[0]
    U = U.copy()
    U[v] = U[v] + factor * (U[w] - U[v])
    U[v] /= np.linalg.norm(U[v])
    return U


def map_problem(V, F, precision="float64"):
    """The :class:`igl_spheremap.folding.problem.MapProblem` of the mesh ``(V, F)`` with default
    options at ``precision``, as :func:`igl_spheremap.conformal_map.map_validated` builds it."""
    from igl_spheremap.folding.problem import MapProblem
    from igl_spheremap.mesh.validate import validate_mesh
    from igl_spheremap.options import map_options

    return MapProblem.of(validate_mesh(V, F), map_options(dict(precision=precision)))


def make_icosphere(level=2):
    """Unit icosphere: ``10 * 4**level + 2`` vertices, outward oriented; fresh copies."""
    V, F = _icosphere_cached(level)
    return V.copy(), F.copy()


def make_ellipsoid(level=3, axes=(1.0, 1.5, 3.0)):
    """Icosphere of ``level`` scaled by ``axes``."""
    V, F = make_icosphere(level)
    return V * np.asarray(axes, dtype=np.float64), F


def make_capsule(aspect=50.0, radius=0.5, n_around=16):
    """Closed capsule of length / width ``aspect``: :func:`igl_spheremap.mesh.shapes.capsule`."""
    from igl_spheremap.mesh.shapes import capsule

    return capsule(aspect, radius, n_around)


def make_rotated_sphere(level=2, seed=0, scale=1.0, translation=(0.0, 0.0, 0.0)):
    """Randomly rotated, scaled and translated icosphere.

    Returns ``V, F, R, X`` with ``V = scale * X + translation`` and ``X = icosphere @ R.T``
    (unit rows: the point of the unit sphere each input vertex corresponds to).
    """
    V0, F = make_icosphere(level)
    R = Rotation.random(random_state=np.random.default_rng(seed)).as_matrix()
    X = V0 @ R.T
    return scale * X + np.asarray(translation, dtype=np.float64), F, R, X


@functools.cache
def _load_cached(name):
    if name == "dino.obj":
        ref = importlib.resources.files("igl_spheremap") / "data" / "dino.obj"
        with importlib.resources.as_file(ref) as path:
            V, F = igl.read_triangle_mesh(str(path))
    else:
        V, F = igl.read_triangle_mesh(str(DATA / name))
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    V.flags.writeable = False
    F.flags.writeable = False
    return V, F


def load_mesh(name):
    """A real test mesh by file name (fresh, writable copies)."""
    V, F = _load_cached(name)
    return V.copy(), F.copy()


def procrustes(A, B):
    """Orthogonal ``Q`` minimizing ``|A Q - B|_F`` (SVD of ``A^T B``).

    Returns ``Q`` and the largest row residual ``max_i |A_i Q - B_i|``.
    """
    W, _, Zt = np.linalg.svd(A.T @ B)
    Q = W @ Zt
    return Q, float(np.max(np.linalg.norm(A @ Q - B, axis=1)))


@pytest.fixture(scope="session")
def icosphere():
    return make_icosphere


@pytest.fixture(scope="session")
def ellipsoid():
    return make_ellipsoid


@pytest.fixture(scope="session")
def rotated_sphere():
    return make_rotated_sphere


@pytest.fixture(scope="session")
def stretched():
    """A 3:1 ellipsoid, its central projection slightly perturbed (fold-free): ``(V, F, U)``."""
    from igl_spheremap.folding.starts import central_projection
    from igl_spheremap.mesh.shapes import ellipsoid as ellipsoid_mesh
    from igl_spheremap.mesh.validate import validate_mesh
    from igl_spheremap.sphere.folds import count_folds

    mesh = validate_mesh(*ellipsoid_mesh(3.0))
    V, F = mesh.V, mesh.F
    U = central_projection(V, F) + 0.01 * np.random.default_rng(0).standard_normal(V.shape)
    U /= np.linalg.norm(U, axis=1, keepdims=True)
    assert count_folds(F, U) == 0
    return V, F, U


@pytest.fixture(scope="session")
def mesh():
    """``mesh(name)``: a real test mesh ``(V, F)`` by file name (see :data:`REAL_MESHES`)."""
    return load_mesh


@pytest.fixture(scope="session")
def fit_rotation():
    return procrustes


@pytest.fixture
def rng():
    return np.random.default_rng(20140521)


@pytest.fixture(scope="session")
def conformal_map():
    """``conformal_map(name)``: ``(V, F, result, rounds_from_callback)``, mapped once per session.

    Default options of :func:`igl_spheremap.spherical_conformal_map`.
    """
    from igl_spheremap import spherical_conformal_map

    cache = {}

    def run(name):
        if name not in cache:
            V, F = load_mesh(name)
            seen = []
            result = spherical_conformal_map(V, F, callback=seen.append)
            cache[name] = (V, F, result, seen)
        return cache[name]

    return run
