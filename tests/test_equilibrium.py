"""The sinkage solve (terramechanics.equilibrium) against roots known in closed form."""

import numpy as np

from terramechanics import LETE_SAND, Wheel, WheelModel
from terramechanics.equilibrium import REL_TOL, solve_increasing


def power_law(k, p, calls=None):
    """f(x) = k x^p elementwise; ``calls`` collects how many elements each call evaluates."""
    def f(x, at):
        if calls is not None:
            calls.append(x.size)
        return (k if at is None else k[at]) * x ** (p if at is None else p[at])
    return f


def test_roots_of_power_laws_whatever_the_solve_power():
    """k x^p = W has the root (W/k)^(1/p); the solve reaches it to REL_TOL W whether its
    ``power`` matches p or not (Bekker's n + 1/2 is only a guess for a real wheel)."""
    p = np.array([0.8, 1.5, 1.5, 2.5, 4.0, 1.2])
    k = np.array([3e3, 2e5, 2e5, 1e7, 5e9, 400.0])
    w = np.array([50.0, 120.0, 900.0, 300.0, 80.0, 7.0])
    x, residual = solve_increasing(power_law(k, p), np.full(6, 0.125), w,
                                   np.array([1.5, 1.5, 2.0, 1.0, 2.5, 1.7]))
    np.testing.assert_allclose(x, (w / k) ** (1 / p), rtol=1e-5)
    assert np.all(np.abs(residual) <= REL_TOL * w)
    np.testing.assert_allclose(residual, k * x ** p - w, rtol=1e-9, atol=1e-12)


def test_no_root_in_the_bracket_ends_at_the_top():
    """A load the force at ``hi`` cannot carry: the wheel ends sunk to ``hi`` with a
    negative residual f(hi) - W, and it is not evaluated again."""
    calls = []
    k, p = np.array([1e3, 1e3]), np.array([1.5, 1.5])
    x, residual = solve_increasing(power_law(k, p, calls), np.array([0.1, 0.1]),
                                   np.array([1e3, 10.0]), p)
    assert x[0] == 0.1 and residual[0] == np.float64(1e3 * 0.1 ** 1.5 - 1e3)
    assert abs(residual[1]) <= REL_TOL * 10.0
    assert all(n <= 2 for n in calls)


def test_a_solved_element_is_not_evaluated_again():
    """Elements whose force is linear in x^power are solved in one step; once they are
    more than half, the steps evaluate only the rest."""
    calls = []
    n = 10
    p = np.array([1.5] * 8 + [4.0] * 2)  # solve power 1.5: exact for eight of ten
    k = np.array([2e5] * 8 + [1e9] * 2)
    solve_increasing(power_law(k, p, calls), np.full(n, 0.125), np.full(n, 100.0),
                     np.full(n, 1.5))
    assert calls[:2] == [n, n] and max(calls[2:]) == 2, calls


def test_a_rigid_wheel_needs_few_evaluations(monkeypatch):
    """With u = z^(n + 1/2) the model's vertical force is nearly linear: driven rigid
    wheels on Lete sand at five loads and slips are solved in at most eight evaluations of
    the stress integrals (the plain bracket on z took eleven or more)."""
    model = WheelModel(Wheel(0.125, 0.112), LETE_SAND)
    loads, slips = np.meshgrid([80.0, 140.0, 200.0, 260.0, 320.0], [0.1, 0.25, 0.4, 0.55, 0.7])
    calls = []

    def counting(f, *args):
        return solve_increasing(lambda x, at: calls.append(x.size) or f(x, at), *args)

    monkeypatch.setattr("terramechanics.model.solve_increasing", counting)
    out = model.curves(loads.ravel(), slips.ravel())
    assert out["converged"].all()
    assert np.max(np.abs(out["fz_residual_n"]) / out["load_n"]) <= REL_TOL
    assert sum(calls) <= 8 * loads.size
