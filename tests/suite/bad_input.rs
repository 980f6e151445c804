//! Inputs that once crashed, hung or gave wrong answers: each must now give one line on
//! standard error and exit code 2, within a bounded time, without a panic.

use crate::common;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Time any bad input may take to be refused (a generous bound; most take milliseconds).
const LIMIT: Duration = Duration::from_secs(30);

fn refuses(args: &[&str]) {
    run_bounded(args, &[2]);
}

/// Runs `args` within [`LIMIT`], checks that it exits with one of `codes`, without a panic, and
/// with exactly one line on standard error when it fails; returns that line.
fn run_bounded(args: &[&str], codes: &[i32]) -> String {
    let cache = std::env::temp_dir().join("specvar-bad-input-cache");
    let mut child = Command::new(env!("CARGO_BIN_EXE_specvar"))
        .args(args)
        .env("SPECVAR_CACHE_DIR", &cache)
        .current_dir(std::env::temp_dir())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let status = common::wait_bounded(&mut child, LIMIT, &|| format!("{args:?}"));
    let out = child.wait_with_output().expect("output");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        status.code().is_some_and(|c| codes.contains(&c)),
        "{args:?}: exit {status:?}, stderr {err}"
    );
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    if status.code() != Some(0) {
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
    }
    err.trim().to_string()
}

/// Runs `args`, expects exit code 2 and one error line that contains `expected` (clap's own
/// errors also exit with 2: the text tells which check refused).
fn refuses_with(args: &[&str], expected: &str) {
    let line = run_bounded(args, &[2]);
    assert!(
        line.contains(expected),
        "{args:?}: '{line}' lacks '{expected}'"
    );
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

/// A tabulation too coarse for its sampler is refused with the cells it needs, and rays whose
/// pixels' tabulations would need more than the largest grid are refused before any tracing.
#[test]
fn tabulations_too_coarse_or_too_fine_are_refused_with_what_they_need() {
    let dir = std::env::temp_dir().join("specvar-bad-tabulation");
    std::fs::create_dir_all(&dir).unwrap();
    let grid = dir.join("g.txt");
    std::fs::write(&grid, "0 1 1 0\n1 1 1 1\n0 1 1 0\n0 0 0 0\n").unwrap();
    let spec = format!("grid:{}", grid.display());
    refuses_with(
        &["predict", "-s", "jitter", "-n", "16", "-f", &spec],
        "is too coarse for the sampler at N = 16: 4 cells per axis, where its coarser averages \
         must resolve its points' spacing, which needs at least 32 cells per axis",
    );
    refuses_with(
        &[
            "predict",
            "-s",
            "jitter",
            "-n",
            "16",
            "-f",
            &format!("{spec},wrong"),
        ],
        // An unknown suffix is part of the file name, as the grammar says.
        "g.txt,wrong: No such file",
    );
    refuses_with(
        &["render-ao", "--rays", "1048576", "--budget-memory", "100"],
        "invalid rays per pixel: 1048576 (at most 262144 for the per-pixel prediction",
    );
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
    // A sum in space at its integrand's cost: an edge's autocorrelation (its copies wrap
    // across the faces) costs ten times a disk's, so the regular grid's 10^8 terms on it are
    // minutes of work, above a budget of one minute (they were once counted at a disk's cost
    // and ran).
    refuses_with(
        &[
            "--budget-seconds",
            "60",
            "predict",
            "-s",
            "regular",
            "-n",
            "100000000",
            "-f",
            "edge:theta=30",
        ],
        "summed in space",
    );
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

#[test]
fn every_size_goes_through_the_budget_with_its_reason() {
    // Owen's gains hold a copy of the points' digits per axis and one column's counts: checked
    // before they are taken (at 2^20 points, 80 MiB).
    refuses_with(
        &[
            "predict",
            "-s",
            "sobol",
            "-f",
            "disk",
            "-n",
            "1048576",
            "--budget-memory",
            "0.05",
        ],
        "Owen's gains' pair counts would need 80 MiB, above the budget of 51 MiB",
    );
    let budget = "above the budget of 8.0 GiB";
    for sampler in ["sobol", "jitter"] {
        refuses_with(
            &[
                "predict",
                "-s",
                sampler,
                "-f",
                "disk",
                "-n",
                "64",
                "--kmax",
                "1000000000",
            ],
            "invalid kmax: 1000000000 (1 to 16777216",
        );
        refuses_with(
            &[
                "predict",
                "-s",
                sampler,
                "-f",
                "disk",
                "-n",
                "64",
                "--kmax",
                "10000000",
                "--randomization",
                "shift",
            ],
            budget,
        );
        refuses_with(
            &[
                "predict",
                "-s",
                sampler,
                "-f",
                "disk",
                "-n",
                "64",
                "--kmax",
                "100000",
                "--randomization",
                "shift",
            ],
            "the integrand's power on |k_i| ≤ 100000 in 2D would need 298.0 GiB",
        );
    }
    refuses_with(
        &[
            "predict",
            "-s",
            "regular",
            "-f",
            "disk",
            "-n",
            "1000000000000",
        ],
        "closed-lattice analysis at N = 1000000000000 (the lattice form with a closed form, or summed in space over its peaks) would need",
    );
    refuses_with(
        &[
            "spectrum",
            "-s",
            "random",
            "-n",
            "64",
            "--radial",
            "--bin-width",
            "1e-300",
        ],
        "invalid bin width: 1e-300 (at least",
    );
    refuses_with(
        &[
            "spectrum",
            "-s",
            "random",
            "-n",
            "64",
            "--method",
            "direct",
            "--tolerance",
            "1e-6",
        ],
        "invalid tolerance",
    );
}

/// Point sets whose declared cells do not hold are refused with the first violation found:
/// copies of one grid, a shifted grid, jittered sets declared as rows, random sets as dyadic.
#[test]
fn declared_cells_are_checked() {
    let dir = std::env::temp_dir().join(format!("specvar-cells-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sample = |name: &str, args: &[&str]| {
        let path = dir.join(name);
        let out = Command::new(env!("CARGO_BIN_EXE_specvar"))
            .args(["sample", "-n", "256", "-o"])
            .arg(&path)
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        path.display().to_string()
    };
    let grid = sample("grid.txt", &["-s", "regular"]);
    let one = std::fs::read_to_string(&grid).unwrap();
    let copies = dir.join("copies.txt");
    std::fs::write(&copies, vec![one.trim_end(); 32].join("\n#\n")).unwrap();
    let copies = copies.display().to_string();
    let shifted = sample(
        "shifted.txt",
        &[
            "-s",
            "regular",
            "--realizations",
            "4",
            "--randomization",
            "shift",
        ],
    );
    let jitter = sample("jitter.txt", &["-s", "jitter", "--realizations", "4"]);
    let random = sample("random.txt", &["-s", "random", "--realizations", "4"]);
    for (file, cells, expected) in [
        (&copies, "strata", "sets 0 and 1 are identical"),
        (
            &shifted,
            "strata",
            "set 0 all sit at one offset within their cells",
        ),
        (&jitter, "rows", "points in row"),
        (&random, "dyadic", "points in row"),
    ] {
        refuses_with(
            &["predict", "--input", file, "-f", "disk", "--cells", cells],
            expected,
        );
    }
    // Jittered sets declared as strata are what the declaration says.
    run_bounded(
        &[
            "predict", "--input", &jitter, "-f", "disk", "--cells", "strata",
        ],
        &[0],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Sizes the plan refuses before any work, each naming its analysis and need: patterns that
/// used to abort on their allocation, and a Gaussian too narrow for its cells' sums.
#[test]
fn the_plan_refuses_what_it_cannot_afford() {
    refuses_with(
        &[
            "--budget-seconds",
            "2",
            "predict",
            "-s",
            "sobol",
            "-f",
            "disk",
            "-n",
            "4294967295",
        ],
        "the owen-gains analysis at N = 4294967295",
    );
    refuses_with(
        &[
            "--budget-seconds",
            "2",
            "predict",
            "-s",
            "sobol-ds",
            "-f",
            "disk",
            "-n",
            "1073741824",
        ],
        "the walsh-fixed analysis at N = 1073741824",
    );
    for sigma in ["1e-300", "1e-12", "1e-7"] {
        let integrand = format!("gaussian:sigma={sigma}");
        refuses_with(
            &[
                "--budget-memory",
                "3",
                "predict",
                "-s",
                "jitter",
                "-f",
                &integrand,
                "-n",
                "16",
            ],
            "at least 1e-6",
        );
    }
    refuses_with(
        &[
            "predict",
            "-s",
            "jitter",
            "-f",
            "agaussian:s1=1e-9,s2=0.02,angle=30",
            "-n",
            "16",
        ],
        "invalid sigma_1: 1e-9 (from 1e-6 to 10",
    );
    // The summary's pair loops, against the budget given, before any pattern is drawn.
    refuses_with(
        &[
            "--budget-seconds",
            "2",
            "metrics",
            "-s",
            "lhs",
            "-n",
            "10000000",
        ],
        "above the budget of about 2.00 s of work",
    );
}

#[test]
fn an_allocation_the_system_refuses_is_a_typed_error() {
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 200000 && exec '{}' --no-cache spectrum -s random -n 4096 --kmax 2000 \
             --json -o /dev/null",
            env!("CARGO_BIN_EXE_specvar")
        ))
        .output()
        .expect("sh runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("could not allocate"), "{err}");
}

#[test]
fn a_closed_form_answers_at_any_n() {
    for args in [
        vec![
            "predict",
            "--randomization",
            "shift",
            "-s",
            "jitter",
            "-n",
            "1000000000000",
            "--spectrum",
            "closed",
            "--json",
        ],
        vec![
            "predict",
            "--randomization",
            "shift",
            "-s",
            "jitter",
            "-n",
            "1000000000000",
            "-f",
            "disk",
            "--json",
        ],
        vec![
            "--budget-seconds",
            "1",
            "predict",
            "--randomization",
            "shift",
            "-s",
            "jitter",
            "-n",
            "1000000000000",
            "--json",
        ],
        // A budget below the lattice's work and the tent's: the polar form still answers.
        vec![
            "--budget-seconds",
            "0.1",
            "predict",
            "--randomization",
            "shift",
            "-s",
            "jitter",
            "-n",
            "1000000000000",
            "--json",
        ],
        vec![
            "predict",
            "--randomization",
            "shift",
            "-s",
            "jitter",
            "-d",
            "1",
            "-f",
            "disk",
            "-n",
            "1000000000000",
            "--json",
        ],
    ] {
        let start = Instant::now();
        let out = Command::new(env!("CARGO_BIN_EXE_specvar"))
            .args(&args)
            .output()
            .expect("runs");
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            start.elapsed() < Duration::from_secs(10),
            "{args:?} took {:?}",
            start.elapsed()
        );
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
        // Exact at any N: the polar form's radial integral, or the strata's tent in space.
        let tent = doc["reason"]
            .as_str()
            .is_some_and(|r| r.contains("strata's tent"));
        assert!(doc["form"] == "polar" || tent, "{args:?}: {doc}");
        let v = doc["variance"].as_f64().expect("variance");
        assert!(v > 0.0 && v < 1e-18, "{args:?}: {v}");
    }
}

#[test]
fn standard_output_failures_end_cleanly() {
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full");
    if let Ok(full) = full {
        let out = Command::new(env!("CARGO_BIN_EXE_specvar"))
            .args([
                "predict", "-s", "jitter", "-f", "disk", "-n", "16", "--json",
            ])
            .stdout(full)
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains("standard output: No space left"), "{err}");
    }
    // A reader that closes the pipe at once: the writer ends quietly, as cat does.
    for args in [
        vec!["bias", "--help"],
        vec!["sample", "-s", "random", "-n", "200000"],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_specvar"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("runs");
        drop(child.stdout.take());
        let out = child.wait_with_output().expect("output");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.is_empty(), "{args:?}: {err}");
    }
}

#[test]
fn messages_name_the_option_and_quote_input_safely() {
    refuses_with(
        &["predict", "-s", "jitter", "-f", "disk", "-n", "-1"],
        "invalid value '-1' for '-n <N>'",
    );
    refuses_with(
        &[
            "--budget-memory",
            "-1",
            "predict",
            "-s",
            "jitter",
            "-f",
            "disk",
            "-n",
            "16",
        ],
        "invalid budget memory: -1 (a positive number)",
    );
    refuses_with(
        &[
            "predict",
            "-s",
            "jitter",
            "-n",
            "16",
            "--target-noise",
            "-1",
        ],
        "invalid target noise: -1",
    );
    refuses_with(
        &[
            "mc",
            "-s",
            "random",
            "-f",
            "gaussian:sigma=1e300",
            "-n",
            "16",
        ],
        "invalid sigma: 1e300 (",
    );
    let dir = std::env::temp_dir().join(format!("specvar-bad-text-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let control = dir.join("control.txt");
    std::fs::write(&control, b"\x1b[31mred\x07 0.5\n").unwrap();
    let line = run_bounded(&["spectrum", "--input", control.to_str().unwrap()], &[2]);
    assert!(
        line.contains(r"'\u{1b}[31mred\u{7}' is not a number"),
        "{line}"
    );
    assert!(!line.contains('\x1b'), "{line}");
    let fake = dir.join("fake.png");
    std::fs::write(&fake, b"1 2\n3 4\n").unwrap();
    let spec = format!("grid:{}", fake.display());
    refuses_with(
        &["predict", "-s", "random", "-n", "16", "-f", &spec],
        "named .png but not a PNG image",
    );
}

#[test]
fn a_constant_integrand_has_zero_variance_not_too_few_trials() {
    let out = Command::new(env!("CARGO_BIN_EXE_specvar"))
        .args([
            "mc",
            "-s",
            "random",
            "-f",
            "gaussian:a=0",
            "-n",
            "16",
            "--json",
        ])
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(doc["variance"].as_f64(), Some(0.0), "{doc}");
}

/// Every numeric option of every subcommand at 0, -1, the type's maximum, NaN and infinity:
/// an answer (small inputs) or one error line, never a panic or a hang.
#[test]
fn numeric_options_at_their_extremes_are_answered_or_refused() {
    let render = [
        "render-ao",
        "--sampler",
        "random",
        "--rays",
        "4",
        "--width",
        "8",
        "--height",
        "8",
        "--reference-rays",
        "64",
        "--grid",
        "16",
        "--kmax",
        "8",
    ];
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec!["sample", "-s", "jitter", "-n", "16"],
            vec!["-n", "-d", "--seed", "--realizations"],
        ),
        (
            vec!["spectrum", "-s", "random", "-n", "16", "--kmax", "8"],
            vec![
                "-n",
                "-d",
                "--kmax",
                "--realizations",
                "--bin-width",
                "--tolerance",
                "--sectors",
            ],
        ),
        (
            vec!["predict", "-s", "random", "-f", "disk", "-n", "16"],
            vec![
                "-n",
                "--kmax",
                "--realizations",
                "--target-noise",
                "--reference-n",
                "--seed",
            ],
        ),
        (
            vec!["bias", "-s", "regular", "-f", "disk", "-n", "16"],
            vec!["-n", "--kmax"],
        ),
        (
            vec!["mc", "-s", "random", "-f", "disk", "-n", "16"],
            vec!["-n", "--trials", "--shifts"],
        ),
        (
            vec!["metrics", "-s", "random", "-n", "16", "--realizations", "2"],
            vec!["-n", "--realizations", "--pcf-sigma", "--pcf-rmax"],
        ),
        (
            vec![
                "anisotropy",
                "-s",
                "random",
                "-n",
                "16",
                "--trials",
                "200",
                "--angles",
                "0:90:90",
            ],
            vec!["-n", "--trials", "--offset"],
        ),
        (
            vec![
                "rates",
                "--samplers",
                "random",
                "--integrands",
                "disk",
                "--range",
                "16",
                "32",
            ],
            vec!["--trials"],
        ),
        (
            render.to_vec(),
            vec![
                "--rays",
                "--width",
                "--height",
                "--grid",
                "--kmax",
                "--stride",
                "--patterns",
                "--max-distance",
                "--spectrum-realizations",
            ],
        ),
        (vec!["atlas", "--quick", "--samplers", "random"], vec!["-n"]),
    ];
    let values = ["0", "-1", "18446744073709551615", "nan", "inf"];
    let mut runs: Vec<Vec<String>> = Vec::new();
    for (base, options) in &cases {
        for option in options {
            for value in values {
                // The option replaces its value in the base arguments, or is appended.
                let mut args: Vec<String> = base.iter().map(|s| s.to_string()).collect();
                match args.iter().position(|a| a == option) {
                    Some(i) => args[i + 1] = value.to_string(),
                    None => args.extend([option.to_string(), value.to_string()]),
                }
                runs.push(args);
            }
        }
    }
    let dir = std::env::temp_dir().join(format!("specvar-extremes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::thread::scope(|scope| {
        for (worker, chunk) in runs.chunks(runs.len().div_ceil(2)).enumerate() {
            // Each worker its own output directory: outputs of one directory are one writer's.
            let out = dir
                .join(format!("out-{worker}"))
                .to_string_lossy()
                .into_owned();
            scope.spawn(move || {
                for args in chunk {
                    let mut args: Vec<&str> = args.iter().map(String::as_str).collect();
                    if matches!(args[0], "render-ao" | "atlas") {
                        args.extend(["--out", out.as_str()]);
                    }
                    run_bounded(&args, &[0, 2]);
                }
            });
        }
    });
}

/// What the user typed is named back: shifts beyond the trials, too few trials, the samplers of
/// a pilot, a dimension --pixels cannot take, a file given for a directory; a sampler named
/// twice is planned once.
#[test]
fn refusals_name_what_was_typed() {
    refuses_with(
        &[
            "mc",
            "-s",
            "jitter",
            "-f",
            "disk",
            "-n",
            "16",
            "--shifts",
            "1000000000000",
        ],
        "invalid shifts: 1000000000000 (at most --trials (10000)",
    );
    refuses_with(
        &["anisotropy", "-s", "lhs", "--trials", "0"],
        "invalid trials: 0 (at least 20",
    );
    refuses_with(
        &[
            "plan",
            "--rmse",
            "0.01",
            "--pilot",
            "pilot.npy",
            "--pilot-n",
            "16",
        ],
        "invalid samplers: none given",
    );
    refuses_with(
        &[
            "predict",
            "-s",
            "jitter",
            "-n",
            "16",
            "--pixels",
            "pixels.npy",
            "-d",
            "3",
        ],
        "invalid dimension: 3 (2 with --pixels",
    );
    let file = std::env::temp_dir().join(format!("specvar-out-file-{}", std::process::id()));
    std::fs::write(&file, "mine").unwrap();
    let out = file.display().to_string();
    refuses_with(
        &["atlas", "--quick", "--out", &out],
        "a file, not a directory",
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "mine");
    std::fs::remove_file(&file).unwrap();
    // A run refused after its output directory was checked leaves no directory behind.
    let fresh = file.with_extension("new").join("atlas");
    let out = fresh.display().to_string();
    refuses_with(
        &[
            "--budget-seconds",
            "0.001",
            "atlas",
            "--quick",
            "--out",
            &out,
        ],
        "above the budget",
    );
    assert!(!fresh.exists() && !fresh.parent().unwrap().exists());
    let plan = run_bounded(
        &[
            "plan",
            "-f",
            "disk",
            "--rmse",
            "0.01",
            "--samplers",
            "random,random",
        ],
        &[0],
    );
    assert!(plan.is_empty(), "{plan}");
    let stdout = Command::new(env!("CARGO_BIN_EXE_specvar"))
        .args([
            "plan",
            "-f",
            "disk",
            "--rmse",
            "0.01",
            "--samplers",
            "random,random",
        ])
        .output()
        .unwrap()
        .stdout;
    let rows = String::from_utf8_lossy(&stdout)
        .lines()
        .filter(|l| l.starts_with("random "))
        .count();
    assert_eq!(rows, 1);
}
