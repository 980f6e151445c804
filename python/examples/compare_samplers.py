"""Compare samplers on an integrand of your own, predicted and measured; then analyse and
predict a point set made elsewhere (scipy.stats.qmc).

Paste it into a notebook cell by cell, or run it:

    python examples/compare_samplers.py [output-directory]

It writes compare_samplers.png (and prints the table behind it).
"""

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import specvar  # noqa: E402

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
out.mkdir(parents=True, exist_ok=True)


# 1. An integrand of your own: a soft highlight cut by a shadow edge, vectorized over (N, 2).
def highlight(points):
    x, y = points[:, 0], points[:, 1]
    lobe = np.exp(-((x - 0.45) ** 2 + (y - 0.55) ** 2) / (2 * 0.12**2))
    shadow = (y > 0.3 + 0.4 * x).astype(float)
    return lobe * (0.25 + 0.75 * shadow)


# The prediction reads a function through its values at the centres of 256 × 256 cells, and is
# made for the function itself: extrapolated from the grid and its coarser levels, the
# extrapolation's bound in the budget's tabulation term (256 cells per axis serve N ≤ 1024).
values = specvar.tabulate(highlight, resolution=256)
tabulated = (values, "samples")

# 2. Three samplers, predicted from their spectra and measured by Monte Carlo on the function
# itself (its sample variance: we do not know its integral exactly).
samplers = ["random", "jitter", "sobol"]
ns = [16, 64, 256, 1024]
rows = []
for sampler in samplers:
    for n in ns:
        p = specvar.predict(tabulated, sampler=sampler, n=n)
        m = specvar.monte_carlo(highlight, sampler=sampler, n=n, trials=4000, seed=1)
        rows.append((sampler, n, p, m))
        print(
            f"{sampler:7s} N={n:5d}  predicted {p.variance:.3e} ± {p.budget.half_width(3.0):.1e}"
            f" (tabulation {p.budget.tabulation:.1e}, {p.route.form} form)"
            f"  measured {m.variance:.3e} [{m.ci_low:.3e}, {m.ci_high:.3e}]"
        )

# 3. A point set from elsewhere: 32 scrambled Sobol' sets from scipy, analysed and predicted.
try:
    from scipy.stats import qmc

    external = np.array([qmc.Sobol(d=2, scramble=True, seed=s).random(256) for s in range(32)])
    spectrum = specvar.spectrum(points=external, kmax=32)
    # Given sets have no law to read cells from: they are predicted under a random shift,
    # and measured under the same one.
    p_ext = specvar.predict(tabulated, points=external, randomization="shift")
    m_ext = specvar.monte_carlo(values, points=external, trials=32 * 100, seed=2, randomization="shift")
    print(
        f"scipy Sobol' N=256, shifted: predicted {p_ext.variance:.3e}, measured {m_ext.variance:.3e} "
        f"[{m_ext.ci_low:.3e}, {m_ext.ci_high:.3e}]"
    )
except ImportError:
    spectrum = None
    print("scipy is not installed: the external point set is left out")

# 4. The plot: predicted (lines, with their ±3σ budget) and measured (points, 99% intervals).
fig, axes = plt.subplots(1, 2 if spectrum is not None else 1, figsize=(12, 4.8), squeeze=False)
ax = axes[0, 0]
colours = dict(zip(samplers, ["tab:gray", "tab:blue", "tab:red"]))
for sampler in samplers:
    mine = [r for r in rows if r[0] == sampler]
    n = np.array([r[1] for r in mine])
    predicted = np.array([r[2].variance for r in mine])
    band = np.array([r[2].budget.half_width(3.0) for r in mine])
    measured = np.array([r[3].variance for r in mine])
    low = measured - np.array([r[3].ci_low for r in mine])
    high = np.array([r[3].ci_high for r in mine]) - measured
    ax.plot(n, predicted, "-", color=colours[sampler], label=f"{sampler}: predicted")
    ax.fill_between(n, predicted - band, predicted + band, color=colours[sampler], alpha=0.2)
    ax.errorbar(n, measured, yerr=[low, high], fmt="o", ms=3.5, color=colours[sampler], capsize=5,
                label=f"{sampler}: Monte Carlo, 99%")
ax.set_xscale("log", base=2)
ax.set_yscale("log")
ax.set_xlabel("N (points per pattern)")
ax.set_ylabel("variance of the estimate")
ax.set_title("Your integrand: predicted from spectra, measured")
ax.legend(fontsize=8, loc="lower left")
ax.grid(True, which="both", alpha=0.3)
if spectrum is not None:
    ax2 = axes[0, 1]
    r = spectrum.radial
    ax2.errorbar(r.nu, r.power, yerr=r.stderr, fmt=".-", ms=3, color="tab:green", capsize=2)
    ax2.axhline(1.0, color="black", lw=0.8, ls=":")
    ax2.set_xlabel("ν = |k| / √N")
    ax2.set_ylabel("radial power (white noise = 1)")
    ax2.set_title("scipy's scrambled Sobol', N = 256: radial spectrum")
    ax2.grid(True, alpha=0.3)
fig.tight_layout()
fig.savefig(out / "compare_samplers.png", dpi=110)
print(f"wrote {out / 'compare_samplers.png'}")
