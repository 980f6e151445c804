"""A renderer's pixel, predicted before rendering.

One pixel's direct lighting under a square area light, partly hidden by a tilted occluder (a
soft shadow), as a function of the 2D light sample u in [0, 1)^2: the integrand a renderer's
sampler integrates. Mitsuba 3 supplies the geometry (its ray tests decide the visibility) and
its samplers supply the points, exactly as one pixel receives them (seeded, then one
``next_2d`` and one ``advance`` per sample). The integrand jumps at the light square's faces
(the shadow's edge meets them), the seam that the shifted estimator pays for and a renderer's
unshifted strata do not.

For each sampler and sample count the script prints the variance measured over many pixels
(seeds) with Mitsuba's own points, the prediction for those point sets as given (cells
declared as the sampler guarantees them), specvar's prediction with its own sampler of the same
law (made before any rendering), and the homogenized (shifted) prediction of the talk.

Then it plans: the samples each sampler needs for 1% relative RMSE (``specvar.plan``, on the
pixel tabulated adaptively), each checked by Monte Carlo of the same estimator at the planned
count, beside qmcpy's ``CubQMCSobolG`` for an absolute tolerance of the same size where qmcpy
is installed.

Needs ``pip install mitsuba`` (not a dependency of specvar or of its tests); ``pip install
qmcpy`` for the last table.
Run: ``python python/examples/mitsuba_pixel.py``.
"""

import sys

import numpy as np

import specvar

try:
    import mitsuba as mi
except ImportError:
    sys.exit("this example needs Mitsuba 3: pip install mitsuba")

mi.set_variant("scalar_rgb")
T = mi.ScalarTransform4f

# The shading point at the origin, facing +z; the light is the square [-1/2, 1/2]^2 at height 1,
# facing down, of radiance 1; the occluder a square of side 0.6 at height 1/2, turned by 30°.
SCENE = mi.load_dict(
    {
        "type": "scene",
        "occluder": {
            "type": "rectangle",
            "to_world": T().translate([0.12, 0.05, 0.5]) @ T().rotate([0, 0, 1], 30) @ T().scale(0.3),
        },
    }
)
LIGHT_CORNER = np.array([-0.5, -0.5, 1.0])


def radiance(u):
    """The light's contribution for light sample u (area 1, so the pdf is 1)."""
    y = LIGHT_CORNER + np.array([u[0], u[1], 0.0])
    d = y
    dist = float(np.linalg.norm(d))
    ray = mi.Ray3f(mi.ScalarPoint3f(0.0, 0.0, 1e-4), mi.ScalarVector3f(*(d / dist)))
    ray.maxt = dist * (1.0 - 1e-4)
    if SCENE.ray_test(ray):
        return 0.0
    cos = d[2] / dist  # at the point and at the light alike
    return cos * cos / (dist * dist)


def tabulate(resolution):
    """Cell values at the cells' centres, values[y, x]."""
    c = (np.arange(resolution) + 0.5) / resolution
    return np.array([[radiance((x, y)) for x in c] for y in c])


def mitsuba_points(name, spp, seeds):
    """One pixel's 2D samples under each seed: what the renderer feeds this integrand."""
    sets = []
    for seed in range(seeds):
        s = mi.load_dict({"type": name, "sample_count": spp})
        s.seed(seed)
        points = []
        for _ in range(s.sample_count()):
            u = s.next_2d()
            points.append((u[0], u[1]))
            s.advance()
        sets.append(points)
    return np.array(sets)


values = tabulate(256)
print(f"pixel integrand tabulated on 256 x 256 cells: mean {values.mean():.5f}")
# Mitsuba's sampler, how its points are used (the cells they are guaranteed uniform in, or a
# digital shift), and specvar's sampler of the same law. Mitsuba's ldsampler is a (0,2)-sequence
# under one digital shift per pixel: its points are not uniform cell by cell (one shift moves
# them all), but its sets shifted again have its law, so the Walsh form predicts them as given;
# specvar's sobol-ds is the same net under the same shift.
SAMPLERS = [
    ("independent", "whole", "random", (16, 64, 256)),
    ("stratified", "strata", "jitter", (16, 64, 256)),
    ("multijitter", "rows", "cmj", (16, 64, 256)),
    ("orthogonal", "rows", "orthogonal", (25, 49, 289)),
    ("ldsampler", "digital-shift", "sobol-ds", (16, 64, 256)),
]
SEEDS = 1000
print(
    f"{'sampler':12s} {'spp':>4s}  {'measured (99% interval)':>34s}  {'as given':>10s}"
    f"  {'specvar sampler, as drawn':>25s}  {'shifted':>9s}"
)
for name, cells, ours, counts in SAMPLERS:
    for spp in counts:
        sets = mitsuba_points(name, spp, SEEDS)
        measured = specvar.monte_carlo(values, points=sets, randomization="none")
        if cells == "digital-shift":
            given = specvar.predict(values, points=sets, randomization="digital-shift").variance
        else:
            given = specvar.predict(values, points=sets, cells=cells).variance
        before = specvar.predict(values, sampler=ours, n=sets.shape[1])
        shifted = specvar.predict(values, sampler=ours, n=sets.shape[1], randomization="shift")
        print(
            f"{name:12s} {sets.shape[1]:4d}  {measured.variance:.3e} "
            f"[{measured.ci_low:.3e}, {measured.ci_high:.3e}]  {given:.3e}  "
            f"{before.variance:.3e} ({ours:10s})  {shifted.variance:.3e}"
        )


# How many samples for 1% relative RMSE: the pixel tabulated where it varies, then one call.
adaptive = specvar.tabulate_adaptive(lambda u: np.array([radiance(p) for p in u]), 256)
print(
    f"\nadaptive tabulation: {adaptive.evaluations} evaluations of the 65536 cells "
    f"({adaptive.flat_share:.0%} filled, largest gap to the full grid "
    f"{np.abs(adaptive.values - values).max():.2e})"
)
plans = specvar.plan(
    adaptive.values, rmse=0.01, relative=True, samplers=["random", "jitter", "cmj", "orthogonal", "sobol"]
)
print(f"{'sampler':12s} {'planned N':>9s}  {'predicted RMSE':>14s}  {'measured RMSE (99% interval)':>36s}")
for p in plans:
    m = specvar.monte_carlo(values, sampler=p.sampler, n=p.n, trials=2000)
    print(
        f"{p.sampler:12s} {p.n:9d}  {p.rmse:14.4e}  {m.variance ** 0.5:.4e} "
        f"[{m.ci_low ** 0.5:.4e}, {m.ci_high ** 0.5:.4e}]"
    )
try:
    import qmcpy as qp
except ImportError:
    sys.exit("qmcpy is not installed: pip install qmcpy for its CubQMCSobolG beside the plan")
eps = 0.01 * values.mean()
used, errors = [], []
for seed in range(20):
    f = qp.CustomFun(qp.Uniform(qp.DigitalNetB2(2, seed=seed)), g=lambda u: np.array([radiance(p) for p in u]))
    solution, data = qp.CubQMCSobolG(f, abs_tol=eps, n_init=256).integrate()
    used.append(int(data.n_total))
    errors.append(float(np.ravel(solution)[0]) - values.mean())
errors = np.array(errors)
print(
    f"qmcpy CubQMCSobolG, abs_tol {eps:.3e}, 20 seeds: N {int(np.median(used))} "
    f"[{min(used)}, {max(used)}], error RMSE {np.sqrt(np.mean(errors ** 2)):.3e} "
    f"(against the 256² tabulation's mean), beyond tolerance in {np.mean(np.abs(errors) > eps):.0%}"
)
