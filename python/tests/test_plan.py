"""`plan`: the counts it picks, the same as the command line's, checked by Monte Carlo."""

import json
import math

import numpy as np
import pytest

import specvar


def soft_shadow(m=64):
    """A penumbra across a line at 30° over a gradient whose opposite faces differ (a seam)."""
    y, x = (np.mgrid[0:m, 0:m] + 0.5) / m
    t = np.clip((x * math.cos(math.pi / 6) + y * math.sin(math.pi / 6) - 0.6) / 0.15 + 0.5, 0, 1)
    return 0.1 + 0.6 * t * t * (3 - 2 * t) + 0.3 * x


def test_each_planned_count_reaches_the_target_by_monte_carlo():
    values = soft_shadow()
    integral = float(values.mean())
    plans = specvar.plan((values, "exact"), rmse=0.01, relative=True)
    assert [p.sampler for p in plans] == ["random", "jitter", "cmj", "sobol"]
    for p in plans:
        assert p.target == pytest.approx(0.01 * integral)
        assert p.rmse <= p.target and p.rmse_interval[0] <= p.rmse <= p.rmse_interval[1]
        assert p.below is not None and p.below["n"] < p.n and p.below["rmse"] > p.target
        mc = specvar.monte_carlo(values, sampler=p.sampler, n=p.n, trials=800, seed=3)
        # The 99% intervals of the measurement and of the prediction meet.
        assert math.sqrt(mc.ci_low) <= p.rmse_interval[1], p
        assert math.sqrt(mc.ci_high) >= p.rmse_interval[0], p


def test_sobol_is_planned_on_powers_of_two():
    (p,) = specvar.plan("edge:theta=30", rmse=2e-3, samplers=["sobol"])
    assert p.n & (p.n - 1) == 0 and p.counts == "power_of_two"
    assert p.below["n"] == p.n // 2


def test_the_same_plan_as_the_command_line(cli):
    ours = specvar.plan("edge:theta=30", rmse=0.02, relative=True, samplers=["jitter", "sobol"])
    done = cli("plan", "-f", "edge:theta=30", "--rmse", "0.02", "--relative",
               "--samplers", "jitter,sobol", "--json")
    theirs = json.loads(done.stdout)
    assert theirs["refused"] == []
    assert [(p.sampler, p.n, p.rmse) for p in ours] == [
        (t["sampler"], t["n"], t["rmse"]) for t in theirs["rows"]
    ]


def test_a_sampler_without_a_route_is_a_warning_beside_the_others():
    with pytest.warns(UserWarning, match="gjitter is not planned: .*--randomization shift"):
        (p,) = specvar.plan("disk", rmse=1e-3, samplers=["gjitter", "jitter"])
    assert p.sampler == "jitter" and p.reached
    with pytest.raises(ValueError, match="gjitter used as drawn is biased"):
        specvar.plan("disk", rmse=1e-3, samplers=["gjitter"])


@pytest.mark.parametrize("bad", [0.0, -0.01, float("nan"), float("inf")])
def test_bad_targets_raise(bad):
    with pytest.raises(ValueError, match="target"):
        specvar.plan("disk", rmse=bad)


def test_an_unreachable_target_names_the_largest_n():
    with pytest.raises(ValueError, match="largest N it allows is 4096"):
        specvar.plan("edge:theta=30", rmse=1e-4, samplers=["random"], max_n=4096)


def test_an_image_of_pixels_is_predicted_pixel_by_pixel():
    stack = np.stack([np.stack([soft_shadow(32) * (1 + 0.1 * c + 0.2 * r) for c in range(3)]) for r in range(2)])
    image = specvar.predict_image(stack, "jitter", 64, tabulation="exact")
    assert image.variance.shape == (2, 3) and image.randomization == "none"
    alone = specvar.predict((stack[1, 2], "exact"), sampler="jitter", n=64)
    assert image.variance[1, 2] == alone.variance
    assert image.mse == pytest.approx(image.variance.mean(), rel=1e-14)
    flat = specvar.predict_image(stack.reshape(6, 32, 32), "jitter", 64, tabulation="exact")
    assert flat.variance.shape == (1, 6)
    with pytest.raises(ValueError, match="shape"):
        specvar.predict_image(stack[0, 0], "jitter", 64)


def test_a_function_is_tabulated_adaptively_then_planned():
    def visibility(points):
        x, y = points[:, 0], points[:, 1]
        return 0.8 * (np.hypot(x - 0.35, y - 0.4) >= 0.2)

    ours = specvar.plan(visibility, rmse=0.01, relative=True, samplers=["jitter"])
    tabulated = specvar.plan(
        (specvar.tabulate(visibility, 256), "samples"), rmse=0.01, relative=True, samplers=["jitter"]
    )
    assert [(p.n, p.rmse) for p in ours] == [(p.n, p.rmse) for p in tabulated]


def test_an_image_is_planned_for_its_rmse():
    stack = np.stack([soft_shadow(32) * (1 + 0.2 * c) for c in range(4)])
    (p,) = specvar.plan((stack, "exact"), rmse=0.01, relative=True, samplers=["jitter"])
    image = specvar.predict_image(stack, "jitter", p.n, tabulation="exact")
    assert math.sqrt(image.mse) == pytest.approx(p.rmse, rel=1e-12)
    assert p.rmse <= p.target == pytest.approx(0.01 * stack.mean())
