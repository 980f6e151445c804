//! The command line: exit codes, one-line errors, output formats and JSON keys.

use std::process::Command;

fn specvar(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_specvar"))
        .args(args)
        .output()
        .expect("the binary runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text.trim()).expect("valid JSON")
}

#[test]
fn bad_input_prints_one_line_and_exits_2() {
    for args in [
        vec!["sample", "-s", "jitter", "-n", "17"],
        vec!["sample", "-s", "nope", "-n", "4"],
        vec!["sample", "--bogus"],
        vec!["predict", "-s", "jitter", "-n", "16", "-f", "disk:q=1"],
        vec!["predict", "-s", "halton", "-n", "16", "--form", "polar"],
        vec!["mc", "-s", "ccvt", "-n", "16", "-d", "5"],
        vec!["spectrum", "--input", "/nonexistent/points.txt"],
    ] {
        let (code, _, err) = specvar(&args);
        assert_eq!(code, 2, "{args:?}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
    }
    let (_, _, err) = specvar(&["sample", "-s", "jitter", "-n", "17"]);
    assert!(err.contains("16 or 18"), "{err}");
}

#[test]
fn malformed_files_report_the_line() {
    let path = std::env::temp_dir().join("specvar_cli_bad.txt");
    std::fs::write(&path, "0.1 0.2\n0.3 0.4\n0.5 1.5\n").unwrap();
    let (code, _, err) = specvar(&["spectrum", "--input", path.to_str().unwrap(), "--radial"]);
    assert_eq!(code, 2);
    assert!(err.contains("line 3"), "{err}");
}

#[test]
fn sample_writes_utk_text_and_json() {
    let (code, out, _) = specvar(&[
        "sample",
        "-s",
        "jitter",
        "-n",
        "16",
        "-m",
        "2",
        "--homogenize",
    ]);
    assert_eq!(code, 0);
    let sets = specvar::io::read_text(&out).unwrap();
    assert_eq!((sets.len(), sets[0].len()), (2, 16));
    let (_, out, _) = specvar(&["sample", "-s", "sobol", "-n", "8", "-d", "3", "--json"]);
    let sets = specvar::io::read_json(&out).unwrap();
    assert_eq!((sets[0].len(), sets[0].dimension()), (8, 3));
}

#[test]
fn json_outputs_have_the_documented_keys() {
    let (_, out, _) = specvar(&[
        "spectrum", "-s", "random", "-n", "64", "-m", "4", "--kmax", "8", "--radial", "--json",
    ]);
    let v = json(&out);
    for key in ["n", "dimension", "realizations", "method", "bins"] {
        assert!(v.get(key).is_some(), "radial: {key}");
    }
    for key in ["nu", "rho", "power", "stderr", "count", "anisotropy_db"] {
        assert!(v["bins"][0].get(key).is_some(), "bin: {key}");
    }
    let (_, out, _) = specvar(&[
        "spectrum", "-s", "random", "-n", "64", "-m", "2", "--kmax", "4", "--json",
    ]);
    let v = json(&out);
    assert_eq!(v["values"].as_array().unwrap().len(), 81);
    let (_, out, _) = specvar(&[
        "predict",
        "-s",
        "jitter",
        "-f",
        "disk",
        "-n",
        "64",
        "--spectrum",
        "closed",
        "--json",
    ]);
    let v = json(&out);
    for key in [
        "sampler",
        "integrand",
        "n",
        "dimension",
        "variance",
        "variance_lattice",
        "dc_term",
        "spectrum_source",
        "quadrature_error",
    ] {
        assert!(v.get(key).is_some(), "predict: {key}");
    }
    let (_, out, _) = specvar(&[
        "mc", "-s", "jitter", "-f", "disk", "-n", "16", "--trials", "500", "--json",
    ]);
    let v = json(&out);
    for key in [
        "sampler",
        "integrand",
        "n",
        "trials",
        "variance",
        "ci_low",
        "ci_high",
        "bias",
    ] {
        assert!(v.get(key).is_some(), "mc: {key}");
    }
    let (_, out, _) = specvar(&[
        "bias", "-s", "regular", "-f", "gaussian", "-n", "16", "--json",
    ]);
    assert!(json(&out)["bias"].as_f64().unwrap() < 0.0);
    let (_, out, _) = specvar(&[
        "rates",
        "--samplers",
        "jitter",
        "--integrands",
        "gaussian",
        "--range",
        "16",
        "256",
        "--trials",
        "300",
        "--json",
    ]);
    let v = json(&out);
    for key in [
        "sampler",
        "integrand",
        "dimension",
        "theory_rate",
        "predicted_rate",
        "empirical_rate",
        "alpha",
        "alpha_source",
    ] {
        assert!(v["rows"][0].get(key).is_some(), "rates: {key}");
    }
    for key in ["slope", "stderr", "ci"] {
        assert!(
            v["rows"][0]["empirical_rate"].get(key).is_some(),
            "rates: {key}"
        );
    }
    assert!(v["n_values"].as_array().is_some_and(|a| a.len() >= 2));
}

#[test]
fn samplers_lists_every_sampler() {
    let (code, out, _) = specvar(&["samplers"]);
    assert_eq!(code, 0);
    for name in specvar::SamplerKind::names() {
        assert!(out.contains(name), "{name}");
    }
}

#[test]
fn render_ao_writes_images_and_prints_the_json_keys() {
    let dir = std::env::temp_dir().join("specvar-cli-render");
    let _ = std::fs::remove_dir_all(&dir);
    let out_dir = dir.to_string_lossy().into_owned();
    let args = [
        "render-ao",
        "--sampler",
        "jitter",
        "--rays",
        "96",
        "--width",
        "6",
        "--height",
        "4",
        "--reference-rays",
        "256",
        "--grid",
        "16",
        "--kmax",
        "16",
        "--spectrum-realizations",
        "8",
        "--out",
        &out_dir,
        "--json",
    ];
    let (code, out, err) = specvar(&args);
    assert_eq!(code, 0, "{err}");
    let v = json(&out);
    for key in ["sampler", "rays", "mse", "mse_stderr", "predicted_mse"] {
        assert!(v.get(key).is_some(), "render-ao: {key}");
    }
    assert_eq!(v["rays"], 96);
    for file in [
        "ao-jitter.png",
        "reference.png",
        "strip.svg",
        "comparison.md",
    ] {
        assert!(dir.join(file).exists(), "{file}");
    }
    for bad in [
        vec!["render-ao", "--sampler", "nope"],
        vec!["render-ao", "--sampler", "jitter", "--rays", "17"],
        vec!["render-ao", "--sampler", "random", "--width", "0"],
        vec!["render-ao", "--sampler", "random", "--max-distance", "-1"],
    ] {
        let (code, _, err) = specvar(&bad);
        assert_eq!(code, 2, "{bad:?}");
        assert_eq!(err.trim().lines().count(), 1, "{bad:?}: {err}");
    }
}

#[test]
fn predict_accepts_grid_files_and_names_bad_lines() {
    let dir = std::env::temp_dir().join("specvar-cli-grid");
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("g.txt");
    std::fs::write(&good, "0 1 1 0\n1 1 1 1\n0 1 1 0\n0 0 0 0\n").unwrap();
    let spec = format!("grid:{},exact", good.display());
    let (code, out, err) = specvar(&[
        "predict",
        "-s",
        "random",
        "-n",
        "16",
        "-f",
        &spec,
        "--spectrum",
        "closed",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v = json(&out);
    // 8 of 16 cells are 1: (1/2 - 1/4) / 16.
    let variance = v["variance"].as_f64().unwrap();
    assert!((variance - 0.25 / 16.0).abs() < 1e-15, "{variance}");
    assert_eq!(v["form"], "lattice");
    let bad = dir.join("bad.txt");
    std::fs::write(&bad, "0 1\n1 oops\n").unwrap();
    let spec = format!("grid:{}", bad.display());
    let (code, _, err) = specvar(&["predict", "-s", "random", "-n", "16", "-f", &spec]);
    assert_eq!(code, 2);
    assert!(err.contains("line 2"), "{err}");
}

/// Point sets written by another program (here: formulas in this test, formatted by hand): 24
/// shifted copies of 128 points of the R2 Kronecker sequence, `x_i = frac(s + i (1/φ, 1/φ²))`
/// with φ the plastic number, shifts from a linear congruential generator. `predict --input`
/// gives the mean of the sets' exact shift variances (up to its tail bound), which `mc --input`
/// measures on exactly those sets: they must agree within Monte Carlo's error.
#[test]
fn predict_and_mc_accept_point_sets_written_elsewhere() {
    let phi = 1.324_717_957_244_746_f64;
    let step = [1.0 / phi, 1.0 / (phi * phi)];
    let mut state: u64 = 12345;
    let mut lcg = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut text = String::from("# R2 sequence, 24 shifted copies\n");
    for set in 0..24 {
        if set > 0 {
            text.push_str("#\n");
        }
        let shift = [lcg(), lcg()];
        for i in 0..128 {
            let x: Vec<String> = (0..2)
                .map(|a| format!("{:.17}", (shift[a] + i as f64 * step[a]).fract()))
                .collect();
            text.push_str(&x.join(" "));
            text.push('\n');
        }
    }
    let path = std::env::temp_dir().join("specvar_cli_r2_sets.txt");
    std::fs::write(&path, &text).unwrap();
    let file = path.to_str().unwrap();
    // The shifted estimator of the given sets, predicted and measured.
    let (code, out, err) = specvar(&[
        "predict",
        "--input",
        file,
        "-f",
        "gaussian",
        "--randomization",
        "shift",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let p = json(&out);
    assert_eq!(p["n"].as_u64(), Some(128));
    let variance = p["variance"].as_f64().unwrap();
    let truncation = p["budget"]["truncation"].as_f64().unwrap();
    let (code, out, err) = specvar(&[
        "mc",
        "--input",
        file,
        "-f",
        "gaussian",
        "--trials",
        "96000",
        "--randomization",
        "shift",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let m = json(&out);
    assert_eq!(
        (m["patterns"].as_u64(), m["shifts"].as_u64()),
        (Some(24), Some(4000))
    );
    let (lo, hi) = (
        m["ci_low"].as_f64().unwrap(),
        m["ci_high"].as_f64().unwrap(),
    );
    assert!(
        variance + truncation >= lo && variance - truncation <= hi,
        "predicted {variance} vs Monte Carlo [{lo}, {hi}]"
    );
}

/// The help of every command that takes an integrand names every form the parser accepts, and
/// each form named there parses.
#[test]
fn the_help_lists_every_integrand_form() {
    for command in ["predict", "mc", "bias"] {
        let (code, help, _) = specvar(&[command, "--help"]);
        assert_eq!(code, 0);
        let flat = help.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(
            flat.contains(specvar::integrand::INTEGRAND_FORMS),
            "{command} --help: {help}"
        );
    }
    for form in [
        "disk",
        "ball",
        "gaussian",
        "grid:x.png",
        "polygon:0,0;1,0;0,1",
        "edge:theta=30",
        "agaussian:s1=0.05",
    ] {
        assert!(
            specvar::integrand::INTEGRAND_FORMS.contains(form.split(':').next().unwrap()),
            "{form}"
        );
        specvar::integrand::parse_integrand(form).expect(form);
    }
}
