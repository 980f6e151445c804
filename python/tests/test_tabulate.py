"""Adaptive tabulation: the same cells as the full grid where the integrand is piecewise
constant on features larger than the first level's cells, for a fraction of the evaluations."""

import math

import numpy as np
import pytest

import specvar


def visibility(points):
    """A pixel's light-sample visibility: an occluding disk and a wall's edge, times radiance."""
    x, y = points[:, 0], points[:, 1]
    open_sky = np.hypot(x - 0.35, y - 0.4) >= 0.2
    before_wall = x * math.cos(math.pi / 6) + y * math.sin(math.pi / 6) < 0.9
    return 0.8 * (open_sky & before_wall)


def test_a_piecewise_constant_pixel_costs_a_fraction_of_the_grid():
    full = specvar.tabulate(visibility, 256)
    t = specvar.tabulate_adaptive(visibility, 256)
    assert t.values.shape == (256, 256)
    assert np.array_equal(t.values, full)
    assert t.evaluations < 0.1 * 256 * 256
    assert t.flat_share > 0.9 and t.l2_error == 0.0
    assert specvar.predict(t.values, sampler="cmj", n=256).variance == \
        specvar.predict(full, sampler="cmj", n=256).variance


def test_a_smooth_gradient_is_refined_everywhere():
    t = specvar.tabulate_adaptive(lambda p: p[:, 0], 64, start=8)
    assert np.allclose(t.values, specvar.tabulate(lambda p: p[:, 0], 64))
    assert t.flat_share == 0.0


def test_a_budget_of_evaluations_stops_the_refinement_and_says_what_it_costs():
    t = specvar.tabulate_adaptive(lambda p: p[:, 0], 64, start=8, max_evaluations=100)
    assert t.evaluations == 64
    # The first level's values, kept: each final cell is off by at most half a coarse cell's
    # slope, and the estimate (a neighbour's difference, 1/8) is no smaller than the truth.
    gap = np.sqrt(np.mean((t.values - specvar.tabulate(lambda p: p[:, 0], 64)) ** 2))
    assert 0 < gap <= t.l2_error and t.flat_share == 1.0


@pytest.mark.parametrize("args", [dict(resolution=100, start=16), dict(start=0), dict(tolerance=0.0)])
def test_sizes_that_do_not_nest_are_refused(args):
    with pytest.raises(ValueError):
        specvar.tabulate_adaptive(visibility, **args)
