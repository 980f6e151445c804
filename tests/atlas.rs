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
