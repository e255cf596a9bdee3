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


def test_a_single_unplaced_landmark_is_attempted_once_per_stage(sphere, monkeypatch):
    """Three landmarks placed, the fourth blocked: the all-at-once deformation, then its stage
    (the same four landmarks), and no third identical attempt; the fourth stays unplaced."""
    F, U = sphere
    lm = np.array([0, 5, 9, 17])
    calls = _recorder(monkeypatch, {17})
    placed = np.array([True, True, True, False])
    _, out = landmark_bend.place(F, U, lm, U[lm], np.arange(4), placed)
    assert out.tolist() == [True, True, True, False]
    assert calls == [(0, 5, 9, 17), (0, 5, 9, 17)]


def test_a_stage_that_fails_is_retried_one_landmark_at_a_time(sphere, monkeypatch):
    """Two unplaced landmarks, one blocked: their stage fails, each is tried alone with the
    placed ones, and the one that can be placed is kept."""
    F, U = sphere
    lm = np.array([0, 5, 9, 17])
    calls = _recorder(monkeypatch, {17})
    placed = np.array([True, True, False, False])
    _, out = landmark_bend.place(F, U, lm, U[lm], np.arange(4), placed)
    assert out.tolist() == [True, True, True, False]
    assert calls[1:] == [(0, 5, 9, 17), (0, 5, 9), (0, 5, 9, 17)]
