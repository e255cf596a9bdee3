"""One frozen options object for every layer: the API, the CLI, batch runs and the benchmarks.

Precedence, lowest first:

1. the defaults of :class:`MapOptions` that no method changes (``max_rounds=6``,
   ``h1_solver="auto"``, the line-search constants of Algorithm 1, ...);
2. the preset of ``method`` (:data:`METHODS`: ``"folding_free"``, the default, or
   ``"paper"``, Algorithms 1 and 2 as published);
3. the options given explicitly (keywords, or fields of an options object).

Some options only make sense together.  A local repair (:mod:`igl_spheremap.folding.local_repair`)
untangles folds and re-minimizes under the fold barrier, so ``local_repair`` needs
``untangle`` and ``fold_barrier``; an ``h1_solver`` other than ``"auto"`` needs
``metric="H1"``.  When both sides of such a pair are given explicitly and disagree, a
``ValueError`` says so.  When the dependent option comes from the method's preset and
its prerequisite is switched off explicitly, the dependent option is switched off
too (``fold_barrier=False`` alone turns the preset's ``local_repair`` off); the
resolved values are what :meth:`MapOptions.to_dict` reports.  ``precision="float32"``
needs ``fold_barrier`` whatever its source (the barrier is what keeps the margin).
"""

import contextlib
import math
import numbers
from dataclasses import dataclass, field, fields

#: The presets.  Every deviation of "folding_free" from the paper is listed in README.md.
METHODS = {
    "folding_free": dict(laplacian_kind="intrinsic_delaunay", metric="H1", mobius=True,
                         fold_barrier=True, untangle=True, local_repair=True,
                         round_guard=True, guaranteed_path=True, gtol=1e-5, max_iter=5000),
    "paper": dict(laplacian_kind="cotan", metric="L2", mobius=False, fold_barrier=False,
                  untangle=False, local_repair=False, round_guard=False,
                  guaranteed_path=False, gtol=1e-5, max_iter=20000),
}

#: Values no method changes.
DEFAULTS = dict(method="folding_free", max_rounds=6, h1_solver="auto", rho=1e-4, delta=0.1,
                xi=0.85, tau_max=1e6, mobius_tol=1e-2, max_backtracks=60, max_fold_shrinks=1,
                refactor_every=25, blas_threads=1, precision="float64", polish="auto")

_CHOICES = dict(method=tuple(METHODS), laplacian_kind=("intrinsic_delaunay", "cotan"),
                metric=("H1", "L2"), h1_solver=("auto", "direct", "amg", "cholmod", "superlu"),
                precision=("float64", "float32"), polish=("auto", "always", "never"))
_BOOLS = ("mobius", "fold_barrier", "untangle", "local_repair", "round_guard", "guaranteed_path")
#: name -> smallest value
_INTS = dict(max_rounds=0, max_iter=0, max_backtracks=1, max_fold_shrinks=0, refactor_every=1,
             blas_threads=0)
#: name -> the interval of allowed values, as text and as a test
_FLOATS = dict(gtol=("> 0", lambda x: x > 0), rho=("in (0, 1)", lambda x: 0 < x < 1),
               delta=("in (0, 1)", lambda x: 0 < x < 1), xi=("in [0, 1]", lambda x: 0 <= x <= 1),
               tau_max=("> 0", lambda x: x > 0), mobius_tol=("> 0", lambda x: x > 0))
#: dependent option -> (the options it needs, with the value they need; why)
_REQUIRES = dict(
    local_repair=(dict(untangle=True, fold_barrier=True),
                  "a local repair untangles the folds and then re-minimizes under the fold barrier"),
    guaranteed_path=(dict(fold_barrier=True),
                     "the guaranteed path descends under the fold barrier from fold-free starts"),
    polish=(dict(guaranteed_path=True),
            "the polish is the guaranteed path's conformal descent, run from the accepted map"))

#: Value of a dependent option that is off (a bool's False, a choice's "never").
_OFF = dict(polish="never")


@dataclass(frozen=True)
class MapOptions:
    """Options of :func:`igl_spheremap.spherical_conformal_map` and of Algorithm 1.

    Build one with keywords (``MapOptions(method="paper", gtol=1e-6)``); fields
    left at None take the value of ``method``'s preset or the default (see the
    module docstring for the precedence).  Use :meth:`updated` to change fields:
    it keeps the explicitly given ones and re-resolves the rest.

    Attributes
    ----------
    method : {"folding_free", "paper"}
        The preset (:data:`METHODS`).
    max_rounds : int
        Cap on folding-removal rounds after the Gauss-map stage (>= 0).
    laplacian_kind : {"intrinsic_delaunay", "cotan"}
        :func:`igl_spheremap.mesh.operators.laplacian`; the paper uses ``"cotan"`` (Eq. 13).
    untangle : bool
        Local untangling of the folds a star map keeps (:func:`igl_spheremap.untangle_folds`).
    local_repair : bool
        Repair isolated folds left by the Gauss-map stage locally instead of a
        star-map round (needs ``untangle`` and ``fold_barrier``).
    gtol : float
        Algorithm 1 stops when the RMS Riemannian gradient of the mesh scaled to
        area ``4 pi`` is at most ``gtol`` (> 0, dimensionless).
    max_iter : int
        Iteration cap of each Algorithm 1 run (>= 0).
    metric : {"H1", "L2"}
        Metric of the search direction (:mod:`igl_spheremap.optimize.direction`);
        the paper's is ``"L2"``.
    h1_solver : {"auto", "direct", "amg", "cholmod", "superlu"}
        How the H1 metric is inverted (:func:`igl_spheremap.optimize.preconditioner.h1_preconditioner`).
    mobius : bool
        Möbius normalization (:class:`igl_spheremap.optimize.gauge.MobiusGauge`), applied
        when the energy is Möbius invariant.
    fold_barrier : bool
        The fold barrier (:class:`igl_spheremap.optimize.barrier.FreeVertices`) in
        the rounds that start from a fold-free map; it keeps the rounding margin
        of ``precision``.
    round_guard : bool
        Stop Algorithm 2's rounds at a futile one (:func:`igl_spheremap.folding.rounds.futile`:
        a map collapsed to degree 0, or a round that did not lower the fold
        count) and return the best round.
    guaranteed_path : bool
        When nothing supports the rounds' map (folds, degree, faces below the
        margin, no convergence, a barrier that held most vertices), try maps
        fold-free by construction (:mod:`igl_spheremap.folding.guaranteed`);
        needs ``fold_barrier``.
    polish : {"auto", "always", "never"}
        When the guaranteed path's conformal descent also runs from a map the verdict
        accepts, kept where it converges with less mean angle distortion
        (:func:`igl_spheremap.folding.guaranteed.guaranteed_map`): ``"auto"`` (default) when
        the fold barrier froze more than a tenth of the vertices, more than a tenth of the
        area is on faces distorted over twice a conformal map's, or the round started from
        untangled patches (``Round.patched``), ``"always"`` for the most
        conformal fold-free map we reach (several times the seconds), ``"never"`` for the
        speed of the rounds alone.  Anything but ``"never"`` needs ``guaranteed_path``.
    rho, delta, xi : float
        Zhang-Hager search constants (paper: 1e-4, 0.1, 0.85), in (0, 1), (0, 1), [0, 1].
        The guaranteed path's conformal descent always searches with ``xi = 0`` (monotone;
        :data:`igl_spheremap.folding.guaranteed.DESCENT_XI`).
    tau_max : float
        Upper clip of the Barzilai-Borwein step (> 0).
    mobius_tol : float
        Re-centering threshold of the centroid norm (> 0).
    max_backtracks : int
        Line-search trials per iteration (>= 1).
    max_fold_shrinks : int
        Step shortenings by the fold barrier before it freezes vertices (>= 0;
        default 1, chosen in ``docs/decisions.md``).  Each shortening shrinks the
        whole step, so a few crowded faces that block every step slow every
        vertex; freezing them sooner lets the rest move.
    refactor_every : int
        Smallest number of iterations between two set-ups of the H1 solver on a
        new free set (>= 1).
    blas_threads : int
        Threads of the BLAS libraries during a call (default 1: the BLAS calls are
        small and threads only add synchronization); 0 leaves them alone.
    precision : {"float64", "float32"}
        Storage precision the map must stay fold-free in (default ``"float64"``).
        ``"float32"`` (GIfTI, FreeSurfer): every face keeps its signed image volume
        above its float32 rounding margin (:func:`igl_spheremap.sphere.folds.rounding_margin`),
        so the map stays fold-free when ``R * U`` is stored as float32 at any radius
        ``R``; the fold barrier keeps the margin, and faces still below it after the
        rounds are repaired (:func:`igl_spheremap.precision.repair.make_representable`),
        at some cost in angle distortion on thin features.  Needs ``fold_barrier``.
    """

    method: str = None
    max_rounds: int = None
    laplacian_kind: str = None
    untangle: bool = None
    local_repair: bool = None
    gtol: float = None
    max_iter: int = None
    metric: str = None
    h1_solver: str = None
    mobius: bool = None
    fold_barrier: bool = None
    round_guard: bool = None
    guaranteed_path: bool = None
    polish: str = None
    rho: float = None
    delta: float = None
    xi: float = None
    tau_max: float = None
    mobius_tol: float = None
    max_backtracks: int = None
    max_fold_shrinks: int = None
    refactor_every: int = None
    blas_threads: int = None
    precision: str = None
    explicit: frozenset = field(default=frozenset(), repr=False, compare=False)

    def __post_init__(self):
        given = {f.name: getattr(self, f.name) for f in fields(self)
                 if f.name != "explicit" and getattr(self, f.name) is not None}
        explicit = frozenset(set(given) | set(self.explicit))
        method = given.get("method", DEFAULTS["method"])
        _check_choice("method", method)
        values = {**DEFAULTS, **METHODS[method], **given}
        _resolve_dependencies(values, explicit)
        for name, value in values.items():
            object.__setattr__(self, name, _checked(name, value))
        object.__setattr__(self, "explicit", explicit)

    def updated(self, **changes):
        """A new :class:`MapOptions` with ``changes`` applied (None values are ignored).

        Options given explicitly before stay explicit; the others are resolved
        again (so a new ``method`` brings its preset).

        Raises
        ------
        ValueError
            Unknown option names, or values as in the constructor.
        """
        unknown = sorted(set(changes) - {f.name for f in fields(self)} - {"explicit"})
        if unknown:
            raise ValueError(f"unknown option{'s' if len(unknown) > 1 else ''} "
                             f"{', '.join(unknown)}; expected some of {option_names()}")
        keep = {name: getattr(self, name) for name in self.explicit}
        keep.update({k: v for k, v in changes.items() if v is not None})
        return MapOptions(**keep)

    def blas_limit(self):
        """Context manager limiting the BLAS libraries to ``blas_threads`` threads for a call.

        Entered once by each public entry point (threadpoolctl; ~1 ms); with
        ``blas_threads=0`` it does nothing.
        """
        if not self.blas_threads:
            return contextlib.nullcontext()
        from threadpoolctl import threadpool_limits

        return threadpool_limits(limits=self.blas_threads, user_api="blas")

    def to_dict(self):
        """All resolved options as a plain dict (JSON-ready)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name != "explicit"}


def option_names():
    """Names of the fields of :class:`MapOptions` (list of str)."""
    return [f.name for f in fields(MapOptions) if f.name != "explicit"]


def map_options(options=None, **changes):
    """A :class:`MapOptions` from an options object and/or keywords (keywords win).

    Parameters
    ----------
    options : MapOptions or dict, optional
    **changes
        Fields of :class:`MapOptions`; None values are ignored.

    Returns
    -------
    MapOptions

    Raises
    ------
    ValueError
        Unknown names, invalid values or conflicting options.
    TypeError
        ``options`` is neither a MapOptions nor a dict.
    """
    if options is None:
        return MapOptions().updated(**changes)
    if isinstance(options, dict):
        return MapOptions().updated(**{**options, **changes})
    if not isinstance(options, MapOptions):
        raise TypeError(f"options must be a MapOptions or a dict, got {type(options).__name__}")
    return options.updated(**changes) if changes else options


def _resolve_dependencies(values, explicit):
    for dependent, (needs, why) in _REQUIRES.items():
        missing = {k: v for k, v in needs.items() if values[k] != v}
        if values[dependent] in (False, _OFF.get(dependent)) or not missing:
            continue
        names = ", ".join(f"{k}={values[k]}" for k in missing)
        source = "was given" if set(missing) & explicit else \
            f"comes from method={values['method']!r}"
        if dependent in explicit:
            raise ValueError(f"{dependent}={values[dependent]!r} needs "
                             f"{' and '.join(f'{k}=True' for k in needs)} ({why}), but {names} "
                             f"{source}")
        values[dependent] = _OFF.get(dependent, False)
    if values["precision"] != "float64" and not values["fold_barrier"]:
        source = "was given" if "fold_barrier" in explicit else \
            f"comes from method={values['method']!r}"
        raise ValueError(f"precision={values['precision']!r} needs fold_barrier=True (the fold "
                         f"barrier keeps every face above its rounding margin), but "
                         f"fold_barrier=False {source}")
    if values["metric"] != "H1" and values["h1_solver"] != "auto" and "h1_solver" in explicit:
        raise ValueError(f"h1_solver={values['h1_solver']!r} applies to metric='H1' only, but "
                         f"metric={values['metric']!r}")


def _check_choice(name, value):
    if value not in _CHOICES[name]:
        raise ValueError(f"unknown {name} {value!r}; expected one of {list(_CHOICES[name])}")


def _checked(name, value):
    """``value`` validated (and normalized to a plain Python type) for option ``name``."""
    if name in _CHOICES:
        _check_choice(name, value)
        return value
    if name in _BOOLS:
        if not isinstance(value, (bool, numbers.Integral)) or value not in (0, 1):
            raise ValueError(f"{name} must be True or False, got {value!r}")
        return bool(value)
    if name in _INTS:
        low = _INTS[name]
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
        if value < low:
            raise ValueError(f"{name} must be >= {low}, got {value}")
        return int(value)
    interval, ok = _FLOATS[name]
    if isinstance(value, bool) or not isinstance(value, numbers.Real) \
            or not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number {interval}, got {value!r}")
    if not ok(value):
        raise ValueError(f"{name} must be {interval}, got {value}")
    return float(value)
