//! NumPy's `.npy` array files: the format `numpy.save` writes, read into `f64` values in C
//! order with their shape.
//!
//! A file is the magic `\x93NUMPY`, a version (1.0 with a 2-byte header length; 2.0 and 3.0
//! with 4 bytes), and a header, a Python dictionary literal with `descr` (the element type),
//! `fortran_order` and `shape`, then the data. Little-endian `f8`, `f4`, `u2`, `i4`, `i8` and
//! one-byte `u1` are read; other element types and Fortran order are refused with what to
//! write instead.

use crate::error::{Error, Result};

/// The first bytes of every `.npy` file.
pub const MAGIC: &[u8] = b"\x93NUMPY";

/// An array read from a `.npy` file.
#[derive(Debug, Clone, PartialEq)]
pub struct NpyArray {
    /// Its shape, outermost axis first.
    pub shape: Vec<usize>,
    /// Its values in C order (the last axis varies fastest).
    pub values: Vec<f64>,
}

/// The element types read.
#[derive(Debug, Clone, Copy)]
enum Element {
    F8,
    F4,
    U1,
    U2,
    I4,
    I8,
}

impl Element {
    fn parse(descr: &str) -> Option<Self> {
        Some(match descr {
            "<f8" => Element::F8,
            "<f4" => Element::F4,
            "|u1" | "<u1" => Element::U1,
            "<u2" => Element::U2,
            "<i4" => Element::I4,
            "<i8" => Element::I8,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Element::U1 => 1,
            Element::U2 => 2,
            Element::F4 | Element::I4 => 4,
            Element::F8 | Element::I8 => 8,
        }
    }

    fn read(self, b: &[u8]) -> f64 {
        match self {
            Element::F8 => f64::from_le_bytes(b.try_into().unwrap_or([0; 8])),
            Element::F4 => f32::from_le_bytes(b.try_into().unwrap_or([0; 4])) as f64,
            Element::U1 => b[0] as f64,
            Element::U2 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Element::I4 => i32::from_le_bytes(b.try_into().unwrap_or([0; 4])) as f64,
            Element::I8 => i64::from_le_bytes(b.try_into().unwrap_or([0; 8])) as f64,
        }
    }
}

/// Parses a `.npy` file's bytes.
///
/// # Errors
/// Bytes that are not a `.npy` file, an element type other than those read, Fortran order, a
/// shape whose product does not match the data, or a value that is not finite; each message
/// says what was found and what is read.
///
/// # Examples
/// ```
/// use specvar::npy::read_npy;
/// // numpy.save of np.array([[1.0, 2.0, 3.0]]) (header padded to 64 bytes).
/// let header = "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3), }";
/// let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
/// let padded = format!("{header:<55}\n");
/// bytes.extend_from_slice(&(padded.len() as u16).to_le_bytes());
/// bytes.extend_from_slice(padded.as_bytes());
/// for v in [1.0f64, 2.0, 3.0] {
///     bytes.extend_from_slice(&v.to_le_bytes());
/// }
/// let array = read_npy(&bytes)?;
/// assert_eq!((array.shape, array.values), (vec![1, 3], vec![1.0, 2.0, 3.0]));
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn read_npy(bytes: &[u8]) -> Result<NpyArray> {
    let bad = |message: String| Error::format(".npy array", message);
    if !bytes.starts_with(MAGIC) || bytes.len() < 10 {
        return Err(bad("not a .npy file (no \\x93NUMPY magic)".into()));
    }
    let (length, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => return Err(bad(format!("version {v} (1, 2 and 3 are read)"))),
    };
    let header = bytes
        .get(start..start + length)
        .and_then(|h| std::str::from_utf8(h).ok())
        .ok_or_else(|| bad("a header shorter than its stated length".into()))?;
    let descr =
        quoted_value(header, "descr").ok_or_else(|| bad("no 'descr' in the header".into()))?;
    let element = Element::parse(descr).ok_or_else(|| {
        bad(format!(
            "element type {descr} (read: <f8, <f4, u1, <u2, <i4, <i8; convert with \
             array.astype(np.float64))"
        ))
    })?;
    if header.contains("'fortran_order': True") {
        return Err(bad(
            "Fortran order (save np.ascontiguousarray(array) instead)".into(),
        ));
    }
    let shape = shape(header).ok_or_else(|| bad("no readable 'shape' in the header".into()))?;
    let count = shape
        .iter()
        .try_fold(1usize, |acc, &s| acc.checked_mul(s))
        .ok_or_else(|| bad(format!("shape {shape:?} overflows")))?;
    let data = &bytes[start + length..];
    let needed = count.saturating_mul(element.size());
    if data.len() != needed {
        return Err(bad(format!(
            "shape {shape:?} needs {needed} bytes of data, the file has {}",
            data.len()
        )));
    }
    let values: Vec<f64> = data
        .chunks_exact(element.size())
        .map(|b| element.read(b))
        .collect();
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(bad(format!(
            "value {i} is {} (finite values only)",
            values[i]
        )));
    }
    Ok(NpyArray { shape, values })
}

/// The string value of `key` in a header dictionary: `'key': 'value'`.
fn quoted_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let after = &header[header.find(&format!("'{key}'"))? + key.len() + 2..];
    let after = after.trim_start().strip_prefix(':')?.trim_start();
    let quote = after.chars().next().filter(|c| *c == '\'' || *c == '"')?;
    let body = &after[1..];
    Some(&body[..body.find(quote)?])
}

/// The `shape` tuple of a header: `'shape': (2, 3)`, `(4,)` or `()`.
fn shape(header: &str) -> Option<Vec<usize>> {
    let after = &header[header.find("'shape'")? + 7..];
    let after = after.trim_start().strip_prefix(':')?.trim_start();
    let inner = &after.strip_prefix('(')?[..after[1..].find(')')?];
    inner
        .split(',')
        .map(str::trim)
        .filter(|t| !t.is_empty())
        .map(|t| t.trim_end_matches('L').parse().ok())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn npy(header: &str, data: &[u8]) -> Vec<u8> {
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        let padded = format!("{header}\n");
        bytes.extend_from_slice(&(padded.len() as u16).to_le_bytes());
        bytes.extend_from_slice(padded.as_bytes());
        bytes.extend_from_slice(data);
        bytes
    }

    #[test]
    fn element_types_and_shapes() {
        let h = "{'descr': '<u2', 'fortran_order': False, 'shape': (2, 2), }";
        let data: Vec<u8> = [1u16, 2, 65535, 0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let a = read_npy(&npy(h, &data)).unwrap();
        assert_eq!(a.shape, vec![2, 2]);
        assert_eq!(a.values, vec![1.0, 2.0, 65535.0, 0.0]);
        let h = "{'descr': '|u1', 'fortran_order': False, 'shape': (3,), }";
        assert_eq!(read_npy(&npy(h, &[7, 8, 9])).unwrap().shape, vec![3]);
    }

    #[test]
    fn refusals_say_what_was_found() {
        let h = "{'descr': '>f8', 'fortran_order': False, 'shape': (1,), }";
        let e = read_npy(&npy(h, &[0; 8])).unwrap_err().to_string();
        assert!(e.contains(">f8"), "{e}");
        let h = "{'descr': '<f8', 'fortran_order': True, 'shape': (1,), }";
        assert!(read_npy(&npy(h, &[0; 8]))
            .unwrap_err()
            .to_string()
            .contains("Fortran"));
        let h = "{'descr': '<f8', 'fortran_order': False, 'shape': (2,), }";
        assert!(read_npy(&npy(h, &[0; 8]))
            .unwrap_err()
            .to_string()
            .contains("16 bytes"));
        assert!(read_npy(b"P6 not an array").is_err());
        let nan = f64::NAN.to_le_bytes();
        let h = "{'descr': '<f8', 'fortran_order': False, 'shape': (1,), }";
        assert!(read_npy(&npy(h, &nan)).is_err());
    }
}
