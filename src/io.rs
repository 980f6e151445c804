//! Point-set files: UTK's text and binary formats and a JSON form.
//!
//! **Text (UTK):** one point per line, coordinates separated by white space; a line that begins
//! with `#` ends the current realization. Blank lines carry nothing and are skipped.
//!
//! **Binary (UTK):** a 20-byte little-endian header — the magic number `UTK!`, four bytes of
//! metadata whose first is the value type (4: `f32`, 5: `f64`; UTK's integer codes 0–3 carry no
//! scale and are refused), then the realizations M, the points N and the dimension d as `u32`
//! — followed by `M · N · d` values, point after point.
//!
//! **JSON:** `{"dimension": d, "realizations": [[[x, y], [x, y], ...], ...]}`.
//!
//! Every parser returns a point set for each realization or an [`Error::Parse`] naming the line;
//! no value is silently dropped.

use crate::error::{quoted, Error, Result};
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
                .map_err(|_| parse_error(line_no, format!("{} is not a number", quoted(token))))?;
            if !(0.0..1.0).contains(&v) {
                return Err(parse_error(
                    line_no,
                    format!("coordinate {} is outside [0, 1)", quoted(token)),
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

/// The memory formatted text takes per coordinate, in bytes (a shortest round-trip double and
/// its separator, about 25 characters), to check against a budget before formatting.
pub const TEXT_BYTES_PER_COORDINATE: f64 = 25.0;

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

/// UTK's binary magic number: the bytes `U`, `T`, `K`, `!`.
pub const UTK_MAGIC: [u8; 4] = *b"UTK!";

/// Parses UTK's binary format (see the module's documentation).
///
/// # Errors
/// [`Error::Format`] for a wrong magic number, an integer or unknown value type, a count of
/// zero or a dimension above 8, a length that does not match the header, or a value that is
/// not in `[0, 1)`.
///
/// # Examples
/// ```
/// use specvar::io::{read_utk_binary, write_utk_binary};
/// let sets = specvar::io::read_text("0.1 0.2\n0.3 0.4\n")?;
/// let bytes = write_utk_binary(&sets)?;
/// assert_eq!(&bytes[..4], b"UTK!");
/// assert_eq!(read_utk_binary(&bytes)?, sets);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn read_utk_binary(bytes: &[u8]) -> Result<Vec<PointSet>> {
    let bad = |message: String| Error::format("UTK binary point sets", message);
    if bytes.len() < 20 || bytes[..4] != UTK_MAGIC {
        return Err(bad(
            "the file does not start with the 20-byte UTK! header".into()
        ));
    }
    let word =
        |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let width = match bytes[4] {
        4 => 4usize,
        5 => 8,
        code @ 0..=3 => {
            return Err(bad(format!(
                "value type {code} is an integer type, which carries no scale to [0, 1); \
                 write the points as float (4) or double (5)"
            )))
        }
        code => {
            return Err(bad(format!(
                "unknown value type {code}; allowed: 4 (float), 5 (double)"
            )))
        }
    };
    let (m, n, d) = (word(8) as usize, word(12) as usize, word(16) as usize);
    if m == 0 || n == 0 {
        return Err(bad(format!(
            "{m} realizations of {n} points: both must be at least 1"
        )));
    }
    check_dimension(d)?;
    let values = m.checked_mul(n).and_then(|c| c.checked_mul(d));
    let expected = values
        .and_then(|v| v.checked_mul(width))
        .and_then(|b| b.checked_add(20));
    if expected != Some(bytes.len()) {
        return Err(bad(format!(
            "the header announces {m} × {n} points in {d}D of {width} bytes ({} bytes in all) \
             but the file has {} bytes",
            expected.map_or("more than addressable".to_string(), |e| e.to_string()),
            bytes.len()
        )));
    }
    let data = &bytes[20..];
    let value = |i: usize| -> f64 {
        let at = i * width;
        if width == 4 {
            f32::from_le_bytes([data[at], data[at + 1], data[at + 2], data[at + 3]]) as f64
        } else {
            let mut b = [0u8; 8];
            b.copy_from_slice(&data[at..at + 8]);
            f64::from_le_bytes(b)
        }
    };
    (0..m)
        .map(|r| {
            let coords: Vec<f64> = (r * n * d..(r + 1) * n * d).map(value).collect();
            if let Some(i) = coords.iter().position(|v| !(0.0..1.0).contains(v)) {
                return Err(bad(format!(
                    "realization {r}, point {}: coordinate {} is not in [0, 1)",
                    (i / d) % n,
                    coords[i]
                )));
            }
            PointSet::new(d, coords)
        })
        .collect()
}

/// Writes point sets (all of one N and dimension) in UTK's binary format, as doubles.
///
/// # Errors
/// No sets, sets of different sizes or dimensions, or counts beyond `u32`.
pub fn write_utk_binary(sets: &[PointSet]) -> Result<Vec<u8>> {
    let first = sets
        .first()
        .ok_or_else(|| Error::Mismatch("no point sets to write".into()))?;
    let (n, d) = (first.len(), first.dimension());
    if sets.iter().any(|s| s.len() != n || s.dimension() != d) {
        return Err(Error::Mismatch(
            "UTK's binary format holds realizations of one N and dimension".into(),
        ));
    }
    let count = |v: usize, what: &'static str| {
        u32::try_from(v).map_err(|_| crate::error::invalid(what, v, "at most 2^32 - 1"))
    };
    let mut bytes = Vec::with_capacity(20 + sets.len() * n * d * 8);
    bytes.extend_from_slice(&UTK_MAGIC);
    bytes.extend_from_slice(&[5, 0, 0, 0]);
    for v in [
        count(sets.len(), "realizations")?,
        count(n, "points")?,
        count(d, "dimension")?,
    ] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    for s in sets {
        for &c in s.coords() {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    Ok(bytes)
}

/// Reads a point-set file: UTK binary when it starts with `UTK!`, JSON when the first
/// non-blank character is `{`, UTK text otherwise.
///
/// # Errors
/// As [`read_utk_binary`], [`read_text`] and [`read_json`], and [`Error::Io`] if the file
/// cannot be read.
pub fn read_file(path: &std::path::Path) -> Result<Vec<PointSet>> {
    let bytes = read_bounded(path)?;
    if bytes.starts_with(&UTK_MAGIC) {
        return read_utk_binary(&bytes);
    }
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
