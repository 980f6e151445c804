//! `specvar samplers`: the table of samplers and their facts.

use specvar::sampler::{SamplerKind, SamplerSummary};

/// Arguments of `specvar samplers`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Print JSON instead of a table.
    #[arg(long, conflicts_with = "markdown")]
    pub json: bool,
    /// Print the facts as a Markdown table (the README's list).
    #[arg(long)]
    pub markdown: bool,
    /// Print, as Markdown, every analysis and the one that answers each sampler, randomization
    /// and kind of integrand at N = 256 (the theory notes' table).
    #[arg(long, conflicts_with_all = ["json", "markdown"])]
    pub analyses: bool,
}

/// Prints every sampler with its dimensions, N rule and facts.
pub fn run(args: &Args) -> specvar::Result<()> {
    let rows: Vec<SamplerSummary> = SamplerKind::ALL.iter().map(|k| k.summary()).collect();
    if args.analyses {
        out!("{}", specvar::predict::analyses_markdown(256))?;
        return Ok(());
    }
    if args.markdown {
        out!("{}", SamplerKind::markdown_table())?;
        return Ok(());
    }
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
        .map(|r| r.count_rule.chars().count())
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
            pad(&r.count_rule, rule_width),
        ];
        outln!("{} {}", cells.join(" "), r.description)?;
    }
    Ok(())
}
