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
