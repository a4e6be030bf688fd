//! A bounded fuzz test of scenes (issue 35): every shipped scene, mutated at random with a fixed
//! seed (values and strings of any length, paths to files outside the scene's directory, to
//! devices, to links and to files that do not parse, counts far beyond the limits), is loaded
//! from a file as `fmu-harness package` loads it; an accepted one is resolved, explained and
//! put together as an FMU's contents. Fails on a panic, on a message that shows a byte of a
//! named file (each holds a secret marker), on a message longer than a few lines, and on a
//! refusal that takes more than a second. Stops after [`BUDGET_S`] seconds.

use crate::common;
use fmu_beam::Scene;
use fmu_harness::package;
use fmu_harness::platform::Platform;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::time::Instant;
use toml::Value;

/// The marker every named file holds; no message may show it.
const SECRET: &str = "SECRET-c0ffee";
/// Seconds of mutants at most.
const BUDGET_S: f64 = 8.0;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Paths to every leaf value of a TOML document (array items as `#i`).
fn leaves(v: &Value, prefix: Vec<String>, out: &mut Vec<Vec<String>>) {
    match v {
        Value::Table(t) => {
            for (k, x) in t {
                let mut p = prefix.clone();
                p.push(k.clone());
                leaves(x, p, out);
            }
        }
        Value::Array(a) => {
            out.push(prefix.clone());
            for (i, x) in a.iter().enumerate() {
                let mut p = prefix.clone();
                p.push(format!("#{i}"));
                leaves(x, p, out);
            }
        }
        _ => out.push(prefix),
    }
}

fn slot<'a>(v: &'a mut Value, path: &[String]) -> Option<&'a mut Value> {
    let mut cur = v;
    for key in path {
        cur = match key.strip_prefix('#') {
            Some(i) => cur.as_array_mut()?.get_mut(i.parse::<usize>().ok()?)?,
            None => cur.as_table_mut()?.get_mut(key)?,
        };
    }
    Some(cur)
}

/// Names of files a mutant may point a beam's `matrix_file` at.
const PATHS: [&str; 10] = [
    "../secret.txt",
    "/etc/passwd",
    "/proc/self/environ",
    "/dev/zero",
    "link_out.txt",
    "bad.txt",
    "fifo.txt",
    "matrices",
    "matrices/pendulum_3d_element.txt",
    "",
];

#[derive(Debug, Clone)]
enum Mutation {
    /// A leaf replaced.
    Replace(Value),
    /// The first beam's matrix file set to one of [`PATHS`].
    MatrixFile(usize),
    /// An array grown to this many copies of its last item.
    Grow(usize),
}

fn value() -> impl Strategy<Value = Value> {
    prop_oneof![
        prop_oneof![
            Just(0i64),
            Just(-1),
            Just(2001),
            Just(100_000),
            Just(i64::MAX),
            any::<i64>()
        ]
        .prop_map(Value::Integer),
        prop_oneof![Just(f64::NAN), Just(1e300), Just(-1e-300), any::<f64>()]
            .prop_map(Value::Float),
        (
            prop::sample::select(vec![0usize, 1, 64, 65, 5000, 70_000]),
            "[a-z_.]{1,3}"
        )
            .prop_map(|(n, s)| Value::String(s.repeat(n.max(1)))),
        prop::sample::select(PATHS.to_vec()).prop_map(|p| Value::String(p.into())),
        prop::collection::vec(any::<f64>(), 0..6)
            .prop_map(|v| Value::Array(v.into_iter().map(Value::Float).collect())),
        prop::collection::vec("[a-z.]{1,8}", 0..4)
            .prop_map(|v| Value::Array(v.into_iter().map(Value::String).collect())),
    ]
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        6 => value().prop_map(Mutation::Replace),
        2 => (0..PATHS.len()).prop_map(Mutation::MatrixFile),
        1 => prop::sample::select(vec![3usize, 101, 1001, 10_001]).prop_map(Mutation::Grow),
    ]
}

fn mutate(doc: &Value, path: &[String], m: &Mutation) -> Value {
    let mut d = doc.clone();
    match m {
        Mutation::Replace(v) => {
            if let Some(s) = slot(&mut d, path) {
                *s = v.clone();
            }
        }
        Mutation::MatrixFile(k) => {
            if let Some(Value::Table(b)) = slot(&mut d, &["beam".into(), "#0".into()]) {
                b.insert("matrix_file".into(), Value::String(PATHS[*k].into()));
            }
        }
        Mutation::Grow(n) => {
            // the nearest array on the path
            let mut p = path.to_vec();
            loop {
                if let Some(Value::Array(a)) = slot(&mut d, &p) {
                    if let Some(last) = a.last().cloned() {
                        a.resize(*n, last);
                    }
                    break;
                }
                if p.pop().is_none() {
                    break;
                }
            }
        }
    }
    d
}

/// The scene's directory with a matrix file, and around it files that hold the secret: one
/// outside, a link out, one that does not parse, a FIFO.
fn arena() -> PathBuf {
    let root = common::scratch("hostile_scenes_fuzz");
    let dir = root.join("scene");
    std::fs::create_dir_all(dir.join("matrices")).unwrap();
    let matrix =
        std::fs::read_to_string(repo().join("scenes/matrices/pendulum_3d_element.txt")).unwrap();
    std::fs::write(dir.join("matrices/pendulum_3d_element.txt"), &matrix).unwrap();
    std::fs::write(root.join("secret.txt"), format!("# {SECRET}\n{matrix}")).unwrap();
    std::os::unix::fs::symlink(root.join("secret.txt"), dir.join("link_out.txt")).unwrap();
    std::fs::write(
        dir.join("bad.txt"),
        format!("{SECRET}:x:0:0\nlength {SECRET}\n"),
    )
    .unwrap();
    let made = std::process::Command::new("mkfifo")
        .arg(dir.join("fifo.txt"))
        .status()
        .unwrap();
    assert!(made.success());
    dir
}

#[test]
fn mutated_scenes_never_panic_hang_or_show_a_file() {
    let dir = arena();
    let mut docs = Vec::new();
    for e in std::fs::read_dir(repo().join("scenes")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            let doc: Value = toml::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
            let mut ps = Vec::new();
            leaves(&doc, Vec::new(), &mut ps);
            docs.push((
                p.file_name().unwrap().to_string_lossy().into_owned(),
                doc,
                ps,
            ));
        }
    }
    docs.sort_by(|a, b| a.0.cmp(&b.0));
    let mut runner = TestRunner::new_with_rng(
        Config {
            cases: 400,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    );
    let start = Instant::now();
    let (accepted, refused, skipped) = (Cell::new(0usize), Cell::new(0usize), Cell::new(0usize));
    let strategy = (0..docs.len(), any::<prop::sample::Index>(), mutation());
    runner
        .run(&strategy, |(d, idx, m)| {
            if start.elapsed().as_secs_f64() > BUDGET_S {
                skipped.set(skipped.get() + 1);
                return Ok(());
            }
            let (name, doc, ps) = &docs[d];
            let leaf: &Vec<String> = idx.get(ps);
            let text = toml::to_string(&mutate(doc, leaf, &m)).unwrap_or_default();
            let path = dir.join("scene.toml");
            std::fs::write(&path, &text).unwrap();
            let t0 = Instant::now();
            match Scene::load(&path) {
                Ok(scene) => {
                    accepted.set(accepted.get() + 1);
                    let explained = fmu_beam::resolve_effects(&scene).explain(&scene);
                    prop_assert!(!explained.contains(SECRET));
                    let contents = package::contents(&scene, &[(Platform::Linux64, b"engine")]);
                    if let Ok(c) = contents {
                        prop_assert!(!c.scene_text.contains(SECRET), "{name}: {m:?}");
                    }
                }
                Err(e) => {
                    refused.set(refused.get() + 1);
                    let msg = e.to_string();
                    let took = t0.elapsed().as_secs_f64();
                    prop_assert!(took < 1.0, "{name}: {m:?} took {took} s: {msg}");
                    prop_assert!(!msg.contains(SECRET), "{name}: {m:?}: {msg}");
                    prop_assert!(msg.len() < 1500, "{name}: {m:?}: {} bytes", msg.len());
                }
            }
            Ok(())
        })
        .unwrap();
    println!(
        "{} accepted, {} refused, {} past the {BUDGET_S} s budget",
        accepted.get(),
        refused.get(),
        skipped.get()
    );
    assert!(refused.get() > 50 && accepted.get() > 5);
}
