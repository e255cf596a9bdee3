"""The elongated shapes of the precision benchmark (issue #15), by name.

The shapes themselves are the package's (:mod:`igl_spheremap.mesh.shapes`, shared with
the tests): ``ellipsoid(aspect)`` is the level-3 icosphere (642 vertices, 1,280 faces)
scaled by ``(1, 1, aspect)``, convex, with a fold-free Gauss map, but its conformal map
crowds the tips (the Gauss map's own crowding grows like ``aspect**2``);
``capsule(aspect)`` is a cylinder with hemispherical caps, 16 vertices per ring about
one edge length apart (50:1: 4,114 vertices, 8,224 faces), whose Gauss map is
degenerate (every ring of the cylinder maps to the equator), so round 0 starts folded.
"""

from igl_spheremap.mesh.shapes import capsule, ellipsoid

#: name -> (kind, aspect) of the shapes of the precision benchmark.
SHAPES = {"ellipsoid_10": ("ellipsoid", 10.0), "ellipsoid_30": ("ellipsoid", 30.0),
          "ellipsoid_100": ("ellipsoid", 100.0), "ellipsoid_1000": ("ellipsoid", 1000.0),
          "capsule_50": ("capsule", 50.0)}


def shape(name):
    """``(V, F)`` of a shape of :data:`SHAPES` (float64 (n, 3), int64 (m, 3))."""
    kind, aspect = SHAPES[name]
    return ellipsoid(aspect) if kind == "ellipsoid" else capsule(aspect)
