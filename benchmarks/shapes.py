"""The constructed shapes of the benchmarks, by name: the elongated shapes of the precision
benchmark (issue #15) and the split icosphere of the corpus (issue #21).

The shapes themselves are the package's (:mod:`igl_spheremap.mesh.shapes`, shared with
the tests): ``ellipsoid(aspect)`` is the level-3 icosphere (642 vertices, 1,280 faces)
scaled by ``(1, 1, aspect)``, convex, with a fold-free Gauss map, but its conformal map
crowds the tips (the Gauss map's own crowding grows like ``aspect**2``);
``capsule(aspect)`` is a cylinder with hemispherical caps, 16 vertices per ring about
one edge length apart (50:1: 4,114 vertices, 8,224 faces), whose Gauss map is
degenerate (every ring of the cylinder maps to the equator), so round 0 starts folded.
"""

import igl
import numpy as np

import igl_spheremap.mesh.shapes as generators

#: name -> (generator of :mod:`igl_spheremap.mesh.shapes`, arguments) of every constructed
#: shape of the benchmarks; ``split_ico`` is the level-3 icosphere with every face split at
#: points 3% along its edges (issue #21).
SHAPES = {"ellipsoid_10": ("ellipsoid", (10.0,)), "ellipsoid_30": ("ellipsoid", (30.0,)),
          "ellipsoid_100": ("ellipsoid", (100.0,)), "ellipsoid_1000": ("ellipsoid", (1000.0,)),
          "capsule_50": ("capsule", (50.0,)), "split_ico": ("split_icosphere", (3, 0.03))}

#: The shapes of the precision benchmark.
PRECISION_SHAPES = ("ellipsoid_10", "ellipsoid_30", "ellipsoid_100", "ellipsoid_1000", "capsule_50")


def shape(name):
    """``(V, F)`` of a shape of :data:`SHAPES` (float64 (n, 3), int64 (m, 3))."""
    kind, args = SHAPES[name]
    return getattr(generators, kind)(*args)


# --------------------------------------------------------------------------- awkward shapes

#: Awkward closed genus-0 shapes no file of ``../shared`` has (``benchmarks/awkward_shapes.py``):
#: convex hulls of random points in a cube, a plate and a rod (needle faces, fan-like
#: flat regions; 40, 300 and 3,000 points), the hull of two 64-gons 8 radii apart (a CAD
#: collision hull of a cylinder: long fans), and level sets of smooth unions of a ball or
#: two and thin capsules, triangulated by libigl's marching cubes (input slivers): a ball
#: with 6 or 14 spikes, a palm with five fingers and a thumb, two balls joined by a thin
#: rod, and a helical tube about 150 radii long.
AWKWARD_SHAPES = ("hull_cube_40", "hull_cube_300", "hull_cube_3000", "hull_plate_40",
                  "hull_plate_300", "hull_plate_3000", "hull_rod_40", "hull_rod_300",
                  "hull_rod_3000", "hull_cylinder_64", "spiky_6", "spiky_14", "hand", "dumbbell",
                  "snake")


def awkward_shape(name):
    """``(V, F)`` of a shape of :data:`AWKWARD_SHAPES` (float64 (n, 3), int64 (m, 3)); the same
    arrays on every call (fixed seeds)."""
    if name.startswith("hull_"):
        return _hull(name)
    return _level_set(*_IMPLICIT[name])


def _hull(name):
    """Convex hull of points (scipy's Qhull), its faces turned outward."""
    from scipy.spatial import ConvexHull
    _, kind, count = name.split("_")
    if kind == "cylinder":
        t = np.linspace(0.0, 2.0 * np.pi, int(count), endpoint=False)
        ring = np.c_[np.cos(t), np.sin(t)]
        P = np.r_[np.c_[ring, np.zeros(t.size)], np.c_[ring, np.full(t.size, 8.0)]]
    else:
        scale = {"cube": (1.0, 1.0, 1.0), "plate": (1.0, 1.0, 0.05), "rod": (1.0, 0.1, 0.03)}[kind]
        P = np.random.default_rng(1).uniform(-1.0, 1.0, (int(count), 3)) * scale
    hull = ConvexHull(P)
    used = np.unique(hull.simplices)
    V, F = P[used], np.searchsorted(used, hull.simplices).astype(np.int64)
    inward = np.einsum("ij,ij->i", np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]),
                       V[F[:, 0]] - V.mean(axis=0)) < 0
    F[inward] = F[inward][:, ::-1]
    return V, F


def _capsule_distance(P, a, b, r):
    """Signed distance of the points ``P`` (k, 3) to the capsule of radius ``r`` about ``ab``."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    t = np.clip((P - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
    return np.linalg.norm(P - (a + t[:, None] * (b - a)), axis=1) - r


def _smooth_union(distances, k):
    """Polynomial smooth minimum of signed distances (Quilez), blend width ``k``."""
    out = distances[0]
    for d in distances[1:]:
        h = np.clip(0.5 + 0.5 * (d - out) / k, 0.0, 1.0)
        out = d * (1.0 - h) + out * h - k * h * (1.0 - h)
    return out


def _spikes(count, radius):
    axes = np.r_[np.eye(3), -np.eye(3)]
    if count == 14:
        axes = np.r_[axes, np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1)
                                     for z in (-1, 1)]) / np.sqrt(3.0)]
    return lambda P: _smooth_union([np.linalg.norm(P, axis=1) - 0.5]
                                   + [_capsule_distance(P, (0, 0, 0), 1.5 * d, radius) for d in axes],
                                   0.05)


def _hand(P):
    palm = 0.2 * (np.linalg.norm(P / (0.6, 0.7, 0.2), axis=1) - 1.0)
    fingers = [_capsule_distance(P, (x, 0.5, 0), (1.3 * x, 1.5, 0), 0.05)
               for x in (-0.4, -0.2, 0.0, 0.2, 0.4)]
    return _smooth_union([palm, *fingers, _capsule_distance(P, (0.5, 0, 0), (1.4, 0.3, 0), 0.06)],
                         0.05)


def _dumbbell(P):
    return _smooth_union([np.linalg.norm(P - (1, 0, 0), axis=1) - 0.45,
                          np.linalg.norm(P + (1, 0, 0), axis=1) - 0.45,
                          _capsule_distance(P, (-1, 0, 0), (1, 0, 0), 0.03)], 0.05)


def _helix(s):
    return 1.3 * np.cos(s), 1.3 * np.sin(s), 0.3 * s - 1.2


def _snake(P):
    return _smooth_union([_capsule_distance(P, _helix(s), _helix(s + 0.3), 0.07)
                          for s in np.arange(0.0, 8.0, 0.3)], 0.02)


#: name -> (signed distance function, grid resolution) of the level-set shapes.
_IMPLICIT = {"spiky_6": (_spikes(6, 0.06), 96), "spiky_14": (_spikes(14, 0.05), 128),
             "hand": (_hand, 128), "dumbbell": (_dumbbell, 128), "snake": (_snake, 128)}


def _level_set(distance, resolution, extent=1.6):
    """The zero level set of ``distance`` on a cubic grid of ``resolution``^3 corners in
    ``[-extent, extent]^3`` (libigl's marching cubes), its largest component, faces outward."""
    g = np.linspace(-extent, extent, resolution)
    Z, Y, X = np.meshgrid(g, g, g, indexing="ij")  # libigl: S(x + y nx + z nx ny)
    GV = np.c_[X.ravel(), Y.ravel(), Z.ravel()]
    V, F, _ = igl.marching_cubes(distance(GV), GV, resolution, resolution, resolution, 0.0)
    V, F = _merged(V, F)
    volume = np.einsum("ij,ij->i", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])).sum()
    return V, (F if volume > 0 else F[:, ::-1]).astype(np.int64)


def _merged(V, F):
    """Vertices at the same position merged, degenerate faces and unreferenced vertices dropped."""
    _, first, inverse = np.unique(np.round(V, 12), axis=0, return_index=True, return_inverse=True)
    F = inverse.ravel()[F]
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])]
    used = np.unique(F)
    return V[first][used], np.searchsorted(used, F)
