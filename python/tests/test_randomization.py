"""The estimator a prediction and a Monte Carlo run are for: how each pattern is randomized."""

import numpy as np
import pytest

import specvar


def test_monte_carlo_names_the_estimator_it_measured():
    for name in ("shift", "digital-shift", "none"):
        m = specvar.monte_carlo("disk", sampler="jitter", n=16, trials=400, randomization=name)
        assert m.randomization == name
    # Native: jitter is used as drawn.
    m = specvar.monte_carlo("disk", sampler="jitter", n=16, trials=400, randomization="native")
    assert m.randomization == "none"
    with pytest.raises(ValueError, match="native, shift, digital-shift or none"):
        specvar.monte_carlo("disk", sampler="jitter", n=16, trials=400, randomization="xor")


def test_a_digital_shift_keeps_a_net_stratified():
    # A digitally shifted (0,2)-net of 64 points has one point in each 1/64 column.
    sets = specvar.sample("sobol", 64, realizations=3, randomization="digital-shift")
    for points in sets:
        assert sorted((points[:, 0] * 64).astype(int).tolist()) == list(range(64))


def test_predictions_are_for_the_estimator_asked_or_refused():
    # Toroidal dart throwing treats every position alike: unshifted is shifted.
    p = specvar.predict("disk", sampler="poisson", n=64, randomization="none", realizations=8)
    assert p.randomization == "none"
    # Jitter's strata are not: the cell form predicts them as drawn, the default.
    p = specvar.predict("disk", sampler="jitter", n=64)
    assert (p.randomization, p.route.form) == ("none", "cells")
    m = specvar.monte_carlo("disk", sampler="jitter", n=64, trials=8000, seed=4)
    assert m.randomization == "none"
    assert m.ci_low <= p.variance <= m.ci_high, (p, m)
    # Gaussian jitter as drawn: independent points, exact by its aliased frequency pairs.
    p = specvar.predict("disk", sampler="gjitter", n=64)
    assert (p.randomization, p.route.form) == ("none", "aliased_pairs")
    m = specvar.monte_carlo("disk", sampler="gjitter", n=64, trials=8000, seed=4)
    assert m.ci_low <= p.variance <= m.ci_high, (p, m)
    # Halton's digit permutations as drawn: exact on a product of one factor per axis, and
    # through a level of digit cells on a disk.
    for integrand in ["gaussian:sigma=0.2,c=0.2;0.7", "disk"]:
        p = specvar.predict(integrand, sampler="halton", n=100, randomization="none")
        m = specvar.monte_carlo(integrand, sampler="halton", n=100, trials=20000, seed=4)
        assert m.ci_low <= p.variance <= m.ci_high, (p, m)
    # A fixed rule used as drawn has a bias, not a variance.
    with pytest.raises(ValueError, match="bias"):
        specvar.predict("disk", sampler="korobov", n=89, randomization="none")


def test_every_sampler_states_its_native_randomization():
    facts = {s.name: s for s in specvar.samplers()}
    assert facts["jitter"].native_randomization == "none"
    assert facts["korobov"].native_randomization == "shift"
    assert facts["orthogonal"].count_rule.startswith("N = p²")
    assert all(s.randomness for s in facts.values())


def test_results_ignore_fields_they_do_not_know():
    raw = {"slope": 1.0, "stderr": 0.1, "ci": (0.8, 1.2), "intercept": 0.0, "points": 5, "new": 1}
    fit = specvar._build(specvar.SlopeFit, raw)
    assert fit.slope == 1.0 and not hasattr(fit, "new")
    assert np.isfinite(fit.stderr)


def test_given_sets_with_declared_cells_are_predicted_as_given():
    # A renderer's jittered strata, read as point sets: as given, with the strata declared,
    # they are jitter's unshifted estimator exactly.
    sets = specvar.sample("jitter", 64, realizations=50, seed=3)
    p = specvar.predict("edge:theta=30,offset=0.4", points=sets, cells="strata")
    q = specvar.predict("edge:theta=30,offset=0.4", sampler="jitter", n=64)
    assert (p.randomization, p.route.form) == ("none", "cells")
    assert p.variance == q.variance
    # Without cells the sets have no route as given; a wrong declaration is refused.
    with pytest.raises(ValueError, match="--cells"):
        specvar.predict("disk", points=sets)
    random_sets = specvar.sample("random", 64, realizations=4, seed=3)
    with pytest.raises(ValueError, match="stratum"):
        specvar.predict("disk", points=random_sets, cells="strata")


def test_a_digitally_shifted_net_is_predicted_by_its_walsh_form():
    # The unscrambled Sobol' net is used under a digital shift (Mitsuba's ldsampler).
    p = specvar.predict("edge:theta=30,offset=0.4", sampler="sobol-ds", n=256, seed=2)
    assert (p.randomization, p.route.form) == ("digital-shift", "walsh")
    m = specvar.monte_carlo("edge:theta=30,offset=0.4", sampler="sobol-ds", n=256, trials=20000, seed=4)
    assert m.randomization == "digital-shift"
    half = 2.576 * p.budget.spectrum_noise + p.budget.quadrature
    assert m.ci_low - half <= p.variance <= m.ci_high + half, (p, m)
    # Its sets, as a renderer would write them, shifted anew: the same estimator.
    sets = specvar.sample("sobol-ds", 256, realizations=2, randomization="digital-shift", seed=1)
    q = specvar.predict("edge:theta=30,offset=0.4", points=sets, randomization="digital-shift", seed=2)
    assert q.route.form == "walsh"
    # Its pattern's Walsh sums |S_κ| are those of the net: only the measured remainder differs.
    assert abs(q.variance - p.variance) <= 5 * (p.budget.spectrum_noise + q.budget.spectrum_noise)
    # Owen's scrambling absorbs a digital shift: the gains, as drawn.
    a = specvar.predict("disk", sampler="sobol", n=256)
    b = specvar.predict("disk", sampler="sobol", n=256, randomization="digital-shift")
    assert a.variance == b.variance and b.randomization == "digital-shift"


def test_a_rate_study_takes_each_sampler_as_it_is_used():
    s = specvar.study(["jitter", "sobol-ds"], ["disk"], [16, 64], trials=400, randomization="native")
    used = {series.sampler: series.predicted[0].randomization for series in s.series}
    assert used == {"jitter": "none", "sobol-ds": "digital-shift"}
    assert {series.measured[0].randomization for series in s.series} == {"none", "digital-shift"}
