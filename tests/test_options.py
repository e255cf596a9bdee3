"""igl_spheremap.options.MapOptions: presets, precedence, conflicts, value checks, BLAS limit."""

import pytest

from igl_spheremap import MapOptions
from igl_spheremap.options import METHODS, map_options


def test_presets_and_defaults():
    default = MapOptions()
    assert default.method == "folding_free"
    for name, value in METHODS["folding_free"].items():
        assert getattr(default, name) == value
    paper = MapOptions(method="paper")
    for name, value in METHODS["paper"].items():
        assert getattr(paper, name) == value
    # values no preset sets: the paper's line-search constants
    assert (paper.rho, paper.delta, paper.xi) == (1e-4, 0.1, 0.85)
    assert paper.max_rounds == default.max_rounds == 6


def test_explicit_options_beat_the_preset_and_survive_updates():
    opts = MapOptions(method="paper", gtol=1e-7)
    assert opts.gtol == 1e-7 and opts.metric == "L2"
    switched = opts.updated(method="folding_free")
    assert switched.gtol == 1e-7            # explicit: kept
    assert switched.metric == "H1"          # from the new preset
    assert map_options({"method": "paper"}, max_iter=7).max_iter == 7
    assert map_options(opts) is opts


def test_a_dependent_preset_option_follows_its_prerequisite():
    """fold_barrier=False alone switches the preset's local repair off (it needs the
    barrier); asking for both explicitly is a conflict."""
    opts = MapOptions(fold_barrier=False)
    assert opts.local_repair is False
    assert MapOptions(untangle=False).local_repair is False
    with pytest.raises(ValueError, match="local_repair=True needs untangle=True and "
                                         "fold_barrier=True"):
        MapOptions(fold_barrier=False, local_repair=True)
    with pytest.raises(ValueError, match="h1_solver='amg' applies to metric='H1' only"):
        MapOptions(metric="L2", h1_solver="amg")
    assert MapOptions(metric="L2").h1_solver == "auto"


def test_polish_needs_the_guaranteed_path_and_says_where_it_was_switched_off():
    assert MapOptions().polish == "auto" and MapOptions(polish="always").polish == "always"
    assert MapOptions(guaranteed_path=False).polish == "never"
    assert MapOptions(method="paper").polish == "never"
    assert MapOptions(polish="never", guaranteed_path=False).polish == "never"
    with pytest.raises(ValueError, match="polish='always' needs guaranteed_path=True .* but "
                                         "guaranteed_path=False was given"):
        MapOptions(polish="always", guaranteed_path=False)
    with pytest.raises(ValueError, match="but guaranteed_path=False comes from method='paper'"):
        MapOptions(polish="auto", method="paper")
    with pytest.raises(ValueError, match="unknown polish True"):
        MapOptions(polish=True)


@pytest.mark.parametrize("name, value, message", [
    ("max_rounds", -1, "max_rounds must be >= 0"),
    ("max_rounds", 1.5, "max_rounds must be an integer"),
    ("max_rounds", True, "max_rounds must be an integer"),
    ("max_iter", "10", "max_iter must be an integer"),
    ("gtol", 0.0, "gtol must be > 0"),
    ("gtol", float("nan"), "gtol must be a finite number"),
    ("gtol", -1e-5, "gtol must be > 0"),
    ("rho", 1.0, r"rho must be in \(0, 1\)"),
    ("xi", 1.5, r"xi must be in \[0, 1\]"),
    ("method", "gu_yau", "unknown method 'gu_yau'"),
    ("metric", "H2", "unknown metric 'H2'"),
    ("mobius", 2, "mobius must be True or False"),
    ("h1_solver", "cholesky", "unknown h1_solver 'cholesky'"),
])
def test_invalid_values_are_value_errors(name, value, message):
    with pytest.raises(ValueError, match=message):
        MapOptions(**{name: value})


def test_unknown_names_are_value_errors():
    with pytest.raises(ValueError, match="unknown option max_round"):
        MapOptions().updated(max_round=3)
    with pytest.raises(TypeError, match="MapOptions or a dict"):
        map_options([("gtol", 1e-6)])


def test_numpy_integers_are_accepted():
    import numpy as np
    assert MapOptions(max_rounds=np.int64(2)).max_rounds == 2


def test_blas_limit_is_local_to_the_call():
    from threadpoolctl import threadpool_info

    def blas_threads():
        return [d["num_threads"] for d in threadpool_info() if d["user_api"] == "blas"]

    before = blas_threads()
    with MapOptions().blas_limit():
        assert blas_threads() and all(t == 1 for t in blas_threads())
    assert blas_threads() == before
    with MapOptions(blas_threads=0).blas_limit():
        assert blas_threads() == before


def test_to_dict_is_complete_and_round_trips():
    opts = MapOptions(method="paper", max_rounds=2)
    d = opts.to_dict()
    assert set(d) == {f for f in d} and "explicit" not in d
    assert MapOptions(**d) == opts
