//! Issue 45, item 3: an output never replaces what is not a regular file. Every writer
//! (`package -o`, `simulate -o`, `cosim -o`, `animate -o/--gif/--csv/--metadata`,
//! `accuracy --dir`, `modes --campbell -o`, `schema -o`, `reference -o`) refuses a FIFO, a
//! directory, a symbolic link to a device (/dev/null) and a symbolic link to a regular file
//! (a link is never written through nor replaced), leaves each as it was and no temporary file
//! behind; a regular file is replaced whole. Before the fix `simulate -o` renamed its CSV over
//! a link to /dev/null, and `animate --gif` opened a FIFO for writing and blocked. Each run is
//! a child bounded in time: a hang fails. No test names a real device as the output.

use crate::common;
use common::*;
use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

/// `fmu-harness <args>` in `dir` within 120 s: (success, stderr).
fn run(dir: &Path, args: &[&str]) -> (bool, String) {
    let err = dir.join(".stderr.txt");
    let child = Command::new(env!("CARGO_BIN_EXE_fmu-harness"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&err).unwrap())
        .spawn()
        .expect("run fmu-harness");
    let (status, _) = wait_bounded(
        child,
        Duration::from_secs(120),
        &format!("fmu-harness {args:?}"),
    );
    let stderr = std::fs::read_to_string(&err).unwrap_or_default();
    let _ = std::fs::remove_file(&err);
    assert!(!stderr.contains("panicked"), "{stderr}");
    (status.success(), stderr)
}

/// The hostile targets of one extension in `dir`: a FIFO, a directory, a link to /dev/null, a
/// link to a regular file (`target<ext>`, holding "target").
fn hostile_targets(dir: &Path, ext: &str) -> Vec<String> {
    let name = |stem: &str| format!("{stem}{ext}");
    let made = Command::new("mkfifo")
        .arg(dir.join(name("pipe")))
        .status()
        .unwrap();
    assert!(made.success());
    std::fs::create_dir(dir.join(name("folder"))).unwrap();
    std::os::unix::fs::symlink("/dev/null", dir.join(name("null"))).unwrap();
    std::fs::write(dir.join(name("target")), "target").unwrap();
    std::os::unix::fs::symlink(name("target"), dir.join(name("link"))).unwrap();
    ["pipe", "folder", "null", "link"]
        .iter()
        .map(|s| name(s))
        .collect()
}

/// The targets of [`hostile_targets`] are as they were, and no temporary file is left.
fn unchanged(dir: &Path, ext: &str) {
    let meta = |stem: &str| std::fs::symlink_metadata(dir.join(format!("{stem}{ext}"))).unwrap();
    assert!(meta("pipe").file_type().is_fifo(), "pipe{ext} replaced");
    assert!(meta("folder").is_dir(), "folder{ext} replaced");
    assert!(
        std::fs::read_dir(dir.join(format!("folder{ext}")))
            .unwrap()
            .next()
            .is_none(),
        "folder{ext} written into"
    );
    assert!(meta("null").file_type().is_symlink(), "null{ext} replaced");
    assert_eq!(
        std::fs::read_link(dir.join(format!("null{ext}"))).unwrap(),
        PathBuf::from("/dev/null")
    );
    assert!(meta("link").file_type().is_symlink(), "link{ext} replaced");
    assert_eq!(
        std::fs::read_to_string(dir.join(format!("target{ext}"))).unwrap(),
        "target",
        "written through link{ext}"
    );
    let null = std::fs::metadata("/dev/null").unwrap();
    assert!(null.file_type().is_char_device() && null.rdev() != 0);
    let left: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

/// Runs `args` with `{}` replaced by each hostile target of extension `ext`: each refused with
/// a message naming the target as given, nothing changed.
fn refuses_each(dir: &Path, ext: &str, args: &[&str]) {
    for target in hostile_targets(dir, ext) {
        let args: Vec<String> = args.iter().map(|a| a.replace("{}", &target)).collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (ok, stderr) = run(dir, &args);
        assert!(!ok, "{args:?} succeeded");
        assert!(
            stderr.contains(&target) && stderr.contains("regular file"),
            "{args:?}: {stderr}"
        );
        assert!(
            !stderr.contains("/dev/null"),
            "{args:?}: where a link leads: {stderr}"
        );
    }
    unchanged(dir, ext);
}

/// C1 packaged with the release engine into `dir` as c1.fmu.
fn c1_fmu(dir: &Path) -> PathBuf {
    let out = dir.join("c1.fmu");
    let r = harness(&[
        "package".as_ref(),
        c1_path().as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    out
}

#[test]
fn package_refuses_what_is_not_a_regular_file() {
    let dir = scratch("outputs_package");
    let scene = c1_path().display().to_string();
    refuses_each(&dir, ".fmu", &["package", &scene, "-o", "{}"]);
    std::fs::write(dir.join("regular.fmu"), "old").unwrap();
    let (ok, e) = run(&dir, &["package", &scene, "-o", "regular.fmu"]);
    assert!(ok, "{e}");
    assert_eq!(&std::fs::read(dir.join("regular.fmu")).unwrap()[..2], b"PK");
}

#[test]
fn simulate_and_cosim_refuse_what_is_not_a_regular_file() {
    let dir = scratch("outputs_simulate");
    c1_fmu(&dir);
    refuses_each(
        &dir,
        ".csv",
        &["simulate", "c1.fmu", "--stop", "0.01", "-o", "{}"],
    );
    std::fs::write(
        dir.join("system.toml"),
        "stop_time = 0.01\nstep = { size = 1e-3 }\n\n[[unit]]\nname = \"a\"\nfmu = \"c1.fmu\"\n",
    )
    .unwrap();
    let dir2 = dir.join("cosim");
    std::fs::create_dir(&dir2).unwrap();
    std::fs::copy(dir.join("c1.fmu"), dir2.join("c1.fmu")).unwrap();
    std::fs::copy(dir.join("system.toml"), dir2.join("system.toml")).unwrap();
    refuses_each(&dir2, ".csv", &["cosim", "system.toml", "-o", "{}"]);
    std::fs::write(dir.join("regular.csv"), "old").unwrap();
    let (ok, e) = run(
        &dir,
        &["simulate", "c1.fmu", "--stop", "0.01", "-o", "regular.csv"],
    );
    assert!(ok, "{e}");
    assert!(std::fs::read_to_string(dir.join("regular.csv"))
        .unwrap()
        .starts_with("time,"));
}

#[test]
fn animate_refuses_what_is_not_a_regular_file() {
    let dir = scratch("outputs_animate");
    let scene = c1_path().display().to_string();
    let run_args = ["animate", &scene, "--stop", "0.02"];
    let with = |extra: &[&'static str]| -> Vec<&str> {
        run_args
            .iter()
            .copied()
            .chain(extra.iter().copied())
            .collect()
    };
    for (ext, extra) in [
        (".html", &["-o", "{}"][..]),
        (".gif", &["--gif", "{}"][..]),
        (".csv", &["-o", "page.html", "--csv", "{}"][..]),
        (".json", &["--gif", "run.gif", "--metadata", "{}"][..]),
    ] {
        let sub = dir.join(&ext[1..]);
        std::fs::create_dir(&sub).unwrap();
        refuses_each(&sub, ext, &with(extra));
        assert!(!sub.join("page.html").exists() && !sub.join("run.gif").exists());
    }
    let (ok, e) = run(&dir, &with(&["--gif", "run.gif", "-o", "page.html"]));
    assert!(ok, "{e}");
    assert_eq!(&std::fs::read(dir.join("run.gif")).unwrap()[..3], b"GIF");
}

#[test]
fn studies_and_generated_files_refuse_what_is_not_a_regular_file() {
    let dir = scratch("outputs_studies");
    let scene = c1_path().display().to_string();
    refuses_each(&dir, ".json", &["schema", "-o", "{}"]);
    let sub = dir.join("reference");
    std::fs::create_dir(&sub).unwrap();
    refuses_each(&sub, ".md", &["reference", "-o", "{}"]);
    // --campbell writes PREFIX.csv and PREFIX.png: a hostile PREFIX.csv refuses both
    let sub = dir.join("campbell");
    std::fs::create_dir(&sub).unwrap();
    for target in hostile_targets(&sub, ".csv") {
        let prefix = target.trim_end_matches(".csv");
        let (ok, e) = run(
            &sub,
            &[
                "modes",
                &scene,
                "--campbell",
                "0:1:2",
                "--count",
                "2",
                "-o",
                prefix,
            ],
        );
        assert!(
            !ok && e.contains(&target) && e.contains("regular file"),
            "{e}"
        );
        assert!(
            !sub.join(format!("{prefix}.png")).exists(),
            "{prefix}.png written"
        );
    }
    unchanged(&sub, ".csv");
    // accuracy --dir D writes D/accuracy.csv, .png and chosen.toml: refused before the study
    let sub = dir.join("accuracy");
    std::fs::create_dir(&sub).unwrap();
    for target in hostile_targets(&sub, ".csv") {
        let d = sub.join(format!("d-{target}"));
        std::fs::create_dir(&d).unwrap();
        let at = d.join("accuracy.csv");
        let from = sub.join(&target);
        std::fs::rename(&from, &at).unwrap();
        let (ok, e) = run(
            &sub,
            &[
                "accuracy",
                &scene,
                "--output",
                "beam.tip.deflection",
                "--target",
                "1e-2",
                "--max-runs",
                "2",
                "--dir",
                &d.display().to_string(),
            ],
        );
        assert!(
            !ok && e.contains("accuracy.csv") && e.contains("regular file"),
            "{e}"
        );
        assert!(!e.contains("runs"), "the study ran before the refusal: {e}");
        std::fs::rename(&at, &from).unwrap();
        assert!(!d.join("accuracy.png").exists());
    }
    unchanged(&sub, ".csv");
}
