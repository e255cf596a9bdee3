"""The JSON report of a map: the run's rows per round, the quality of the map, the libraries."""

import platform
from datetime import datetime, timezone
from importlib import metadata as _metadata

import numpy as np

from ..mesh.operators import SPHERE_AREA
from ..sphere.quality import angle_distortion


def library_versions():
    """Versions of Python and of the libraries a run depends on (dict of str -> str)."""
    out = {"python": platform.python_version(), "platform": platform.platform()}
    for dist in ("igl-spheremap", "libigl", "numpy", "scipy", "pyamg", "scikit-sparse",
                 "sksparse-minimal", "nibabel", "dask", "distributed"):
        try:
            out[dist] = _metadata.version(dist)
        except _metadata.PackageNotFoundError:
            pass
    return out


def round_row(V, F, rnd):
    """Summary of one :class:`igl_spheremap.Round` for tables and reports.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
        The mesh that was mapped (``rnd.U`` is indexed like ``V``; angles do not
        depend on the orientation of ``F``).
    rnd : igl_spheremap.Round

    Returns
    -------
    dict
        ``round, kind``, ``folds_previous`` (folds of the map the round started
        from: the previous round's result; None for round 0), ``folds_before``
        (folds of its initial map), ``folds_after``, ``nit``, ``folds_star`` (folds
        of the star map before untangling), ``frozen`` (vertices frozen by the fold
        barrier), ``converged``, ``energy_over_4pi`` (the energy the round lowered / 4 pi,
        1 for a conformal map: harmonic for Algorithm 2's rounds, the conformal
        distortion for the guaranteed path's), ``angle_distortion_mean_deg`` (mean over corners,
        degrees), ``seconds, message``.
    """
    return {"round": rnd.index, "kind": rnd.kind,
            "folds_previous": None if rnd.folds_previous is None else int(rnd.folds_previous),
            "folds_before": int(rnd.folds_before),
            "folds_after": int(rnd.folds_after), "nit": int(rnd.nit),
            "folds_star": None if rnd.folds_star is None else int(rnd.folds_star),
            "frozen": int(rnd.frozen),
            "converged": bool(rnd.converged),
            "energy_over_4pi": float(rnd.energy) / SPHERE_AREA,
            "angle_distortion_mean_deg": float(np.mean(angle_distortion(V, F, rnd.U))),
            "seconds": float(rnd.seconds), "message": rnd.message}


def map_report(input_path, in_family, V, F, result, vdata, rounds, timings):
    """The report's entries that describe the input and the map.

    ``energy_over_4pi`` is the harmonic energy with the Laplacian the run used
    (``energy_laplacian``: intrinsic Delaunay by default), as in Algorithm 2's rounds;
    ``below_margin`` and ``repair`` are those of
    :class:`igl_spheremap.SphericalMapResult` for the run's ``precision``; ``chosen`` the
    index in ``rounds`` of the round the map came from.
    """
    ad = angle_distortion(V, result.F, result.U)
    return {
        "complete": True,
        "input": str(input_path.absolute()),
        "input_family": in_family,
        "vertices": int(V.shape[0]),
        "faces": int(F.shape[0]),
        "folds": int(result.folds),
        "below_margin": int(result.below_margin),
        "precision": result.options.precision,
        "repair": result.repair,
        "converged": bool(result.converged),
        "success": bool(result.success),
        "message": result.message,
        "nit": int(result.nit),
        "energy_over_4pi": float(result.energy_over_4pi),
        "energy_laplacian": result.options.laplacian_kind,
        "centroid_norm": float(result.centroid_norm),
        "min_image_area": float(result.min_image_area),
        "angle_distortion_mean_deg": float(ad.mean()),
        "angle_distortion_sd_deg": float(ad.std()),
        "folded_vertices": int(np.count_nonzero(vdata["folded"])),
        "orientation_flipped": bool(result.orientation_flipped),
        "reorientation": result.mesh.reorientation,
        "validation_notes": list(result.mesh.notes),
        "rounds": rounds,
        "chosen": int(result.chosen),
        "timings": timings,
        "versions": library_versions(),
        "finished": datetime.now(timezone.utc).isoformat(timespec="seconds"),
    }
