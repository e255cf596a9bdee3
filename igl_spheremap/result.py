"""Result objects of :func:`igl_spheremap.spherical_conformal_map` (scipy.optimize style)."""

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Round:
    """One stage of Algorithm 2: an initial map followed by Algorithm 1.

    Attributes
    ----------
    index : int
        0 for the Gauss-map stage, ``k >= 1`` for folding-removal round ``k``.
    kind : str
        ``"gauss"`` (initial map = Gauss map), ``"star"`` (initial map = star
        map) or ``"local"`` (local repair of the previous map's folds,
        :func:`igl_spheremap.local_repair.local_repair`: initial map = that map
        untangled, Algorithm 1 only over ``region`` vertices).
    U_init : (n, 3) float64 array
        Initial map of this round (Gauss map, star map or untangled map), unit rows.
    U : (n, 3) float64 array
        Map after Algorithm 1, unit rows.
    folds_before, folds_after : int
        Folded faces of ``U_init`` and of ``U``.
    nit : int
        Algorithm 1 iterations.
    converged : bool
        Whether Algorithm 1 met its stopping rule.
    message : str
        Algorithm 1's stopping message.
    energy_history, grad_norm_history : list of float
        Harmonic energy (dimensionless, ``4 pi`` for a conformal bijection) and RMS
        Riemannian gradient per Algorithm 1 iterate.
    seconds : float
        Wall time of this round (eigen-projection included).
    Phi : (n, 3) float64 array or None
        Star rounds only: weighted Laplace-Beltrami eigenfunctions ``Phi^u`` (Eq. 27).
    eigenvalues : (3,) float64 array or None
        Star rounds only (mesh scaled to area ``4 pi``; 2 on a round sphere).
    reflected : bool
        Star rounds only: whether the eigenbasis was a reflection and was flipped.
    frozen : int
        Vertices the fold barrier froze in this round's Algorithm 1 (0 without
        the barrier): where the energy would have folded faces.
    folds_star : int or None
        Star rounds only: folded faces of the star map itself, before the local
        untangling (:func:`igl_spheremap.untangle.untangle_folds`) that produced
        ``U_init``; equals ``folds_before`` when nothing was untangled.
    region : int or None
        Local rounds only: vertices free to move in the local Algorithm 1.
    """

    index: int
    kind: str
    U_init: np.ndarray
    U: np.ndarray
    folds_before: int
    folds_after: int
    nit: int
    converged: bool
    message: str
    energy_history: list = field(default_factory=list)
    grad_norm_history: list = field(default_factory=list)
    seconds: float = 0.0
    Phi: np.ndarray = None
    eigenvalues: np.ndarray = None
    reflected: bool = False
    frozen: int = 0
    folds_star: int = None
    region: int = None

    @property
    def energy(self):
        """Final harmonic energy of the round."""
        return self.energy_history[-1]


@dataclass
class SphericalMapResult:
    """Outcome of :func:`igl_spheremap.spherical_conformal_map`.

    Attributes
    ----------
    U : (n, 3) float64 array
        The spherical map, unit rows, indexed like the input ``V``.
    folds : int
        Folded faces of ``U`` (0 for a folding-free map).
    converged : bool
        Whether the last Algorithm 1 run met its stopping rule.
    success : bool
        ``folds == 0 and converged``.
    message : str
        Human-readable summary of how the run ended.
    rounds : list of Round
        Every stage, in order (Gauss-map stage first).
    nit : int
        Algorithm 1 iterations over all rounds.
    energy : float
        Harmonic energy of ``U`` (Laplacian used by the run; ``4 pi`` ideally).
    centroid_norm : float
        ``|sum_i A_i U_i| / sum_i A_i`` (input vertex areas) after Möbius normalization.
    min_image_area : float
        Smallest image triangle area (flat, on the unit sphere): how crowded thin
        features are.
    orientation_flipped : bool
        The input was oriented inward and its faces were flipped to map it.
    seconds : float
        Total wall time.
    options : dict
        The options the run used.
    """

    U: np.ndarray
    folds: int
    converged: bool
    message: str
    rounds: list
    nit: int
    energy: float
    centroid_norm: float
    min_image_area: float
    orientation_flipped: bool = False
    seconds: float = 0.0
    options: dict = field(default_factory=dict)

    @property
    def success(self):
        return self.folds == 0 and self.converged
