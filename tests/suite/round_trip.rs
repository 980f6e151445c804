//! Every value a user can name on the command line, in Python or in a file reads back from its
//! display: `parse(display(x)) == x`.

use specvar::integrand::IntegrandSpec;
use specvar::predict::{FormChoice, SpectrumChoice};
use specvar::randomization::{Randomization, RandomizationChoice};
use specvar::sampler::SamplerKind;
use specvar::spectrum::{Engine, EngineChoice};
use std::fmt::Display;
use std::str::FromStr;

fn round_trips<T>(values: impl IntoIterator<Item = T>)
where
    T: Display + FromStr + PartialEq + std::fmt::Debug,
    T::Err: std::fmt::Debug,
{
    for x in values {
        let text = x.to_string();
        let back: T = text
            .parse()
            .unwrap_or_else(|e| panic!("'{text}' does not parse: {e:?}"));
        assert_eq!(back, x, "'{text}'");
    }
}

#[test]
fn samplers_round_trip() {
    round_trips(SamplerKind::ALL);
}

#[test]
fn options_round_trip() {
    round_trips(Randomization::ALL);
    round_trips(
        Randomization::ALL
            .map(RandomizationChoice::Given)
            .into_iter()
            .chain([RandomizationChoice::Native]),
    );
    round_trips([FormChoice::Auto, FormChoice::Lattice, FormChoice::Polar]);
    round_trips([
        SpectrumChoice::Auto,
        SpectrumChoice::Closed,
        SpectrumChoice::Estimated,
    ]);
    round_trips([EngineChoice::Auto, EngineChoice::Direct, EngineChoice::Fast]);
    round_trips([
        Engine::Auto,
        Engine::Direct,
        Engine::fast(),
        Engine::Fast { tolerance: 1e-9 },
        Engine::Fast { tolerance: 3.7e-12 },
    ]);
}

#[test]
fn integrands_round_trip() {
    let texts = [
        "disk",
        "ball:r=0.1,a=2,c=0.3",
        "disk:c=0.2;0.7",
        "gaussian",
        "gaussian:sigma=0.05,a=0.5,c=0.5;0.25;0.75",
        "grid:some picture.png",
        "polygon:0.2,0.3;0.7,0.3;0.7,0.8",
        "edge",
        "edge:theta=30,offset=0.25,a=3",
        "agaussian",
        "agaussian:s1=0.2,s2=0.01,angle=-15,a=2,c=0.4;0.6",
    ];
    round_trips(texts.iter().map(|t| t.parse::<IntegrandSpec>().unwrap()));
}

#[test]
fn bad_names_list_what_is_allowed() {
    let e = "cube".parse::<IntegrandSpec>().unwrap_err().to_string();
    assert!(e.contains("disk") && e.contains("polygon"), "{e}");
    let e = "disk:sigma=0.1"
        .parse::<IntegrandSpec>()
        .unwrap_err()
        .to_string();
    assert!(e.contains("accepted keys for disk: r (radius)"), "{e}");
    let e = "xor".parse::<Randomization>().unwrap_err().to_string();
    assert!(e.contains("shift, digital-shift or none"), "{e}");
    let e = "fast:tolerance=2"
        .parse::<Engine>()
        .unwrap_err()
        .to_string();
    assert!(e.contains("fast:tolerance=T"), "{e}");
}
