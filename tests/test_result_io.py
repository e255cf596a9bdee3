"""igl_spheremap.io.result_file: a SphericalMapResult survives save_result / load_result."""

import dataclasses

import numpy as np
import pytest

import igl_spheremap as sm
from igl_spheremap.io.result_file import load_result, save_result


def _assert_same(a, b, where="result"):
    if dataclasses.is_dataclass(b) and not isinstance(b, sm.MapOptions):
        assert type(a) is type(b), where
        for f in dataclasses.fields(b):
            _assert_same(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(b, np.ndarray):
        assert isinstance(a, np.ndarray) and a.dtype == b.dtype, where
        assert np.array_equal(a, b), where
    elif isinstance(b, (list, tuple)):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            _assert_same(x, y, f"{where}[{i}]")
    else:
        assert a == b, where


def test_round_trip_keeps_every_field(mesh, tmp_path):
    """The fish with a star round (two iterations per round leave folds): arrays, lists,
    nested rounds and runs, the validated mesh and the options come back equal."""
    V, F = mesh("fish_lowres.obj")
    with pytest.warns(sm.SphericalMapWarning):
        result = sm.spherical_conformal_map(V, F, max_rounds=1, max_iter=2, gtol=1e-6,
                                            guaranteed_path=False)
    assert len(result.rounds) == 2 and result.rounds[1].Phi is not None
    path = tmp_path / "sub" / "fish_result.npz"
    save_result(path, result)
    again = load_result(path)
    _assert_same(again, result)
    assert again.options.gtol == 1e-6 and again.options.explicit == result.options.explicit
    assert again.rounds[1].U is again.rounds[1].run.U


def test_a_foreign_file_is_refused(tmp_path):
    path = tmp_path / "x.npz"
    np.savez(path, V=np.zeros((3, 3)))
    with pytest.raises(ValueError, match="not a result file"):
        load_result(path)
