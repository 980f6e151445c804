//! Point-set files: round trips, errors with line numbers, and no panics on any input.

use proptest::prelude::*;
use specvar::io::{read_json, read_text, write_json, write_text};
use specvar::sampler::SamplerKind;
use specvar::{Error, PointSet};

fn sets() -> Vec<PointSet> {
    let s = SamplerKind::Random.build(3).unwrap();
    (0..3).map(|r| s.sample(10, 1, r).unwrap()).collect()
}

#[test]
fn text_round_trip_is_exact() {
    let original = sets();
    assert_eq!(read_text(&write_text(&original)).unwrap(), original);
}

#[test]
fn json_round_trip_is_exact() {
    let original = sets();
    assert_eq!(
        read_json(&write_json(&original).unwrap()).unwrap(),
        original
    );
}

fn error_line(r: specvar::Result<Vec<PointSet>>) -> usize {
    match r {
        Err(Error::Parse { line, .. }) => line,
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn bad_text_names_the_line() {
    assert_eq!(error_line(read_text("0.1 0.2\n0.3 0.4\n0.5\n")), 3);
    assert_eq!(error_line(read_text("0.1 0.2\n# next\n0.3 x\n")), 3);
    assert_eq!(error_line(read_text("0.1 0.2\n\n0.3 1.0\n")), 3);
    assert_eq!(error_line(read_text("0.1 -0.2\n")), 1);
    assert_eq!(error_line(read_text("0.1 NaN\n")), 1);
    assert_eq!(error_line(read_text("")), 1);
    assert_eq!(error_line(read_text("# only a comment\n")), 1);
    let nine = "0.1 ".repeat(9);
    assert_eq!(error_line(read_text(&nine)), 1);
}

#[test]
fn comments_separate_realizations_and_blank_lines_are_skipped() {
    let s = read_text("# header\n0.1\n0.2\n\n#\n0.3\n").unwrap();
    assert_eq!(s.len(), 2);
    assert_eq!(s[0].coords(), &[0.1, 0.2]);
    assert_eq!(s[1].coords(), &[0.3]);
}

#[test]
fn bad_json_is_an_error_with_a_line() {
    assert_eq!(
        error_line(read_json(
            "{\n\"dimension\": 2,\n\"realizations\": [[[0.1, 0.2]]\n"
        )),
        4
    );
    assert!(read_json(r#"{"dimension": 2, "realizations": [[[0.1]]]}"#).is_err());
    assert!(read_json(r#"{"dimension": 2, "realizations": [[[0.1, 1.5]]]}"#).is_err());
    assert!(read_json(r#"{"dimension": 2, "realizations": []}"#).is_err());
    assert!(read_json(r#"{"dimension": 0, "realizations": [[[0.1]]]}"#).is_err());
}

proptest! {
    #[test]
    fn any_text_gives_points_or_an_error(text in "\\PC{0,200}") {
        match read_text(&text) {
            Ok(sets) => prop_assert!(sets.iter().all(|s| s.coords().iter().all(|c| (0.0..1.0).contains(c)))),
            Err(Error::Parse { line, .. }) => prop_assert!(line >= 1),
            Err(e) => prop_assert!(false, "unexpected error kind {e:?}"),
        }
        let _ = read_json(&text);
    }

    #[test]
    fn numeric_looking_text_never_panics(text in "([0-9. e#\\-]{0,12}\n){0,12}") {
        let _ = read_text(&text);
        let _ = read_json(&text);
    }
}

/// UTK's binary format: written as doubles and read back bit for bit; a float file typed by
/// hand (the header's fields at their offsets) reads to the floats' values; malformed headers,
/// integer types, short files and coordinates outside [0, 1) are refused.
#[test]
fn utk_binary_round_trips_and_refuses_malformed_files() {
    use specvar::io::{read_utk_binary, write_utk_binary};
    use specvar::sampler::{Sampler, SamplerKind};
    let s = SamplerKind::Sobol.build(3).unwrap();
    let sets: Vec<_> = (0..3).map(|r| s.sample(50, 2, r).unwrap()).collect();
    let bytes = write_utk_binary(&sets).unwrap();
    assert_eq!(bytes.len(), 20 + 3 * 50 * 3 * 8);
    assert_eq!(read_utk_binary(&bytes).unwrap(), sets);

    let mut floats = b"UTK!".to_vec();
    floats.extend_from_slice(&[4, 0, 0, 0]);
    for v in [1u32, 2, 2] {
        floats.extend_from_slice(&v.to_le_bytes());
    }
    for v in [0.25f32, 0.5, 0.75, 0.125] {
        floats.extend_from_slice(&v.to_le_bytes());
    }
    let read = read_utk_binary(&floats).unwrap();
    assert_eq!(read[0].coords(), &[0.25, 0.5, 0.75, 0.125]);

    let mut integer = floats.clone();
    integer[4] = 2;
    let mut short = floats.clone();
    short.pop();
    let mut outside = floats.clone();
    outside[20..24].copy_from_slice(&1.5f32.to_le_bytes());
    let mut zero_points = floats.clone();
    zero_points[12..16].copy_from_slice(&0u32.to_le_bytes());
    let mut huge = floats.clone();
    huge[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    for bad in [
        &b"UTK?"[..],
        &integer,
        &short,
        &outside,
        &zero_points,
        &huge,
        &floats[..10],
    ] {
        assert!(read_utk_binary(bad).is_err());
    }
}
