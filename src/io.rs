//! Point-set files: UTK's text format and a JSON form.
//!
//! **Text (UTK):** one point per line, coordinates separated by white space; a line that begins
//! with `#` ends the current realization. Blank lines carry nothing and are skipped.
//!
//! **JSON:** `{"dimension": d, "realizations": [[[x, y], [x, y], ...], ...]}`.
//!
//! Every parser returns a point set for each realization or an [`Error::Parse`] naming the line;
//! no value is silently dropped.

use crate::error::{Error, Result};
use crate::pointset::{check_dimension, PointSet};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

fn parse_error(line: usize, message: impl Into<String>) -> Error {
    Error::Parse {
        line,
        message: message.into(),
    }
}

/// Parses UTK text into one point set per realization.
///
/// # Errors
/// A line with a different number of columns from the first point, a value that is not a
/// number or not in `[0, 1)`, a dimension above 8, or a text with no points.
///
/// # Examples
/// ```
/// let sets = specvar::io::read_text("0.1 0.2\n0.3 0.4\n#\n0.5 0.6\n").unwrap();
/// assert_eq!(sets.len(), 2);
/// assert_eq!(sets[0].len(), 2);
/// assert!(specvar::io::read_text("0.1 0.2\n0.3\n").is_err());
/// ```
pub fn read_text(text: &str) -> Result<Vec<PointSet>> {
    let mut sets = Vec::new();
    let mut current: Vec<f64> = Vec::new();
    let mut dimension: Option<usize> = None;
    let flush = |current: &mut Vec<f64>, dimension: Option<usize>, sets: &mut Vec<PointSet>| {
        if let (Some(d), false) = (dimension, current.is_empty()) {
            sets.push(PointSet::from_trusted(d, std::mem::take(current)));
        }
    };
    for (index, raw) in text.lines().enumerate() {
        let line_no = index + 1;
        let line = raw.trim();
        if line.starts_with('#') {
            flush(&mut current, dimension, &mut sets);
            continue;
        }
        if line.is_empty() {
            continue;
        }
        let before = current.len();
        for token in line.split_whitespace() {
            let v: f64 = token
                .parse()
                .map_err(|_| parse_error(line_no, format!("'{token}' is not a number")))?;
            if !(0.0..1.0).contains(&v) {
                return Err(parse_error(
                    line_no,
                    format!("coordinate {token} is outside [0, 1)"),
                ));
            }
            current.push(v);
        }
        let columns = current.len() - before;
        match dimension {
            None => {
                check_dimension(columns).map_err(|_| {
                    parse_error(line_no, format!("{columns} columns; allowed 1 to 8"))
                })?;
                dimension = Some(columns);
            }
            Some(d) if d != columns => {
                return Err(parse_error(
                    line_no,
                    format!("{columns} columns, but the first point has {d}"),
                ))
            }
            Some(_) => {}
        }
    }
    flush(&mut current, dimension, &mut sets);
    if sets.is_empty() {
        return Err(parse_error(1, "no points found"));
    }
    Ok(sets)
}

/// Formats point sets as UTK text: realizations separated by a `#` line.
pub fn write_text(sets: &[PointSet]) -> String {
    let mut out = String::new();
    for (r, set) in sets.iter().enumerate() {
        if r > 0 {
            out.push_str("#\n");
        }
        for p in set.points() {
            for (j, c) in p.iter().enumerate() {
                if j > 0 {
                    out.push(' ');
                }
                // `{}` prints the shortest text that parses back to the same f64.
                let _ = write!(out, "{c}");
            }
            out.push('\n');
        }
    }
    out
}

#[derive(Serialize, Deserialize)]
struct JsonSets {
    dimension: usize,
    realizations: Vec<Vec<Vec<f64>>>,
}

/// Parses the JSON form into one point set per realization.
///
/// # Errors
/// Malformed JSON (with its line), a point with the wrong number of coordinates, a value outside
/// `[0, 1)`, an empty realization or no realizations.
///
/// # Examples
/// ```
/// let sets = specvar::io::read_json(r#"{"dimension": 1, "realizations": [[[0.25], [0.5]]]}"#).unwrap();
/// assert_eq!(sets[0].len(), 2);
/// ```
pub fn read_json(text: &str) -> Result<Vec<PointSet>> {
    let parsed: JsonSets =
        serde_json::from_str(text).map_err(|e| parse_error(e.line(), e.to_string()))?;
    let d = parsed.dimension;
    check_dimension(d).map_err(|e| parse_error(1, e.to_string()))?;
    if parsed.realizations.is_empty() {
        return Err(parse_error(1, "no realizations"));
    }
    // Serde drops positions once parsed; locate points by realization and index instead.
    let mut sets = Vec::with_capacity(parsed.realizations.len());
    for (r, points) in parsed.realizations.into_iter().enumerate() {
        if points.is_empty() {
            return Err(parse_error(1, format!("realization {r} has no points")));
        }
        let mut coords = Vec::with_capacity(points.len() * d);
        for (i, p) in points.into_iter().enumerate() {
            if p.len() != d {
                return Err(parse_error(
                    1,
                    format!(
                        "realization {r}, point {i}: {} coordinates, expected {d}",
                        p.len()
                    ),
                ));
            }
            if let Some(v) = p.iter().find(|v| !(0.0..1.0).contains(*v)) {
                return Err(parse_error(
                    1,
                    format!("realization {r}, point {i}: coordinate {v} is outside [0, 1)"),
                ));
            }
            coords.extend(p);
        }
        sets.push(PointSet::from_trusted(d, coords));
    }
    Ok(sets)
}

/// Formats point sets as JSON (all of one dimension).
///
/// # Errors
/// An empty slice or sets of different dimensions.
pub fn write_json(sets: &[PointSet]) -> Result<String> {
    let d = sets
        .first()
        .ok_or_else(|| Error::Mismatch("no point sets to write".into()))?
        .dimension();
    if sets.iter().any(|s| s.dimension() != d) {
        return Err(Error::Mismatch("point sets of different dimensions".into()));
    }
    let doc = JsonSets {
        dimension: d,
        realizations: sets
            .iter()
            .map(|s| s.points().map(<[f64]>::to_vec).collect())
            .collect(),
    };
    serde_json::to_string(&doc).map_err(|e| Error::format("point sets", e))
}

/// Reads a point-set file, choosing JSON when the first non-blank character is `{`.
///
/// # Errors
/// As [`read_text`] and [`read_json`], and [`Error::Io`] if the file cannot be read.
pub fn read_file(path: &std::path::Path) -> Result<Vec<PointSet>> {
    let bytes = read_bounded(path)?;
    let text = String::from_utf8(bytes)
        .map_err(|_| Error::format(path.display().to_string(), "not UTF-8 text"))?;
    if text.trim_start().starts_with('{') {
        read_json(&text)
    } else {
        read_text(&text)
    }
}

/// The largest input file read, in bytes (1 GiB): a bound checked while reading, so that a
/// device or a runaway file fails fast instead of filling memory.
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// Reads a whole file of at most [`MAX_FILE_BYTES`].
///
/// # Errors
/// An unreadable file, or one larger than the bound ([`Error::TooLarge`]).
pub fn read_bounded(path: &std::path::Path) -> Result<Vec<u8>> {
    use std::io::Read;
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut bytes = Vec::new();
    file.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(Error::TooLarge {
            what: format!("reading {}", path.display()),
            needed: "more than 1 GiB".into(),
            budget: "1 GiB".into(),
            advice: "split the file".into(),
        });
    }
    Ok(bytes)
}
