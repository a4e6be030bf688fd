//! The validator's rule table is what the validator does (issue 16): every rule of
//! `scene::rules::RULES` refuses at least one scene of `tests/refused_scenes.toml`, with the
//! rule's code and a field the rule names; each entry says truly whether the rule has a
//! JSON-Schema form (the Python test checks the schema against the same entries). Together with
//! the validator refusing only through a rule (`Checker::fail` takes a `Rule`), the reference
//! page generated from the table cannot claim a rule the validator does not apply.

use fmu_beam::scene::rules::{self, Schema, RULES};
use fmu_beam::scene::SceneError;
use fmu_beam::Scene;
use std::path::{Path, PathBuf};
use toml::Value;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn cases() -> Value {
    let text = std::fs::read_to_string(repo().join("tests/refused_scenes.toml")).unwrap();
    toml::from_str(&text).unwrap()
}

/// The value at a dotted path (`beam.0.section.A`), created as tables (or appended to an array)
/// where missing.
fn slot<'a>(doc: &'a mut Value, path: &str) -> &'a mut Value {
    let mut cur = doc;
    for key in path.split('.') {
        cur = match (cur, key.parse::<usize>()) {
            (Value::Array(a), Ok(i)) => {
                if i == a.len() {
                    a.push(Value::Table(Default::default()));
                }
                &mut a[i]
            }
            (Value::Table(t), _) => t
                .entry(key.to_string())
                .or_insert_with(|| Value::Table(Default::default())),
            (other, _) => panic!("{path}: {key} inside {other:?}"),
        };
    }
    cur
}

fn unset(doc: &mut Value, path: &str) {
    let (parent, last) = match path.rsplit_once('.') {
        Some((p, l)) => (Some(p), l),
        None => (None, path),
    };
    let table = match parent {
        Some(p) => slot(doc, p),
        None => doc,
    };
    table.as_table_mut().unwrap().remove(last);
}

/// The scene of one entry: its base with `set` and `unset` applied, a matrix file read from
/// `scenes/` as `Scene::load` would.
fn scene_text(all: &Value, case: &Value) -> String {
    let base = case.get("base").and_then(Value::as_str).unwrap_or("planar");
    let text = all["base"][base].as_str().unwrap();
    let mut doc: Value = toml::from_str(text).unwrap();
    for path in case
        .get("unset")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        unset(&mut doc, path.as_str().unwrap());
    }
    if let Some(Value::Table(set)) = case.get("set") {
        for (path, v) in set {
            *slot(&mut doc, path) = v.clone();
        }
    }
    if let Some(Value::Table(repeat)) = case.get("repeat") {
        for (path, length) in repeat {
            let length = length.as_integer().unwrap() as usize;
            let Value::Array(items) = slot(&mut doc, path) else {
                panic!("repeat {path}: not an array");
            };
            while items.len() < length {
                let mut item = items.last().unwrap().clone();
                if let Some(Value::String(name)) = item.get_mut("name") {
                    *name = format!("{name}_{}", items.len());
                }
                items.push(item);
            }
        }
    }
    for beam in doc
        .get_mut("beam")
        .and_then(Value::as_array_mut)
        .into_iter()
        .flatten()
    {
        if let Some(file) = beam.get("matrix_file").and_then(Value::as_str) {
            let text = std::fs::read_to_string(repo().join("scenes").join(file)).unwrap();
            beam.as_table_mut()
                .unwrap()
                .insert("matrix_text".into(), Value::String(text));
        }
    }
    toml::to_string(&doc).unwrap()
}

#[test]
fn the_base_scenes_are_accepted() {
    let all = cases();
    for (name, text) in all["base"].as_table().unwrap() {
        Scene::from_toml_str(text.as_str().unwrap(), name).unwrap();
    }
}

#[test]
fn every_rule_refuses_its_scenes_with_its_code_and_field() {
    let all = cases();
    let entries = all["refused"].as_array().unwrap();
    for (k, case) in entries.iter().enumerate() {
        let code = case["rule"].as_str().unwrap();
        let rule = rules::find(code).unwrap_or_else(|| panic!("entry {k}: no rule {code}"));
        let text = scene_text(&all, case);
        let err = Scene::from_toml_str(&text, "refused")
            .map(|_| ())
            .expect_err(&format!("entry {k} ({code}) is accepted:\n{text}"));
        let SceneError::Invalid {
            code: got,
            field,
            rule: message,
            ..
        } = &err
        else {
            panic!("entry {k} ({code}): {err}");
        };
        assert_eq!(*got, code, "entry {k}: {err}");
        assert!(
            rule.fields.iter().any(|p| rules::field_matches(p, field)),
            "entry {k}: field {field} is not among the rule's {:?}",
            rule.fields
        );
        assert!(message.starts_with(rule.text), "entry {k}: {err}");
        let schema = case.get("schema").and_then(Value::as_bool).unwrap_or(false);
        let partial = code == "modes_range"; // the schema checks its lower bound only
        if !partial || schema {
            assert_eq!(
                schema,
                rule.schema != Schema::None,
                "entry {k} ({code}): `schema` must say whether the rule has a schema form"
            );
        }
    }
    for rule in RULES {
        assert!(
            entries
                .iter()
                .any(|c| c["rule"].as_str() == Some(rule.code)),
            "no scene of tests/refused_scenes.toml shows rule {}",
            rule.code
        );
    }
}

/// Every shipped scene (scenes/, examples/) is within the limits (issue 35), and the estimate
/// of a unit's variables that the `variables_max` rule uses bounds the table the unit builds,
/// also with many shape points and parts.
#[test]
fn shipped_scenes_are_within_the_limits_and_the_variable_estimate_bounds_the_table() {
    let mut paths = Vec::new();
    for dir in [
        "scenes",
        "examples/split_slider_crank",
        "examples/hinged_blade",
    ] {
        for e in std::fs::read_dir(repo().join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "toml") {
                paths.push(p);
            }
        }
    }
    let mut checked = 0;
    for p in &paths {
        let text = std::fs::read_to_string(p).unwrap();
        // the examples' system files are not scenes
        if !text.contains("[[beam]]") {
            continue;
        }
        let scene = Scene::load(p).unwrap_or_else(|e| panic!("{e}"));
        let size = scene.size();
        let table = fmu_beam::VariableTable::build(&scene).variables.len() as u64;
        assert!(
            table <= size.variables,
            "{}: {table} > {size:?}",
            p.display()
        );
        assert!(size.memory < 64 << 20, "{}: {size:?}", p.display());
        let mut more = scene.clone();
        for b in &mut more.beams {
            b.shape_points = Some(1000);
            b.outputs.clear();
        }
        let table = fmu_beam::VariableTable::build(&more).variables.len() as u64;
        assert!(table <= more.size().variables, "{}: {table}", p.display());
        checked += 1;
    }
    assert!(checked >= 25, "{checked} scenes");
}
