#![cfg(unix)]
//! Outputs never lose what the user owns: directories keep the user's files, special files are
//! written in place, symbolic links through to their targets.

use specvar::output::{check_output_dir, write_atomic, write_dir, MANIFEST};
use specvar::Error;
use std::path::{Path, PathBuf};

/// A fresh directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("specvar-output-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

fn write(stage: &Path, name: &str, text: &str) -> specvar::Result<()> {
    if let Some(parent) = stage.join(name).parent() {
        std::fs::create_dir_all(parent)?;
    }
    write_atomic(&stage.join(name), text.as_bytes())
}

/// Names in `dir`, staging directories included (none may be left).
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("readable")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_directory_keeps_the_users_files_and_loses_only_specvars_earlier_output() {
    let dir = scratch("keeps");
    std::fs::create_dir_all(dir.join("sub")).expect("sub");
    std::fs::write(dir.join("thesis.tex"), "mine").expect("user file");
    write_dir(&dir, |s| {
        write(s, "report.md", "1")?;
        write(s, "ao/old.png", "1")
    })
    .expect("first output");
    write_dir(&dir, |s| write(s, "report.md", "2")).expect("second output");
    assert_eq!(
        std::fs::read_to_string(dir.join("thesis.tex")).unwrap(),
        "mine"
    );
    assert!(dir.join("sub").is_dir());
    assert_eq!(std::fs::read_to_string(dir.join("report.md")).unwrap(), "2");
    assert!(
        !dir.join("ao").exists(),
        "the earlier output's own file and directory go"
    );
    assert_eq!(
        names(&dir),
        [MANIFEST, "report.md", "sub", "thesis.tex"],
        "no staging directory is left"
    );
}

#[test]
fn a_file_of_the_users_in_the_way_is_refused_and_kept() {
    let dir = scratch("refuses");
    std::fs::write(dir.join("report.md"), "mine").expect("user file");
    let err = write_dir(&dir, |s| write(s, "report.md", "specvar's")).unwrap_err();
    assert!(matches!(err, Error::WouldOverwrite { .. }), "{err}");
    assert!(err
        .to_string()
        .contains("report.md exists and was not written by specvar"));
    assert_eq!(
        std::fs::read_to_string(dir.join("report.md")).unwrap(),
        "mine"
    );
    assert_eq!(names(&dir), ["report.md"]);
}

#[test]
fn a_failure_leaves_the_directory_as_it_was() {
    let dir = scratch("fails");
    std::fs::write(dir.join("notes.txt"), "mine").expect("user file");
    let err = write_dir(&dir, |s| {
        write(s, "half.md", "written")?;
        Err(Error::Mismatch("the work failed".into()))
    })
    .unwrap_err();
    assert!(matches!(err, Error::Mismatch(_)));
    assert_eq!(names(&dir), ["notes.txt"]);
}

#[test]
fn the_working_directory_itself_can_take_an_output() {
    let dir = scratch("dot");
    std::fs::write(dir.join("mine.txt"), "mine").expect("user file");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_specvar"))
        .args([
            "render-ao",
            "--sampler",
            "random",
            "--rays",
            "4",
            "--width",
            "8",
        ])
        .args([
            "--height",
            "8",
            "--reference-rays",
            "64",
            "--kmax",
            "8",
            "--grid",
            "16",
        ])
        .args(["--out", "."])
        .env("SPECVAR_CACHE_DIR", dir.join("cache"))
        .current_dir(&dir)
        .output()
        .expect("runs");
    assert!(status.status.success(), "{status:?}");
    let listed = names(&dir);
    assert!(listed.contains(&"mine.txt".to_string()) && listed.contains(&"comparison.md".into()));
    assert!(
        !listed.iter().any(|n| n.starts_with(".specvar-staging")),
        "{listed:?}"
    );
}

#[test]
fn a_path_that_is_not_a_directory_is_named_before_any_work() {
    let dir = scratch("notdir");
    let file = dir.join("plain");
    std::fs::write(&file, "x").expect("file");
    let err = check_output_dir(&file.join("out")).unwrap_err();
    assert!(err.to_string().contains("plain/out"), "{err}");
}

#[test]
fn symbolic_links_are_followed_and_kept() {
    let dir = scratch("links");
    let target = dir.join("target.txt");
    let link = dir.join("link.txt");
    std::os::unix::fs::symlink(&target, &link).expect("symlink");
    write_atomic(&link, b"through the link").expect("written");
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read(&target).unwrap(), b"through the link");
}

#[test]
fn a_fifo_is_written_in_place() {
    let dir = scratch("fifo");
    let fifo = dir.join("pipe");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("mkfifo is not available: skipped");
        return;
    }
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).expect("read the fifo"))
    };
    write_atomic(&fifo, b"streamed").expect("written");
    assert_eq!(reader.join().unwrap(), b"streamed");
    let meta = std::fs::symlink_metadata(&fifo).unwrap();
    assert!(!meta.is_file(), "the FIFO is still a FIFO");
}

#[test]
fn a_full_device_is_an_error() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        return;
    }
    let err = write_atomic(full, b"x").unwrap_err();
    assert!(err.to_string().contains("No space left"), "{err}");
    assert!(std::fs::symlink_metadata(full)
        .unwrap()
        .file_type()
        .is_char_device_like());
}

/// Whether a file type is a character device (standard on Unix).
trait CharDevice {
    fn is_char_device_like(&self) -> bool;
}

impl CharDevice for std::fs::FileType {
    fn is_char_device_like(&self) -> bool {
        use std::os::unix::fs::FileTypeExt;
        self.is_char_device()
    }
}
