//! Inputs that once crashed, hung or gave wrong answers: each must now give one line on
//! standard error and exit code 2, within a bounded time, without a panic.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Time any bad input may take to be refused (a generous bound; most take milliseconds).
const LIMIT: Duration = Duration::from_secs(30);

fn refuses(args: &[&str]) {
    let cache = std::env::temp_dir().join("specvar-bad-input-cache");
    let mut child = Command::new(env!("CARGO_BIN_EXE_specvar"))
        .args(args)
        .env("SPECVAR_CACHE_DIR", &cache)
        .current_dir(std::env::temp_dir())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break status;
        }
        if start.elapsed() > LIMIT {
            let _ = child.kill();
            panic!("{args:?} ran past {LIMIT:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let out = child.wait_with_output().expect("output");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        status.code(),
        Some(2),
        "{args:?}: exit {status:?}, stderr {err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
}

#[test]
fn sizes_that_would_exhaust_memory_are_refused_up_front() {
    for args in [
        vec!["sample", "-s", "random", "-n", "1000000000000"],
        vec!["spectrum", "-s", "random", "-n", "1000000000000"],
        vec!["mc", "-s", "random", "-f", "disk", "-n", "1000000000000"],
        vec![
            "mc",
            "-s",
            "random",
            "-f",
            "disk",
            "-n",
            "16",
            "--trials",
            "100000000000",
        ],
        vec!["bias", "-s", "random", "-n", "16", "--kmax", "100000"],
        vec!["render-ao", "--kmax", "100000"],
        vec!["spectrum", "-d", "3", "--kmax", "4096"],
        vec!["spectrum", "--kmax", "4096"],
        vec!["sample", "-s", "ccvt", "-n", "100000000"],
        vec![
            "predict",
            "-s",
            "poisson",
            "-f",
            "disk",
            "-n",
            "100000000000",
        ],
    ] {
        refuses(&args);
    }
}

#[test]
fn long_runs_and_unbounded_inputs_are_refused_before_they_start() {
    refuses(&["rates", "--range", "16", "1000000000000"]);
    refuses(&["spectrum", "--input", "/dev/zero"]);
    refuses(&[
        "render-ao",
        "--width",
        "4096",
        "--height",
        "4096",
        "--reference-rays",
        "100000",
    ]);
}

#[test]
fn meaningless_parameters_are_errors_not_defaults() {
    let grid = std::env::temp_dir().join("specvar-bad-huge-grid.txt");
    std::fs::write(&grid, "1 2\n3 1e308\n").unwrap();
    let grid_spec = format!("grid:{}", grid.display());
    for args in [
        vec!["bias", "-s", "random", "-n", "16", "--kmax", "0"],
        vec!["rates", "--trials", "0"],
        vec!["anisotropy", "-s", "jitter", "--angles", "0:90:0"],
        vec!["anisotropy", "-s", "jitter", "--angles", "90:0:5"],
        vec!["anisotropy", "-s", "jitter", "--angles", "0:1000000:0.001"],
        vec!["anisotropy", "-s", "jitter", "--angles", "a,b"],
        vec!["anisotropy", "-s", "jitter", "--offset", "1.5"],
        vec!["anisotropy", "-s", "jitter", "--polar", "plot.png"],
        vec!["anisotropy", "-s", "jitter", "--rates", "64"],
        vec!["anisotropy", "-s", "poisson", "-n", "64", "--trials", "0"],
        vec![
            "predict",
            "-s",
            "jitter",
            "-n",
            "64",
            "-f",
            "polygon:0,0;1,1;1,0;0,1",
        ],
        vec![
            "predict",
            "-s",
            "jitter",
            "-n",
            "64",
            "-f",
            "polygon:@/nonexistent",
        ],
        vec![
            "predict", "-s", "jitter", "-d", "3", "-n", "64", "-f", "edge",
        ],
        vec!["metrics", "-n", "64", "--pcf-sigma", "0"],
        vec!["metrics", "-n", "64", "--pcf-sigma", "NaN"],
        vec!["metrics", "-n", "16", "--pcf-rmax", "3"],
        vec!["metrics", "-n", "64", "-m", "0"],
        vec!["metrics", "-n", "1", "-m", "1"],
        vec!["metrics", "-s", "fibonacci", "-n", "64"],
        vec!["metrics", "-s", "random", "-d", "4", "-n", "64"],
        vec![
            "predict",
            "-s",
            "jitter",
            "-n",
            "16",
            "-f",
            "gaussian:sigma=1e300",
        ],
        vec![
            "predict",
            "-s",
            "jitter",
            "-n",
            "16",
            "-f",
            grid_spec.as_str(),
        ],
        vec![
            "predict", "-s", "poisson", "-n", "16", "-f", "disk", "-m", "1",
        ],
        vec![
            "spectrum",
            "-s",
            "random",
            "-n",
            "64",
            "--radial",
            "--bin-width",
            "1e300",
        ],
        vec!["spectrum", "-s", "random", "-n", "64", "--plot", "x.jpg"],
        vec![
            "predict",
            "-s",
            "jitter",
            "-n",
            "16",
            "-f",
            "disk:r=0.1,r=0.2",
        ],
        vec!["predict", "-s", "jitter", "-n", "16", "-f", "cube"],
        vec![
            "mc", "-s", "random", "-n", "16", "-f", "disk", "--trials", "10",
        ],
        vec![
            "mc",
            "-s",
            "random",
            "-n",
            "4",
            "-f",
            "gaussian:sigma=0.002",
            "--trials",
            "100",
        ],
        vec!["render-ao", "--stride", "0"],
        vec!["render-ao", "--grid", "0"],
        vec!["render-ao", "--spectrum-realizations", "0"],
        vec![
            "predict", "-s", "halton", "-n", "64", "-f", "disk", "--form", "polar",
        ],
        vec![
            "predict",
            "-s",
            "jitter",
            "-n",
            "16",
            "-f",
            "disk:r=0.45",
            "--form",
            "polar",
        ],
        vec![
            "predict",
            "-s",
            "random",
            "-n",
            "16",
            "-f",
            "disk",
            "--budget-seconds",
            "-1",
        ],
        vec!["sample", "-s", "jitter", "-n", "17"],
    ] {
        refuses(&args);
    }
}

/// Every check of a render happens before its reference (which takes the longest).
#[test]
fn late_validation_is_gone() {
    let start = Instant::now();
    refuses(&["render-ao", "--grid", "0", "--reference-rays", "1000000"]);
    assert!(start.elapsed() < Duration::from_secs(5));
}
