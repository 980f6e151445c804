//! `specvar render-ao`: ambient occlusion rendered with every sampler (or one), the measured MSE
//! and the MSE predicted from spectra.

use specvar::randomization::{Randomization, RandomizationChoice};
use specvar::render::{
    comparison_table, measured_ratio, run_comparison, samplers_for_rays, talk_ratio,
    write_comparison, ComparisonConfig,
};
use specvar::sampler::SamplerKind;
use specvar::Result;
use std::path::PathBuf;

/// Arguments of `specvar render-ao` (what is not given takes the library's defaults).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Sampler name, or `all` for the comparison run over every 2D sampler.
    #[arg(long, short = 's', default_value = "all", value_parser = parse_samplers)]
    pub sampler: Samplers,
    /// Secondary rays (points) per pixel [default: 96].
    #[arg(long)]
    pub rays: Option<usize>,
    /// Image width in pixels [default: 128].
    #[arg(long)]
    pub width: Option<usize>,
    /// Image height in pixels [default: 128].
    #[arg(long)]
    pub height: Option<usize>,
    /// Independent uniform rays per pixel of the reference (cached) [default: 16384].
    #[arg(long)]
    pub reference_rays: Option<usize>,
    /// Output directory: images and table (specvar's earlier ones there are replaced; other
    /// files stay).
    #[arg(long, default_value = "render")]
    pub out: PathBuf,

    /// Maximum occlusion distance (the room's side is 1) [default: 0.5].
    #[arg(long)]
    pub max_distance: Option<f64>,
    /// Distinct patterns per image, each shared by pixels under their own shifts [default: 1024].
    #[arg(long)]
    pub patterns: Option<usize>,
    /// Cells per side of each pixel's visibility grid for the prediction [default: 64].
    #[arg(long)]
    pub grid: Option<usize>,
    /// Largest frequency per axis of the prediction's lattice [default: 64].
    #[arg(long)]
    pub kmax: Option<usize>,
    /// Use every STRIDE-th pixel per axis for the prediction [default: 1].
    #[arg(long)]
    pub stride: Option<usize>,
    /// Realizations of the sampler's spectrum at N for the prediction [default: 512].
    #[arg(long)]
    pub spectrum_realizations: Option<usize>,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// How each pixel randomizes its pattern, for the render and the prediction alike: shift
    /// (the default: a random toroidal shift per pixel, the talk's homogenized estimator),
    /// native (each sampler as a renderer uses it: strata and nets as drawn, fixed rules
    /// shifted), digital-shift, or none.
    #[arg(long, default_value_t = RandomizationChoice::Given(Randomization::Shift))]
    pub randomization: RandomizationChoice,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

/// The samplers to render.
#[derive(Debug, Clone)]
pub enum Samplers {
    /// Every 2D sampler that can draw the ray count.
    All,
    /// One sampler.
    One(SamplerKind),
}

fn parse_samplers(text: &str) -> Result<Samplers> {
    Ok(match text.trim() {
        "all" => Samplers::All,
        name => Samplers::One(SamplerKind::from_name(name)?),
    })
}

impl Args {
    fn config(&self, ctx: &super::Context) -> ComparisonConfig {
        let d = ComparisonConfig::default();
        let mut c = ComparisonConfig {
            width: self.width.unwrap_or(d.width),
            height: self.height.unwrap_or(d.height),
            samplers: Vec::new(),
            reference_rays: self.reference_rays.unwrap_or(d.reference_rays),
            spectrum_realizations: self
                .spectrum_realizations
                .unwrap_or(d.spectrum_realizations),
            cache_dir: ctx.cache.clone(),
            ..d
        };
        c.render.rays = self.rays.unwrap_or(c.render.rays);
        c.samplers = match self.sampler {
            Samplers::All => samplers_for_rays(c.render.rays),
            Samplers::One(kind) => vec![kind],
        };
        c.render.max_distance = self.max_distance.unwrap_or(c.render.max_distance);
        c.render.patterns = self.patterns.unwrap_or(c.render.patterns);
        c.render.seed = self.seed;
        c.render.randomization = self.randomization;
        c.pixel_power.resolution = self.grid.unwrap_or(c.pixel_power.resolution);
        c.pixel_power.kmax = self.kmax.unwrap_or(c.pixel_power.kmax);
        c.pixel_power.stride = self.stride.unwrap_or(c.pixel_power.stride);
        c
    }
}

#[derive(serde::Serialize)]
struct Row {
    sampler: SamplerKind,
    rays: usize,
    mse: f64,
    mse_stderr: f64,
    predicted_mse: f64,
    predicted_stderr: f64,
    randomization: Randomization,
    route: String,
}

/// Renders, measures, predicts, writes the images and prints the table.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    let mut config = args.config(ctx);
    specvar::output::check_output_dir(&args.out)?;
    // Every sampler whose estimator has a route and an MSE equal to its variance (Gaussian
    // jitter as drawn has a bias).
    let mut unrouted = Vec::new();
    if let Samplers::All = args.sampler {
        let disk = specvar::integrand::Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
        config.samplers.retain(|&kind| {
            let routed = kind.build(2).and_then(|s| {
                let n = kind.nearest_count(config.render.rays, 2);
                let r = config
                    .render
                    .randomization
                    .resolve(kind.native_randomization());
                specvar::predict::check_route(
                    &specvar::predict::Problem::new(s.as_ref(), &disk, n)?.with_randomization(r),
                )?;
                specvar::predict::check_unbiased(kind, r)
            });
            if routed.is_err() {
                unrouted.push(kind.name());
            }
            routed.is_ok()
        });
    }
    let run = run_comparison(&config, &super::bars::Bars::default())?;
    specvar::output::write_dir(&args.out, |dir| {
        write_comparison(dir, &run.rows, &run.reference)
    })?;
    if args.json {
        let rows: Vec<Row> = run
            .rows
            .iter()
            .map(|r| Row {
                sampler: r.sampler,
                rays: r.rays,
                mse: r.measured.mse,
                mse_stderr: r.measured.stderr,
                predicted_mse: r.predicted.variance,
                predicted_stderr: r.predicted.budget.spectrum_noise,
                randomization: r.predicted.randomization,
                route: r.predicted.route.to_string(),
            })
            .collect();
        match rows.as_slice() {
            [one] => outln!("{}", super::to_json(one)?)?,
            _ => outln!("{}", super::to_json(&rows)?)?,
        }
        return Ok(());
    }
    let cached = if run.reference_cached {
        " (cached)"
    } else {
        ""
    };
    outln!(
        "{} × {} pixels, {} rays per pixel; reference: {} rays per pixel{cached}",
        config.width,
        config.height,
        config.render.rays,
        config.reference_rays
    )?;
    outln!(
        "estimator: {} ({})",
        config.render.randomization.estimator(),
        config.render.randomization.per_trial()
    )?;
    outln!("prediction: {}", run.power_label)?;
    if !unrouted.is_empty() {
        outln!(
            "left out, their estimator having no prediction route (measure them with `specvar \
             mc`): {}",
            unrouted.join(", ")
        )?;
    }
    out!("{}", comparison_table(&run.rows))?;
    let (random, jitter) = (SamplerKind::Random, SamplerKind::Jitter);
    if let (Some(r), Some(talk)) = (
        measured_ratio(&run.rows, random, jitter),
        talk_ratio(random, jitter),
    ) {
        outln!("random / jitter MSE: {r:.2} (talk: {talk:.2})")?;
    }
    outln!("images and table in {}", args.out.display())?;
    Ok(())
}
