//! Spectra as tables: text, CSV and JSON, for the command line and for other tools.

use super::{LatticeSpectrum, RadialBin, RadialSpectrum};
use crate::error::{Error, Result};
use serde::Serialize;
use std::fmt::Write as _;

/// A table format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableFormat {
    /// Columns separated by spaces, with `#` comment lines on top.
    Text,
    /// Comma-separated with a header row.
    Csv,
    /// One JSON object.
    Json,
}

#[derive(Serialize)]
struct RadialDoc<'a> {
    n: usize,
    dimension: usize,
    realizations: usize,
    method: &'a str,
    bin_width: f64,
    dc_limit: f64,
    bins: &'a [RadialBin],
}

/// A radial spectrum as a table: one row per ring (`nu rho power stderr count anisotropy_db`),
/// or JSON `{"n", "dimension", "realizations", "method", "bin_width", "dc_limit", "bins"}`.
///
/// # Errors
/// A JSON encoding failure.
pub fn radial_table(radial: &RadialSpectrum, method: &str, format: TableFormat) -> Result<String> {
    if format == TableFormat::Json {
        let doc = RadialDoc {
            n: radial.n,
            dimension: radial.dimension,
            realizations: radial.realizations,
            method,
            bin_width: radial.bin_width,
            dc_limit: radial.dc_limit,
            bins: &radial.bins,
        };
        return json(&doc);
    }
    let sep = if format == TableFormat::Csv { "," } else { " " };
    let mut out = if format == TableFormat::Csv {
        String::from("nu,rho,power,stderr,count,anisotropy_db\n")
    } else {
        format!(
            "# radial spectrum: N = {}, d = {}, {} realizations, {method}; P(0+) ≈ {:.4}\n\
             # nu rho power stderr count anisotropy_db\n",
            radial.n, radial.dimension, radial.realizations, radial.dc_limit
        )
    };
    for b in &radial.bins {
        let _ = writeln!(
            out,
            "{:.6}{sep}{:.4}{sep}{:.6}{sep}{:.3e}{sep}{}{sep}{:.3}",
            b.nu, b.rho, b.power, b.stderr, b.count, b.anisotropy_db
        );
    }
    Ok(out)
}

#[derive(Serialize)]
struct LatticeDoc<'a> {
    n: usize,
    dimension: usize,
    realizations: usize,
    method: &'a str,
    kmax: usize,
    shape: Vec<usize>,
    order: &'a str,
    values: &'a [f64],
    stderr: &'a [f64],
}

/// A lattice spectrum as a table: CSV rows `k0,…,power,stderr,dc` (also for
/// [`TableFormat::Text`]), or JSON with the values row-major, first axis slowest.
///
/// # Errors
/// A JSON encoding failure.
pub fn lattice_table(spectrum: &LatticeSpectrum, format: TableFormat) -> Result<String> {
    let lattice = spectrum.lattice;
    if format == TableFormat::Json {
        let doc = LatticeDoc {
            n: spectrum.n,
            dimension: lattice.dimension,
            realizations: spectrum.realizations,
            method: spectrum.engine.name(),
            kmax: lattice.kmax,
            shape: vec![lattice.side(); lattice.dimension],
            order: "row-major, first axis slowest; index i along an axis is frequency i - kmax; \
                    the centre is DC (value N)",
            values: &spectrum.mean,
            stderr: &spectrum.stderr,
        };
        return json(&doc);
    }
    let axes = ["k0", "k1", "k2"];
    let mut out = axes[..lattice.dimension].join(",") + ",power,stderr,dc\n";
    for i in 0..lattice.len() {
        for c in &lattice.frequency(i)[..lattice.dimension] {
            let _ = write!(out, "{c},");
        }
        let _ = writeln!(
            out,
            "{},{},{}",
            spectrum.mean[i],
            spectrum.stderr[i],
            spectrum.is_dc(i)
        );
    }
    Ok(out)
}

fn json(doc: &impl Serialize) -> Result<String> {
    serde_json::to_string(doc)
        .map(|s| s + "\n")
        .map_err(|e| Error::format("spectrum JSON", e))
}
