"""The stages of a run of Algorithm 2, as data to draw (no polyscope here)."""

import numpy as np

from ..errors import plural
from ..folding.result import SphericalMapResult
from ..mesh.operators import SPHERE_AREA, laplacian, vertex_areas
from ..sphere.folds import folded_faces
from ..sphere.quality import angle_distortion, conformal_factor, harmonic_energy


def _stage(name, index, kind, mesh, L, U, nit, Phi, phi_note, eigenvalues):
    V, F = mesh.V, mesh.F
    folded = folded_faces(F, U)
    e2u = conformal_factor(V, F, U)
    u = 0.5 * np.log(np.maximum(e2u, 1e-300))
    with np.errstate(invalid="ignore"):
        ang = float(np.nanmean(angle_distortion(V, F, U)))
    return dict(name=name, round=index, kind=kind, V=V, F=F, U=U, folded=folded,
                folds=int(np.count_nonzero(folded)), nit=nit,
                energy_over_4pi=harmonic_energy(V, F, U, L) / SPHERE_AREA,
                mean_angle_distortion_deg=ang, u=u, Phi=Phi, phi_note=phi_note,
                eigenvalues=eigenvalues, extra=[])


def build_stages(result, *, final_phi=True):
    """The maps of a :func:`spherical_conformal_map` run as a list of display stages.

    Parameters
    ----------
    result : SphericalMapResult
        The run's result; its validated mesh (``result.mesh``) is what is drawn.
    final_phi : bool
        Also solve the weighted eigenproblem for the last map so the last stage
        can show its ``Phi^u`` (one extra sparse eigensolve).

    Returns
    -------
    stages : list of dict
        In order "Gauss map", "after Algorithm 1", then for each round ``k >= 1``
        "star map k" (or "untangled map k" for a local repair round, the start's title of
        :data:`STARTS` for the restart and the guaranteed path's rounds), "after
        Algorithm 1, round k" ("after the conformal descent, round k" for the guaranteed
        path's rounds: Algorithm 1 on the conformal distortion, with the polish).  Keys:

        ``name`` (str), ``round`` (int), ``kind`` ("gauss", "star", "local", "start" for the restart and the guaranteed path's starts, or "alg1"),
        ``V``, ``F`` the validated mesh (``result.mesh``),
        ``U`` (k, 3) float64 map on the validated vertices,
        ``folded`` (m,) bool mask from :func:`igl_spheremap.folded_faces`,
        ``folds`` (int), ``nit`` (Algorithm 1 iterations, None for initial maps),
        ``energy_over_4pi`` (harmonic energy with the run's Laplacian / 4 pi; 1 for a
        conformal bijection), ``mean_angle_distortion_deg`` (mean over corners of
        :func:`igl_spheremap.angle_distortion`, degrees), ``u`` (k,) float64 log
        conformal factor, ``Phi`` (k, 3) float64 or None, ``phi_note`` (str),
        ``eigenvalues`` (3,) or None, ``extra`` (list of str: further notes for the panel).

    Raises
    ------
    TypeError
        If ``result`` is not a :class:`igl_spheremap.SphericalMapResult` (e.g. a
        ``SurfaceMapResult``: see :func:`build_registration_stages`, or a bare map).
    ValueError
        If the result carries no rounds.
    """
    check_result(result)
    mesh, rounds = result.mesh, result.rounds
    if not rounds:
        raise ValueError("the result has no rounds to show")
    ours = mesh.from_input
    L = laplacian(mesh.V, mesh.F, result.options.laplacian_kind)
    stages = []
    for k, rnd in enumerate(rounds):
        if k == 0:
            stages.append(_stage("Gauss map", 0, "gauss", mesh, L, ours(rnd.U_init), None, None,
                                 "", None))
        elif rnd.kind in STARTS:
            title, note = STARTS[rnd.kind]
            stages.append(_stage(title, k, "start", mesh, L, ours(rnd.U_init), None, None, "",
                                 None))
            stages[-1]["extra"].append(note)
        elif rnd.kind == "local":
            stages.append(_stage(f"untangled map {k}", k, "local", mesh, L, ours(rnd.U_init),
                                 None, None, "", None))
            stages[-1]["extra"].append(
                f"local repair of {plural(rounds[k - 1].folds_after, 'folded face')}; Algorithm 1 "
                f"then moves {rnd.region} vertices")
        else:
            stages.append(_stage(f"star map {k}", k, "star", mesh, L, ours(rnd.U_init), None,
                                 ours(rnd.Phi),
                                 f"Φ^u of the previous map (normalized: star map {k})",
                                 rnd.eigenvalues))
            raw = getattr(rnd, "folds_star", None)
            if raw is not None and raw != stages[-1]["folds"]:
                stages[-1]["extra"].append(f"star map before local untangling: "
                                           f"{plural(raw, 'folded face')}")
        if k + 1 < len(rounds) and rounds[k + 1].Phi is not None:
            Phi, lam = ours(rounds[k + 1].Phi), rounds[k + 1].eigenvalues
            note = f"Φ^u of this map (gives star map {k + 1})"
        elif final_phi:
            Phi, lam = _final_phi(mesh, L, ours(rnd.U))
            note = "Φ^u of this map (final)" if Phi is not None else "eigensolver failed"
        else:
            Phi, lam, note = None, None, ""
        name = (f"after the conformal descent, round {k}" if rnd.kind in STARTS
                and rnd.kind != "restart" else "after Algorithm 1" + (f", round {k}" if k else ""))
        stages.append(_stage(name, k, "alg1", mesh, L, ours(rnd.U), rnd.nit, Phi, note, lam))
    return stages


#: Stage title and note of the rounds that start from a map other than a star map: the
#: restart after a collapse (:func:`igl_spheremap.folding.rounds.restart_round`) and the
#: guaranteed path's starts (:mod:`igl_spheremap.folding.guaranteed`).
STARTS = {
    "restart": ("punctured Tutte map, lifted to the sphere",
                "restart after a round collapsed to degree 0"),
    "central": ("central projection from the kernel",
                "fold-free by construction (the guaranteed path)"),
    "tutte": ("punctured Tutte map, lifted to the sphere",
              "fold-free by construction (the guaranteed path)"),
    "untangled": ("punctured disk untangled in the plane, lifted to the sphere",
                  "fold-free by construction, some angle given up (the guaranteed path)"),
    "polish": ("start of the polish", "the accepted round's map, or its initial map where the "
               "fold barrier held it: the conformal descent starts here"),
}


def check_result(result):
    """Raise a TypeError unless ``result`` is a :class:`SphericalMapResult` (what it is instead,
    and what to pass)."""
    if isinstance(result, SphericalMapResult):
        return
    hint = ""
    if hasattr(result, "map1") and hasattr(result, "map2"):
        hint = ("; an inter-surface map is drawn by viz.build_registration_stages and "
                "viz.show_registration")
    elif isinstance(result, np.ndarray):
        hint = "; pass the result of spherical_conformal_map, not its map U"
    raise TypeError(f"expected a SphericalMapResult from igl_spheremap.spherical_conformal_map, "
                    f"got {type(result).__name__}{hint}")


def _final_phi(mesh, L, U):
    from ..folding.star_map import star_map_of
    try:
        _, Phi, lam, _ = star_map_of(mesh.F, U, L, vertex_areas(mesh.V, mesh.F))
    except RuntimeError:
        return None, None
    return Phi, lam


def phi_shape(Phi, area):
    """Centre ``Phi`` like the star map does; scale it to unit largest radius.

    Returns the scaled points and the radius spread: area-weighted standard
    deviation / mean of ``|Phi - c|`` (0 for a round sphere).
    """
    c = (area @ Phi) / area.sum()
    X = Phi - c
    r = np.linalg.norm(X, axis=1)
    mean_r = float(area @ r / area.sum())
    spread = float(np.sqrt(area @ (r - mean_r) ** 2 / area.sum()) / mean_r)
    return X / float(r.max()), spread
