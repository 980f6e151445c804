//! The atlas: one entry per sampler with every section filled, and the reasons where a
//! quantity does not exist.

use specvar::atlas::{atlas_markdown, compute_atlas, AtlasConfig};
use specvar::progress::Silent;
use specvar::sampler::SamplerKind;

#[test]
fn atlas_fills_every_section_and_says_why_a_fit_is_missing() {
    let config = AtlasConfig {
        samplers: vec![
            SamplerKind::Random,
            SamplerKind::Korobov,
            SamplerKind::Fibonacci,
        ],
        n: 64,
        realizations: 8,
        alpha_n: 256,
        trials: 2000,
        ..AtlasConfig::quick(5)
    };
    let atlas = compute_atlas(&config, &Silent).unwrap();
    assert_eq!(atlas.entries.len(), 3);
    let random = &atlas.entries[0];
    assert_eq!(random.known_alpha, Some(0.0));
    assert!(
        random.effective_nyquist.is_none(),
        "white noise is above 0.1 everywhere"
    );
    assert_eq!(random.rows.len(), 2);
    // A lattice has no power below its first dual vector: no power law to fit, and a ν_eff.
    let korobov = &atlas.entries[1];
    assert!(korobov.alpha_fit.is_err());
    assert!(korobov.effective_nyquist.unwrap() > 0.5);
    assert_eq!(atlas.entries[2].n, 55, "Fibonacci at the count nearest 64");
    let md = atlas_markdown(&atlas);
    for name in ["## random", "## korobov", "## fibonacci", "pcf-korobov.svg"] {
        assert!(md.contains(name), "{name}");
    }
}

/// The atlas as used: each sampler's predictions and Monte Carlo are for its own estimator
/// (jitter's strata as drawn, by the cell form), the theoretical rate is left to the shifted
/// estimator, and Halton's permuted digits as drawn are predicted through a level of digit
/// cells.
#[test]
fn atlas_as_used_predicts_each_sampler_under_its_own_randomization() {
    use specvar::predict::Form;
    use specvar::randomization::{Randomization, RandomizationChoice};
    let config = AtlasConfig {
        samplers: vec![SamplerKind::Jitter, SamplerKind::Halton],
        n: 64,
        realizations: 8,
        alpha_n: 256,
        trials: 2000,
        randomization: RandomizationChoice::Native,
        ..AtlasConfig::quick(5)
    };
    let atlas = compute_atlas(&config, &Silent).unwrap();
    let jitter = &atlas.entries[0];
    for r in &jitter.rows {
        assert_eq!(r.randomization, Randomization::None);
        let p = r.predicted.as_ref().unwrap();
        assert_eq!(p.route.form, Form::Cells);
        assert_eq!(p.randomization, Randomization::None);
        assert!(r.agrees().unwrap(), "{r:?}");
        assert_eq!(r.rate, None);
    }
    let halton = &atlas.entries[1];
    for r in &halton.rows {
        assert_eq!(r.randomization, Randomization::None);
        let p = r.predicted.as_ref().unwrap();
        assert_eq!(
            p.route.form,
            Form::Walsh,
            "{} {}: {}",
            r.integrand,
            p.route,
            p.reason
        );
        assert_eq!(p.randomization, Randomization::None);
        assert!(r.agrees().unwrap(), "{r:?}");
    }
    let md = atlas_markdown(&atlas);
    assert!(md.contains("as-used estimator"), "{md}");
}

/// The atlas at the smallest documented N (its pair correlation cut to what 16 points' torus
/// holds), and with every pattern used as drawn: the fixed rules say they have no route and no
/// variance to measure, where the atlas used to fail on its Monte Carlo.
#[test]
fn atlas_at_its_edges_answers() {
    use specvar::randomization::{Randomization, RandomizationChoice};
    let small = AtlasConfig {
        samplers: vec![SamplerKind::Random],
        n: 16,
        realizations: 4,
        alpha_n: 256,
        trials: 2000,
        ..AtlasConfig::quick(5)
    };
    let atlas = compute_atlas(&small, &Silent).unwrap();
    let pcf = &atlas.entries[0].pcf;
    assert!(*pcf.radius_in_spacings.last().unwrap() <= 1.6 + 1e-12);
    let drawn = AtlasConfig {
        samplers: vec![SamplerKind::Random, SamplerKind::Korobov],
        n: 64,
        realizations: 4,
        alpha_n: 256,
        trials: 2000,
        randomization: RandomizationChoice::Given(Randomization::None),
        ..AtlasConfig::quick(5)
    };
    let atlas = compute_atlas(&drawn, &Silent).unwrap();
    for r in &atlas.entries[1].rows {
        assert!(r.predicted.is_none() && r.measured.is_none(), "{r:?}");
        assert!(r.unpredicted.as_deref().unwrap().contains("fixed pattern"));
    }
    assert!(atlas.entries[0]
        .rows
        .iter()
        .all(|r| r.agrees() == Some(true)));
    assert!(atlas_markdown(&atlas).contains("a bias, no variance"));
}
