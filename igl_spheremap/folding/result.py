"""Result objects (scipy.optimize style): one round of Algorithm 2, and a whole map."""

from dataclasses import dataclass, field

import igl
import numpy as np

from ..errors import plural
from ..mesh.operators import SPHERE_AREA, dirichlet_energy, vertex_areas
from ..optimize.result import Algorithm1Result, success_first_repr
from ..sphere.folds import below_margin, map_degree

#: Kinds of the rounds of Algorithm 2; the others start the guaranteed path
#: (:mod:`igl_spheremap.folding.guaranteed`).
ALGORITHM_2_ROUNDS = ("gauss", "star", "local")

#: A map whose round froze more than this share of the vertices under the fold barrier
#: is held by it near its start: not known to be a minimizer, so no success.
FROZEN_SHARE = 0.5


@dataclass
class Round:
    """One stage of Algorithm 2: an initial map, then Algorithm 1 from it.

    Attributes
    ----------
    index : int
        0 for the Gauss-map stage, ``k >= 1`` for folding-removal round ``k``.
    kind : str
        ``"gauss"`` (initial map = Gauss map), ``"star"`` (initial map = star
        map, paper Section 4), ``"local"`` (local repair of the previous map's
        folds, :func:`igl_spheremap.folding.local_repair.local_repair`: initial map = that
        map untangled, Algorithm 1 only over ``region`` vertices) or
        ``"landmark"`` (:func:`igl_spheremap.landmark_map`: initial map = the
        previous map with the landmarks moved a step toward their targets), or a
        start of the guaranteed path (:mod:`igl_spheremap.folding.guaranteed`,
        its feasible descent of the conformal distortion, nothing frozen):
        ``"central"`` (the central projection from the mesh's kernel, also a
        float32 repair), ``"tutte"`` (the punctured Tutte embedding lifted to
        the sphere) or ``"polish"`` (from the rounds' map, or from the initial map of
        its round where the barrier held it).
    U_init : (n, 3) float64 array
        Initial map of this round, unit rows, indexed like the input ``V``.
    run : Algorithm1Result
        Algorithm 1 from ``U_init``; ``run.U`` is indexed like the input ``V``.
    folds_before : int
        Folded faces of ``U_init``.
    seconds : float
        Wall time of this round (eigen-projection or untangling included).
    Phi : (n, 3) float64 array or None
        Star rounds only: weighted Laplace-Beltrami eigenfunctions ``Phi^u`` (Eq. 27).
    eigenvalues : (3,) float64 array or None
        Star rounds only (mesh scaled to area ``4 pi``; 2 on a round sphere).
    reflected : bool
        Star rounds only: whether the eigenbasis was a reflection and was flipped.
    folds_star : int or None
        Star rounds only: folded faces of the star map itself, before the local
        untangling that produced ``U_init``.
    region : int or None
        Local rounds only: vertices free to move in the local Algorithm 1.
    folds_previous : int or None
        Folded faces of the map this round started from (the previous round's
        result); None for the Gauss-map stage.
    fold_barrier : bool
        Whether Algorithm 1 ran under the fold barrier in this round.
    patched : bool
        Star and local rounds: whether the initial map kept untangled patches
        (:func:`igl_spheremap.folding.untangle.untangle_patches`), regions shaped toward
        equilateral triangles rather than conformally.

    ``U``, ``folds_after``, ``nit``, ``converged``, ``message``, ``energy_history``,
    ``grad_norm_history``, ``frozen`` and ``energy`` are those of ``run``.
    """

    index: int
    kind: str
    U_init: np.ndarray = field(repr=False)
    run: Algorithm1Result
    folds_before: int
    seconds: float = 0.0
    Phi: np.ndarray = field(default=None, repr=False)
    eigenvalues: np.ndarray = None
    reflected: bool = False
    folds_star: int = None
    region: int = None
    folds_previous: int = None
    fold_barrier: bool = False
    patched: bool = False

    U = property(lambda self: self.run.U)
    folds_after = property(lambda self: self.run.folds)
    nit = property(lambda self: self.run.nit)
    converged = property(lambda self: self.run.converged)
    message = property(lambda self: self.run.message)
    energy_history = property(lambda self: self.run.energy_history)
    grad_norm_history = property(lambda self: self.run.grad_norm_history)
    frozen = property(lambda self: self.run.frozen)
    energy = property(lambda self: self.run.energy)


@dataclass
class SphericalMapResult:
    """Outcome of :func:`igl_spheremap.spherical_conformal_map`.

    Attributes
    ----------
    U : (n, 3) float64 array
        The spherical map, unit rows, indexed like the input ``V``.
    F : (m, 3) int64 array
        The faces the map was computed on, in the input's vertex numbering:
        the input faces, consistently oriented outward (orientation repairs
        applied).  ``count_folds(result.F, result.U)`` counts folded faces.
    folds : int
        Folded faces of ``U`` (0 for a folding-free map).
    converged : bool
        Whether the Algorithm 1 run of the returned map met its stopping rule
        (the last round's, the chosen round's after a collapse, the rerun's
        after a float32 repair that reran Algorithm 2).
    success : bool
        ``folds == 0 and converged and below_margin == 0`` (and no ``failure``).
    message : str
        Human-readable summary of how the run ended.
    rounds : list of Round
        Every stage that ran, in order (Gauss-map stage first), in the input's
        vertex order (a float32 repair's own rounds are in ``repair``).
    nit : int
        Algorithm 1 iterations over all rounds.
    energy : float
        Harmonic energy of ``U`` (Laplacian used by the run; ``4 pi`` ideally).
    centroid_norm : float
        ``|sum_i A_i U_i| / sum_i A_i`` (input vertex areas) after Möbius normalization.
    min_image_area : float
        Smallest image triangle area (flat, on the unit sphere): how crowded thin
        features are.
    mesh : igl_spheremap.ValidatedMesh
        The validated mesh (its ``notes`` record every repair).
    seconds : float
        Total wall time.
    timings : dict of str -> float
        Seconds per stage: ``validate``, ``laplacian``, ``rounds``, ``finish``.
    options : MapOptions
        The options the run used (resolved).
    landmark_errors : (k,) float64 array or None
        :func:`igl_spheremap.landmark_map` only: the angle between each landmark's
        image and its target, in degrees.
    failure : str or None
        Why the run did not do what was asked although the map is fold-free
        (landmarks that could not be reached, a map the fold barrier held near
        its start); then ``success`` is False.
    chosen : int
        Index in ``rounds`` of the round the map came from (the last one, unless a
        futile round stopped the loop or the guaranteed path kept another).
    degree : float
        Degree of the map (:func:`igl_spheremap.sphere.folds.map_degree`): 1 for
        a fold-free map, 0 for a collapsed one.
    below_margin : int
        Faces whose signed image volume is at or below their rounding margin for
        ``options.precision`` (:func:`igl_spheremap.sphere.folds.below_margin`): with
        ``"float32"`` the faces that storing the map as float32 might fold; with
        ``"float64"`` (margin 0) the folded faces.
    repair : dict or None
        With ``precision="float32"``, when faces were below their margin after the
        rounds: what :func:`igl_spheremap.precision.repair.make_representable` did
        (``method`` that was kept or None, ``tried`` with each attempt's
        ``method``, ``below_margin`` and ``seconds``, ``below_before``); else None.
    notes : list of str
        The validation's changes to the input (``mesh.repairs``: faces flipped,
        unreferenced vertices dropped), then what else the run did that the message
        reports (a collapsed round reverted, the float32 repair).  The message
        mentions flipped faces in short (``"F re-oriented: ... use result.F"``).
    """

    U: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    folds: int
    converged: bool
    message: str
    rounds: list = field(repr=False)
    nit: int
    energy: float
    centroid_norm: float
    min_image_area: float
    mesh: object = field(default=None, repr=False)
    seconds: float = 0.0
    timings: dict = field(default_factory=dict)
    options: object = None
    landmark_errors: np.ndarray = field(default=None, repr=False)
    failure: str = None
    chosen: int = None
    degree: float = 1.0
    below_margin: int = 0
    repair: dict = field(default=None, repr=False)
    notes: list = field(default_factory=list)

    @property
    def success(self):
        return (self.folds == 0 and self.converged and self.below_margin == 0
                and self.failure is None)

    __repr__ = success_first_repr

    @property
    def orientation_flipped(self):
        """The input was oriented inward and all its faces were flipped to map it."""
        return bool(self.mesh is not None and self.mesh.orientation_flipped)

    @property
    def energy_over_4pi(self):
        """``energy / 4 pi`` (1 for a conformal bijection)."""
        return self.energy / SPHERE_AREA


def with_reorientation(message, mesh):
    """``message`` ending with the mesh's :attr:`~igl_spheremap.ValidatedMesh.reorientation`
    and ``", use result.F"`` where faces were flipped, unless it says so already (a message
    quoting another result's).

    Parameters
    ----------
    message : str
    mesh : igl_spheremap.ValidatedMesh

    Returns
    -------
    str
    """
    note = mesh.reorientation
    if note is None or note in message:
        return message
    return f"{message}; {note}, use result.F"


def build_result(problem, rounds, U, folds, message=None, *, chosen=None, converged=None,
                 notes=()):
    """The :class:`SphericalMapResult` of the map ``U`` (validated order) after ``rounds``.

    ``message`` replaces the default summary (folds, convergence of ``chosen``,
    the round whose map ``U`` is: default the last), and ``notes`` are appended
    to it, then the faces flipped (:func:`with_reorientation`).  The result's
    ``notes`` are the mesh's ``repairs`` and ``notes``.  ``converged`` defaults to
    ``chosen.converged``.
    """
    mesh, opts = problem.mesh, problem.options
    chosen = rounds[-1] if chosen is None else chosen
    converged = chosen.converged if converged is None else converged
    ran = sum(r.kind in ALGORITHM_2_ROUNDS for r in rounds) - 1
    if message is not None:
        msg = message
    elif folds:
        msg = (f"{plural(folds, 'folded face remains', 'folded faces remain')} after "
               f"{plural(ran, 'folding-removal round')}")
    elif not converged:
        msg = f"fold-free, but Algorithm 1 did not converge: {chosen.message}"
    elif chosen.kind in ALGORITHM_2_ROUNDS:
        msg = f"fold-free after {plural(ran, 'folding-removal round')}; {chosen.message}"
    else:
        msg = f"fold-free from the {chosen.kind} start; {chosen.message}"
    frozen, n = int(chosen.frozen or 0), mesh.V.shape[0]
    energy = dirichlet_energy(problem.L, U)
    held = None
    if frozen > FROZEN_SHARE * n:
        held = (f"the fold barrier held {frozen} of {n} vertices (E/4pi = "
                f"{energy / (4 * np.pi):.2f}): fold-free, but far from conformal there, and not "
                "known to be the best map there is")
        notes = [*notes, held]
    below = int(below_margin(mesh.F, U, opts.precision).sum())
    if below and not folds and opts.precision != "float64":
        notes = [*notes, f"{plural(below, 'face')} below their {opts.precision} rounding margin "
                         "(storing the map as float32 may fold them)"]
    msg = with_reorientation("; ".join([msg, *notes]), mesh)
    w = vertex_areas(mesh.V, mesh.F)
    return SphericalMapResult(
        U=mesh.to_input(U), F=mesh.F_input, folds=folds, converged=converged, message=msg,
        rounds=rounds, nit=sum(r.nit for r in rounds), energy=energy,
        centroid_norm=float(np.linalg.norm((w @ U) / w.sum())),
        min_image_area=float(igl.doublearea(U, mesh.F).min() / 2), mesh=mesh,
        options=opts, below_margin=below, notes=[*mesh.repairs, *notes], failure=held,
        chosen=next(i for i, r in enumerate(rounds) if r is chosen),
        degree=map_degree(mesh.F, U))
