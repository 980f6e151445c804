//! Writing outputs without losing what the user owns, and so that an interrupted run leaves
//! either the old output or the complete new one.
//!
//! - A regular file (or a missing one) is written beside its target and renamed over it; a
//!   symbolic link is followed and its target written that way; a FIFO, a device or a socket is
//!   written in place (it cannot be replaced without breaking whoever reads it).
//! - An output directory ([`write_dir`]) is filled in a staging directory inside it, and only
//!   then are its files moved into place one by one. The directory keeps a manifest of the
//!   files specvar wrote there ([`MANIFEST`]): a new output replaces and removes only files the
//!   manifest lists, and refuses to replace any other file.

use crate::error::{Error, Result};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The name of the manifest that lists, one relative path a line, the files specvar wrote in
/// an output directory.
pub const MANIFEST: &str = ".specvar-manifest";

/// A name no other writer of this process or another uses, made of `prefix`, the process id
/// and a counter.
fn unique_name(prefix: &str) -> String {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    format!(
        "{prefix}-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    )
}

/// Writes `bytes` to `path`: atomically for a regular file or a new one (a temporary file in
/// the same directory, flushed to disk, then renamed over `path`); through a symbolic link to
/// its target; in place for a FIFO, a device or a socket.
///
/// # Errors
/// The directory is not writable, or the disk or device is full.
///
/// # Examples
/// ```
/// let path = std::env::temp_dir().join("specvar_doc_atomic.txt");
/// specvar::output::write_atomic(&path, b"complete")?;
/// assert_eq!(std::fs::read(&path)?, b"complete");
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let target = resolve_links(path).map_err(|e| Error::io(path, e))?;
    match std::fs::metadata(&target) {
        Ok(meta) if !meta.is_file() && !meta.is_dir() => write_in_place(&target, bytes),
        _ => write_replacing(&target, bytes),
    }
    .map_err(|e| Error::io(path, e))
}

/// `path` with every symbolic link it ends in followed (a dangling link resolves to the path it
/// names, so that writing creates the file there).
fn resolve_links(path: &Path) -> std::io::Result<PathBuf> {
    let mut current = path.to_path_buf();
    // A cycle of links is refused after as many steps as the system allows (40 on Linux).
    for _ in 0..40 {
        match std::fs::symlink_metadata(&current) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let next = std::fs::read_link(&current)?;
                current = match current.parent() {
                    Some(dir) if next.is_relative() => dir.join(next),
                    _ => next,
                };
            }
            _ => return Ok(current),
        }
    }
    Err(std::io::Error::other("too many levels of symbolic links"))
}

/// Writes into an existing special file (FIFO, device, socket) without replacing it.
fn write_in_place(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let mut file = std::fs::OpenOptions::new().write(true).open(path)?;
    file.write_all(bytes)?;
    file.flush()
}

/// Writes a regular file by a temporary sibling renamed over it.
fn write_replacing(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let name = path
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    let temp = path.with_file_name(unique_name(&format!(".{name}.partial")));
    let written = (|| {
        let mut file = std::fs::File::create(&temp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        std::fs::rename(&temp, path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
    written
}

/// Checks, before any work, that `dir` can take an output: proves it writable (creating it and
/// its parents where missing) by creating and removing a staging directory in it, then removes
/// again the directories it created, so that a run refused after the check leaves nothing
/// behind (the output's writing creates them anew). The error names `dir` itself.
///
/// # Errors
/// A path that is not a directory, or one that cannot be created or written.
///
/// # Examples
/// ```
/// let dir = std::env::temp_dir().join("specvar_doc_check_dir").join("out");
/// specvar::output::check_output_dir(&dir)?;
/// assert!(!dir.exists(), "nothing left behind by the check");
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn check_output_dir(dir: &Path) -> Result<()> {
    let missing: Vec<PathBuf> = dir
        .ancestors()
        .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
        .map(Path::to_path_buf)
        .collect();
    let checked = Staging::create(dir).map(drop);
    // Leaf first: each only if still empty (remove_dir refuses otherwise).
    for created in &missing {
        let _ = std::fs::remove_dir(created);
    }
    checked
}

/// A staging directory inside an output directory, removed when dropped.
struct Staging {
    path: PathBuf,
}

impl Staging {
    fn create(dir: &Path) -> Result<Self> {
        if dir.exists() && !dir.is_dir() {
            return Err(Error::io(
                dir,
                std::io::Error::other(
                    "a file, not a directory: --out names the directory the output goes in",
                ),
            ));
        }
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        if !dir.is_dir() {
            return Err(Error::io(
                dir,
                std::io::Error::other("not a directory; choose a directory for the output"),
            ));
        }
        remove_abandoned(dir);
        let path = dir.join(unique_name(STAGING));
        std::fs::create_dir(&path).map_err(|e| Error::io(dir, e))?;
        Ok(Self { path })
    }
}

/// The prefix of staging directories: `.specvar-staging-PID-COUNTER`.
const STAGING: &str = ".specvar-staging";

/// Removes the staging directories that processes killed before they could clean up left in
/// `dir` (those of a process id that no longer runs; where that cannot be told, none).
fn remove_abandoned(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let pid = name
            .strip_prefix(STAGING)
            .and_then(|rest| rest.strip_prefix('-'))
            .and_then(|rest| rest.split('-').next())
            .and_then(|pid| pid.parse::<u32>().ok());
        if pid.is_some_and(|pid| !process_runs(pid)) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// Whether a process with this id runs (Linux: it has an entry in /proc). Elsewhere every
/// process is assumed to run, so that nothing is removed that might be in use.
fn process_runs(pid: u32) -> bool {
    if cfg!(target_os = "linux") && Path::new("/proc/self").exists() {
        Path::new("/proc").join(pid.to_string()).exists()
    } else {
        true
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.path);
    }
}

/// Writes an output directory: `fill` writes the files into a fresh staging directory inside
/// `dir`, and only when it succeeds are they moved into `dir`, each replacing a file of the same
/// name that specvar wrote earlier; files of an earlier output that the new one lacks are
/// removed; nothing else in `dir` is touched. `dir` may be `.` or hold files of the user's.
/// On failure, or when a file would replace one specvar did not write, the staging directory is
/// removed and `dir` keeps what it had.
///
/// # Errors
/// As `fill`; [`Error::WouldOverwrite`] for a file of the user's in the way; a directory that
/// cannot be created or written.
///
/// # Examples
/// ```
/// let dir = std::env::temp_dir().join(format!("specvar_doc_write_dir_{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// std::fs::write(dir.join("thesis.tex"), "mine")?;
/// specvar::output::write_dir(&dir, |stage| specvar::output::write_atomic(&stage.join("a.md"), b"1"))?;
/// specvar::output::write_dir(&dir, |stage| specvar::output::write_atomic(&stage.join("b.md"), b"2"))?;
/// assert!(!dir.join("a.md").exists(), "an earlier output of specvar's is removed");
/// assert_eq!(std::fs::read_to_string(dir.join("thesis.tex"))?, "mine", "the user's file stays");
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn write_dir(dir: &Path, fill: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let staging = Staging::create(dir)?;
    fill(&staging.path)?;
    let mut fresh = Vec::new();
    list_files(&staging.path, Path::new(""), &mut fresh)?;
    let manifest = dir.join(MANIFEST);
    let earlier = read_manifest(&manifest)?;
    for file in &fresh {
        let dest = dir.join(file);
        if dest.symlink_metadata().is_ok() && !earlier.contains(file) {
            return Err(Error::WouldOverwrite {
                path: dest.display().to_string(),
                manifest: manifest.display().to_string(),
            });
        }
    }
    // The new manifest first lists both outputs, so that an interruption during the moves
    // leaves every file specvar wrote listed.
    let union: BTreeSet<PathBuf> = earlier.iter().chain(&fresh).cloned().collect();
    write_manifest(&manifest, &union)?;
    for file in &fresh {
        let dest = dir.join(file);
        if let Some(parent) = dest.parent() {
            std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, e))?;
        }
        std::fs::rename(staging.path.join(file), &dest).map_err(|e| Error::io(&dest, e))?;
    }
    let kept: BTreeSet<PathBuf> = fresh.into_iter().collect();
    for stale in earlier.difference(&kept) {
        remove_stale(dir, stale);
    }
    write_manifest(&manifest, &kept)
}

/// Every regular file under `root/relative`, as paths relative to `root`.
fn list_files(root: &Path, relative: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
    let here = root.join(relative);
    let entries = std::fs::read_dir(&here).map_err(|e| Error::io(&here, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(&here, e))?;
        let path = relative.join(entry.file_name());
        if entry.file_type().map_err(|e| Error::io(&here, e))?.is_dir() {
            list_files(root, &path, out)?;
        } else {
            out.push(path);
        }
    }
    Ok(())
}

/// The files an earlier output listed (none if there is no manifest). Entries that could
/// leave the directory (absolute, or with `..`) are ignored: the manifest is a file anyone
/// can edit, and it must never name a file outside.
fn read_manifest(path: &Path) -> Result<BTreeSet<PathBuf>> {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(BTreeSet::new()),
        Err(e) => return Err(Error::io(path, e)),
    };
    Ok(text
        .lines()
        .map(PathBuf::from)
        .filter(|p| {
            p.components()
                .all(|c| matches!(c, std::path::Component::Normal(_)))
                && p.components().next().is_some()
        })
        .collect())
}

fn write_manifest(path: &Path, files: &BTreeSet<PathBuf>) -> Result<()> {
    let mut text = String::new();
    for f in files {
        text.push_str(&f.to_string_lossy());
        text.push('\n');
    }
    write_atomic(path, text.as_bytes())
}

/// Removes a file of an earlier output, and the directories it leaves empty (up to `dir`).
fn remove_stale(dir: &Path, relative: &Path) {
    let _ = std::fs::remove_file(dir.join(relative));
    let mut parent = relative.parent();
    while let Some(p) = parent.filter(|p| !p.as_os_str().is_empty()) {
        // Fails, harmlessly, while the directory holds anything.
        if std::fs::remove_dir(dir.join(p)).is_err() {
            break;
        }
        parent = p.parent();
    }
}
