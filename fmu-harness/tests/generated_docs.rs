//! The documents generated from the code are the committed ones (issue 16): the scene schema
//! `scenes/scene.schema.json` (`fmu-harness schema`) and the scene reference
//! `docs/scene-reference.md` (`fmu-harness reference`); a change of a scene struct, a doc
//! comment or a rule fails here until the files are regenerated (`make docs`). And every FMU's
//! `documentation/index.html` lists each variable of the table that writes its
//! modelDescription.xml, with its causality, variability, type, unit and meaning.

use fmu_beam::Scene;
use fmu_beam::VariableTable;
use fmu_harness::platform::Platform;
use fmu_harness::{model_description, package, reference, schema};
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

/// The rows of the documentation's variable table, as the cells' text.
fn rows(html: &str) -> Vec<Vec<String>> {
    let table = html
        .split("<table id=\"variables\">")
        .nth(1)
        .and_then(|t| t.split("</table>").next())
        .expect("no variables table");
    table
        .split("<tr>")
        .skip(2) // before the first row, the header
        .map(|row| {
            row.split("<td")
                .skip(1)
                .map(|c| {
                    let inner = &c[c.find('>').unwrap() + 1..c.find("</td>").unwrap()];
                    inner
                        .replace("<code>", "")
                        .replace("</code>", "")
                        .replace("&lt;", "<")
                        .replace("&gt;", ">")
                        .replace("&amp;", "&")
                })
                .collect()
        })
        .collect()
}

#[test]
fn every_fmu_documents_each_variable_as_its_model_description_declares_it() {
    let mut scenes: Vec<_> = std::fs::read_dir(repo().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 20);
    for path in scenes {
        let scene = Scene::load(&path).unwrap();
        let table = VariableTable::build(&scene);
        let c = package::contents(&scene, &[(Platform::Linux64, b"engine".as_slice())]).unwrap();
        let rows = rows(&c.documentation);
        assert_eq!(rows.len(), table.variables.len(), "{}", path.display());
        for v in &table.variables {
            let row = rows
                .iter()
                .find(|r| r[0] == v.name)
                .unwrap_or_else(|| panic!("{}: {} is not documented", path.display(), v.name));
            let expected = [
                v.name.clone(),
                v.causality.as_str().to_string(),
                v.variability.as_str().to_string(),
                v.ty.as_str().to_string(),
                model_description::unit(v).unwrap_or("").to_string(),
                model_description::start_text(v).unwrap_or_default(),
                v.vr.to_string(),
                v.description.clone(),
            ];
            assert_eq!(row[..], expected[..], "{}", path.display());
            assert!(!v.description.is_empty(), "{} has no meaning", v.name);
        }
        // what a master's user connects comes first
        let rank = |c: &str| {
            ["input", "output"]
                .iter()
                .position(|x| *x == c)
                .unwrap_or(2)
        };
        assert!(rows.windows(2).all(|w| rank(&w[0][1]) <= rank(&w[1][1])));
    }
}
