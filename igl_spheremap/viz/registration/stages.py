"""The stages of an inter-surface map (:func:`igl_spheremap.surface_map`) and the data carried.

No polyscope here.  A *stage* is one spherical map of surface 1 on the way
through :func:`igl_spheremap.surface_map` (its ``stages``), each with surface
2's data carried onto surface 1 through it and the per-triangle distortion of
the map between the surfaces it defines:

1. the conformal map of surface 1 aligned to surface 2's (Möbius-fitted to the
   landmarks, or rotated by the alignment's search);
2. that map bent until the landmarks sit on their targets (when there are
   landmarks);
3. the map after the distortion stage on coarse levels of surface 1 (when it ran);
4. the map after the distortion stage with the landmark descriptors (when they
   were used), and the map after the distortion stage (the result's ``map1.U``).

The distortion of a triangle of surface 1 is the symmetric Dirichlet energy
of its linear map onto the triangle of its three images on surface 2, both
surfaces scaled to area ``4 pi`` (:func:`igl_spheremap.uses.surface_distortion.face_distortion`):
1 for an isometry.

The default data is a checkerboard of a conformal chart of surface 2's sphere
(:func:`checker_values`, per vertex of surface 2): each check of surface 2
lands, carried by the barycentric interpolation matrix ``P``, on the
corresponding region of surface 1.
"""

import numpy as np

from ...errors import plural
from ...mesh.arrays import as_points, vertex_indices, vertex_values
from ...mesh.operators import vertex_areas
from ...sphere.folds import folded_faces
from ...sphere.locate import locate_on_sphere
from ...sphere.quality import angle_distortion, harmonic_energy
from ...sphere.transfer import barycentric_matrix
from ...uses.surface_arap import to_sphere_scale
from ...uses.surface_distortion import face_distortion
from ...uses.registration import SurfaceMapResult
from ..fields import chart_poles

#: Checks of the default checkerboard round each pole of its chart (even: no seam).
CHECKS_AROUND = 8


def checker_values(U, south, north=None, *, weights=None, around=CHECKS_AROUND):
    """Checkerboard of a conformal chart of a spherical map: 0 or 1 per vertex.

    The chart is :func:`igl_spheremap.viz.fields.mercator_vertices` (Mercator's
    chart after the Möbius map sending the images of ``south`` and ``north`` to
    the poles; ``log |w|`` shifted so that its ``weights``-weighted median is 0).
    With ``s = 2 pi / around``, the vertex with chart coordinates ``(a, y)`` is
    in check ``(floor(a / s), floor(y / s))`` and gets that check's parity.
    The chart is conformal, so the checks pulled back to the surface are squares
    where the map is conformal, down the thin limbs too (a ``(theta, phi)``
    grid would leave a limb the map shrinks inside a single check).

    Parameters
    ----------
    U : (n, 3) float array
        A spherical map.
    south, north : int
        Vertices at the chart's poles (``north`` None: the antipode of ``south``).
    weights : (n,) float array, optional
    around : int
        Checks round each pole; even, so the seam of ``arg w`` does not show.

    Returns
    -------
    (n,) float64 array of 0.0 and 1.0
    """
    from ..fields import mercator_vertices

    X = mercator_vertices(U, south, north, weights=weights)
    k = np.floor(X / (2.0 * np.pi / around)).astype(np.int64)
    return ((k[:, 0] + k[:, 1]) % 2).astype(np.float64)


def angles_deg(A, B):
    """Angle between corresponding rows of ``A`` and ``B`` in degrees ((k,) float64)."""
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(A, B), axis=1),
                                 np.sum(A * B, axis=1)))


def build_registration_stages(result, V1, V2, landmarks1, landmarks2, data2=None,
                              data_name=None, mode="hard"):
    """The stages of surface 1's map, each with surface 2's data carried onto surface 1.

    Parameters
    ----------
    result : SurfaceMapResult
        From :func:`igl_spheremap.surface_map`.
    V1, V2 : (n1, 3), (n2, 3) float arrays
        The two surfaces as given to :func:`surface_map`.
    landmarks1, landmarks2 : (k,) int arrays
        The landmark pairs (vertex indices).
    data2 : (n2,) float array, optional
        Per-vertex data of surface 2; default :func:`checker_values` of surface 2's
        map with poles at landmark 1 and the first landmark at least 115 degrees
        from it on the sphere (:func:`igl_spheremap.viz.fields.chart_poles`).
    data_name : str, optional
        What ``data2`` is (for the legend).
    mode : {"hard", "soft"}
        The ``mode`` :func:`surface_map` ran with (kept for callers; the stages
        are the result's own).

    Returns
    -------
    list of dict
        One per stage (see the module docstring), keys ``name``, ``kind``
        ("aligned", "deformed", "distortion"), ``U`` (n1, 3) surface 1's map,
        ``folded`` (m1,) bool, ``folds``, ``landmark_errors`` (k,) degrees
        (angle between each landmark's image and its target), ``max_error``,
        ``energy_over_4pi`` (:func:`igl_spheremap.harmonic_energy` / 4 pi),
        ``mean_angle_distortion_deg``, ``P`` (n1 x n2 csr; the result's own ``P``
        for the final map), ``carried`` (n1,) ``P @ data2``, ``distortion`` (m1,)
        per-triangle distortion of the map between the surfaces,
        ``median_distortion`` its area-weighted median (a few crushed triangles make
        the mean meaningless), ``note`` (str) and
        ``pair``, a dict shared by all stages: ``V1``, ``F1``, ``V2``, ``F2`` (the
        maps' faces, input numbering), ``l1``, ``l2``, ``U2`` surface 2's map,
        ``targets`` ``U2[l2]``, ``data2``, ``checker`` (bool: the default data),
        ``data_name``, ``message`` (the result's), ``success``, ``poles`` (the
        checker chart's poles: vertices of surface 2, :func:`chart_poles` of
        its landmarks).

    Raises
    ------
    TypeError
        If ``result`` is not a :class:`igl_spheremap.SurfaceMapResult` (e.g. a
        ``SphericalMapResult``: see :func:`igl_spheremap.viz.build_stages`).
    ValueError
        If ``V1``/``V2`` are not the surfaces the maps were computed on (row counts),
        the landmark lists differ in length, are empty or name vertices the surfaces do
        not have, or ``data2`` is not one finite value per vertex of surface 2 (the
        counts are given).
    """
    if not isinstance(result, SurfaceMapResult):
        hint = ("; a single map's stages are built by viz.build_stages"
                if hasattr(result, "rounds") else "")
        raise TypeError("expected a SurfaceMapResult from igl_spheremap.surface_map, got "
                        f"{type(result).__name__}{hint}")
    map1, map2 = result.map1, result.map2
    V1 = as_points(V1, "V1", rows=map1.U.shape[0])
    V2 = as_points(V2, "V2", rows=map2.U.shape[0])
    l1 = vertex_indices(landmarks1, V1.shape[0], "landmarks1")
    l2 = vertex_indices(landmarks2, V2.shape[0], "landmarks2")
    if l1.size != l2.size or not l1.size:
        raise ValueError(f"landmarks1 has {plural(l1.size, 'vertex', 'vertices')} and landmarks2 "
                         f"{l2.size}; expected the same number of pairs, at least one")
    checker = data2 is None
    if not checker:
        data2 = vertex_values(data2, V2.shape[0], "data2")
    poles = chart_poles(map2.U, l2)
    if checker:
        data2 = checker_values(map2.U, *poles, weights=vertex_areas(V2, map2.F))
        data_name = (f"checkerboard of a conformal chart of surface 2's sphere (Mercator, poles "
                     f"at landmark {_pole_names(l2, poles)}; {CHECKS_AROUND} checks round)")
    pair = dict(V1=np.asarray(V1, np.float64), F1=map1.F, V2=np.asarray(V2, np.float64),
                F2=map2.F, l1=l1, l2=l2, U2=map2.U, targets=map2.U[l2],
                data2=np.asarray(data2, np.float64), checker=checker,
                data_name=data_name or "data of surface 2", message=result.message,
                success=result.success, poles=poles)
    stages = []
    for k, st in enumerate(result.stages):
        last = k == len(result.stages) - 1
        stages.append(_stage(pair, st["name"], stage_kind(st["name"]),
                             np.asarray(st["U"], np.float64), st["note"],
                             result.P if last else None))
    return stages


def stage_kind(name):
    """The kind of a stage of :func:`igl_spheremap.surface_map` from its name (str).

    "deformed" for the landmarks (given or found) moved onto their targets,
    "distortion" for every stage that lowers the distortion between the surfaces
    (on coarse levels, with the descriptors, without them, with the robust
    penalty), "aligned" for the aligned conformal map.
    """
    if "moved onto their targets" in name:
        return "deformed"
    return "distortion" if name.startswith("distortion") else "aligned"


def _pole_names(l2, poles):
    south, north = (None if p is None else int(np.flatnonzero(l2 == p)[0]) + 1 for p in poles)
    return f"{south} and its antipode" if north is None else f"{south} and {north}"


def _stage(pair, name, kind, U, note, P=None):
    V1, F1, U2, F2 = pair["V1"], pair["F1"], pair["U2"], pair["F2"]
    if P is None:
        face, bary = locate_on_sphere(U2, F2, U)
        P = barycentric_matrix(face, bary, F2, U2.shape[0])
    P = P.tocsr()
    err = angles_deg(U[pair["l1"]], pair["targets"])
    folded = folded_faces(F1, U)
    V1s = to_sphere_scale(V1, F1)
    dist = face_distortion(V1s, F1, np.asarray(P @ to_sphere_scale(pair["V2"], F2)))
    face_area = 0.5 * np.linalg.norm(np.cross(V1s[F1[:, 1]] - V1s[F1[:, 0]],
                                              V1s[F1[:, 2]] - V1s[F1[:, 0]]), axis=1)
    return dict(name=name, kind=kind, U=U, folded=folded, folds=int(folded.sum()),
                landmark_errors=err, max_error=float(err.max(initial=0.0)),
                distortion=dist, median_distortion=weighted_median(dist, face_area),
                energy_over_4pi=float(harmonic_energy(V1, F1, U) / (4 * np.pi)),
                mean_angle_distortion_deg=float(np.nanmean(angle_distortion(V1, F1, U))),
                P=P, carried=np.asarray(P @ pair["data2"]), note=note, pair=pair)


def weighted_median(x, w):
    """The smallest value of ``x`` (q,) whose weights ``w`` (q,) up to it in sorted order reach
    half of their total (float)."""
    order = np.argsort(x, kind="stable")
    c = np.cumsum(w[order])
    return float(x[order][np.searchsorted(c, 0.5 * c[-1])])


def stage_line(stage, index):
    """The line the demo prints per stage (the tests parse it)."""
    return (f"stage {index + 1}: {stage['name']}: largest landmark error "
            f"{stage['max_error']:.4f} deg, {stage['folds']} folded faces, median distortion "
            f"{stage['median_distortion']:.4f}")
