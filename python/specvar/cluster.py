"""Rate studies on a Dask cluster (``dask.distributed``).

A study's Monte Carlo is split into blocks of patterns, keyed by (sampler, N, first pattern,
count). A block's errors depend on the study's seed and the pattern indices alone, so the
blocks can run on any worker in any order; one final task puts them in pattern order and
computes the spectra, the predictions and the rate table. The result is the single-process
study bit for bit, whatever the number of workers or the block size.

Point it at a real cluster as at any Dask scheduler::

    from dask.distributed import Client
    import specvar
    client = Client("tcp://scheduler-host:8786")   # every worker has specvar installed
    result = specvar.study(["jitter", "poisson"], ["disk", "gaussian"], [64, 256, 1024],
                           trials=100_000, client=client, patterns_per_block=512)

Locally, ``Client(LocalCluster(n_workers=4, threads_per_worker=1))`` spreads the blocks over
worker processes. Each block uses all the cores its worker allows (the library is parallel
over patterns), so one thread per worker process is the natural setting.
"""

from __future__ import annotations

from typing import Any

from . import _specvar


def _block(described: str, block: tuple) -> Any:
    """One block's errors, on a worker: an array ``(count, integrands, 2)``."""
    return _specvar.study_block(described, tuple(block))


def _finish(described: str, blocks: list, *errors: Any) -> dict:
    """The study from every block's errors, on a worker."""
    return _specvar.finish_study(described, [tuple(b) for b in blocks], list(errors))


def run(described: str, client: Any, patterns_per_block: int) -> Any:
    """Runs the study ``described`` (see :func:`specvar.study`) on ``client``'s cluster."""
    from . import Study

    blocks = _specvar.study_blocks(described, patterns_per_block)
    futures = client.map(_block, [described] * len(blocks), blocks, pure=True)
    raw = client.submit(_finish, described, blocks, *futures, pure=True).result()
    return Study._from(raw)
