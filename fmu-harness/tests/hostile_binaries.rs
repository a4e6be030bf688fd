//! `fmu-harness package --binary` reads with care (issue 35, items 2 and 8): a character device
//! (`/dev/zero`), a FIFO or a folder is refused before it is read, by its type and at once; a
//! file over the size cap is refused; a library that exports no FMI 2.0 function, or not all
//! of them, is refused naming what is missing; so is one without the FMI 3.0 functions for a
//! `--fmi-version 3` unit. Each run is bounded in time: a hang fails.

use crate::common;
use common::*;
use fmu_harness::engine_library::MAX_LIBRARY_BYTES;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

/// `fmu-harness package C1 -o <dir>/x.fmu --binary <binary>` within 20 s: (success, stderr).
fn package_with(dir: &Path, binary: &str) -> (bool, String, Duration) {
    package_as(dir, binary, "2")
}

/// [`package_with`] as an FMI `version` unit (`--fmi-version`).
fn package_as(dir: &Path, binary: &str, version: &str) -> (bool, String, Duration) {
    let err = dir.join("stderr.txt");
    let out = dir.join("x.fmu");
    let child = Command::new(env!("CARGO_BIN_EXE_fmu-harness"))
        .arg("package")
        .arg(c1_path())
        .arg("-o")
        .arg(&out)
        .args(["--binary", binary, "--fmi-version", version])
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&err).unwrap())
        .spawn()
        .expect("run fmu-harness");
    let (status, took) = wait_bounded(
        child,
        Duration::from_secs(20),
        &format!("package --binary {binary}"),
    );
    let stderr = std::fs::read_to_string(&err).unwrap_or_default();
    assert!(!stderr.contains("panicked"), "{stderr}");
    if !status.success() {
        assert!(
            !out.exists(),
            "a refused --binary {binary} left {}",
            out.display()
        );
    }
    (status.success(), stderr, took)
}

#[test]
fn dev_zero_is_refused_at_once_as_a_device() {
    let dir = scratch("binary_dev_zero");
    for arg in ["/dev/zero", "linux64=/dev/zero"] {
        let (ok, stderr, elapsed) = package_with(&dir, arg);
        assert!(!ok);
        assert!(
            stderr.contains(
                "/dev/zero: a character device; an engine library must be a regular file"
            ),
            "{stderr}"
        );
        assert!(elapsed < Duration::from_secs(5), "{elapsed:?}");
    }
}

#[test]
fn a_fifo_is_refused_without_blocking() {
    let dir = scratch("binary_fifo");
    let fifo = dir.join("engine.so");
    let made = Command::new("mkfifo").arg(&fifo).status().expect("mkfifo");
    assert!(made.success());
    let (ok, stderr, _) = package_with(&dir, &fifo.display().to_string());
    assert!(!ok);
    assert!(
        stderr.contains("a FIFO; an engine library must be a regular file"),
        "{stderr}"
    );
}

#[test]
fn a_folder_and_an_oversized_file_are_refused() {
    let dir = scratch("binary_large");
    let (ok, stderr, _) = package_with(&dir, &dir.display().to_string());
    assert!(!ok && stderr.contains("a directory"), "{stderr}");
    // A sparse file one byte over the cap: refused from its size, nothing read.
    let big = dir.join("big.so");
    let f = std::fs::File::create(&big).unwrap();
    f.set_len(MAX_LIBRARY_BYTES + 1).unwrap();
    let (ok, stderr, elapsed) = package_with(&dir, &big.display().to_string());
    assert!(!ok);
    assert!(
        stderr.contains(&format!(
            "larger than {MAX_LIBRARY_BYTES} bytes, the most an engine library may have"
        )),
        "{stderr}"
    );
    assert!(elapsed < Duration::from_secs(5), "{elapsed:?}");
}

#[test]
fn a_library_without_fmi2_exports_is_refused() {
    let dir = scratch("binary_exports");
    // A real x86-64 shared object with no fmi2 function.
    let libm = [
        "/lib/x86_64-linux-gnu/libm.so.6",
        "/usr/lib/x86_64-linux-gnu/libm.so.6",
    ]
    .into_iter()
    .find(|p| Path::new(p).is_file())
    .expect("libm.so.6 on this machine");
    let (ok, stderr, _) = package_with(&dir, libm);
    assert!(!ok);
    assert!(
        stderr.contains("exports none of the 34 FMI 2.0 co-simulation functions"),
        "{stderr}"
    );
    // The header of an ELF shared object and nothing else: no symbol table to read.
    let bare = dir.join("bare.so");
    let mut bytes =
        fmu_harness::platform::library_header(fmu_harness::platform::Platform::Linux64, 0);
    bytes.truncate(64);
    bytes[40..48].fill(0); // no section headers
    bytes.resize(0x200, 0);
    std::fs::write(&bare, bytes).unwrap();
    let (ok, stderr, _) = package_with(&dir, &bare.display().to_string());
    assert!(!ok);
    assert!(
        stderr.contains("bare.so: exports none of the 34"),
        "{stderr}"
    );
    // The engine itself passes.
    let engine = fmu_harness::package::default_binary().expect("the release engine is built");
    let (ok, stderr, _) = package_with(&dir, &engine.display().to_string());
    assert!(ok, "{stderr}");
}

#[test]
fn a_library_without_fmi3_exports_is_refused_for_an_fmi3_unit() {
    let dir = scratch("binary_exports_fmi3");
    let libm = [
        "/lib/x86_64-linux-gnu/libm.so.6",
        "/usr/lib/x86_64-linux-gnu/libm.so.6",
    ]
    .into_iter()
    .find(|p| Path::new(p).is_file())
    .expect("libm.so.6 on this machine");
    let (ok, stderr, _) = package_as(&dir, libm, "3");
    assert!(!ok);
    assert!(
        stderr.contains("exports none of the 75 FMI 3.0 functions"),
        "{stderr}"
    );
    for arg in ["/dev/zero", "x86_64-linux=/dev/zero"] {
        let (ok, stderr, _) = package_as(&dir, arg, "3");
        assert!(!ok && stderr.contains("a character device"), "{stderr}");
    }
    let engine = fmu_harness::package::default_binary().expect("the release engine is built");
    let (ok, stderr, _) = package_as(&dir, &engine.display().to_string(), "3");
    assert!(ok, "{stderr}");
}
