"""`predict_padded`: a 4D pixel under two padded 2D patterns, against its Monte Carlo."""

import math

import numpy as np
import pytest

import specvar


def pixel(m=12):
    """A silhouette across the film coordinates, a shadow edge on the light that moves with
    the film position."""
    c = (np.arange(m) + 0.5) / m
    ay, ax, by, bx = np.meshgrid(c, c, c, c, indexing="ij")
    silhouette = ax * math.cos(math.radians(30)) + ay * math.sin(math.radians(30)) > 0.75
    lit = bx * math.cos(math.radians(70)) + by * math.sin(math.radians(70)) > 0.3 + 0.5 * ax
    return np.where(silhouette, 0.2, (0.5 + 0.5 * ay) * lit)


@pytest.mark.parametrize("first,second", [("jitter", "jitter"), ("cmj", "sobol")])
def test_the_padded_prediction_meets_its_monte_carlo(first, second):
    p = specvar.predict_padded(pixel(), first, 64, second=second, mc=4000, seed=3, tabulation="exact")
    m = p["measured"]
    half = 2.576 * p["budget"]["spectrum_noise"] + sum(
        p["budget"][k] for k in ("quadrature", "truncation", "model")
    )
    assert m["ci_low"] <= p["variance"] + half and p["variance"] - half <= m["ci_high"], p
    # Padding integrates the interaction almost as independent points do.
    assert p["interaction"] == pytest.approx(p["interaction_white"], rel=0.1)


def test_a_padded_plan_reaches_its_target():
    values = pixel()
    p = specvar.plan_padded(values, "jitter", rmse=0.02, relative=True, tabulation="exact")
    assert p.rmse <= p.target and p.below["rmse"] > p.target
    m = specvar.predict_padded(values, "jitter", p.n, mc=4000, seed=5, tabulation="exact")["measured"]
    assert math.sqrt(m["ci_low"]) <= 1.25 * p.target and math.sqrt(m["ci_high"]) >= 0.75 * p.target


def test_a_stack_of_padded_pixels_plans_the_image():
    one = specvar.plan_padded(pixel(), "jitter", rmse=0.02, relative=True, tabulation="exact")
    two = specvar.plan_padded(
        np.stack([pixel(), pixel()]), "jitter", rmse=0.02, relative=True, tabulation="exact"
    )
    assert one.n == two.n and one.rmse == pytest.approx(two.rmse, rel=1e-12)


def test_bad_padded_input_is_refused():
    with pytest.raises(ValueError, match="rank 4"):
        specvar.predict_padded(np.ones((4, 4, 4)), "jitter", 16)
    with pytest.raises(ValueError, match="stack of pixels"):
        specvar.predict_padded(np.stack([pixel(4), pixel(4)]), "jitter", 16)
    with pytest.raises(ValueError, match="biased"):
        specvar.predict_padded(pixel(4), "regular", 16, randomization="none")
