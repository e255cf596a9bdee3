"""Elongated test shapes of issue #15 (benchmark helper): ellipsoids and a capsule.

* ``ellipsoid(aspect)``: the level-3 icosphere (:func:`igl_spheremap.resampling.icosphere`,
  642 vertices, 1,280 faces) scaled by ``(1, 1, aspect)``.  Convex, and its Gauss
  map is fold-free, but a conformal map crowds its tips (the Gauss map's own
  crowding grows like ``aspect**2``).
* ``capsule(aspect)``: a cylinder with hemispherical caps, length / width
  ``aspect``, 16 vertices per ring about one edge length apart (50:1: 4,114
  vertices, 8,224 faces).  Its Gauss map is degenerate (every ring of the
  cylinder maps to the equator), so round 0 starts folded.

The same shapes as ``tests/conftest.py`` (``make_ellipsoid(3, (1, 1, a))`` uses
its own icosahedron, so vertex positions differ in rounding; ``make_capsule``
is identical).
"""

import numpy as np

#: name -> (kind, aspect) of the shapes of the precision benchmark.
SHAPES = {"ellipsoid_10": ("ellipsoid", 10.0), "ellipsoid_30": ("ellipsoid", 30.0),
          "ellipsoid_100": ("ellipsoid", 100.0), "ellipsoid_1000": ("ellipsoid", 1000.0),
          "capsule_50": ("capsule", 50.0)}


def shape(name):
    """``(V, F)`` of a shape of :data:`SHAPES` (float64 (n, 3), int64 (m, 3))."""
    kind, aspect = SHAPES[name]
    return ellipsoid(aspect) if kind == "ellipsoid" else capsule(aspect)


def ellipsoid(aspect, level=3):
    """Icosphere of ``level`` scaled by ``(1, 1, aspect)``: ``(V, F)``, outward oriented."""
    from igl_spheremap.resampling import icosphere

    V, F = icosphere(level)
    return V * np.array([1.0, 1.0, float(aspect)]), F


def capsule(aspect=50.0, radius=0.5, n_around=16):
    """Closed capsule of length / width ``aspect`` about the z axis: ``(V, F)``, outward oriented."""
    h = (aspect - 1.0) * 2.0 * radius  # length of the cylinder
    ds = 2.0 * np.pi * radius / n_around
    n_cap = max(2, int(round(np.pi / 2.0 * radius / ds)))
    n_cyl = max(1, int(round(h / ds)))
    phi = np.pi / 2.0 * np.arange(1, n_cap + 1) / n_cap
    profile = ([(-h / 2 - radius * np.cos(a), radius * np.sin(a)) for a in phi]
               + [(-h / 2 + h * i / n_cyl, radius) for i in range(1, n_cyl)]
               + [(h / 2 + radius * np.cos(a), radius * np.sin(a)) for a in phi[::-1]])
    th = 2.0 * np.pi * np.arange(n_around) / n_around
    rings = [np.column_stack([r * np.cos(th), r * np.sin(th), np.full(n_around, z)])
             for z, r in profile]
    V = np.vstack([[[0.0, 0.0, -h / 2 - radius]], *rings, [[0.0, 0.0, h / 2 + radius]]])
    N, j = n_around, np.arange(n_around)
    j1 = (j + 1) % N
    F = [np.column_stack([np.zeros(N, dtype=np.int64), 1 + j1, 1 + j])]
    for k in range(len(rings) - 1):
        a, b = 1 + k * N, 1 + (k + 1) * N
        quads = [np.column_stack([a + j, a + j1, b + j1]), np.column_stack([a + j, b + j1, b + j])]
        F.append(np.stack(quads, axis=1).reshape(-1, 3))
    top, last = V.shape[0] - 1, 1 + (len(rings) - 1) * N
    F.append(np.column_stack([np.full(N, top), last + j, last + j1]))
    return V, np.vstack(F).astype(np.int64)
