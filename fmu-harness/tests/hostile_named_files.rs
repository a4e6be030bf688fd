//! Files named to the master (issue 35, items 2 and 8): a `cosim` system file and the CSV that
//! `animate` reads must be regular files of bounded size (`/dev/zero` and a FIFO are refused at
//! once, by type), and a file that does not parse is located (line, column, field), never
//! quoted: a system file or CSV holding a line of /etc/passwd does not print it. Each run is a
//! child process bounded in time: a hang fails.

use crate::common;
use common::*;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

const SECRET: &str = "root:x:0:0:SECRET:/root:/bin/bash";

/// `fmu-harness <args>` within 20 s: (success, stderr).
fn bounded(dir: &Path, args: &[&str]) -> (bool, String) {
    let err = dir.join("stderr.txt");
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
        Duration::from_secs(20),
        &format!("fmu-harness {args:?}"),
    );
    let stderr = std::fs::read_to_string(&err).unwrap_or_default();
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!stderr.contains("root:x"), "file content in: {stderr}");
    (status.success(), stderr)
}

fn fifo(dir: &Path, name: &str) -> String {
    let p = dir.join(name);
    assert!(Command::new("mkfifo").arg(&p).status().unwrap().success());
    p.display().to_string()
}

#[test]
fn a_system_file_must_be_a_regular_file_and_is_never_quoted() {
    let dir = scratch("named_system_file");
    let (ok, e) = bounded(&dir, &["cosim", "/dev/zero"]);
    assert!(
        !ok && e.contains("a character device; a system file must be a regular file"),
        "{e}"
    );
    let f = fifo(&dir, "system.toml");
    let (ok, e) = bounded(&dir, &["cosim", &f]);
    assert!(
        !ok && e.contains("a FIFO; a system file must be a regular file"),
        "{e}"
    );
    std::fs::write(dir.join("passwd.toml"), format!("{SECRET}\n")).unwrap();
    let (ok, e) = bounded(&dir, &["cosim", "passwd.toml"]);
    assert!(!ok && e.contains("passwd.toml: line 1, column 5"), "{e}");
    std::fs::write(
        dir.join("value.toml"),
        format!("stop_time = \"{SECRET}\"\nstep = {{ size = 1e-3 }}\n"),
    )
    .unwrap();
    let (ok, e) = bounded(&dir, &["cosim", "value.toml"]);
    assert!(!ok && e.contains("value.toml: line 1, column 13"), "{e}");
}

#[test]
fn animate_reads_a_regular_csv_and_says_where_it_is_wrong() {
    let dir = scratch("named_csv");
    let (ok, e) = bounded(&dir, &["animate", "/dev/zero", "-o", "x.html"]);
    assert!(
        !ok && e.contains("a character device; a run's CSV must be a regular file"),
        "{e}"
    );
    let f = fifo(&dir, "run.csv");
    let (ok, e) = bounded(&dir, &["animate", &f, "-o", "x.html"]);
    assert!(
        !ok && e.contains("a FIFO; a run's CSV must be a regular file"),
        "{e}"
    );
    std::fs::write(dir.join("passwd.csv"), format!("{SECRET}\n")).unwrap();
    let (ok, e) = bounded(&dir, &["animate", "passwd.csv", "-o", "x.html"]);
    assert!(!ok && e.contains("the first column must be `time`"), "{e}");
    std::fs::write(
        dir.join("value.csv"),
        format!("time,x\n0,1\n0.1,{SECRET}\n"),
    )
    .unwrap();
    let (ok, e) = bounded(&dir, &["animate", "value.csv", "-o", "x.html"]);
    assert!(!ok && e.contains("line 3: field 2 is not a number"), "{e}");
}
