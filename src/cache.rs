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
