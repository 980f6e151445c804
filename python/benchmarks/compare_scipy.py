"""specvar from Python against scipy.stats.qmc (point generation) and numpy (periodograms),
in one run on one machine. Prints a Markdown table of median times and ratios.

    python3 -m venv /tmp/bench && /tmp/bench/bin/pip install './python' scipy
    RAYON_NUM_THREADS=1 /tmp/bench/bin/python python/benchmarks/compare_scipy.py
    /tmp/bench/bin/python python/benchmarks/compare_scipy.py          # every core

specvar's realizations are drawn in parallel by the Rust core (RAYON_NUM_THREADS threads);
scipy and numpy run on one thread here (numpy's exp and sum do not thread).
"""

import os
import statistics
import time

import numpy as np
from scipy.stats import qmc

import specvar

REPEATS = 5


def median_seconds(work):
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        work()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def numpy_periodogram(points, kmax, chunk=2048):
    """`|Σ exp(-2πi k·x)|² / N` on |k_i| ≤ kmax, summed directly, frequencies in chunks."""
    n, d = points.shape
    axis = np.arange(-kmax, kmax + 1)
    k = np.stack(np.meshgrid(*([axis] * d), indexing="ij"), axis=-1).reshape(-1, d).astype(float)
    out = np.empty(len(k))
    for i in range(0, len(k), chunk):
        s = np.exp(-2j * np.pi * (k[i : i + chunk] @ points.T)).sum(axis=1)
        out[i : i + chunk] = np.abs(s) ** 2 / n
    return out


def generation_rows():
    m, n = 64, 4096
    peers = {
        "sobol": lambda s: qmc.Sobol(d=2, scramble=True, seed=s).random(n),
        "halton": lambda s: qmc.Halton(d=2, scramble=True, seed=s).random(n),
        "lhs": lambda s: qmc.LatinHypercube(d=2, seed=s).random(n),
    }
    for name, peer in peers.items():
        theirs = median_seconds(lambda: [peer(s) for s in range(m)])
        ours = median_seconds(lambda: specvar.sample(name, n, realizations=m))
        yield f"{name}: {m} sets of {n} points, 2D", ours, theirs


def periodogram_rows():
    for n, kmax in [(1024, 32), (4096, 64)]:
        x = specvar.sample("jitter", n, seed=1)[0]
        reference = numpy_periodogram(x, kmax)
        for engine in ("direct", "fast"):
            ours = specvar.periodogram(x, kmax, engine=engine, tolerance=1e-9 if engine == "fast" else None)
            err = np.max(np.abs(ours.ravel() - reference))
            assert err < 1e-6 * n, (engine, err)
        theirs = median_seconds(lambda: numpy_periodogram(x, kmax))
        for engine in ("direct", "fast"):
            tol = 1e-9 if engine == "fast" else None
            ours = median_seconds(lambda: specvar.periodogram(x, kmax, engine=engine, tolerance=tol))
            yield f"periodogram N = {n}, |k_i| ≤ {kmax}, {engine} engine", ours, theirs


def spectrum_rows():
    m, n, kmax = 16, 1024, 32
    sets = specvar.sample("jitter", n, realizations=m, seed=2)
    theirs = median_seconds(lambda: np.mean([numpy_periodogram(s, kmax) for s in sets], axis=0))
    ours = median_seconds(lambda: specvar.spectrum(points=sets, kmax=kmax))
    yield f"expected spectrum of {m} sets, N = {n}, |k_i| ≤ {kmax} (auto engine)", ours, theirs


def main():
    threads = os.environ.get("RAYON_NUM_THREADS", f"all ({os.cpu_count()})")
    print(f"specvar threads: {threads}; scipy {__import__('scipy').__version__}, numpy {np.__version__}")
    print()
    print("| task | specvar | scipy / numpy | speed-up |")
    print("|---|---|---|---|")
    for rows in (generation_rows(), periodogram_rows(), spectrum_rows()):
        for task, ours, theirs in rows:
            print(f"| {task} | {ours * 1e3:.2f} ms | {theirs * 1e3:.2f} ms | {theirs / ours:.1f}× |")


if __name__ == "__main__":
    main()
