"""Spectra of samplers and of the user's own arrays, against sums written out in numpy."""

import numpy as np
import pytest

import specvar


def numpy_periodogram(points, kmax):
    """`|Σ exp(-2πi k·x)|² / N` on the lattice |k_i| ≤ kmax, summed directly in numpy."""
    n, d = points.shape
    axis = np.arange(-kmax, kmax + 1)
    k = np.stack(np.meshgrid(*([axis] * d), indexing="ij"), axis=-1).reshape(-1, d)
    s = np.exp(-2j * np.pi * (k @ points.T)).sum(axis=1)
    return (np.abs(s) ** 2 / n).reshape([2 * kmax + 1] * d)


@pytest.mark.parametrize("d,kmax", [(1, 40), (2, 12), (3, 4)])
@pytest.mark.parametrize("engine", ["direct", "fast"])
def test_periodogram_of_a_users_array_is_the_direct_sum(d, kmax, engine):
    points = np.random.default_rng(1).random((97, d))
    # A tolerance is for the fast engine: the direct sum is exact, and refuses one.
    tolerance = 1e-12 if engine == "fast" else None
    ours = specvar.periodogram(points, kmax, engine=engine, tolerance=tolerance)
    # The direct engine sums by recurrence: rounding grows like N·K·ε; the fast engine's
    # bound is 2ε√(NP) + ε²N at tolerance ε.
    assert np.allclose(ours, numpy_periodogram(points, kmax), rtol=0, atol=1e-9)


def test_a_tolerance_with_the_direct_engine_is_refused():
    with pytest.raises(ValueError, match="the direct sum is exact"):
        specvar.periodogram(np.zeros((4, 2)), 3, engine="direct", tolerance=1e-9)


def test_a_strided_view_is_read_in_logical_order():
    big = np.random.default_rng(2).random((64, 5))
    view = big[:, 1:3]
    assert not view.flags["C_CONTIGUOUS"]
    assert np.allclose(specvar.periodogram(view, 6), numpy_periodogram(np.ascontiguousarray(view), 6), atol=1e-9)


def test_spectrum_of_point_sets_is_the_mean_of_their_periodograms():
    sets = specvar.sample("jitter", 64, realizations=5, seed=4)
    s = specvar.spectrum(points=sets, kmax=10, engine="direct")
    mean = np.mean([numpy_periodogram(p, 10) for p in sets], axis=0)
    off_dc = np.ones_like(mean, dtype=bool)
    off_dc[10, 10] = False
    assert s.mean.shape == (21, 21) and s.realizations == 5 and s.n == 64
    assert np.allclose(s.mean[off_dc], mean[off_dc], atol=1e-9)


def test_white_noise_has_unit_power_in_every_ring():
    s = specvar.spectrum(sampler="random", n=256, realizations=64, kmax=16)
    r = s.radial
    z = (r.power - 1.0) / r.stderr
    # 16 rings: a Bonferroni bound at 99.9% overall.
    assert np.all(np.abs(z) < 4.0), z
    assert len(r.nu) == len(r.count) and np.all(r.count > 0)


def test_a_sampler_and_its_arrays_give_the_same_spectrum():
    by_name = specvar.spectrum(sampler="sobol", n=128, realizations=4, kmax=8, seed=9, engine="direct")
    arrays = specvar.sample("sobol", 128, realizations=4, seed=9)
    by_points = specvar.spectrum(points=arrays, kmax=8, engine="direct")
    assert np.array_equal(by_name.mean, by_points.mean)


def test_bad_arrays_are_value_errors():
    with pytest.raises(ValueError, match="shape"):
        specvar.periodogram(np.zeros((2, 3, 4, 5)), 4)
    with pytest.raises(ValueError):
        specvar.periodogram(np.array([[0.5, 1.5]]), 4)
    with pytest.raises(ValueError):
        specvar.periodogram(np.array([[0.5, np.nan]]), 4)
    with pytest.raises(ValueError, match="exactly one"):
        specvar.spectrum()
    with pytest.raises(ValueError, match="engine"):
        specvar.periodogram(np.array([[0.5, 0.5]]), 4, engine="warp")
