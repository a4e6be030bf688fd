//! Bad input is refused, never a panic (issue 7): valid scenes mutated at random (values,
//! types, missing and unknown keys, NaN/Inf, huge and tiny numbers) are either accepted and
//! run, or refused with a message naming the field; mutated FMU-state bytes are refused.

mod common;
use fmu_beam::{Engine, Scene};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use std::cell::Cell;
use std::path::Path;
use toml::Value;

fn scene_texts() -> Vec<(String, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| {
            (
                p.display().to_string(),
                std::fs::read_to_string(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

/// Paths to every leaf value (and table) of a TOML document.
fn paths(v: &Value, prefix: Vec<String>, out: &mut Vec<Vec<String>>) {
    match v {
        Value::Table(t) => {
            out.push(prefix.clone());
            for (k, x) in t {
                let mut p = prefix.clone();
                p.push(k.clone());
                paths(x, p, out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                let mut p = prefix.clone();
                p.push(format!("#{i}"));
                paths(x, p, out);
            }
            out.push(prefix);
        }
        _ => out.push(prefix),
    }
}

fn get_mut<'a>(v: &'a mut Value, path: &[String]) -> Option<&'a mut Value> {
    let mut cur = v;
    for key in path {
        cur = match key.strip_prefix('#') {
            Some(i) => cur.as_array_mut()?.get_mut(i.parse::<usize>().ok()?)?,
            None => cur.as_table_mut()?.get_mut(key)?,
        };
    }
    Some(cur)
}

#[derive(Debug, Clone)]
enum Mutation {
    Replace(Value),
    Remove,
    AddUnknownKey,
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        prop_oneof![
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(f64::NEG_INFINITY),
            Just(0.0),
            Just(-1.0),
            Just(1e300),
            Just(1e-300),
            Just(-1e-300),
            any::<f64>(),
        ]
        .prop_map(|x| Mutation::Replace(Value::Float(x))),
        prop_oneof![
            Just(0i64),
            Just(-1),
            Just(i64::MAX),
            Just(i64::MIN),
            any::<i64>()
        ]
        .prop_map(|x| Mutation::Replace(Value::Integer(x))),
        "[a-z_.]{0,12}".prop_map(|s| Mutation::Replace(Value::String(s))),
        any::<bool>().prop_map(|b| Mutation::Replace(Value::Boolean(b))),
        Just(Mutation::Replace(Value::Array(vec![]))),
        Just(Mutation::Remove),
        Just(Mutation::AddUnknownKey),
    ]
}

fn mutate(doc: &Value, path: &[String], m: &Mutation) -> Value {
    let mut d = doc.clone();
    match m {
        Mutation::Replace(v) => {
            if let Some(slot) = get_mut(&mut d, path) {
                *slot = v.clone();
            }
        }
        Mutation::Remove => {
            if let Some((last, parent)) = path.split_last() {
                if let Some(p) = get_mut(&mut d, parent) {
                    match (p, last.strip_prefix('#')) {
                        (Value::Table(t), None) => {
                            t.remove(last);
                        }
                        (Value::Array(a), Some(i)) => {
                            let i: usize = i.parse().unwrap();
                            if i < a.len() {
                                a.remove(i);
                            }
                        }
                        _ => {}
                    }
                }
            }
        }
        Mutation::AddUnknownKey => {
            if let Some(Value::Table(t)) = get_mut(&mut d, path) {
                t.insert("lenght".into(), Value::Float(1.0));
            }
        }
    }
    d
}

/// Every scene, 300 mutants in all: parse → validate → (if accepted) build, initialize and
/// take a step. Refusals name a field; nothing panics.
#[test]
fn mutated_scenes_are_accepted_or_refused_with_the_field_named() {
    let scenes = scene_texts();
    let docs: Vec<(String, Value, Vec<Vec<String>>)> = scenes
        .iter()
        .map(|(name, text)| {
            let doc: Value = toml::from_str(text).unwrap();
            let mut ps = Vec::new();
            paths(&doc, Vec::new(), &mut ps);
            (name.clone(), doc, ps)
        })
        .collect();
    let mut runner = TestRunner::new(Config {
        cases: 300,
        failure_persistence: None,
        ..Config::default()
    });
    let (accepted, refused) = (Cell::new(0usize), Cell::new(0usize));
    let strategy = (0..docs.len(), any::<prop::sample::Index>(), mutation());
    runner
        .run(&strategy, |(d, idx, m)| {
            let (name, doc, ps) = &docs[d];
            let path = idx.get(ps);
            let text = toml::to_string(&mutate(doc, path, &m)).unwrap_or_default();
            match Scene::from_toml_str(&text, name) {
                Ok(scene) => {
                    accepted.set(accepted.get() + 1);
                    let mut e = Engine::new(scene);
                    // accepted values may still make a model that cannot start or step
                    // (E = 1e300): an error is fine, a panic is not
                    if e.exit_initialization().is_ok() {
                        let _ = e.do_step(0.0, 1e-3);
                    }
                }
                Err(err) => {
                    refused.set(refused.get() + 1);
                    // the rule table names every field a rule refuses (the reference lists it)
                    if let fmu_beam::scene::SceneError::Invalid { code, field, .. } = &err {
                        let rule = fmu_beam::scene::rules::find(code);
                        prop_assert!(
                            rule.is_some_and(|r| r
                                .fields
                                .iter()
                                .any(|p| fmu_beam::scene::rules::field_matches(p, field))),
                            "rule {code} does not name field {field}: {err}"
                        );
                    }
                    let msg = err.to_string();
                    prop_assert!(
                        msg.starts_with(name.as_str()),
                        "message does not name the file: {msg}"
                    );
                    let names_field = msg.contains("field `")
                        || msg.contains("unknown field")
                        || msg.contains("missing field")
                        || msg.contains("invalid type")
                        || msg.contains("TOML parse error");
                    prop_assert!(names_field, "message does not name the field: {msg}");
                }
            }
            Ok(())
        })
        .unwrap();
    let (accepted, refused) = (accepted.get(), refused.get());
    println!("{accepted} mutants accepted, {refused} refused with the field named");
    assert!(refused > 50 && accepted > 10);
}

/// FMU-state bytes with random edits are refused (or, where the edit hits a value, restored
/// as a valid state); never a panic.
#[test]
fn mutated_state_bytes_are_refused_not_a_panic() {
    let scene = common::scene("slider_crank.toml");
    let mut e = Engine::new(scene);
    e.exit_initialization().unwrap();
    e.do_step(0.0, 0.05).unwrap();
    let good = e.serialize(&e.snapshot());
    let mut runner = TestRunner::new(Config {
        cases: 500,
        failure_persistence: None,
        ..Config::default()
    });
    let (ok, refused) = (Cell::new(0usize), Cell::new(0usize));
    let strategy = (
        any::<prop::sample::Index>(),
        any::<u8>(),
        0usize..3,
        any::<prop::sample::Index>(),
    );
    runner
        .run(&strategy, |(at, byte, kind, cut)| {
            let mut b = good.clone();
            match kind {
                0 => {
                    let i = at.index(b.len());
                    b[i] = byte;
                }
                1 => b.truncate(cut.index(b.len())),
                _ => b.insert(at.index(b.len()), byte),
            }
            match e.deserialize(&b) {
                Ok(s) => {
                    ok.set(ok.get() + 1);
                    let mut f = Engine::new(common::scene("slider_crank.toml"));
                    if f.restore(&s).is_ok() {
                        let t = f.time();
                        let _ = f.do_step(t, 0.01);
                    }
                }
                Err(err) => {
                    refused.set(refused.get() + 1);
                    prop_assert!(err.to_string().starts_with("FMU state:"));
                }
            }
            Ok(())
        })
        .unwrap();
    let (ok, refused) = (ok.get(), refused.get());
    println!("{ok} mutated states accepted, {refused} refused");
    assert!(refused > 100);
}

/// A vanishing internal step is refused, never a hang: as a scene value, and as the tunable
/// parameter a master sets between steps (t + h == t would loop forever).
#[test]
fn a_vanishing_max_step_is_refused_not_a_hang() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/flexible_pendulum.toml"),
    )
    .unwrap();
    let tiny = text.replace("max_step = 1e-2", "max_step = 1e-300");
    assert_ne!(tiny, text);
    let err = Scene::from_toml_str(&tiny, "tiny.toml").unwrap_err();
    assert!(err.to_string().contains("solver.max_step"), "{err}");
    let mut e = Engine::new(common::scene("flexible_pendulum.toml"));
    e.exit_initialization().unwrap();
    let v = common::vr(&e, "solver.max_step");
    let err = e.set_real(v, 1e-300).unwrap_err();
    assert!(err.to_string().contains("solver.max_step"), "{err}");
    e.do_step(0.0, 1e-3).unwrap();
}
