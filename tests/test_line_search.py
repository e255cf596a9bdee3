"""igl_spheremap.optimize.line_search: the Zhang-Hager recursion and the curvilinear search."""

import numpy as np
import pytest

from igl_spheremap.optimize.line_search import ZhangHager, curvilinear_search


def test_reference_value_recursion_by_hand():
    """Line 5 of Algorithm 1 with xi = 0.85, from E = 10, then 8, then 9:
    Q1 = 1.85, C1 = (0.85 * 10 + 8) / 1.85; Q2 = 0.85 * 1.85 + 1 = 2.5725,
    C2 = (0.85 * 1.85 * C1 + 9) / 2.5725 = (14.025 + 9) / 2.5725."""
    zh = ZhangHager(rho=1e-4, delta=0.1, xi=0.85, energy=10.0)
    assert (zh.C, zh.Q) == (10.0, 1.0)
    zh.update(8.0)
    assert zh.Q == pytest.approx(1.85, rel=1e-15)
    assert zh.C == pytest.approx(16.5 / 1.85, rel=1e-15)
    zh.update(9.0)
    assert zh.Q == pytest.approx(2.5725, rel=1e-15)
    assert zh.C == pytest.approx(23.025 / 2.5725, rel=1e-14)
    zh.reset(3.0)
    assert (zh.C, zh.Q) == (3.0, 1.0)


def test_acceptance_is_sufficient_decrease_from_the_reference_value():
    zh = ZhangHager(rho=1e-4, delta=0.1, xi=0.85, energy=10.0)
    # C - rho tau <G, X> = 10 - 1e-4 * 0.5 * 2 = 9.9999
    assert zh.accepts(9.9999, tau=0.5, slope=2.0)
    assert not zh.accepts(9.99991, tau=0.5, slope=2.0)


def test_xi_zero_is_the_monotone_armijo_search_and_C_bounds_the_energies(rng):
    zh = ZhangHager(rho=1e-4, delta=0.1, xi=0.0, energy=5.0)
    zh.update(4.0)
    assert zh.C == 4.0
    # Zhang-Hager Lemma 1.1: with descending energies, E_k <= C_k <= mean(E_0..E_k).
    energies = np.sort(rng.uniform(0, 10, 30))[::-1]
    zh = ZhangHager(rho=1e-4, delta=0.1, xi=0.85, energy=energies[0])
    for k, e in enumerate(energies[1:], start=1):
        zh.update(e)
        assert e <= zh.C <= energies[:k + 1].mean() + 1e-12


class _Space:
    @staticmethod
    def retract(U, X, tau):
        return U - tau * X


class _Energy:
    """E(Y) = |Y|^2 in one dimension."""

    def evaluate(self, Y):
        from igl_spheremap.optimize.energy import Evaluation
        return Evaluation(U=Y, value=float(np.sum(Y ** 2)))


class _It:
    def __init__(self, U, X, gx):
        self.U, self.X, self.gx = U, X, gx


class _Constraints:
    """Rejects the first ``n`` trials (as the fold barrier would); with ``cap``, a feasible
    barrier whose maximal step is ``cap``."""

    def __init__(self, n, cap=None):
        self.n, self.seen, self.cap = n, [], cap
        self.feasible = cap is not None

    def max_step(self, U, X, tau):
        return min(tau, self.cap)

    def check(self, Y):
        self.seen.append(float(Y[0]))
        if len(self.seen) <= self.n:
            return None, np.array([True])
        return "folded-now", None


def test_backtracking_shortens_by_delta_until_sufficient_decrease():
    """E = x^2 from x = 1 along -X with X = 2 (the gradient): tau = 10 overshoots to
    -19, tau = 1 to -1 (no decrease), tau = 0.1 to 0.8 (accepted)."""
    zh = ZhangHager(rho=1e-4, delta=0.1, xi=0.85, energy=1.0)
    it = _It(np.array([1.0]), np.array([2.0]), gx=4.0)
    _, step, tau = curvilinear_search(it, 10.0, zh, _Space, _Energy(), _Constraints(0),
                                      None, max_backtracks=10, max_fold_shrinks=2)
    assert tau == pytest.approx(0.1)
    ev, now_folded = step
    assert ev.U[0] == pytest.approx(0.8) and now_folded == "folded-now"
    _, step, tau = curvilinear_search(it, 10.0, zh, _Space, _Energy(), _Constraints(0),
                                      None, max_backtracks=2, max_fold_shrinks=2)
    assert step is None and tau == pytest.approx(0.1)


def test_barrier_vetoes_shorten_twice_then_freeze_without_shortening():
    zh = ZhangHager(rho=1e-4, delta=0.1, xi=0.85, energy=1.0)
    it = _It(np.array([1.0]), np.array([2.0]), gx=4.0)
    constraints = _Constraints(3)
    frozen = []

    def freeze(it, flipped):
        frozen.append(flipped)
        return _It(it.U, it.X * 0.5, it.gx * 0.5)  # a new direction at the same point

    it2, step, tau = curvilinear_search(it, 0.5, zh, _Space, _Energy(), constraints, freeze,
                                        max_backtracks=10, max_fold_shrinks=2)
    # trials: 0.5, 0.05 (shrink), 0.005 (shrink), then a freeze and 0.005 again
    assert len(frozen) == 1
    assert constraints.seen == pytest.approx([0.0, 0.9, 0.99, 0.995])
    assert tau == pytest.approx(0.005) and step is not None
    assert it2.X[0] == 1.0


def test_a_feasible_barrier_caps_the_first_trial_and_only_shortens():
    """A feasible barrier: the first trial is the maximal step (0.3, not 10), a rejected
    trial is shortened by delta (0.03), no vertex is frozen (``freeze`` is never called)."""
    zh = ZhangHager(rho=1e-4, delta=0.1, xi=0.85, energy=1.0)
    it = _It(np.array([1.0]), np.array([2.0]), gx=4.0)
    constraints = _Constraints(1, cap=0.3)

    def freeze(it, flipped):
        raise AssertionError("a feasible barrier never freezes")

    it2, step, tau = curvilinear_search(it, 10.0, zh, _Space, _Energy(), constraints, freeze,
                                        max_backtracks=10, max_fold_shrinks=0)
    assert constraints.seen == pytest.approx([1.0 - 2 * 0.3, 1.0 - 2 * 0.03])
    assert tau == pytest.approx(0.03) and step is not None and it2 is it


def test_an_infinite_energy_is_shortened():
    """A barrier energy (infinite where a face folds) fails the sufficient-decrease test."""
    class _Wall(_Energy):
        def evaluate(self, Y):
            ev = super().evaluate(Y)
            ev.value = np.inf if Y[0] < 0.5 else ev.value
            return ev

    zh = ZhangHager(rho=1e-4, delta=0.1, xi=0.85, energy=1.0)
    it = _It(np.array([1.0]), np.array([2.0]), gx=4.0)
    _, step, tau = curvilinear_search(it, 0.4, zh, _Space, _Wall(), _Constraints(0, cap=1.0),
                                      None, max_backtracks=10, max_fold_shrinks=0)
    assert tau == pytest.approx(0.04) and np.isfinite(step[0].value)
