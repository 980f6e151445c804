"""`plan_pilot`: a plan from a few renders of an image, against the plan from its pixels."""

import math

import numpy as np
import pytest

import specvar

PIXELS = 64
RENDERS = 4
PILOT_N = 16


def image(m=32):
    """Pixels whose light-sample integrand is cut by a shadow edge at changing angles."""
    y, x = (np.mgrid[0:m, 0:m] + 0.5) / m
    pixels = []
    for p in range(PIXELS):
        angle = math.radians(10 + 157 * p / PIXELS)
        offset = 0.3 + 0.5 * ((p * 7) % 11) / 11
        lit = (x * math.cos(angle) + y * math.sin(angle)) > offset
        pixels.append(0.1 + 0.6 * lit + 0.3 * x)
    return np.array(pixels)


def render(pixels, sampler):
    """``RENDERS`` renders at ``PILOT_N`` samples per pixel: each pixel's cells averaged at the
    sampler's points."""
    m = pixels.shape[-1]
    points = specvar.sample(sampler, PILOT_N, realizations=RENDERS * PIXELS, seed=11)
    cells = np.minimum((points * m).astype(int), m - 1)
    values = np.empty((RENDERS, PIXELS))
    for r in range(RENDERS):
        for p in range(PIXELS):
            c = cells[r * PIXELS + p]
            values[r, p] = pixels[p][c[:, 1], c[:, 0]].mean()
    return values


@pytest.mark.parametrize("sampler", ["random", "jitter"])
def test_a_pilot_plans_near_the_plan_from_the_pixels(sampler):
    pixels = image()
    renders = render(pixels, sampler)
    pilot = specvar.plan_pilot(renders, PILOT_N, sampler, rmse=0.01, relative=True, model="single")
    (tabulated,) = specvar.plan((pixels, "exact"), rmse=0.01, relative=True, samplers=[sampler])
    assert pilot.pilot["renders"] == RENDERS and pilot.pilot["pixels"] == PIXELS
    assert pilot.route.startswith("pilot") and pilot.rmse <= pilot.target
    # The pilot's variance has a relative standard error of about √(2/(3·64)), 10%: at 99% the
    # two counts differ by less than a factor of 1.6 (N ∝ variance^{1/|rate|}, rate ≤ -1).
    assert 1 / 1.6 <= pilot.n / tabulated.n <= 1.6, (pilot.n, tabulated.n)
    # The pilot's 99% interval contains the image's RMSE predicted from its pixels at its N.
    from_pixels = math.sqrt(specvar.predict_image(pixels, sampler, pilot.n, tabulation="exact").mse)
    assert pilot.rmse_interval[0] <= from_pixels <= pilot.rmse_interval[1], pilot


def test_the_padded_model_asks_more_samples_of_strata_than_the_single_one():
    renders = render(image(), "jitter")
    single = specvar.plan_pilot(renders, PILOT_N, "jitter", rmse=0.01, relative=True, model="single")
    padded = specvar.plan_pilot(renders, PILOT_N, "jitter", rmse=0.01, relative=True)
    assert "padded model" in padded.route and padded.n > single.n
    # Random points: every part falls like 1/N, and the two models agree.
    renders = render(image(), "random")
    one, two = (
        specvar.plan_pilot(renders, PILOT_N, "random", rmse=0.01, relative=True, model=m).n
        for m in ("single", "padded")
    )
    assert abs(one - two) <= 0.01 * one


def test_bad_pilots_are_refused():
    with pytest.raises(ValueError, match="at least 2 renders"):
        specvar.plan_pilot(np.ones((1, 8)), 16, "jitter", rmse=0.01)
    with pytest.raises(ValueError, match="identical renders"):
        specvar.plan_pilot(np.ones((4, 8)), 16, "jitter", rmse=0.01)
    with pytest.raises(ValueError, match="finite"):
        specvar.plan_pilot(np.array([[1.0, np.nan], [2.0, 3.0]]), 16, "jitter", rmse=0.01)
    with pytest.raises(ValueError, match="padded or single"):
        specvar.plan_pilot(np.eye(4), 16, "jitter", rmse=0.01, model="4d")
