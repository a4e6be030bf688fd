//! Issue 45, items 2 and 4 (the surfaces' part): every argument bounds its work before the work
//! starts, and no file named to the harness is echoed.
//!
//! - `accuracy --reference FILE --column x` printed the file's first line ("no column x (it has:
//!   root:*:...)"); now a first line that is not a header of column names over rows of numbers
//!   is refused without a byte of it, and a FIFO or a device is refused by its type.
//! - `animate --speed 1e-17` aborted at once (a 2e18-byte allocation), `--fps 1e9` after 3.9 GB,
//!   `--speed 1e-300` wrote a GIF of 0 frames: frames, pixels and the run's rows are bounded
//!   before the run, and a count that is no number of frames is refused.
//! - A system file of 20 000 `[[unit]]` extracted 339 copies (3.4 GB) and went on: the units and
//!   the bytes their FMUs declare are bounded before anything is extracted.
//! - An FMU path that is a FIFO blocked `simulate`, `animate` and `cosim`: it is refused by its
//!   type, without being opened for reading.
//!
//! Each run is a child process bounded in time: a hang or an abort fails.

use crate::common;
use common::*;
use std::io::Write;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

/// What a bounded run gave.
struct Run {
    ok: bool,
    stderr: String,
    elapsed: Duration,
    /// `fmu-harness-*` folders left in the run's TMPDIR.
    left: usize,
}

/// `fmu-harness <args>` in `dir` (TMPDIR = `dir/tmp`) within `limit`; an abort or another
/// signal fails the test.
fn run(dir: &Path, args: &[&str], limit: Duration) -> Run {
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    let err = dir.join(".stderr.txt");
    let child = Command::new(env!("CARGO_BIN_EXE_fmu-harness"))
        .args(args)
        .current_dir(dir)
        .env("TMPDIR", &tmp)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&err).unwrap())
        .spawn()
        .expect("run fmu-harness");
    let (status, elapsed) = wait_bounded(child, limit, &format!("fmu-harness {args:?}"));
    let stderr = std::fs::read_to_string(&err).unwrap_or_default();
    assert!(
        status.signal().is_none(),
        "{args:?}: killed by signal {:?}: {stderr}",
        status.signal()
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    let left = std::fs::read_dir(&tmp).unwrap().count();
    Run {
        ok: status.success(),
        stderr,
        elapsed,
        left,
    }
}

/// The run was refused within `seconds`, saying each of `words`, leaving nothing in TMPDIR.
fn refused(r: &Run, seconds: u64, words: &[&str]) {
    assert!(!r.ok, "accepted: {}", r.stderr);
    for w in words {
        assert!(r.stderr.contains(w), "{w:?} not in: {}", r.stderr);
    }
    assert!(
        r.elapsed < Duration::from_secs(seconds),
        "{:?}: {}",
        r.elapsed,
        r.stderr
    );
    assert_eq!(r.left, 0, "extraction folders left: {}", r.stderr);
}

fn fifo(dir: &Path, name: &str) -> PathBuf {
    let p = dir.join(name);
    assert!(Command::new("mkfifo").arg(&p).status().unwrap().success());
    p
}

const SHADOW: &str = "root:*:19000:0:99999:7:::\ndaemon:*:19000:0:99999:7:::\n";

#[test]
fn accuracy_never_echoes_a_reference_it_cannot_use() {
    let dir = scratch("args_reference");
    let scene = c1_path().display().to_string();
    let accuracy = |reference: &str, column: &str| {
        run(
            &dir,
            &[
                "accuracy",
                &scene,
                "--output",
                "beam.tip.deflection",
                "--target",
                "1e-2",
                "--reference",
                reference,
                "--column",
                column,
                "--dir",
                "study",
            ],
            Duration::from_secs(30),
        )
    };
    std::fs::write(dir.join("shadow"), SHADOW).unwrap();
    std::fs::write(dir.join("one_word.csv"), "PASSWORD_hunter2\nsecond_line\n").unwrap();
    std::fs::write(
        dir.join("wide.csv"),
        format!("{}\n", vec!["hunter2"; 5000].join(",")),
    )
    .unwrap();
    for name in ["shadow", "one_word.csv", "wide.csv"] {
        let r = accuracy(name, "x");
        refused(&r, 30, &[name, "no column x"]);
        for secret in [
            "root",
            "daemon",
            "19000",
            "PASSWORD",
            "hunter2",
            "second_line",
        ] {
            assert!(!r.stderr.contains(secret), "{name}: {}", r.stderr);
        }
    }
    let r = accuracy("/dev/zero", "x");
    refused(&r, 30, &["a character device", "regular file"]);
    fifo(&dir, "pipe.csv");
    let r = accuracy("pipe.csv", "x");
    refused(&r, 30, &["a FIFO", "regular file"]);
    // a reference that is one: its columns are named
    std::fs::write(
        dir.join("good.csv"),
        "t,tip_deflection\n0,0.01\n0.001,0.0099\n",
    )
    .unwrap();
    let r = accuracy("good.csv", "x");
    refused(&r, 30, &["no column x", "t, tip_deflection"]);
    assert!(!dir.join("study").exists());
}

#[test]
fn animate_bounds_frames_pixels_and_rows_before_the_run() {
    let dir = scratch("args_animate");
    let scene = c1_path().display().to_string();
    let animate = |extra: &[&str]| {
        let mut args = vec!["animate", scene.as_str(), "--gif", "run.gif"];
        args.extend_from_slice(extra);
        run(&dir, &args, Duration::from_secs(60))
    };
    for (extra, words) in [
        (
            &["--speed", "1e-17", "--stop", "0.1"][..],
            &["--speed", "frames"][..],
        ),
        (
            &["--speed", "1e-300", "--stop", "0.1"],
            &["--speed", "frames"],
        ),
        (&["--fps", "1e9", "--stop", "0.1"], &["--fps"]),
        (&["--fps", "0", "--stop", "0.1"], &["--fps"]),
        (&["--speed", "inf", "--stop", "0.1"], &["--speed"]),
        (
            &["--size", "4096x4096", "--speed", "0.01", "--stop", "1"],
            &["pixels"],
        ),
        (
            &["--stop", "1e6", "--step", "1e-6"],
            &["--step", "recorded times"],
        ),
    ] {
        let r = animate(extra);
        refused(&r, 10, words);
        assert!(!dir.join("run.gif").exists(), "{extra:?}");
    }
    // the default animation is drawn
    let r = animate(&["--stop", "0.04"]);
    assert!(r.ok, "{}", r.stderr);
    assert_eq!(&std::fs::read(dir.join("run.gif")).unwrap()[..3], b"GIF");
}

/// C1 packaged into `dir`.
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

fn system_text(units: usize, fmu: &str) -> String {
    let mut s = String::from("stop_time = 0.01\nstep = { size = 1e-3 }\n");
    for i in 0..units {
        s.push_str(&format!("\n[[unit]]\nname = \"u{i}\"\nfmu = \"{fmu}\"\n"));
    }
    s
}

#[test]
fn a_system_bounds_its_units_and_their_bytes_before_extracting() {
    let dir = scratch("args_system");
    c1_fmu(&dir);
    std::fs::write(dir.join("many.toml"), system_text(20_000, "c1.fmu")).unwrap();
    let r = run(&dir, &["cosim", "many.toml"], Duration::from_secs(30));
    refused(&r, 10, &["many.toml", "unit", "at most"]);
    // an FMU that declares 400 MiB (deflated zeros: 400 kB on disk), named by 6 units: 2.4 GiB
    let mut z = zip::ZipWriter::new(std::fs::File::create(dir.join("big.fmu")).unwrap());
    z.start_file(
        "resources/zeros.bin",
        zip::write::SimpleFileOptions::default(),
    )
    .unwrap();
    let block = vec![0u8; 1 << 20];
    for _ in 0..400 {
        z.write_all(&block).unwrap();
    }
    z.finish().unwrap();
    std::fs::write(dir.join("big.toml"), system_text(6, "big.fmu")).unwrap();
    let r = run(&dir, &["cosim", "big.toml"], Duration::from_secs(30));
    refused(&r, 10, &["big.fmu", "bytes"]);
}

#[test]
fn an_fmu_path_that_is_a_fifo_is_refused_without_blocking() {
    let dir = scratch("args_fifo_fmu");
    let scene = c1_path().display().to_string();
    fifo(&dir, "pipe.fmu");
    let limit = Duration::from_secs(20);
    let r = run(&dir, &["simulate", "pipe.fmu", "--stop", "0.01"], limit);
    refused(&r, 10, &["pipe.fmu", "a FIFO", "regular file"]);
    let r = run(&dir, &["animate", "pipe.fmu", "-o", "run.html"], limit);
    refused(&r, 10, &["pipe.fmu", "a FIFO", "regular file"]);
    let r = run(
        &dir,
        &["animate", &scene, "--scene", "pipe.fmu", "-o", "run.html"],
        limit,
    );
    refused(&r, 10, &["pipe.fmu", "a FIFO", "regular file"]);
    std::fs::write(dir.join("system.toml"), system_text(1, "pipe.fmu")).unwrap();
    let r = run(&dir, &["cosim", "system.toml"], limit);
    refused(&r, 10, &["pipe.fmu", "a FIFO", "regular file"]);
    let r = run(&dir, &["simulate", "/dev/zero", "--stop", "0.01"], limit);
    refused(&r, 10, &["a character device", "regular file"]);
}
