//! The docs that list library facts say what the library says: the README's table of samplers
//! is the descriptors' table, and the theory notes' table of analyses is the plan's.

use specvar::sampler::SamplerKind;

/// The text between `<!-- NAME:begin -->` and `<!-- NAME:end -->` in `doc`.
fn section<'a>(doc: &'a str, name: &str) -> &'a str {
    let begin = format!("<!-- {name}:begin -->\n");
    let start = doc.find(&begin).expect("the section's start marker") + begin.len();
    let end = doc[start..]
        .find(&format!("<!-- {name}:end -->"))
        .expect("the section's end marker");
    &doc[start..start + end]
}

#[test]
fn the_readme_lists_every_sampler_as_the_library_describes_it() {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    assert_eq!(
        section(&readme, "samplers"),
        SamplerKind::markdown_table(),
        "the README's sampler table differs from the descriptors: paste `specvar samplers \
         --markdown` between its markers"
    );
}

#[test]
fn the_theory_notes_map_every_problem_to_the_analysis_the_plan_takes() {
    let theory =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/theory.md")).unwrap();
    assert_eq!(
        section(&theory, "analyses"),
        specvar::predict::analyses_markdown(256),
        "the theory notes' table of analyses differs from the plan: paste `specvar samplers \
         --analyses` between its markers"
    );
}
