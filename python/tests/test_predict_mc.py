"""Predictions beside Monte Carlo, on built-in integrands and on Python functions."""

import numpy as np
import pytest

import specvar


def disk_indicator(points):
    """The disk of radius 1/4 at the centre, written by hand."""
    return (((points - 0.5) ** 2).sum(axis=1) < 0.25 * 0.25).astype(float)


def test_prediction_carries_its_route_and_budget():
    p = specvar.predict("disk", sampler="jitter", n=256, randomization="shift")
    assert p.route.form == "lattice" and "closed" in str(p.route)
    assert p.budget.spectrum_noise == 0.0 and p.budget.truncation < 1e-3 * p.variance
    assert p.reason and p.n == 256 and p.dimension == 2
    assert p.alternatives and abs(p.alternatives[0].variance / p.variance - 1) < 1e-3


@pytest.mark.parametrize("sampler,integrand", [("jitter", "disk"), ("random", "gaussian"), ("sobol", "disk:r=0.2")])
def test_prediction_falls_inside_monte_carlo(sampler, integrand):
    p = specvar.predict(integrand, sampler=sampler, n=64)
    m = specvar.monte_carlo(integrand, sampler=sampler, n=64, trials=6000, seed=3)
    low, high = p.interval(3.0)
    assert low <= m.ci_high and m.ci_low <= high, (p, m)


def test_a_python_integrand_runs_the_same_experiment_as_the_built_in_one():
    facts = specvar.integrand("disk")
    ours = specvar.monte_carlo(disk_indicator, sampler="jitter", n=64, trials=3000, seed=5, integral=facts.integral)
    built_in = specvar.monte_carlo("disk", sampler="jitter", n=64, trials=3000, seed=5)
    # Same patterns, same shifts, same sums: the same bits.
    assert ours == built_in


def test_a_python_integrand_without_its_integral_gives_the_sample_variance():
    def f(x):
        return np.sin(2 * np.pi * x[:, 0]) ** 2 * x[:, 1]

    m = specvar.monte_carlo(f, sampler="random", n=32, trials=4000, seed=1)
    assert m.bias is None
    # Exact: Var f = E f² − (E f)² with E f = 1/4, E f² = (3/8)(1/3) = 1/8.
    exact = (1 / 8 - 1 / 16) / 32
    assert m.ci_low < exact < m.ci_high


def test_a_python_integrand_sees_each_pattern_as_an_array():
    seen = []

    def f(x):
        seen.append(x.shape)
        return np.ones(len(x))

    specvar.monte_carlo(f, sampler="jitter", n=16, trials=100, integral=1.0, randomization="none")
    assert seen == [(16, 2)] * 100


def test_python_integrand_errors_reach_the_caller():
    with pytest.raises(ValueError, match="one per point"):
        specvar.monte_carlo(lambda x: np.ones(3), sampler="random", n=16, trials=50)
    with pytest.raises(ValueError, match="finite"):
        specvar.monte_carlo(lambda x: np.full(len(x), np.nan), sampler="random", n=16, trials=50)

    def broken(x):
        raise ZeroDivisionError("inside the integrand")

    with pytest.raises(ZeroDivisionError, match="inside the integrand"):
        specvar.monte_carlo(broken, sampler="random", n=16, trials=50)


def test_external_point_sets_are_analysed_and_predicted():
    qmc = pytest.importorskip("scipy.stats.qmc")
    sets = np.array([qmc.Sobol(d=2, scramble=True, seed=s).random(256) for s in range(64)])
    p = specvar.predict("gaussian", points=sets, randomization="shift")
    # Under the shift each set's variance is its pair sum, exact: 64 × 256² pairs.
    assert p.route.spectrum["pairs"]["sets"] == 64 and p.budget.spectrum_noise == 0.0
    m = specvar.monte_carlo("gaussian", points=sets, trials=64 * 50, seed=2, randomization="shift")
    assert m.patterns == 64 and m.shifts == 50
    assert p.interval(3.0)[0] <= m.ci_high and m.ci_low <= p.interval(3.0)[1], (p, m)


def test_built_in_integrands_evaluate_like_the_library():
    f = specvar.integrand("disk")
    points = np.array([[0.5, 0.5], [0.1, 0.1], [0.5, 0.74]])
    assert list(f(points)) == [1.0, 0.0, 1.0]
    assert abs(f.integral - np.pi / 16) < 1e-15


def test_bad_problems_are_value_errors():
    with pytest.raises(ValueError, match="invalid integrand|integrand"):
        specvar.predict("donut", sampler="jitter", n=64)
    with pytest.raises(ValueError):
        specvar.predict("disk", sampler="jitter", n=64, form="square")
    with pytest.raises(ValueError, match="n is required"):
        specvar.predict("disk", sampler="jitter")
    with pytest.raises(ValueError):
        specvar.monte_carlo("disk", sampler="jitter", n=64, trials=5)
    with pytest.raises(ValueError, match="integral"):
        specvar.monte_carlo("disk", sampler="jitter", n=64, integral=0.2)


def test_a_tabulated_function_of_ones_own_is_predicted_and_checked():
    def bump(x):
        return np.exp(-((x[:, 0] - 0.4) ** 2 + (x[:, 1] - 0.6) ** 2) / 0.02) * (x[:, 0] < 0.55)

    # 256 cells per axis: smooth at its cells' scale, the bump needs 4 N cells per axis under
    # Sobol' points, whose projections are stratified into N intervals.
    values = specvar.tabulate(bump, resolution=256)
    assert values.shape == (256, 256)
    f = specvar.integrand(values)
    # The piecewise-constant function's integral is the mean of its cells.
    assert abs(f.integral - values.mean()) < 1e-15
    for sampler in ("jitter", "sobol"):
        # The values at the cells' centres tabulate the bump: predicted for the bump itself (the
        # grid's cell form extrapolated over its coarser levels), measured on the bump.
        p = specvar.predict((values, "samples"), sampler=sampler, n=64)
        m = specvar.monte_carlo(bump, sampler=sampler, n=64, trials=6000, seed=8)
        assert p.budget.tabulation > 0
        assert p.route.form == "cells" and p.randomization == m.randomization == "none"
        assert p.interval(3.0)[0] <= m.ci_high and m.ci_low <= p.interval(3.0)[1], (sampler, p, m)


def test_tabulated_values_must_be_a_finite_2d_array():
    with pytest.raises(ValueError, match="2D"):
        specvar.predict(np.ones(5), sampler="jitter", n=16)
    with pytest.raises(ValueError, match="finite"):
        specvar.predict(np.full((4, 4), np.inf), sampler="jitter", n=16)


def test_tabulation_sizes_are_checked_before_any_evaluation():
    calls = []

    def f(x):
        calls.append(len(x))
        return np.ones(len(x))

    for bad in (0, -1, 2.5, True):
        with pytest.raises(ValueError, match="invalid resolution"):
            specvar.tabulate(f, bad)
    try:
        specvar.set_budget(memory_gib=0.01)
        with pytest.raises(ValueError, match=r"resolution 1000000 would need .* \(set_budget\)"):
            specvar.tabulate(f, 10**6)
    finally:
        specvar.set_budget(memory_gib=8.0)
    assert calls == []


def test_a_huge_n_is_answered_or_refused_naming_set_budget():
    # Shifted jitter at N = 10^12 on the disk has a closed form, summed in space over the
    # strata's tent.
    p = specvar.predict("disk", sampler="jitter", n=10**12, randomization="shift")
    assert "strata's tent" in p.reason and 0 < p.variance < 1e-18
    with pytest.raises(ValueError, match="set_budget"):
        specvar.predict("disk", sampler="regular", n=10**12)
