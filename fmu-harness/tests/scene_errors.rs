//! A wrong scene is refused before anything is written: exit status 2, no panic, no .fmu, and
//! a message that names the file, the field and the rule.

use crate::common;
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
        &["beam \"beam\".length", "must be positive"],
    ),
    (
        "zero_elements",
        "elements = 10",
        "elements = 0",
        &["beam \"beam\".elements", "at least 1"],
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
        &["beam \"beam\".length", "finite"],
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

/// `fmu-harness <args>`, which must end within `seconds`, with exit status 2, no panic and no
/// secret, naming `words`; returns stderr.
fn refused_within(args: &[&std::ffi::OsStr], seconds: f64, words: &[&str]) -> String {
    let start = std::time::Instant::now();
    let r = harness(args);
    let took = start.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&r.stderr).into_owned();
    assert!(took < seconds, "{took} s: {stderr}");
    assert_eq!(r.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!stderr.contains("SECRET"), "{stderr}");
    assert!(stderr.len() < 2000, "{} bytes of stderr", stderr.len());
    for w in words {
        assert!(stderr.contains(w), "{w:?} not in {stderr}");
    }
    stderr
}

/// Issue 35: names of 5 000, 65 535 and 70 000 characters panicked in `explain` and `package`,
/// aborted inside the zip writer, or packaged a unit that no master could open; now each is
/// refused at once with its length and the limit.
#[test]
fn long_names_are_refused_by_package_and_explain() {
    let dir = scratch("long_names");
    let engine = fake_engine(&dir, b"engine");
    let c1 = c1_text();
    let cases = [
        (
            "model_5000",
            "name = \"cantilever_free_vibration\"",
            5000,
            "field `name`",
        ),
        (
            "model_70000",
            "name = \"cantilever_free_vibration\"",
            70_000,
            "field `name`",
        ),
        ("beam_65535", "name = \"beam\"", 65_535, "beam[0].name"),
    ];
    for (case, from, n, field) in cases {
        assert!(c1.contains(from));
        let text = if case.starts_with("beam") {
            // the beam's name and the frames named after it
            c1.replace("\"beam", &format!("\"{}", "n".repeat(n)))
        } else {
            c1.replacen(from, &format!("name = \"{}\"", "n".repeat(n)), 1)
        };
        let scene = dir.join(format!("{case}.toml"));
        std::fs::write(&scene, text).unwrap();
        let out = dir.join(format!("{case}.fmu"));
        let words = [field, "at most 64 characters"];
        refused_within(
            &[
                "package".as_ref(),
                scene.as_os_str(),
                "-o".as_ref(),
                out.as_os_str(),
                "--binary".as_ref(),
                engine.as_os_str(),
            ],
            5.0,
            &words,
        );
        assert!(!out.exists(), "{case}: an FMU was written");
        refused_within(&["explain".as_ref(), scene.as_os_str()], 5.0, &words);
    }
}

/// Issue 35: what a scene names is read only below its directory and only if regular; a huge
/// layout is refused at once (it took 39 s and 3.45 GB, then aborted the master).
#[test]
fn hostile_files_and_sizes_are_refused_by_package() {
    let dir = scratch("hostile_package");
    let engine = fake_engine(&dir, b"engine");
    let scenes = c1_path().parent().unwrap().to_path_buf();
    let matrix = std::fs::read_to_string(scenes.join("matrices/pendulum_3d_element.txt")).unwrap();
    let outside = dir.join("outside.txt");
    std::fs::write(&outside, format!("# SECRET\n{matrix}")).unwrap();
    std::fs::create_dir_all(dir.join("inner")).unwrap();
    let text = std::fs::read_to_string(scenes.join("pendulum_3d_matrix.toml")).unwrap();
    let from = "\"matrices/pendulum_3d_element.txt\"";
    assert!(text.contains(from));
    let package_args = |scene: &std::path::Path, out: &std::path::Path| {
        vec![
            std::ffi::OsString::from("package"),
            scene.as_os_str().to_owned(),
            "-o".into(),
            out.as_os_str().to_owned(),
            "--binary".into(),
            engine.as_os_str().to_owned(),
        ]
    };
    for (case, name) in [
        ("parent", "../outside.txt"),
        ("absolute", outside.to_str().unwrap()),
        ("passwd", "/etc/passwd"),
        ("zero", "/dev/zero"),
    ] {
        let scene = dir.join("inner").join(format!("{case}.toml"));
        std::fs::write(&scene, text.replace(from, &format!("{name:?}"))).unwrap();
        let out = dir.join(format!("{case}.fmu"));
        let args = package_args(&scene, &out);
        let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        refused_within(
            &args,
            5.0,
            &["beam \"beam\".matrix_file", "below the scene's directory"],
        );
        assert!(!out.exists(), "{case}: an FMU was written");
    }
    // the scene itself a device, or a layout far beyond the limits
    let out = dir.join("device.fmu");
    let args = package_args(std::path::Path::new("/dev/zero"), &out);
    let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    refused_within(&args, 5.0, &["/dev/zero", "regular file"]);
    let huge = dir.join("huge.toml");
    std::fs::write(
        &huge,
        c1_text().replacen(
            "elements = 10",
            "substructures = 500\nelements_per_substructure = 2000",
            1,
        ),
    )
    .unwrap();
    let out = dir.join("huge.fmu");
    let args = package_args(&huge, &out);
    let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    refused_within(&args, 5.0, &["beam \"beam\".substructures", "at most 2000"]);
    assert!(!out.exists());
}
