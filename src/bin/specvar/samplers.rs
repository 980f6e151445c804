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
        outln!("{}", super::to_json(&rows)?)?;
        return Ok(());
    }
    // Widths in characters: the rules hold multi-byte symbols (×, ≤, …).
    let pad = |text: &str, width: usize| {
        let fill = width.saturating_sub(text.chars().count());
        format!("{text}{}", " ".repeat(fill))
    };
    let rule_width = rows
        .iter()
        .map(|r| r.n_rule.chars().count())
        .max()
        .unwrap_or(1);
    let name_width = rows.iter().map(|r| r.name.name().len()).max().unwrap_or(4);
    let header = [
        pad("name", name_width),
        pad("dimensions", 10),
        pad("N", rule_width),
    ];
    outln!("{} description", header.join(" "))?;
    for r in &rows {
        let dims = if r.min_dimension == r.max_dimension {
            r.min_dimension.to_string()
        } else {
            format!("{}-{}", r.min_dimension, r.max_dimension)
        };
        let cells = [
            pad(r.name.name(), name_width),
            pad(&dims, 10),
            pad(r.n_rule, rule_width),
        ];
        outln!("{} {}", cells.join(" "), r.description)?;
    }
    Ok(())
}
