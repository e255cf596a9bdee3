"""The data and measures of the atlas-registration benchmarks (:mod:`atlas`, :mod:`atlas_individual`).

FreeSurfer's fsaverage5 (left hemisphere) ships in nilearn's wheel
(``nilearn/datasets/data/fsaverage5``: ``white``, ``pial``, ``sphere``, ``sulc``,
``curv`` as ``.gii.gz``, the arrays of FreeSurfer's files); nilearn is in the
``bench`` extra.  A :class:`Case` is fsaverage5's ``white`` or ``pial`` surface with
its vertices randomly permuted (seed 0) and its own ``sulc`` / ``curv``, registered
to fsaverage5's ``sphere`` with the same features: vertex ``i`` of the subject
belongs at sphere vertex ``perm[i]``, so the error of a registered sphere is the
angle to that vertex (degrees on the unit sphere; fsaverage5's vertex spacing is
about 2.2 degrees).
"""

from pathlib import Path

import numpy as np


def fsaverage5():
    """fsaverage5's left ``white``, ``pial``, ``sphere`` (float64), ``F`` (int64), ``sulc``, ``curv``."""
    import nibabel as nib
    import nilearn

    root = Path(nilearn.__file__).parent / "datasets" / "data" / "fsaverage5"

    def arrays(name):
        return [a.data for a in nib.load(root / name).darrays]

    white, F = arrays("white_left.gii.gz")
    pial, F2 = arrays("pial_left.gii.gz")
    sphere, F3 = arrays("sphere_left.gii.gz")
    assert (F == F2).all() and (F == F3).all()
    return dict(white=white.astype(float), pial=pial.astype(float), sphere=sphere.astype(float),
                F=F.astype(np.int64), sulc=arrays("sulc_left.gii.gz")[0].astype(float),
                curv=arrays("curv_left.gii.gz")[0].astype(float))


def angles(A, B):
    """Angle between the rows of ``A`` and ``B`` (any lengths), degrees."""
    A = A / np.linalg.norm(A, axis=1, keepdims=True)
    B = B / np.linalg.norm(B, axis=1, keepdims=True)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(A, B), axis=1), (A * B).sum(1)))


def oracle_rotation(U, truth):
    """``U`` rotated by the least-squares rotation onto ``truth`` (Kabsch)."""
    a, _, bt = np.linalg.svd(U.T @ truth)
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(bt.T @ a.T))])
    return U @ (bt.T @ D @ a.T).T


def farthest_points(V, k):
    """``k`` vertices by farthest-point sampling (Euclidean), from the one farthest from the centroid."""
    idx = [int(np.argmax(np.linalg.norm(V - V.mean(0), axis=1)))]
    dist = np.linalg.norm(V - V[idx[0]], axis=1)
    for _ in range(k - 1):
        idx.append(int(np.argmax(dist)))
        dist = np.minimum(dist, np.linalg.norm(V - V[idx[-1]], axis=1))
    return np.array(idx)


class Case:
    """fsaverage5's ``surface`` permuted (``seed``), with the target sphere and the truth."""

    def __init__(self, surface, seed=0, data=None):
        data = fsaverage5() if data is None else data
        perm = np.random.default_rng(seed).permutation(data["F"].max() + 1)
        inv = np.argsort(perm)
        self.name = surface
        self.V, self.F = data[surface][perm], inv[data["F"]]
        self.sulc, self.curv = data["sulc"][perm], data["curv"][perm]
        self.T, self.TF = data["sphere"], data["F"]
        self.Tsulc, self.Tcurv = data["sulc"], data["curv"]
        self.truth = data["sphere"][perm] / np.linalg.norm(data["sphere"][perm], axis=1)[:, None]
        self.target_surface = data[surface]

    def features(self, kinds):
        """Subject and target features of ``kinds`` (``"sulc"``, ``"curv"``), (n, d) each."""
        return (np.column_stack([getattr(self, k) for k in kinds]),
                np.column_stack([getattr(self, "T" + k) for k in kinds]))

    def measures(self, U):
        """Errors, folds (float64 and as stored: float32 at radius 100) and the sulc correlation."""
        from igl_spheremap import count_folds
        from igl_spheremap.mesh.operators import vertex_areas
        from igl_spheremap.sphere.field import SphereField
        from igl_spheremap.sphere.folds import folds_after_rounding
        from igl_spheremap.uses.features import weighted_correlation

        U = U / np.linalg.norm(U, axis=1, keepdims=True)
        e = angles(U, self.truth)
        folds = count_folds(self.F, U)
        corr = None
        if folds == 0:
            g = SphereField(self.T, self.TF, self.Tsulc)(U, gradient=False)[0][:, 0]
            corr = float(weighted_correlation(self.sulc, g, vertex_areas(U, self.F))[0])
        return dict(mean=float(e.mean()), median=float(np.median(e)),
                    p90=float(np.percentile(e, 90)), folds=int(folds),
                    stored_folds=int(folds_after_rounding(self.F, U, 100.0)), sulc_corr=corr)


def cat_sphere(V, F):
    """CAT-Surface's metric-relaxed sphere (``surf_to_sphere(stop_at=5, relax=True)``), unit rows."""
    import cat_surf

    S, SF = cat_surf.surf_to_sphere(V, F.astype(np.int32), stop_at=5, relax=True)
    assert (SF == F).all()
    return S / np.linalg.norm(S, axis=1, keepdims=True)


def spherical_demons(V, F, U, target_surface, T, TF):
    """CAT-Surface's Spherical Demons (defaults; GPL, run as a peer, never imported by the
    package) from the start sphere ``U``: the registered sphere (n, 3)."""
    import cat_surf

    F32, TF32 = F.astype(np.int32), TF.astype(np.int32)
    W, _ = cat_surf.spherical_demon((V, F32), (100.0 * U, F32), (target_surface, TF32), (T, TF32))
    return np.asarray(W, dtype=np.float64)
