"""A Cornell-box pixel with antialiasing and a soft shadow, predicted before rendering.

Mitsuba 3's Cornell box, rendered with its ``direct`` integrator (one emitter sample per pixel
sample, no BSDF samples), 128 x 128 pixels, box filter. One floor pixel lies in the penumbra of
the tall box: its value is a 4D integral, over the film position inside the pixel (2D) and the
light sample (2D), which Mitsuba's samplers pad together (each dimension pair its own pattern,
paired by a permutation).

The script
1. renders the image with the 16 x 16 crop around the pixel and the pixel marked
   (``cornell_crop.png``);
2. tabulates the pixel's integrand with Mitsuba's own calls (the camera ray, ``sample_emitter
   _direction``, the BSDF): 4D on 8 x 8 film cells x 64 x 64 light cells, and 2D (the light
   sample at the pixel's centre) adaptively;
3. measures the pixel's variance per sampler and sample count from 400 renders of that pixel
   with Mitsuba's own samplers, and prints it beside specvar's predictions for the padded 4D
   estimator (``predict_padded``) and for the light sample alone (``predict``);
4. plans the samples for 1% relative RMSE of the pixel (``plan_padded``), checks each count
   by renders, and sets qmcpy's ``CubQMCSobolG`` beside it where qmcpy is installed;
5. plans the crop from a pilot of four renders at 16 samples (``plan_pilot``) and compares it
   with the plans from the crop's tabulated pixels (4D padded, and the light alone) and with
   renders at the planned count;
6. draws measured against predicted variance (``cornell_variance.svg``).

Needs ``pip install mitsuba`` (not a dependency of specvar or of its tests); ``pip install
qmcpy`` for step 4's comparison. Run: ``python python/examples/mitsuba_cornell.py [OUT_DIR]``.
"""

import math
import os
import sys

import numpy as np

import specvar

try:
    import mitsuba as mi
except ImportError:
    sys.exit("this example needs Mitsuba 3: pip install mitsuba")

mi.set_variant("scalar_rgb")
mi.set_log_level(mi.LogLevel.Error)

SIZE = 128
CROP = 16
OUT = sys.argv[1] if len(sys.argv) > 1 else "."
# Mitsuba's sampler, specvar's sampler of the same law, and the counts each accepts.
SAMPLERS = [
    ("independent", "random", (16, 64, 256)),
    ("stratified", "jitter", (16, 64, 256)),
    ("multijitter", "cmj", (16, 64, 256)),
    ("ldsampler", "sobol-ds", (16, 64, 256)),
]
RENDERS = 400


def scene_dict(sampler="independent", spp=16, crop=None):
    d = mi.cornell_box()
    d["integrator"] = {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0}
    film = d["sensor"]["film"]
    film.update({"width": SIZE, "height": SIZE, "rfilter": {"type": "box"}})
    if crop is not None:
        x, y, w, h = crop
        film.update({"crop_offset_x": x, "crop_offset_y": y, "crop_width": w, "crop_height": h})
    d["sensor"]["sampler"] = {"type": sampler, "sample_count": spp}
    return d


SCENE = mi.load_dict(scene_dict())
SENSOR = SCENE.sensors()[0]
CONTEXT = mi.BSDFContext()


def shading_point(px, py, film=(0.5, 0.5)):
    """The camera ray's hit through film position ``film`` of pixel (px, py)."""
    position = mi.Point2f((px + film[0]) / SIZE, (py + film[1]) / SIZE)
    ray, _ = SENSOR.sample_ray(0.0, 0.5, position, mi.Point2f(0.5, 0.5))
    return SCENE.ray_intersect(ray)


def radiance(si, u):
    """What the direct integrator adds for light sample ``u`` (red channel)."""
    if not si.is_valid():
        return 0.0
    ds, weight = SCENE.sample_emitter_direction(si, mi.Point2f(float(u[0]), float(u[1])), True)
    value = weight * si.bsdf().eval(CONTEXT, si, si.to_local(ds.d))
    return float(value[0])


def lit_fraction(px, py, m=8):
    si = shading_point(px, py)
    c = (np.arange(m) + 0.5) / m
    return np.mean([radiance(si, (a, b)) > 0 for a in c for b in c])


def find_pixel():
    """A floor pixel in the tall box's penumbra: half its light hidden at its centre."""
    best = None
    for py in range(96, 124):
        for px in range(8, 60):
            gap = abs(lit_fraction(px, py) - 0.5)
            if best is None or gap < best[0]:
                best = (gap, px, py)
    return best[1], best[2]


def tabulate_4d(px, py, film_cells=8, light_cells=64):
    """values[ay, ax, by, bx]: film cell (ax, ay) of the pixel, light cell (bx, by)."""
    f = (np.arange(film_cells) + 0.5) / film_cells
    c = (np.arange(light_cells) + 0.5) / light_cells
    values = np.empty((film_cells, film_cells, light_cells, light_cells))
    for ay, fy in enumerate(f):
        for ax, fx in enumerate(f):
            si = shading_point(px, py, (fx, fy))
            values[ay, ax] = [[radiance(si, (bx, by)) for bx in c] for by in c]
    return values


def render_pixel(sampler, spp, px, py, seeds):
    scene = mi.load_dict(scene_dict(sampler, spp, (px, py, 1, 1)))
    return np.array([np.array(mi.render(scene, spp=spp, seed=s))[0, 0, 0] for s in range(seeds)])


def render_crop(sampler, spp, x, y, seeds):
    scene = mi.load_dict(scene_dict(sampler, spp, (x, y, CROP, CROP)))
    return np.array([np.array(mi.render(scene, spp=spp, seed=s))[:, :, 0] for s in seeds])


def interval(samples, z=2.576):
    """The variance of ``samples`` about their mean, with a 99% interval (normal theory on the
    sample variance's own spread)."""
    v = samples.var(ddof=1)
    fourth = np.mean((samples - samples.mean()) ** 4)
    se = math.sqrt(max(fourth - v * v, 0.0) / len(samples))
    return v, max(v - z * se, 0.0), v + z * se


px, py = find_pixel()
x0, y0 = px - CROP // 2, py - CROP // 2
print(f"pixel ({px}, {py}) of {SIZE} x {SIZE}: light {lit_fraction(px, py):.0%} visible at its centre")

# 1. The image, rendered well, with the crop (red) and the pixel (yellow) marked.
image = np.array(mi.render(mi.load_dict(scene_dict("independent", 256)), seed=0))
shown = np.clip(image / np.percentile(image, 99.5), 0, 1) ** (1 / 2.2)
scale = 4
rgb = np.repeat(np.repeat(shown, scale, 0), scale, 1)


def outline(rgb, x, y, w, h, colour):
    x, y, w, h = x * scale, y * scale, w * scale, h * scale
    rgb[y : y + h, [x, x + 1, x + w - 2, x + w - 1]] = colour
    rgb[[y, y + 1, y + h - 2, y + h - 1], x : x + w] = colour


outline(rgb, x0, y0, CROP, CROP, (1.0, 0.1, 0.1))
outline(rgb, px, py, 1, 1, (1.0, 0.9, 0.0))
mi.util.write_bitmap(os.path.join(OUT, "cornell_crop.png"), mi.Bitmap(rgb.astype(np.float32)), write_async=False)

# 2. The pixel's integrand: 4D (film x light) and 2D (light, at the pixel's centre).
values4d = tabulate_4d(px, py)
centre = shading_point(px, py)
light = specvar.tabulate_adaptive(lambda u: np.array([radiance(centre, p) for p in u]), 256)
print(
    f"4D tabulation {values4d.shape}: mean {values4d.mean():.5f}; light at the centre "
    f"tabulated from {light.evaluations} evaluations, mean {light.values.mean():.5f}"
)

# 3. Measured against predicted, per sampler and count.
print(
    f"\n{'sampler':12s} {'spp':>4s}  {'measured, 400 renders (99%)':>34s}  "
    f"{'padded 4D':>20s}  {'light only':>10s}"
)
rows = []
for name, ours, counts in SAMPLERS:
    for spp in counts:
        m, lo, hi = interval(render_pixel(name, spp, px, py, RENDERS))
        padded = specvar.predict_padded(values4d, ours, spp)
        half = 2.576 * padded["budget"]["spectrum_noise"] + sum(
            padded["budget"][k] for k in ("quadrature", "truncation", "model")
        )
        alone = specvar.predict(light.values, sampler=ours, n=spp).variance
        rows.append((name, spp, m, lo, hi, padded["variance"], half, alone))
        print(
            f"{name:12s} {spp:4d}  {m:.3e} [{lo:.3e}, {hi:.3e}]  "
            f"{padded['variance']:.3e} ± {half:.1e}  {alone:.3e}"
        )

# 4. Samples for 1% relative RMSE of the pixel (4D, padded as Mitsuba pads it), each checked by
# 400 renders at the planned count, and of the light sample alone; qmcpy's answer for the
# same 4D integrand (its own 4D Sobol' points, not padded pairs).
print("\npixel, 1% relative RMSE:")
for name, ours, _ in SAMPLERS:
    p = specvar.plan_padded(values4d, ours, rmse=0.01, relative=True)
    (alone,) = specvar.plan(light.values, rmse=0.01, relative=True, samplers=[ours])
    spp = round(math.sqrt(p.n)) ** 2 if name in ("stratified", "multijitter") else p.n
    m, lo, hi = interval(render_pixel(name, spp, px, py, RENDERS))
    mean = values4d.mean()
    print(
        f"  {name:12s} padded 4D N = {p.n:6d} (light alone: {alone.n:6d}); 400 renders at "
        f"{spp} spp: relative RMSE {math.sqrt(m) / mean:.2%} [{math.sqrt(lo) / mean:.2%}, {math.sqrt(hi) / mean:.2%}]"
    )
try:
    import qmcpy as qp

    eps = 0.01 * values4d.mean()

    def pixel(x):
        """The pixel's integrand at points (film x, film y, light x, light y)."""
        return np.array([radiance(shading_point(px, py, (p[0], p[1])), (p[2], p[3])) for p in x])

    used = []
    for seed in range(20):
        f = qp.CustomFun(qp.Uniform(qp.DigitalNetB2(4, seed=seed)), g=pixel)
        _, data = qp.CubQMCSobolG(f, abs_tol=eps, n_init=256).integrate()
        used.append(int(data.n_total))
    print(
        f"  qmcpy CubQMCSobolG on the 4D pixel, abs_tol {eps:.3e}, 20 seeds: "
        f"N {int(np.median(used))} [{min(used)}, {max(used)}]"
    )
except ImportError:
    print("  qmcpy is not installed: pip install qmcpy for its CubQMCSobolG beside the plan")

# 5. The crop planned from a pilot, against the plan from its tabulated pixels and renders.
# Mitsuba's stratified sampler takes square counts: each plan's N is rounded to the nearest.
pilot = render_crop("stratified", 16, x0, y0, range(1000, 1004))
pixels = np.array(
    [
        specvar.tabulate(lambda u, si=shading_point(x, y): np.array([radiance(si, p) for p in u]), 32)
        for y in range(y0, y0 + CROP)
        for x in range(x0, x0 + CROP)
    ]
)
(from_pixels,) = specvar.plan(pixels, rmse=0.01, relative=True, samplers=["jitter"])
padded_pixels = np.array(
    [tabulate_4d(x, y, film_cells=4, light_cells=16) for y in range(y0, y0 + CROP) for x in range(x0, x0 + CROP)]
)
from_padded = specvar.plan_padded(padded_pixels, "jitter", rmse=0.01, relative=True)
print(
    f"\ncrop, jitter, 1% relative image RMSE, planned from the pixels' integrands tabulated: "
    f"4D (4 x 4 film x 16 x 16 light cells, padded) N = {from_padded.n}; the light integrands "
    f"at the pixels' centres alone (32 x 32) N = {from_pixels.n}"
)
for model in ("padded", "single"):
    p = specvar.plan_pilot(pilot, 16, "jitter", rmse=0.01, relative=True, model=model)
    spp = round(math.sqrt(p.n)) ** 2
    check = render_crop("stratified", spp, x0, y0, range(2000, 2100))
    measured = math.sqrt(check.var(0, ddof=1).mean()) / check.mean()
    print(
        f"  pilot (4 renders at 16 spp), {model} model: N = {p.n}, RMSE interval "
        f"[{p.rmse_interval[0] / p.target:.2f}, {p.rmse_interval[1] / p.target:.2f}] of the target; "
        f"100 renders at {spp} spp measure {measured:.2%}"
    )

# 6. The figure: measured (with its 99% interval) against the padded prediction.
W, H, L, B, T, R = 640, 420, 70, 50, 20, 150
ns = [r[1] for r in rows]
vs = [v for r in rows for v in (r[3], r[4], r[5], r[7])]
lx = lambda n: L + (math.log(n) - math.log(12)) / (math.log(320) - math.log(12)) * (W - L - R)
lo_v, hi_v = math.log10(min(v for v in vs if v > 0)) - 0.2, math.log10(max(vs)) + 0.2
ly = lambda v: T + (hi_v - math.log10(max(v, 10**lo_v))) / (hi_v - lo_v) * (H - T - B)
colours = ["#555555", "#1f77b4", "#2ca02c", "#d62728"]
svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">']
svg.append(f'<rect width="{W}" height="{H}" fill="white"/>')
svg.append(f'<line x1="{L}" y1="{H - B}" x2="{W - R}" y2="{H - B}" stroke="black"/>')
svg.append(f'<line x1="{L}" y1="{T}" x2="{L}" y2="{H - B}" stroke="black"/>')
for n in (16, 64, 256):
    svg.append(f'<text x="{lx(n)}" y="{H - B + 16}" text-anchor="middle">{n}</text>')
for e in range(math.ceil(lo_v), math.floor(hi_v) + 1):
    svg.append(f'<text x="{L - 6}" y="{ly(10**e) + 4}" text-anchor="end">1e{e}</text>')
    svg.append(f'<line x1="{L}" y1="{ly(10**e)}" x2="{W - R}" y2="{ly(10**e)}" stroke="#ddd"/>')
svg.append(f'<text x="{(L + W - R) / 2}" y="{H - 12}" text-anchor="middle">samples per pixel</text>')
svg.append(f'<text x="16" y="{(T + H - B) / 2}" transform="rotate(-90 16 {(T + H - B) / 2})" text-anchor="middle">pixel variance</text>')
for i, (name, _, counts) in enumerate(SAMPLERS):
    mine = [r for r in rows if r[0] == name]
    colour, dx = colours[i], (i - 1.5) * 4
    points = " ".join(f"{lx(r[1]) + dx},{ly(r[5])}" for r in mine)
    svg.append(f'<polyline points="{points}" fill="none" stroke="{colour}" stroke-width="1.5"/>')
    alone = " ".join(f"{lx(r[1]) + dx},{ly(r[7])}" for r in mine)
    svg.append(
        f'<polyline points="{alone}" fill="none" stroke="{colour}" stroke-width="1" stroke-dasharray="4 3"/>'
    )
    for r in mine:
        x = lx(r[1]) + dx
        svg.append(f'<line x1="{x}" y1="{ly(r[3])}" x2="{x}" y2="{ly(r[4])}" stroke="{colour}" stroke-width="2"/>')
        svg.append(f'<circle cx="{x}" cy="{ly(r[2])}" r="3" fill="{colour}"/>')
    y = T + 18 * i + 10
    svg.append(f'<line x1="{W - R + 12}" y1="{y}" x2="{W - R + 32}" y2="{y}" stroke="{colour}" stroke-width="1.5"/>')
    svg.append(f'<circle cx="{W - R + 22}" cy="{y}" r="3" fill="{colour}"/>')
    svg.append(f'<text x="{W - R + 38}" y="{y + 4}">{name}</text>')
for i, text in enumerate(["line: predicted,", "  padded 4D", "dashed: the light", "  sample alone", "dot, bar: measured", "  (400 renders, 99%)"]):
    svg.append(f'<text x="{W - R + 12}" y="{T + 18 * (i + 4) + 14}" xml:space="preserve">{text}</text>')
svg.append("</svg>")
with open(os.path.join(OUT, "cornell_variance.svg"), "w") as fh:
    fh.write("\n".join(svg))
print(f"\nwrote {os.path.join(OUT, 'cornell_crop.png')} and {os.path.join(OUT, 'cornell_variance.svg')}")
