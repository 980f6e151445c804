"""Rate studies: in one process, and on a Dask cluster with the same bits."""

import json

import numpy as np
import pytest

import specvar

STUDY = dict(
    samplers=["random", "jitter"],
    integrands=["gaussian", "disk:r=0.2"],
    # The N values `specvar rates --range 16 256` chooses in 2D.
    ns=[16, 36, 64, 121, 256],
    trials=600,
    seed=5,
    reference={"n": 256, "kmax": 32, "realizations": 8, "costly_realizations": 2},
)


def same_bits(a, b):
    """Equality of two studies' whole results, every float by its bits (JSON keeps 17 digits)."""
    return json.dumps(a.raw, sort_keys=True) == json.dumps(b.raw, sort_keys=True)


@pytest.fixture(scope="module")
def local():
    return specvar.study(**STUDY)


def test_the_study_has_its_table_and_series(local):
    assert len(local.rows) == 4 and len(local.series) == 4
    jitter_gauss = next(r for r in local.rows if r.sampler == "jitter" and "gaussian" in r.integrand)
    assert jitter_gauss.theory_rate == -2.0
    s = local.series[0]
    assert list(s.ns) == STUDY["ns"] and s.measured_interval.shape == (5, 2)
    assert np.all(s.measured_interval[:, 0] < s.measured_variance)


def test_the_same_study_as_the_command_line(cli):
    """`specvar rates` with the library's default reference spectrum."""
    ours = specvar.study(STUDY["samplers"], STUDY["integrands"], STUDY["ns"], trials=300, seed=5)
    done = cli("rates", "--samplers", "random,jitter", "--integrands", "gaussian,disk:r=0.2",
               "--range", "16", "256", "--trials", "300", "--seed", "5", "--json")
    assert json.loads(done.stdout)["rows"] == ours.raw["rows"]


def test_a_dask_cluster_gives_the_single_process_bits(local):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=3, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            for block in (37, 256):
                on_cluster = specvar.study(**STUDY, client=client, patterns_per_block=block)
                assert same_bits(on_cluster, local), f"blocks of {block}"
            workers = client.run(lambda: __import__("os").getpid())
            assert len(set(workers.values())) == 3


def test_bad_studies_are_value_errors():
    with pytest.raises(ValueError, match="two distinct"):
        specvar.study(["jitter"], ["disk"], [64], trials=100)
    with pytest.raises(ValueError):
        specvar.study(["nosuch"], ["disk"], [16, 64], trials=100)


def test_a_study_stops_at_the_floor_of_the_arithmetic():
    study = specvar.study(
        ["korobov", "jitter"],
        ["gaussian"],
        ns=[16, 49, 121, 361, 1024],
        trials=400,
        seed=3,
        reference={"n": 256, "kmax": 32, "realizations": 8, "costly_realizations": 2},
    )
    korobov, jitter = study.rows
    assert korobov.floor_n == 361
    assert korobov.predicted_rate.points == 3
    assert jitter.floor_n is None
    # Exact values that bend carry an interval.
    lo, hi = jitter.predicted_rate.ci
    assert hi - lo > 0.01
