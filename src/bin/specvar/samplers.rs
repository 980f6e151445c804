//! `specvar samplers`: the table of samplers and their facts.

use specvar::sampler::SamplerKind;

/// Arguments of `specvar samplers`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

#[derive(serde::Serialize)]
struct Row {
    name: SamplerKind,
    min_dimension: usize,
    max_dimension: usize,
    n_rule: &'static str,
    scaling: specvar::sampler::Scaling,
    isotropic: bool,
    known_alpha: Option<f64>,
    cost_per_point_ns: f64,
    description: &'static str,
}

/// Prints every sampler with its dimensions, N rule and facts.
pub fn run(args: &Args) -> specvar::Result<()> {
    let rows: Vec<Row> = SamplerKind::ALL
        .iter()
        .map(|&k| Row {
            name: k,
            min_dimension: *k.dimensions().start(),
            max_dimension: *k.dimensions().end(),
            n_rule: k.count_rule(),
            scaling: k.scaling(),
            isotropic: k.is_isotropic(),
            known_alpha: k.known_alpha(),
            cost_per_point_ns: k.cost_per_point_ns(),
            description: k.description(),
        })
        .collect();
    if args.json {
        println!("{}", super::to_json(&rows)?);
        return Ok(());
    }
    println!("{:<8} {:<11} {:<24} description", "name", "dimensions", "N");
    for r in &rows {
        let dims = format!("{}-{}", r.min_dimension, r.max_dimension);
        println!(
            "{:<8} {dims:<11} {:<24} {}",
            r.name, r.n_rule, r.description
        );
    }
    Ok(())
}
