//! The plan of a prediction, made before any work: every sampler's plan names an analysis, a
//! reason and needs; the prediction takes the planned analysis; needs above the budget are
//! refused before anything is drawn.

use specvar::budget::Budget;
use specvar::integrand::*;
use specvar::pixels::{pixel_params, predict_pixels, PixelStack};
use specvar::predict::*;
use specvar::progress::Silent;
use specvar::randomization::{Randomization, RandomizationChoice};
use specvar::sampler::*;
use specvar::Error;
use std::process::Command;

/// Every sampler under its native randomization and under a shift has a plan, and its
/// prediction names the planned analysis.
#[test]
fn every_prediction_takes_its_planned_analysis() {
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let params = PredictParams {
        target_noise: 0.5,
        ..PredictParams::default()
    };
    for kind in SamplerKind::in_dimension(2) {
        let sampler = kind.build(2).unwrap();
        let n = kind.nearest_count(64, 2);
        for r in [kind.native_randomization(), Randomization::Shift] {
            let problem = Problem::new(sampler.as_ref(), &disk, n)
                .unwrap()
                .with_randomization(r);
            let plan = plan_analysis(&problem, &params).unwrap();
            assert!(!plan.reason.is_empty(), "{kind} {r}");
            assert!(plan.needs.seconds >= 0.0 && plan.needs.bytes >= 0.0);
            let p = predict(&problem, &params).unwrap();
            assert_eq!(p.analysis, Some(plan.analysis), "{kind} {r}");
        }
    }
}

/// A plan whose patterns alone exceed the budget is refused before one is drawn: the
/// Owen-scrambled net's one pattern at N = 2^32 − 1 (64 GiB), the digitally shifted net's at
/// 2^30 under two seconds of work. Both used to abort on the allocation.
#[test]
fn needs_above_the_budget_are_refused_before_any_work() {
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let tight = PredictParams {
        budget: Budget {
            work_seconds: 2.0,
            ..Budget::default()
        },
        ..PredictParams::default()
    };
    for (kind, n, analysis) in [
        (
            SamplerKind::Sobol,
            u32::MAX as usize,
            AnalysisKind::OwenGains,
        ),
        (SamplerKind::SobolNet, 1 << 30, AnalysisKind::WalshFixed),
    ] {
        let sampler = kind.build(2).unwrap();
        let problem = Problem::new(sampler.as_ref(), &disk, n).unwrap();
        for outcome in [
            plan_analysis(&problem, &tight).map(|_| ()),
            predict(&problem, &tight).map(|_| ()),
        ] {
            match outcome {
                Err(Error::TooLarge { what, .. }) => {
                    assert!(what.contains(analysis.name()), "{kind}: {what}")
                }
                other => panic!("{kind} at N = {n}: {other:?}"),
            }
        }
    }
}

/// An image's pixels are planned together: 20 000 pixels on dart throwing at N = 16 need
/// minutes, refused under a budget of two seconds before any pixel is predicted.
#[test]
fn an_image_is_planned_as_a_whole() {
    let pixel = GridIntegrand::new(4, 4, (0..16).map(|i| i as f64 / 15.0).collect())
        .unwrap()
        .with_meaning(specvar::integrand::GridMeaning::Exact);
    let stack = PixelStack::new(200, vec![pixel; 20_000]).unwrap();
    let params = PredictParams {
        budget: Budget {
            work_seconds: 2.0,
            ..Budget::default()
        },
        ..pixel_params(&PredictParams::default())
    };
    let poisson = PoissonDisk::new(2).unwrap();
    let outcome = predict_pixels(
        &stack,
        &poisson,
        16,
        RandomizationChoice::Native,
        &params,
        &Silent,
    );
    match outcome {
        Err(Error::TooLarge { what, .. }) => assert!(what.contains("20000 pixels"), "{what}"),
        other => panic!("{:?}", other.map(|i| i.mse)),
    }
}

/// `predict --explain --json` prints the plan alone (analysis, reason, needs), and the
/// prediction's JSON names the same analysis.
#[test]
fn the_command_line_shows_the_plan() {
    let run = |extra: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_specvar"))
            .args(["predict", "-s", "cmj", "-n", "64", "-f", "disk", "--json"])
            .args(extra)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let plan = run(&["--explain"]);
    for key in ["analysis", "reason", "needs"] {
        assert!(plan.get(key).is_some(), "{plan}");
    }
    assert!(plan["needs"]["seconds"].is_number() && plan["needs"]["bytes"].is_number());
    assert_eq!(plan["analysis"], "rooks-pairs");
    let prediction = run(&[]);
    assert_eq!(prediction["analysis"], plan["analysis"]);
}

/// A sampler of one's own: its law unknown, its native estimator is the shifted one, for one
/// problem and for an image's pixels alike (the pixels used to refuse what a problem took).
#[test]
fn a_sampler_of_ones_own_is_shifted_everywhere() {
    #[derive(Debug)]
    struct Own(Jitter);
    impl Sampler for Own {
        fn name(&self) -> &'static str {
            "own"
        }
        fn dimension(&self) -> usize {
            2
        }
        fn sample(
            &self,
            n: usize,
            seed: u64,
            r: u64,
        ) -> specvar::Result<specvar::pointset::PointSet> {
            self.0.sample(n, seed, r)
        }
    }
    let own = Own(Jitter::new(2).unwrap());
    let pixel = GridIntegrand::new(4, 4, (0..16).map(|i| i as f64 / 15.0).collect())
        .unwrap()
        .with_meaning(specvar::integrand::GridMeaning::Exact);
    let problem = Problem::new(&own, &pixel, 64).unwrap();
    assert_eq!(problem.randomization, Randomization::Shift);
    let stack = PixelStack::new(1, vec![pixel.clone()]).unwrap();
    let params = PredictParams {
        target_noise: 0.2,
        ..pixel_params(&PredictParams::default())
    };
    let image = predict_pixels(
        &stack,
        &own,
        64,
        RandomizationChoice::Native,
        &params,
        &Silent,
    )
    .unwrap();
    assert_eq!(image.randomization, Randomization::Shift);
}
