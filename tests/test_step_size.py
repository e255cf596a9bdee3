"""igl_spheremap.optimize.step_size: alternating Barzilai-Borwein steps (paper Eq. 12), clip and turn cap."""

import numpy as np
import pytest

from igl_spheremap.optimize.direction import L2Metric
from igl_spheremap.optimize.manifold import cayley_step
from igl_spheremap.optimize.step_size import MAX_TURN, TAU_MIN, BarzilaiBorwein, bb_step, turn_cap


def test_bb_alternates_between_the_two_formulas():
    assert bb_step(1, dkd=6.0, dw=3.0, wkw=2.0, tau=9.0) == 2.0    # odd: <D,D>/|<D,W>|
    assert bb_step(2, dkd=6.0, dw=3.0, wkw=2.0, tau=9.0) == 1.5    # even: |<D,W>|/<W,W>
    assert bb_step(1, dkd=6.0, dw=0.0, wkw=2.0, tau=9.0) == 9.0    # no curvature: keep tau
    assert bb_step(2, dkd=6.0, dw=3.0, wkw=0.0, tau=9.0) == 9.0


class _It:
    def __init__(self, U, G, MG):
        self.U, self.G, self.X, self.MG, self.ev = U, G, G, MG, None


def test_l2_steps_are_the_papers_eq_12(rng):
    """With the L2 metric (X = G): tau_1 = <D, D>_M / |<D, W>_M| and
    tau_2 = |<D, W>_M| / <W, W>_M, D = U_k - U_{k-1}, W = G_k - G_{k-1}."""
    n = 50
    a = rng.uniform(0.5, 2.0, n)
    U0, U1 = rng.normal(size=(2, n, 3))
    G0, G1 = rng.normal(size=(2, n, 3))
    prev = _It(U0, G0, G0 * a[:, None])
    it = _It(U1, G1, G1 * a[:, None])
    D, W = U1 - U0, G1 - G0
    dd = np.sum(a[:, None] * D * D)
    dw = abs(np.sum(a[:, None] * D * W))
    ww = np.sum(a[:, None] * W * W)
    bb = BarzilaiBorwein(L2Metric(), a, tau_max=1e6, cap_turns=False)
    assert bb.initial(1, it, prev) == pytest.approx(dd / dw, rel=1e-12)
    assert bb.initial(2, it, prev) == pytest.approx(dw / ww, rel=1e-12)
    bb.tau = 0.25
    assert bb.initial(7, it, None) == 0.25  # no previous iterate: the last step is kept
    clipped = BarzilaiBorwein(L2Metric(), a, tau_max=1e-3, cap_turns=False)
    assert clipped.initial(1, it, prev) == 1e-3
    # <D, D> / |<D, W>| = 1e-14 / 1e8 = 1e-22 is clipped from below
    tiny = _It(U0 + 1e-14, G0 + 1e8, (G0 + 1e8) * a[:, None])
    assert BarzilaiBorwein(L2Metric(), a, 1e6, False).initial(1, tiny, prev) == TAU_MIN


def test_turn_cap_limits_every_vertex_to_a_quarter_turn(rng):
    U = rng.normal(size=(500, 3))
    U /= np.linalg.norm(U, axis=1, keepdims=True)
    X = rng.normal(size=U.shape)
    X -= np.einsum("ij,ij->i", U, X)[:, None] * U
    tau = turn_cap(1e6, X)
    assert tau * np.linalg.norm(X, axis=1).max() == pytest.approx(MAX_TURN)
    turned = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", U, cayley_step(U, X, tau)),
                                          -1, 1)))
    assert turned.max() == pytest.approx(90.0, abs=1e-9)
    assert turn_cap(1e-3, X) == 1e-3  # a short step is left alone
