"""The coarse-to-fine landmark bend (:func:`igl_spheremap.uses.landmark_bend.place`): which
deformations it attempts and what it keeps, with the deformation replaced by a recorder."""

import numpy as np
import pytest

from igl_spheremap.mesh.shapes import icosphere
from igl_spheremap.uses import landmark_bend


@pytest.fixture
def sphere():
    V, F = icosphere(2)
    return np.asarray(F, dtype=np.int64), V / np.linalg.norm(V, axis=1, keepdims=True)


def _recorder(monkeypatch, blocked):
    """Replace ``deformed``: the identity map, reaching its targets (t = 1) unless the landmark
    set holds a vertex of ``blocked``; every call's landmark set is recorded."""
    calls = []

    def deformed(F, U, lm, Q, max_untangled=None):
        calls.append(tuple(int(v) for v in lm))
        return U.copy(), 0.5 if blocked & set(calls[-1]) else 1.0

    monkeypatch.setattr(landmark_bend, "deformed", deformed)
    return calls


@pytest.mark.parametrize("placed, staged", [
    # three placed, the fourth blocked: its stage is its own attempt, made once
    ([True, True, True, False], [(0, 5, 9, 17)]),
    # two unplaced, one blocked: their stage fails, then each is tried alone with the placed ones
    ([True, True, False, False], [(0, 5, 9, 17), (0, 5, 9), (0, 5, 9, 17)]),
])
def test_the_stages_attempt_each_landmark_set_once_and_keep_what_is_placed(sphere, monkeypatch,
                                                                           placed, staged):
    """After the all-at-once deformation fails, the staged attempts are ``staged`` (no
    deformation repeated from the same map), and every landmark that can be placed is."""
    F, U = sphere
    lm = np.array([0, 5, 9, 17])
    calls = _recorder(monkeypatch, {17})
    _, out = landmark_bend.place(F, U, lm, U[lm], np.arange(4), np.array(placed))
    assert out.tolist() == [True, True, True, False]
    assert calls == [(0, 5, 9, 17)] + staged
