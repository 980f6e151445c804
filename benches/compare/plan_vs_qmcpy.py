#!/usr/bin/env python3
"""`specvar.plan` against qmcpy's `CubQMCSobolG`: how many samples for a target error.

Setup (once; qmcpy and numpy from the Python registry, specvar from this repository):

    python3 -m venv .venv-qmcpy
    .venv-qmcpy/bin/pip install qmcpy numpy ./python

Run from the repository root:

    .venv-qmcpy/bin/python benches/compare/plan_vs_qmcpy.py [--runs 20] [--trials 1000]

Two pixel-like integrands on the unit square, both with a jump across the square's faces: a
half-plane edge at 30° (`edge:theta=30`) and a soft shadow tabulated on 128 × 128 cells (a
penumbra of width 0.15 over a gradient). For relative tolerances of 2% and 1% of the integral:

- qmcpy: `CubQMCSobolG(abs_tol=ε, n_init=256)` on an LMS + digitally shifted Sobol' net,
  `--runs` seeds; the samples it used (median and range), its errors' RMSE, the share of runs
  whose error exceeds ε (its guarantee is `|error| ≤ ε`), and its time per run.
- specvar: one `plan` call for Owen-scrambled Sobol' aiming at RMSE ε, and one aiming at
  ε / 2.576 (the RMSE at which 99% of Gaussian errors lie within ε, qmcpy's criterion); the N
  it returns, its time, and the errors of `--trials` independent scrambles at that N (RMSE
  and share beyond ε).

Both integrate the same function: specvar's own integrands, evaluated through its Python
package, are qmcpy's integrand too.
"""
import argparse
import math
import time

import numpy as np
import qmcpy as qp

import specvar

Z_99 = 2.5758293035489


def soft_shadow(m=128):
    y, x = (np.mgrid[0:m, 0:m] + 0.5) / m
    c, s = math.cos(math.pi / 6), math.sin(math.pi / 6)
    t = np.clip((x * c + y * s - 0.6) / 0.15 + 0.5, 0, 1)
    return 0.1 + 0.6 * t * t * (3 - 2 * t) + 0.3 * x


def qmcpy_runs(f, integral, eps, runs):
    used, errors, times = [], [], []
    for seed in range(runs):
        net = qp.DigitalNetB2(2, seed=seed)
        integrand = qp.CustomFun(qp.Uniform(net), g=lambda x: f(x))
        start = time.perf_counter()
        solution, data = qp.CubQMCSobolG(integrand, abs_tol=eps, n_init=256).integrate()
        times.append(time.perf_counter() - start)
        used.append(int(data.n_total))
        errors.append(float(np.ravel(solution)[0]) - integral)
    return np.array(used), np.array(errors), np.array(times)


def specvar_plan(spec, f, integral, rmse, trials):
    start = time.perf_counter()
    (p,) = specvar.plan(spec, rmse=rmse, samplers=["sobol"])
    seconds = time.perf_counter() - start
    sets = specvar.sample("sobol", p.n, realizations=trials, seed=11)
    estimates = np.array([f(s).mean() for s in sets])
    return p, seconds, estimates - integral


def row(name, n_text, rmse, beyond, seconds):
    print(f"| {name} | {n_text} | {rmse:.3e} | {beyond:.3f} | {seconds:.3f} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--trials", type=int, default=1000)
    args = parser.parse_args()
    cases = [("edge at 30°", "edge:theta=30"), ("soft shadow 128²", soft_shadow())]
    for name, spec in cases:
        f = specvar.integrand(spec)
        integral = f.integral
        for relative in (0.02, 0.01):
            eps = relative * abs(integral)
            print(f"\n{name}, tolerance ε = {relative:.0%} of I = {eps:.3e}\n")
            print("| method | N | RMSE of errors | share of errors beyond ε | seconds |")
            print("|---|---|---|---|---|")
            used, errors, times = qmcpy_runs(f, integral, eps, args.runs)
            row(
                f"qmcpy CubQMCSobolG ({args.runs} runs)",
                f"{int(np.median(used))} [{used.min()}, {used.max()}]",
                math.sqrt(np.mean(errors**2)),
                np.mean(np.abs(errors) > eps),
                float(np.median(times)),
            )
            for label, rmse in (("RMSE ε", eps), ("RMSE ε/2.576", eps / Z_99)):
                p, seconds, errs = specvar_plan(spec, f, integral, rmse, args.trials)
                row(
                    f"specvar plan, sobol, {label} (predicted {p.rmse:.3e}; {args.trials} trials)",
                    str(p.n),
                    math.sqrt(np.mean(errs**2)),
                    np.mean(np.abs(errs) > eps),
                    seconds,
                )


if __name__ == "__main__":
    main()
