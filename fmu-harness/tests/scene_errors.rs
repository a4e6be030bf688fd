//! A wrong scene is refused before anything is written: exit status 2, no panic, no .fmu, and
//! a message that names the file, the field and the rule.

mod common;
use common::*;

/// (case, edit of the C1 text, words the message must contain besides the file name)
const CASES: &[(&str, &str, &str, &[&str])] = &[
    (
        "misspelled_key",
        "length = 2.0",
        "lenght = 2.0",
        &["lenght", "unknown field"],
    ),
    (
        "negative_length",
        "length = 2.0",
        "length = -2",
        &["beam[0].length", "must be positive"],
    ),
    (
        "zero_elements",
        "elements = 10",
        "elements = 0",
        &["beam[0].elements", "at least 1"],
    ),
    (
        "missing_section",
        "section = { shape = \"rectangle\", a = 0.01, b = 0.01 }\n",
        "",
        &["section", "missing"],
    ),
    (
        "nan_length",
        "length = 2.0",
        "length = nan",
        &["beam[0].length", "finite"],
    ),
];

#[test]
fn wrong_scenes_are_refused_with_the_field_and_the_rule() {
    let dir = scratch("scene_errors");
    let engine = fake_engine(&dir, b"engine");
    let c1 = c1_text();
    for (case, from, to, words) in CASES {
        assert!(c1.contains(from), "{case}: C1 text lacks {from:?}");
        let scene = dir.join(format!("{case}.toml"));
        std::fs::write(&scene, c1.replacen(from, to, 1)).unwrap();
        let out = dir.join(format!("{case}.fmu"));
        let r = package(&scene, &out, &engine);
        let stderr = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{case}: {stderr}");
        assert!(stderr.starts_with("error: "), "{case}: {stderr}");
        assert!(!stderr.contains("panicked"), "{case}: {stderr}");
        assert!(
            stderr.contains(&scene.display().to_string()),
            "{case}: no file name in {stderr}"
        );
        for w in *words {
            assert!(stderr.contains(w), "{case}: {w:?} not in {stderr}");
        }
        assert!(!out.exists(), "{case}: an FMU was written");
    }
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.ends_with(".toml") && !n.ends_with(".so"))
        .collect();
    assert!(left.is_empty(), "files left behind: {left:?}");
}

#[test]
fn missing_scene_file_and_missing_engine_are_errors_not_panics() {
    let dir = scratch("missing_inputs");
    let engine = fake_engine(&dir, b"engine");
    let out = dir.join("x.fmu");
    let r = package(&dir.join("no_such_scene.toml"), &out, &engine);
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("no_such_scene.toml"), "{stderr}");

    let r = package(&c1_path(), &out, &dir.join("no_such_engine.so"));
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("no_such_engine.so") && !stderr.contains("panicked"),
        "{stderr}"
    );
    assert!(!out.exists());

    let r = harness(&["modes".as_ref(), dir.join("no_such_scene.toml").as_os_str()]);
    assert_eq!(r.status.code(), Some(2));
}
