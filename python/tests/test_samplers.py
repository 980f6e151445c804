"""Samplers: the same bits as the command line, realization semantics, errors."""

import json

import numpy as np
import pytest

import specvar


def test_every_sampler_is_listed_with_its_facts():
    names = [s.name for s in specvar.samplers()]
    assert len(names) >= 16 and len(set(names)) == len(names)
    jitter = next(s for s in specvar.samplers() if s.name == "jitter")
    assert jitter.known_alpha == 2.0 and jitter.dimensions[0] == 1


@pytest.mark.parametrize(
    "sampler,n,d",
    [("random", 37, 2), ("jitter", 64, 2), ("sobol", 128, 3), ("poisson", 200, 2), ("pmj02", 64, 2), ("kronecker", 50, 2)],
)
def test_same_bits_as_the_command_line(cli, tmp_path, sampler, n, d):
    out = tmp_path / "p.json"
    cli("--no-cache", "sample", "-s", sampler, "-n", str(n), "-d", str(d), "--seed", "7",
        "--realizations", "3", "--json", "-o", str(out))
    from_cli = np.array(json.loads(out.read_text())["realizations"])
    ours = specvar.sample(sampler, n, realizations=3, dimension=d, seed=7, cache=False)
    assert ours.shape == (3, n, d) and ours.dtype == np.float64
    assert np.array_equal(ours, from_cli.reshape(ours.shape))


def test_a_realization_is_keyed_by_seed_and_index():
    whole = specvar.sample("jitter", 16, realizations=6, seed=3)
    assert np.array_equal(specvar.sample("jitter", 16, realizations=2, seed=3, start=4), whole[4:6])
    assert not np.array_equal(whole[0], whole[1])
    shifted = specvar.sample("regular", 16, realizations=2, seed=3, randomization="shift")
    grid = specvar.sample("regular", 16, realizations=1, seed=3)[0]
    # A homogenized grid is the grid under one toroidal shift: the same differences modulo 1.
    delta = (shifted[0] - grid) % 1.0
    assert np.allclose(delta, delta[0], atol=1e-12) and not np.allclose(delta[0], 0.0)


@pytest.mark.parametrize(
    "args,kwargs",
    [
        (["sample", "-s", "nosuch", "-n", "4"], dict(sampler="nosuch", n=4)),
        (["sample", "-s", "regular", "-n", "17"], dict(sampler="regular", n=17)),
        (["sample", "-s", "jitter", "-n", "16", "-d", "9"], dict(sampler="jitter", n=16, dimension=9)),
        (["sample", "-s", "jitter", "-n", "0"], dict(sampler="jitter", n=0)),
    ],
)
def test_errors_are_value_errors_with_the_command_lines_message(cli, args, kwargs):
    done = cli(*args, check=False)
    assert done.returncode == 2
    line = done.stderr.strip().splitlines()[-1]
    with pytest.raises(ValueError) as raised:
        specvar.sample(**kwargs)
    # The library's message is the line's end: after "error: ", or after the name of the
    # argument where the command line's parser called the library to read it.
    assert line.endswith(": " + str(raised.value)), (line, str(raised.value))


def test_work_beyond_the_budget_is_refused_before_it_starts():
    try:
        assert specvar.set_budget(memory_gib=0.001) == (0.001, 3600.0)
        with pytest.raises(ValueError, match="sampling would need 244 MiB, above the budget of 1 MiB"):
            specvar.sample("random", 4_000_000)
        assert specvar.sample("random", 1000).shape == (1, 1000, 2)
    finally:
        specvar.set_budget(memory_gib=8.0)
    with pytest.raises(ValueError, match="sampling would need"):
        specvar.sample("random", 10**9, realizations=10**6)
    with pytest.raises(ValueError, match="positive"):
        specvar.set_budget(seconds=float("nan"))


@pytest.mark.parametrize("call", [
    lambda: specvar.sample("jitter", -4),
    lambda: specvar.sample("jitter", 16, seed=2**64),
    lambda: specvar.spectrum(sampler="jitter", n=16, kmax=-1),
    lambda: specvar.predict("disk", sampler="jitter", n=-3),
    lambda: specvar.monte_carlo("disk", sampler="jitter", n=16, trials=-1),
])
def test_integers_out_of_range_are_value_errors_naming_the_argument(call):
    with pytest.raises(ValueError, match="invalid (n|seed|kmax|trials): "):
        call()
