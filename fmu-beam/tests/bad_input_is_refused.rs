//! Bad input is refused, never a panic (issue 7): valid scenes mutated at random (values,
//! types, missing and unknown keys, NaN/Inf, huge and tiny numbers) are either accepted and
//! run, or refused with a message naming the field; mutated FMU-state bytes are refused.

use crate::common;
use fmu_beam::{Engine, Scene};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
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
    // a fixed seed: the same mutants on every run, so CI's time is bounded and a failure repeats
    let mut runner = TestRunner::new_with_rng(
        Config {
            cases: 300,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    );
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
                    // a mutant with a tiny max_step ends in the work budget, not minutes later
                    let budget = e.variables().by_name("solver.step_budget").map(|v| v.vr);
                    if let Some(b) = budget {
                        e.set_integer(b, 200_000).unwrap();
                    }
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
    // a fixed seed: the same mutants on every run, so CI's time is bounded and a failure repeats
    let mut runner = TestRunner::new_with_rng(
        Config {
            cases: 500,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    );
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
    let tiny = text.replace("max_step = 1.5625e-4", "max_step = 1e-300");
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

// Hostile scenes (issue 35): what a scene names is read only below its directory, only if it is
// a regular file within its cap, and no refusal shows what a file holds; what a scene sizes is
// refused at once, with the figure and the limit, never a panic or an allocation that aborts.

/// Marks the text of a file that must not reach a message.
const SECRET: &str = "root:SECRET-7f3a9:20228:0:99999";

/// A scratch directory holding a copy of the 3D matrix scene and its matrix file, and a
/// secret file one level up.
fn hostile_dir(name: &str) -> std::path::PathBuf {
    let base = Path::new(env!("CARGO_TARGET_TMPDIR")).join("hostile_scenes");
    let dir = base.join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("matrices")).unwrap();
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    std::fs::copy(
        scenes.join("matrices/pendulum_3d_element.txt"),
        dir.join("matrices/pendulum_3d_element.txt"),
    )
    .unwrap();
    // a file that parses as a matrix file, with the secret in a comment, outside the scene's dir
    let good = std::fs::read_to_string(scenes.join("matrices/pendulum_3d_element.txt")).unwrap();
    std::fs::write(
        base.join(format!("{name}_outside.txt")),
        format!("# {SECRET}\n{good}"),
    )
    .unwrap();
    dir
}

fn matrix_scene(matrix_file: &str) -> String {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/pendulum_3d_matrix.toml"),
    )
    .unwrap();
    let from = "matrix_file = \"matrices/pendulum_3d_element.txt\"";
    assert!(text.contains(from));
    text.replace(from, &format!("matrix_file = {matrix_file:?}"))
}

/// Loads `scene` written into `dir`, expects a refusal within a second, and returns its message,
/// checked to name the scene file and the field and to hold nothing of the secret.
fn refused_load(dir: &Path, scene: &str, words: &[&str]) -> String {
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let start = std::time::Instant::now();
    let err = Scene::load(&path).expect_err("must be refused");
    let took = start.elapsed().as_secs_f64();
    let msg = err.to_string();
    assert!(took < 1.0, "{took} s: {msg}");
    assert!(msg.starts_with(&path.display().to_string()), "{msg}");
    assert!(!msg.contains("SECRET"), "the message shows the file: {msg}");
    for w in words {
        assert!(msg.contains(w), "{w:?} not in {msg}");
    }
    assert!(msg.len() < 1000, "{} bytes: {msg}", msg.len());
    msg
}

#[test]
fn a_matrix_file_is_read_only_below_the_scene_and_only_if_regular() {
    let dir = hostile_dir("outside");
    // the copy beside the scene is read
    std::fs::write(
        dir.join("scene.toml"),
        matrix_scene("matrices/pendulum_3d_element.txt"),
    )
    .unwrap();
    Scene::load(&dir.join("scene.toml")).unwrap();
    let field = "beam \"beam\".matrix_file";
    // absolute, `..`, and a link inside the directory that points out
    refused_load(
        &dir,
        &matrix_scene("/etc/passwd"),
        &[field, "below the scene's directory"],
    );
    refused_load(
        &dir,
        &matrix_scene("../outside_outside.txt"),
        &[field, "below the scene's directory"],
    );
    std::os::unix::fs::symlink(dir.join("../outside_outside.txt"), dir.join("link.txt")).unwrap();
    refused_load(
        &dir,
        &matrix_scene("link.txt"),
        &[field, "below the scene's directory"],
    );
    refused_load(&dir, &matrix_scene("/proc/self/environ"), &[field]);
    // a link inside that stays inside is followed
    std::os::unix::fs::symlink(
        dir.join("matrices/pendulum_3d_element.txt"),
        dir.join("inside.txt"),
    )
    .unwrap();
    std::fs::write(dir.join("scene.toml"), matrix_scene("inside.txt")).unwrap();
    Scene::load(&dir.join("scene.toml")).unwrap();
    // a directory, a FIFO (never opened: opening it would block), a file over the cap
    refused_load(
        &dir,
        &matrix_scene("matrices"),
        &[field, "regular file", "directory"],
    );
    let status = std::process::Command::new("mkfifo")
        .arg(dir.join("fifo.txt"))
        .status()
        .unwrap();
    assert!(status.success());
    refused_load(
        &dir,
        &matrix_scene("fifo.txt"),
        &[field, "regular file", "FIFO"],
    );
    std::fs::write(dir.join("big.txt"), vec![b'#'; 70_000]).unwrap();
    refused_load(
        &dir,
        &matrix_scene("big.txt"),
        &[field, "at most 65536 bytes; it is larger"],
    );
}

#[test]
fn a_scene_file_that_is_a_device_a_fifo_or_huge_is_refused_at_once() {
    let dir = hostile_dir("devices");
    for path in ["/dev/zero", "/dev/urandom"] {
        let start = std::time::Instant::now();
        let err = Scene::load(Path::new(path)).unwrap_err().to_string();
        assert!(start.elapsed().as_secs_f64() < 1.0, "{path}: {err}");
        assert!(err.contains("regular file"), "{err}");
    }
    let fifo = dir.join("scene_fifo.toml");
    let status = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(status.success());
    let err = Scene::load(&fifo).unwrap_err().to_string();
    assert!(err.contains("FIFO"), "{err}");
    let huge = dir.join("huge.toml");
    std::fs::write(&huge, vec![b'#'; (4 << 20) + 1]).unwrap();
    let err = Scene::load(&huge).unwrap_err().to_string();
    assert!(err.contains("at most 4194304 bytes"), "{err}");
}

#[test]
fn a_file_that_fails_to_parse_is_not_shown() {
    let dir = hostile_dir("unparsed");
    let good = std::fs::read_to_string(dir.join("matrices/pendulum_3d_element.txt")).unwrap();
    // the secret where the parser stops: first word, a row's number, the length's value
    let cases = [
        format!("{SECRET}\n{good}"),
        format!("{SECRET} mass\n"),
        good.replacen("length 0.2", &format!("length {SECRET}"), 1),
        {
            let mut lines: Vec<String> = good.lines().map(String::from).collect();
            let k = lines.iter().position(|l| l.starts_with("mass")).unwrap() + 3;
            lines[k] = lines[k].replacen(' ', &format!(" {SECRET} "), 1);
            lines.join("\n")
        },
    ];
    for (k, text) in cases.iter().enumerate() {
        std::fs::write(dir.join("bad.txt"), text).unwrap();
        let msg = refused_load(&dir, &matrix_scene("bad.txt"), &["bad.txt"]);
        println!("case {k}: {msg}");
    }
    // a scene whose TOML breaks on a 200 KB line: line and column, not the line
    let mut scene = matrix_scene("matrices/pendulum_3d_element.txt");
    scene.push_str(&format!("\n[oops\n# {}{SECRET}\n", "x".repeat(200_000)));
    let msg = refused_load(&dir, &scene, &["TOML parse error at line"]);
    println!("{msg}");
    let long_value = matrix_scene("matrices/pendulum_3d_element.txt").replace(
        "name = \"hinge\"",
        &format!(
            "name = \"hinge\"\naxis_angle = \"{}{SECRET}\"",
            "y".repeat(200_000)
        ),
    );
    let msg = refused_load(&dir, &long_value, &["TOML parse error at line"]);
    println!("{msg}");
}

/// A scene of C1 with `from` replaced by `to`.
fn c1_with(from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/cantilever_free_vibration.toml"),
    )
    .unwrap();
    assert!(text.contains(from), "{from}");
    text.replacen(from, to, 1)
}

/// Refused within a second, naming `words`, in a short message.
fn refused_fast(text: &str, words: &[&str]) -> String {
    let start = std::time::Instant::now();
    let err = Scene::from_toml_str(text, "hostile.toml").expect_err("must be refused");
    let msg = err.to_string();
    assert!(start.elapsed().as_secs_f64() < 1.0, "{msg}");
    assert!(msg.len() < 1000, "{} bytes: {msg}", msg.len());
    for w in words {
        assert!(msg.contains(w), "{w:?} not in {msg}");
    }
    msg
}

#[test]
fn long_names_are_refused_with_their_length_not_a_panic() {
    let c1 = c1_with("name = \"cantilever_free_vibration\"", "name = \"c1\"");
    for n in [65, 5000, 70_000] {
        let long = "m".repeat(n);
        let text = c1.replacen("name = \"c1\"", &format!("name = \"{long}\""), 1);
        let msg = refused_fast(&text, &["field `name`", "at most 64 characters"]);
        assert!(msg.contains(&format!("{n}")), "{msg}");
    }
    // the beam's name, 65 535 characters (a part name), and a frame of a body
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/flexible_arm_hub.toml"),
    )
    .unwrap();
    let scene: Value = toml::from_str(&text).unwrap();
    let beam_name = scene["beam"][0]["name"].as_str().unwrap().to_string();
    let long = "b".repeat(65_535);
    let text = text.replace(&format!("\"{beam_name}"), &format!("\"{long}"));
    refused_fast(&text, &["beam[0].name", "at most 64 characters", "65535"]);
    // 64 is allowed
    let ok = c1.replacen(
        "name = \"c1\"",
        &format!("name = \"{}\"", "m".repeat(64)),
        1,
    );
    Scene::from_toml_str(&ok, "ok.toml").unwrap();
}

#[test]
fn sizes_beyond_the_limits_are_refused_at_once() {
    let sub = c1_with(
        "elements = 10",
        "substructures = 500\nelements_per_substructure = 2000",
    );
    refused_fast(
        &sub,
        &["beam \"beam\".substructures", "500 × 2000", "at most 2000"],
    );
    let big = c1_with("elements = 10", "elements = 2000");
    refused_fast(&big, &["field `beam`", "1 GiB", "MiB"]);
    let fine = c1_with("elements = 10", "elements = 500");
    Scene::from_toml_str(&fine, "fine.toml").unwrap();
    let points = c1_with("elements = 10", "elements = 10\nshape_points = 1000");
    Scene::from_toml_str(&points, "points.toml").unwrap();
}

#[test]
fn a_joint_has_two_frames_and_a_vector_its_count_of_numbers() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/flexible_pendulum.toml"),
    )
    .unwrap();
    let frames = text
        .lines()
        .find(|l| l.starts_with("frames = ["))
        .unwrap()
        .to_string();
    let three = frames.replacen('[', "[\"world\", ", 1);
    refused_fast(
        &text.replacen(&frames, &three, 1),
        &["invalid length 3", "exactly 2 frames"],
    );
    let one = "frames = [\"world\"]";
    refused_fast(
        &text.replacen(&frames, one, 1),
        &["invalid length 1", "exactly 2 frames"],
    );
    let five = c1_with("[[beam]]", "[[beam]]\nposition = [0.0, 0.0, 0.0, 0.0, 0.0]");
    refused_fast(
        &five,
        &["invalid length 5", "2 numbers [x, y] or 3 numbers"],
    );
    let d3 = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/pendulum_3d.toml"),
    )
    .unwrap();
    let axis = d3
        .lines()
        .find(|l| l.starts_with("axis = ["))
        .unwrap()
        .to_string();
    refused_fast(
        &d3.replacen(&axis, "axis = [0.0, 1.0]", 1),
        &["invalid length 2", "3 numbers [x, y, z]"],
    );
}
