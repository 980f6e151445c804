//! Integrand specifications on the command line: `disk`, `ball`, `gaussian`, with overrides,
//! and `grid:FILE` (also `image:FILE`) for a function tabulated in a text or PNG file (2D; see
//! [`super::read_grid_file`]).
//!
//! `disk:r=0.2,a=2.2568`, `gaussian:sigma=0.0705,a=8`, `gaussian:c=0.3;0.5`. Keys: `r` (ball
//! radius), `sigma` (Gaussian width), `a` (height), `c` (centre: one value for every axis, or
//! `d` values separated by `;`). Defaults: ball `r = 0.25`, Gaussian `sigma = 0.1`, centre 0.5
//! in every coordinate, `a = 1`.

use super::{read_grid_file, Ball, Gaussian, Integrand};
use crate::error::{invalid, Result};

/// A parsed integrand specification (its kind and parameters), buildable in any dimension.
#[derive(Debug, Clone, PartialEq)]
pub struct IntegrandSpec {
    /// `ball` (also `disk`), `gaussian` or `grid` (also `image`).
    pub kind: String,
    /// The file of a `grid`.
    pub file: Option<std::path::PathBuf>,
    /// Radius (ball) or σ (Gaussian).
    pub scale: f64,
    /// Height `a`.
    pub height: f64,
    /// Centre, if given: one value (all axes) or one per axis.
    pub centre: Option<Vec<f64>>,
    /// The text it was parsed from.
    pub text: String,
}

const KEYS: &str = "accepted keys: r (ball radius), sigma (Gaussian width), a (height), \
                    c (centre, one value or d values separated by ';')";

/// Parses an integrand specification.
///
/// # Errors
/// An unknown kind, an unknown key, a key that does not fit the kind, or a value that is not a
/// number; the message lists the accepted keys.
///
/// # Examples
/// ```
/// use specvar::integrand::{parse_integrand, Integrand};
/// let spec = parse_integrand("disk:r=0.2,a=2").unwrap();
/// let disk = spec.build(2).unwrap();
/// assert!((disk.integral() - 2.0 * std::f64::consts::PI * 0.04).abs() < 1e-12);
/// assert!(parse_integrand("disk:radius=0.2").is_err());
/// ```
pub fn parse_integrand(text: &str) -> Result<IntegrandSpec> {
    let (kind, rest) = text.split_once(':').unwrap_or((text, ""));
    let kind = match kind.trim() {
        "disk" | "ball" => "ball",
        "gaussian" => "gaussian",
        "grid" | "image" => "grid",
        other => {
            return Err(invalid(
                "integrand",
                other,
                "disk, ball or gaussian, with optional overrides such as disk:r=0.2,a=2, \
                 or grid:FILE for a text or PNG grid",
            ))
        }
    };
    if kind == "grid" {
        if rest.trim().is_empty() {
            return Err(invalid("integrand", text, "grid:FILE with a file name"));
        }
        return Ok(IntegrandSpec {
            kind: kind.to_string(),
            file: Some(rest.trim().into()),
            scale: 1.0,
            height: 1.0,
            centre: None,
            text: text.to_string(),
        });
    }
    let mut spec = IntegrandSpec {
        kind: kind.to_string(),
        file: None,
        scale: if kind == "ball" { 0.25 } else { 0.1 },
        height: 1.0,
        centre: None,
        text: text.to_string(),
    };
    for pair in rest.split(',').filter(|p| !p.trim().is_empty()) {
        let (key, value) = pair
            .split_once('=')
            .ok_or_else(|| invalid("integrand override", pair, KEYS))?;
        let number = |v: &str| -> Result<f64> {
            v.trim()
                .parse::<f64>()
                .map_err(|_| invalid("integrand value", format!("{key}={v}"), "a number"))
        };
        match (key.trim(), kind) {
            ("r", "ball") | ("sigma", "gaussian") => spec.scale = number(value)?,
            ("a", _) => spec.height = number(value)?,
            ("c", _) => {
                spec.centre = Some(value.split(';').map(number).collect::<Result<Vec<_>>>()?)
            }
            (other, _) => {
                return Err(invalid(
                    "integrand key",
                    format!("{other} (for {kind})"),
                    KEYS,
                ))
            }
        }
    }
    Ok(spec)
}

impl IntegrandSpec {
    /// Builds the integrand in dimension `d`.
    ///
    /// # Errors
    /// A centre of the wrong length, or invalid parameters (see [`Ball::new`],
    /// [`Gaussian::new`]); for a grid, a dimension other than 2 or an unreadable file.
    pub fn build(&self, d: usize) -> Result<Box<dyn Integrand>> {
        if let Some(file) = &self.file {
            if d != 2 {
                return Err(invalid("dimension", d, "2 for a grid integrand"));
            }
            return Ok(Box::new(read_grid_file(file)?));
        }
        let centre = match &self.centre {
            None => vec![0.5; d],
            Some(c) if c.len() == 1 => vec![c[0]; d],
            Some(c) if c.len() == d => c.clone(),
            Some(c) => {
                return Err(invalid(
                    "centre",
                    format!("{c:?}"),
                    format!("one value or {d} values separated by ';'"),
                ))
            }
        };
        Ok(match self.kind.as_str() {
            "ball" => Box::new(Ball::new(self.scale, centre, self.height)?),
            _ => Box::new(Gaussian::new(self.scale, centre, self.height)?),
        })
    }
}
