//! Grid files: a function tabulated on `[0,1)²` as text or as a PNG image.
//!
//! **Text:** one row of cells per line, values separated by white space or commas; lines that
//! begin with `#` and blank lines are skipped. Every row has the same number of values.
//!
//! **PNG:** grey, grey with alpha, RGB or RGBA, 8 or 16 bits (palette and low bit depths are
//! expanded). A cell's value is the stored grey level in `[0, 1]`, or for colour the Rec. 709
//! luma `0.2126 R + 0.7152 G + 0.0722 B` of the stored values (no gamma decoding); alpha is
//! ignored.
//!
//! In both, the first row is the top of the picture: it becomes the cells at the largest `y`, so
//! that an image keeps its orientation in the unit square (`y` up).
//!
//! **`.npy`:** a 2D array `values[y, x]` as NumPy saves it, in the Python package's convention
//! for cell values: row 0 is the bottom row, `y ∈ [0, 1/height)` (an array from
//! `specvar.tabulate` round-trips).

use super::GridIntegrand;
use crate::error::{Error, Result};
use std::path::Path;

/// Parses a text grid.
///
/// # Errors
/// A value that is not a finite number, a row of another length than the first, or no rows;
/// the message names the line.
///
/// # Examples
/// ```
/// use specvar::integrand::{read_grid_text, Integrand};
/// let f = read_grid_text("# a 3 × 2 grid\n1 0 0\n0, 0, 1\n").unwrap();
/// assert_eq!((f.width(), f.height()), (3, 2));
/// assert_eq!(f.eval(&[0.1, 0.9]), 1.0); // the first line is the top row
/// assert!(read_grid_text("1 0\n1\n").is_err());
/// ```
pub fn read_grid_text(text: &str) -> Result<GridIntegrand> {
    let mut rows: Vec<Vec<f64>> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line_number = i + 1;
        let trimmed = line.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let row = trimmed
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|t| !t.is_empty())
            .map(|t| match t.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(parse_error(
                    line_number,
                    format!("{} is not a finite number", crate::error::quoted(t)),
                )),
            })
            .collect::<Result<Vec<f64>>>()?;
        if let Some(first) = rows.first()
            && row.len() != first.len()
        {
            return Err(parse_error(
                line_number,
                format!(
                    "{} values, but the first row has {}",
                    row.len(),
                    first.len()
                ),
            ));
        }
        rows.push(row);
    }
    if rows.is_empty() {
        return Err(parse_error(
            text.lines().count().max(1),
            "no rows: expected lines of numbers",
        ));
    }
    let width = rows[0].len();
    let height = rows.len();
    let values: Vec<f64> = rows.into_iter().rev().flatten().collect();
    GridIntegrand::new(width, height, values)
}

/// The most cells a grid integrand may have (512 MiB of values).
pub const MAX_GRID_CELLS: usize = 1 << 26;

/// Decodes a PNG image into a grid, one cell per pixel.
///
/// # Errors
/// Bytes that are not a PNG image the decoder can read.
pub fn read_grid_png(bytes: &[u8]) -> Result<GridIntegrand> {
    let bad = |e: png::DecodingError| Error::format("PNG image", e);
    let mut decoder = png::Decoder::new(bytes);
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(bad)?;
    let cells = reader.info().width as u64 * reader.info().height as u64;
    check_image_cells(cells)?;
    let mut buffer = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buffer).map_err(bad)?;
    let (width, height) = (info.width as usize, info.height as usize);
    let samples: Vec<f64> = match info.bit_depth {
        png::BitDepth::Sixteen => buffer[..info.buffer_size()]
            .chunks_exact(2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]) as f64 / 65535.0)
            .collect(),
        _ => buffer[..info.buffer_size()]
            .iter()
            .map(|&b| b as f64 / 255.0)
            .collect(),
    };
    let channels = samples.len() / (width * height).max(1);
    let luma = |p: &[f64]| match channels {
        1 | 2 => p[0],
        _ => 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2],
    };
    let mut values = vec![0.0; width * height];
    for (row, pixels) in samples.chunks_exact(width * channels).enumerate() {
        let y = height - 1 - row;
        for (x, p) in pixels.chunks_exact(channels).enumerate() {
            values[y * width + x] = luma(p);
        }
    }
    GridIntegrand::new(width, height, values)
}

/// Reads a grid file: PNG when the file starts with the PNG signature, text otherwise. The
/// integrand is named after the file.
///
/// # Errors
/// As [`read_grid_text`] and [`read_grid_png`], and [`Error::Io`] if the file cannot be read.
pub fn read_grid_file(path: &Path) -> Result<GridIntegrand> {
    let bytes = crate::io::read_bounded(path)?;
    let named_png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    let grid = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        read_grid_png(&bytes)?
    } else if bytes.starts_with(crate::npy::MAGIC) {
        grid_of_array(crate::npy::read_npy(&bytes)?)?
    } else if bytes.starts_with(&EXR_MAGIC) {
        read_grid_exr(&bytes)?
    } else if named_png {
        return Err(Error::format(
            path.display().to_string(),
            "named .png but not a PNG image (its first bytes are not the PNG signature)",
        ));
    } else {
        let text = String::from_utf8(bytes).map_err(|_| {
            Error::format(
                path.display().to_string(),
                "neither a PNG, OpenEXR or .npy file nor UTF-8 text",
            )
        })?;
        read_grid_text(&text)?
    };
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into(),
    );
    let label = format!("grid({name}, {}×{})", grid.width(), grid.height());
    Ok(grid.with_name(label))
}

/// Refuses an image of more cells than the largest grid, before its pixels are read.
fn check_image_cells(cells: u64) -> Result<()> {
    if cells > MAX_GRID_CELLS as u64 {
        return Err(Error::TooLarge {
            what: "a grid integrand".into(),
            needed: format!("{cells} cells"),
            budget: format!("{MAX_GRID_CELLS} cells"),
            advice: "downscale the image".into(),
        });
    }
    Ok(())
}

/// The first four bytes of an OpenEXR file.
const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// An OpenEXR image as a grid, like a PNG: its first layer at its largest resolution, the top
/// row at `y = 1`; the luminance `0.2126 R + 0.7152 G + 0.0722 B` where it has R, G and B
/// channels, else its `Y` channel, else its first channel. Values are the file's own (linear,
/// unbounded: a render's radiance), not scaled to `[0, 1]`.
///
/// # Errors
/// A malformed file, deep data, more cells than the largest grid (checked from the header,
/// before the pixels are read), or a value that is not finite.
pub fn read_grid_exr(bytes: &[u8]) -> Result<GridIntegrand> {
    use exr::prelude::traits::*;
    use exr::prelude::{read, AnyChannel, FlatSamples};
    let bad = |e: exr::error::Error| Error::format("OpenEXR image", e);
    let meta =
        exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false).map_err(bad)?;
    let header = meta
        .headers
        .first()
        .ok_or_else(|| Error::format("OpenEXR image", "no layer"))?;
    let (width, height) = (header.layer_size.0, header.layer_size.1);
    let cells = width as u64 * height as u64;
    check_image_cells(cells)?;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(bad)?;
    let channels = &image.layer_data.channel_data.list;
    let named = |name: &str| channels.iter().find(|c| c.name.eq(name));
    let at = |c: &AnyChannel<FlatSamples>, i: usize| {
        c.sample_data.value_by_flat_index(i).to_f32() as f64
    };
    let value: Box<dyn Fn(usize) -> f64> = match (named("R"), named("G"), named("B")) {
        (Some(r), Some(g), Some(b)) => {
            Box::new(move |i| 0.2126 * at(r, i) + 0.7152 * at(g, i) + 0.0722 * at(b, i))
        }
        _ => {
            let channel = named("Y")
                .or(channels.first())
                .ok_or_else(|| Error::format("OpenEXR image", "no channel"))?;
            Box::new(move |i| at(channel, i))
        }
    };
    let mut values = vec![0.0; width * height];
    for row in 0..height {
        let y = height - 1 - row;
        for x in 0..width {
            values[y * width + x] = value(row * width + x);
        }
    }
    GridIntegrand::new(width, height, values)
}

/// A 2D array `values[y, x]` (row 0 at `y = 0`) as a grid.
///
/// # Errors
/// An array that is not 2D, or larger than the largest grid (`MAX_GRID_CELLS`, 2^26 cells).
pub fn grid_of_array(array: crate::npy::NpyArray) -> Result<GridIntegrand> {
    let &[height, width] = array.shape.as_slice() else {
        return Err(Error::format(
            ".npy grid",
            format!(
                "shape {:?}: a grid is a 2D array values[y, x] (a stack of pixels is predicted \
                 with predict --pixels)",
                array.shape
            ),
        ));
    };
    if width * height > MAX_GRID_CELLS {
        return Err(Error::TooLarge {
            what: "a grid integrand".into(),
            needed: format!("{} cells", width * height),
            budget: format!("{MAX_GRID_CELLS} cells"),
            advice: "downscale the array".into(),
        });
    }
    GridIntegrand::new(width, height, array.values)
}

fn parse_error(line: usize, message: impl Into<String>) -> Error {
    Error::Parse {
        line,
        message: message.into(),
    }
}
