//! Where specvar keeps what it computed once and can reuse (reference images, and later
//! spectra and costly patterns): never in the repository or the working directory.
//!
//! The directory is `$SPECVAR_CACHE_DIR` if set, else `$XDG_CACHE_HOME/specvar`, else
//! `$HOME/.cache/specvar`, else `specvar-cache` under the system's temporary directory.
//! Deleting it at any time is safe: everything in it is recomputed when missing.

use std::path::PathBuf;

/// The environment variable that overrides the cache directory.
pub const CACHE_DIR_VARIABLE: &str = "SPECVAR_CACHE_DIR";

/// The cache directory (see the module notes); it may not exist yet.
///
/// # Examples
/// ```
/// let dir = specvar::cache::default_dir();
/// assert!(dir.is_absolute() || std::env::var_os("SPECVAR_CACHE_DIR").is_some());
/// ```
pub fn default_dir() -> PathBuf {
    let var = |name: &str| {
        std::env::var_os(name)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    if let Some(dir) = var(CACHE_DIR_VARIABLE) {
        return dir;
    }
    if let Some(xdg) = var("XDG_CACHE_HOME") {
        return xdg.join("specvar");
    }
    if let Some(home) = var("HOME") {
        return home.join(".cache").join("specvar");
    }
    std::env::temp_dir().join("specvar-cache")
}

use crate::error::{Error, Result};

/// Checks that `dir` can hold cached files (creating it), so that a caller can warn once: the
/// library itself goes on without a cache where it cannot write one, at the cost of time.
///
/// # Errors
/// A directory that cannot be created or written, named in the error.
pub fn check_writable(dir: &std::path::Path) -> Result<()> {
    let probe = dir.join(format!(".write-probe-{}", std::process::id()));
    std::fs::create_dir_all(dir)
        .and_then(|()| std::fs::write(&probe, b""))
        .and_then(|()| std::fs::remove_file(&probe))
        .map_err(|e| Error::io(dir, e))
}
use crate::pointset::PointSet;
use crate::sampler::{Sampler, SamplerKind};

/// The format version of cached patterns: a change of a sampler's algorithm bumps it, so that
/// older patterns are recomputed instead of read.
pub const PATTERN_FORMAT: u32 = 5;

const MAGIC: &[u8; 4] = b"SPVP";

/// Bytes before a stored pattern's coordinates: the magic, the format, the dimension, the
/// point count and the parameters' hash.
const HEADER_BYTES: usize = 4 + 4 + 4 + 8 + 8;

/// A sampler whose patterns are kept on disk under a cache directory, keyed by the sampler's
/// kind, dimension and parameters (a hash of its `Debug` text, which names them all, kept in
/// each file's header too), N, seed and realization and by [`PATTERN_FORMAT`]: a costly pattern (CCVT,
/// dart throwing) is drawn once across runs. A file that is missing, truncated, damaged (its
/// checksum differs) or of another format is drawn again and rewritten atomically. The
/// patterns are the inner sampler's, bit for bit.
///
/// # Examples
/// ```
/// use specvar::cache::DiskCached;
/// use specvar::sampler::{PoissonDisk, Sampler, SamplerKind};
/// let dir = std::env::temp_dir().join("specvar-doc-pattern-cache");
/// let cached = DiskCached::new(SamplerKind::PoissonDisk.build(2)?, dir)?;
/// let a = cached.sample(64, 7, 0)?; // drawn and stored
/// let b = cached.sample(64, 7, 0)?; // read back
/// assert_eq!(a, b);
/// assert_eq!(a, PoissonDisk::new(2)?.sample(64, 7, 0)?);
/// # Ok::<(), specvar::Error>(())
/// ```
pub struct DiskCached {
    inner: Box<dyn Sampler>,
    kind: SamplerKind,
    /// FNV-1a of the inner sampler's `Debug` text: its parameters.
    parameters: u64,
    dir: PathBuf,
}

impl DiskCached {
    /// Caches `inner`'s patterns under `dir`.
    ///
    /// # Errors
    /// A sampler of no [`SamplerKind`] (its patterns cannot be keyed).
    pub fn new(inner: Box<dyn Sampler>, dir: PathBuf) -> Result<Self> {
        let kind = inner.kind().ok_or_else(|| {
            crate::error::invalid(
                "sampler",
                inner.name(),
                "one of specvar's samplers, to key its patterns",
            )
        })?;
        let parameters = checksum(format!("{inner:?}").as_bytes());
        Ok(Self {
            inner,
            kind,
            parameters,
            dir,
        })
    }

    fn path(&self, n: usize, seed: u64, realization: u64) -> PathBuf {
        self.dir.join(format!(
            "patterns-v{PATTERN_FORMAT}/{}-d{}/p{:016x}/n{n}-s{seed}/{realization}.bin",
            self.kind,
            self.inner.dimension(),
            self.parameters
        ))
    }

    fn load(&self, path: &std::path::Path, n: usize) -> Option<PointSet> {
        let bytes = std::fs::read(path).ok()?;
        let d = self.inner.dimension();
        let header = HEADER_BYTES;
        let payload = n * d * 8;
        if bytes.len() != header + payload + 8 || &bytes[..4] != MAGIC {
            return None;
        }
        let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap_or([0; 4]));
        let long = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap_or([0; 8]));
        if word(4) != PATTERN_FORMAT
            || word(8) as usize != d
            || long(12) as usize != n
            || long(20) != self.parameters
        {
            return None;
        }
        let mut sum = WordChecksum::default();
        let coords = bytes[header..header + payload]
            .chunks_exact(8)
            .map(|c| {
                let word = u64::from_le_bytes(c.try_into().unwrap_or([0; 8]));
                sum.add(word);
                f64::from_bits(word)
            })
            .collect();
        if long(header + payload) != sum.value() {
            return None;
        }
        PointSet::new(d, coords).ok()
    }

    fn store(&self, path: &std::path::Path, points: &PointSet) -> Result<()> {
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, e))?;
        }
        let mut bytes = Vec::with_capacity(36 + points.coords().len() * 8);
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&PATTERN_FORMAT.to_le_bytes());
        bytes.extend_from_slice(&(points.dimension() as u32).to_le_bytes());
        bytes.extend_from_slice(&(points.len() as u64).to_le_bytes());
        bytes.extend_from_slice(&self.parameters.to_le_bytes());
        let mut sum = WordChecksum::default();
        for c in points.coords() {
            let word = c.to_bits();
            sum.add(word);
            bytes.extend_from_slice(&word.to_le_bytes());
        }
        bytes.extend_from_slice(&sum.value().to_le_bytes());
        crate::output::write_atomic(path, &bytes)
    }
}

/// The inner sampler's text: the patterns are its own.
impl std::fmt::Debug for DiskCached {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.inner.fmt(f)
    }
}

/// FNV-1a's offset basis and prime, 64 bits.
const FNV_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0100_0000_01b3;

/// FNV-1a, 64 bits, byte by byte (the parameters' text).
fn checksum(data: &[u8]) -> u64 {
    data.iter()
        .fold(FNV_BASIS, |h, &b| (h ^ b as u64).wrapping_mul(FNV_PRIME))
}

/// A pattern's checksum: FNV-1a's step over its 64-bit words, word `i` into lane `i mod 4`,
/// so that the multiplications of four lanes overlap instead of waiting on each other (a
/// byte-wise chain costs a multiplication's latency per byte, 20 ms for a million 2D points);
/// the lanes and the word count are then hashed in order.
#[derive(Debug, Clone, Copy)]
struct WordChecksum {
    lanes: [u64; 4],
    words: u64,
}

impl Default for WordChecksum {
    fn default() -> Self {
        Self {
            lanes: [FNV_BASIS; 4],
            words: 0,
        }
    }
}

impl WordChecksum {
    fn add(&mut self, word: u64) {
        let lane = &mut self.lanes[(self.words & 3) as usize];
        *lane = (*lane ^ word).wrapping_mul(FNV_PRIME);
        self.words += 1;
    }

    fn value(&self) -> u64 {
        self.lanes
            .iter()
            .chain(std::iter::once(&self.words))
            .fold(FNV_BASIS, |h, &w| (h ^ w).wrapping_mul(FNV_PRIME))
    }
}

impl Sampler for DiskCached {
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    fn dimension(&self) -> usize {
        self.inner.dimension()
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(self.kind)
    }
    fn check_count(&self, n: usize) -> Result<()> {
        self.inner.check_count(n)
    }
    fn closed_form(&self, n: usize) -> Option<crate::spectrum::ClosedForm> {
        self.inner.closed_form(n)
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        let path = self.path(n, seed, realization);
        if let Some(points) = self.load(&path, n) {
            return Ok(points);
        }
        let points = self.inner.sample(n, seed, realization)?;
        // A cache that cannot be written only costs time: the pattern is still right.
        let _ = self.store(&path, &points);
        Ok(points)
    }
}

/// Memory for keeping costly patterns during a study, a report or a render.
pub const PATTERN_MEMORY: usize = 256 << 20;

/// `kind` in dimension `d`, its costly patterns (a microsecond per point or more) kept on disk
/// under `dir` if given, and in memory up to `memory_bytes` in any case.
///
/// # Errors
/// An unsupported dimension.
pub fn cached_sampler(
    kind: SamplerKind,
    d: usize,
    dir: Option<&std::path::Path>,
    memory_bytes: usize,
) -> Result<Box<dyn Sampler>> {
    let inner = kind.build(d)?;
    if !kind.patterns_worth_keeping() {
        return Ok(inner);
    }
    let on_disk: Box<dyn Sampler> = match dir {
        Some(dir) => Box::new(DiskCached::new(inner, dir.to_path_buf())?),
        None => inner,
    };
    Ok(Box::new(crate::sampler::Memoized::new(
        on_disk,
        memory_bytes,
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stored pattern damaged in any one word, or with two words swapped, is drawn again: the
    /// answer is the sampler's own and the file is rewritten as it was.
    #[test]
    fn a_damaged_pattern_is_drawn_again() {
        let dir = std::env::temp_dir().join(format!("specvar-cache-test-{}", std::process::id()));
        let cached =
            DiskCached::new(SamplerKind::PoissonDisk.build(2).unwrap(), dir.clone()).unwrap();
        let drawn = cached.sample(32, 3, 1).unwrap();
        let path = cached.path(32, 3, 1);
        let stored = std::fs::read(&path).unwrap();
        let header = HEADER_BYTES;
        let damages: [fn(&mut [u8]); 3] = [
            |b| b[HEADER_BYTES + 8 * 5 + 2] ^= 0x10,
            |b| b[HEADER_BYTES + 8 * 63 + 7] ^= 0x80,
            |b| {
                let (first, second) = b[HEADER_BYTES..HEADER_BYTES + 16].split_at_mut(8);
                first.swap_with_slice(second);
            },
        ];
        for damage in damages {
            let mut bytes = stored.clone();
            damage(&mut bytes);
            assert_ne!(bytes[header..], stored[header..]);
            std::fs::write(&path, &bytes).unwrap();
            assert_eq!(cached.sample(32, 3, 1).unwrap(), drawn);
            assert_eq!(std::fs::read(&path).unwrap(), stored);
        }
        let _ = std::fs::remove_dir_all(dir);
    }
}
