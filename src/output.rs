//! Writing outputs so that an interrupted run leaves either the old output or the complete new
//! one: files are written beside their target and renamed over it; a directory is built beside
//! its target and exchanged with it.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// A path beside `target` that no other writer of this process or another uses.
fn sibling(target: &Path, tag: &str) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = target
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    let unique = format!(
        ".{name}.{tag}-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    );
    target.with_file_name(unique)
}

/// Writes `bytes` to `path` atomically: to a temporary file in the same directory, flushed to
/// disk, then renamed over `path`.
///
/// # Errors
/// The directory is not writable, or the disk is full.
///
/// # Examples
/// ```
/// let path = std::env::temp_dir().join("specvar_doc_atomic.txt");
/// specvar::output::write_atomic(&path, b"complete")?;
/// assert_eq!(std::fs::read(&path)?, b"complete");
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let temp = sibling(path, "partial");
    let written = (|| {
        use std::io::Write;
        let mut file = std::fs::File::create(&temp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        std::fs::rename(&temp, path)
    })();
    written.map_err(|e| {
        let _ = std::fs::remove_file(&temp);
        Error::io(path, e)
    })
}

/// Replaces the directory `target` by one that `fill` writes: `fill` gets a fresh directory
/// beside `target`, and only when it succeeds is that directory put in `target`'s place (one
/// atomic exchange on Linux). On failure `target` is untouched and the partial one removed.
///
/// # Errors
/// As `fill`, or a directory that cannot be created or exchanged.
pub fn replace_dir(target: &Path, fill: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let fresh = sibling(target, "new");
    std::fs::create_dir_all(&fresh).map_err(|e| Error::io(&fresh, e))?;
    if let Err(e) = fill(&fresh) {
        let _ = std::fs::remove_dir_all(&fresh);
        return Err(e);
    }
    if !target.exists() {
        return std::fs::rename(&fresh, target).map_err(|e| Error::io(target, e));
    }
    exchange(&fresh, target).map_err(|e| Error::io(target, e))?;
    // `fresh` now holds the old output.
    let _ = std::fs::remove_dir_all(&fresh);
    Ok(())
}

/// Swaps two existing paths in one step.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let c = |p: &Path| {
        CString::new(p.as_os_str().as_bytes())
            .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e))
    };
    let (ca, cb) = (c(a)?, c(b)?);
    // SAFETY: both arguments are valid NUL-terminated paths that outlive the call, and
    // AT_FDCWD resolves them against the working directory, as `rename` does.
    let status = unsafe {
        libc::renameat2(
            libc::AT_FDCWD,
            ca.as_ptr(),
            libc::AT_FDCWD,
            cb.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if status == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

/// Swaps two existing paths by two renames (a short window without `b` remains).
#[cfg(not(target_os = "linux"))]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    let old = sibling(b, "old");
    std::fs::rename(b, &old)?;
    std::fs::rename(a, b)?;
    std::fs::rename(&old, a)
}
