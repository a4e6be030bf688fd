//! The documents generated from the code are the committed ones (issue 16): the scene schema
//! `scenes/scene.schema.json` (`fmu-harness schema`) and the scene reference
//! `docs/scene-reference.md` (`fmu-harness reference`); a change of a scene struct, a doc
//! comment or a rule fails here until the files are regenerated (`make docs`).

use fmu_harness::{reference, schema};
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The first line where two texts differ, for a message that says where the drift is.
fn first_difference(committed: &str, generated: &str) -> String {
    let (a, b): (Vec<_>, Vec<_>) = (committed.lines().collect(), generated.lines().collect());
    for k in 0..a.len().max(b.len()) {
        let (x, y) = (a.get(k), b.get(k));
        if x != y {
            return format!(
                "line {}:\n  committed: {:?}\n  generated: {:?}",
                k + 1,
                x.unwrap_or(&"<end>"),
                y.unwrap_or(&"<end>")
            );
        }
    }
    "(line endings)".into()
}

fn assert_committed(path: &str, generated: &str, command: &str) {
    let committed = std::fs::read_to_string(repo().join(path)).unwrap_or_default();
    assert!(
        committed == generated,
        "{path} is not what the code generates; run `{command}` (or `make docs`).\n{}",
        first_difference(&committed, generated)
    );
}

#[test]
fn the_committed_schema_is_generated_from_the_code() {
    assert_committed(
        &format!("scenes/{}", schema::FILE_NAME),
        &schema::scene_schema_text(),
        "fmu-harness schema -o scenes/scene.schema.json",
    );
}

#[test]
fn the_committed_reference_is_generated_from_the_code() {
    assert_committed(
        reference::FILE_NAME,
        &reference::scene_reference(),
        "fmu-harness reference -o docs/scene-reference.md",
    );
}

#[test]
fn the_reference_lists_every_field_of_every_table() {
    let page = reference::scene_reference();
    let mut root = schema::raw();
    schema::tidy(&mut root);
    let tables = reference::tables(&root);
    for heading in [
        "[world]",
        "[solver]",
        "[experiment]",
        "[[beam]]",
        "[beam.material]",
        "[beam.section]",
        "[beam.rayleigh]",
        "[beam.initial]",
        "[[body]]",
        "[[joint]]",
        "[joint.drive]",
        "[[load]]",
        "[load.scale]",
    ] {
        assert!(
            tables.iter().any(|t| t.heading == heading),
            "no table {heading}"
        );
        assert!(
            page.contains(&format!("## `{heading}`")),
            "no section {heading}"
        );
    }
    for t in &tables {
        for f in &t.fields {
            assert!(
                f.schema.get("description").is_some(),
                "{} has no doc comment",
                f.path
            );
            assert!(
                page.contains(&format!("| `{}` |", f.key)),
                "{} is not on the page",
                f.path
            );
        }
    }
    // every rule, by its code
    for r in fmu_beam::scene::rules::RULES {
        assert!(
            page.contains(&format!("| `{}` |", r.code)),
            "rule {}",
            r.code
        );
    }
}
