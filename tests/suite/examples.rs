//! Every command shown in README.md and docs/cli.md runs as written: in a scratch directory that
//! holds the files the examples name, each succeeds, or fails with exit code 2 where the docs
//! show the error it prints, within a generous time.

use crate::common;
use std::path::Path;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Time one documented example may take (the longest, a full render with its reference, takes
/// well under a minute on 2 cores).
const LIMIT: Duration = Duration::from_secs(300);

struct Example {
    source: &'static str,
    line: usize,
    args: Vec<String>,
    fails: bool,
}

/// The runnable `specvar …` lines of a document: not the synopses (which hold `[`, `|` or
/// placeholders in capitals).
fn examples(source: &'static str) -> Vec<Example> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(source);
    let text = std::fs::read_to_string(&path).expect("the document exists");
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start().trim_start_matches("$ ");
        let Some(rest) = trimmed.strip_prefix("specvar ") else {
            continue;
        };
        let command = rest.split('#').next().unwrap_or("").trim();
        let placeholder = command
            .split_whitespace()
            .any(|w| w.len() > 1 && w.chars().all(|c| c.is_ascii_uppercase() || c == '_'));
        if command.contains('[') || command.contains('|') || command.contains('…') || placeholder
        {
            continue;
        }
        let fails = lines
            .get(i + 1)
            .is_some_and(|next| next.trim_start().starts_with("error:"));
        out.push(Example {
            source,
            line: i + 1,
            args: command.split_whitespace().map(str::to_string).collect(),
            fails,
        });
    }
    out
}

/// The files the examples read.
fn fixtures(dir: &Path) {
    let sets: Vec<_> = (0..24)
        .map(|r| {
            use specvar::Sampler;
            specvar::sampler::LatinHypercube::new(2)
                .unwrap()
                .sample(256, 3, r)
                .unwrap()
        })
        .collect();
    std::fs::write(dir.join("my_points.txt"), specvar::io::write_text(&sets)).unwrap();
    let pixels: Vec<u8> = (0..64 * 64)
        .map(|i| (((i % 64) * 4) ^ ((i / 64) * 3)) as u8)
        .collect();
    std::fs::write(dir.join("pixels.npy"), pixel_stack_npy()).unwrap();
    std::fs::write(dir.join("pilot.npy"), pilot_npy()).unwrap();
    std::fs::write(dir.join("pixel4d.npy"), pixel4d_npy()).unwrap();
    let png = specvar::plot::gray_png(&pixels, 64, 64).unwrap();
    for name in ["my_image.png", "photo.png"] {
        std::fs::write(dir.join(name), &png).unwrap();
    }
}

/// The bytes `numpy.save` writes for an `f8` array of `shape` holding `values` in C order.
fn npy(shape: &[usize], values: &[f64]) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let mut header = format!(
        "{{'descr': '<f8', 'fortran_order': False, 'shape': ({}), }}",
        dims.join(", ")
    );
    while !(10 + header.len() + 1).is_multiple_of(64) {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes
}

/// Pixel `p` of the fixtures' image: a 16 × 16 grid of an edge at its own angle.
fn edge_pixel(p: usize) -> specvar::integrand::GridIntegrand {
    let angle = (10.0 + 15.0 * p as f64).to_radians();
    let values = (0..256)
        .map(|i| {
            let (x, y) = ((i % 16) as f64 / 16.0, (i / 16) as f64 / 16.0);
            if x * angle.cos() + y * angle.sin() > 0.5 {
                1.0
            } else {
                0.2
            }
        })
        .collect();
    specvar::integrand::GridIntegrand::new(16, 16, values)
        .unwrap()
        .with_meaning(specvar::integrand::GridMeaning::Exact)
}

/// A `.npy` stack of 2 × 3 pixels ([`edge_pixel`]), shape `(2, 3, 16, 16)`.
fn pixel_stack_npy() -> Vec<u8> {
    let values: Vec<f64> = (0..6)
        .flat_map(|p| edge_pixel(p).values().to_vec())
        .collect();
    npy(&[2, 3, 16, 16], &values)
}

/// A pilot: four renders of the stack's image at 16 jittered samples per pixel, shape
/// `(4, 2, 3)`.
fn pilot_npy() -> Vec<u8> {
    use specvar::Sampler;
    let jitter = specvar::sampler::Jitter::new(2).unwrap();
    let values: Vec<f64> = (0..24)
        .map(|i| {
            let points = jitter.sample(16, 5, i as u64).unwrap();
            specvar::montecarlo::estimate_integral(&edge_pixel(i % 6), &points)
        })
        .collect();
    npy(&[4, 2, 3], &values)
}

/// A 4D pixel, `f[ay, ax, by, bx]` on 16⁴ cells: a silhouette across the film coordinates `u`
/// (beyond it 0.2), in front a floor lit where the light sample `v` is not hidden, the
/// shadow's edge moving with `u_x`.
fn pixel4d_npy() -> Vec<u8> {
    const M: usize = 16;
    let c = |i: usize| (i as f64 + 0.5) / M as f64;
    let (c30, s30) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let (c70, s70) = (70f64.to_radians().cos(), 70f64.to_radians().sin());
    let values: Vec<f64> = (0..M.pow(4))
        .map(|i| {
            let (bx, by, ax, ay) = (c(i % M), c(i / M % M), c(i / M / M % M), c(i / M / M / M));
            if ax * c30 + ay * s30 > 0.75 {
                0.2
            } else {
                let lit = bx * c70 + by * s70 > 0.3 + 0.5 * ax;
                (0.5 + 0.5 * ay) * lit as u8 as f64
            }
        })
        .collect();
    npy(&[M, M, M, M], &values)
}

fn run(example: &Example, dir: &Path, cache: &Path) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_specvar"))
        .args(&example.args)
        .current_dir(dir)
        .env("SPECVAR_CACHE_DIR", cache)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let status = common::wait_bounded(&mut child, LIMIT, &|| {
        format!("{}:{} {:?}", example.source, example.line, example.args)
    });
    let err =
        String::from_utf8_lossy(&child.wait_with_output().expect("output").stderr).into_owned();
    let expected = if example.fails { 2 } else { 0 };
    assert_eq!(
        status.code(),
        Some(expected),
        "{}:{} {:?}: {err}",
        example.source,
        example.line,
        example.args
    );
}

#[test]
fn every_documented_command_runs_as_written() {
    let scratch = |name: &str| {
        let dir = std::env::temp_dir().join(format!("specvar-doc-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    };
    // The README runs in an empty directory: every file it reads, it makes first.
    let (readme, reference) = (scratch("readme"), scratch("reference"));
    fixtures(&reference);
    // The costly patterns (CCVT, Gaussian blue noise) and reference images are kept between
    // runs under the build's directory, as a user's cache keeps them between commands: the
    // first run after a clean build draws them, later runs read them.
    let cache = Path::new(env!("CARGO_TARGET_TMPDIR")).join("documented-commands-cache");
    assert!(
        examples("README.md").len() + examples("docs/cli.md").len() >= 20,
        "too few examples found"
    );
    // Each document's commands run in order (a later one may read what an earlier one wrote);
    // the two documents run side by side.
    // A command written in both documents runs once, in the README's directory: the reference's
    // own commands read none of what such a command writes.
    let readme_commands: Vec<Vec<String>> =
        examples("README.md").into_iter().map(|e| e.args).collect();
    let readme_commands = &readme_commands;
    std::thread::scope(|scope| {
        for (source, dir) in [("README.md", &readme), ("docs/cli.md", &reference)] {
            let cache = &cache;
            scope.spawn(move || {
                for example in examples(source) {
                    if source != "README.md" && readme_commands.contains(&example.args) {
                        continue;
                    }
                    let start = Instant::now();
                    run(&example, dir, cache);
                    // Shown with --nocapture: where the suite's time goes.
                    eprintln!(
                        "{:>6.1} s  {}:{} {}",
                        start.elapsed().as_secs_f64(),
                        example.source,
                        example.line,
                        example.args.join(" ")
                    );
                }
            });
        }
    });
}
