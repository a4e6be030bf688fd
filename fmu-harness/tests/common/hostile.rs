//! The bounded runs of `fmu-harness simulate` on hostile FMUs and the archives they are made of,
//! shared by `hostile_fmus.rs` (FMI 2.0) and `hostile_fmi3_fmus.rs` (FMI 3.0).

use super::*;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::Duration;
use zip::write::SimpleFileOptions;

/// What one bounded run of the harness gave.
pub struct Run {
    pub status: ExitStatus,
    pub stderr: String,
    pub elapsed: Duration,
    /// `fmu-harness-*` entries left in the run's TMPDIR.
    pub left: Vec<PathBuf>,
}

pub fn leftovers(tmp: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(tmp)
        .map(|d| {
            d.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.file_name()
                        .is_some_and(|n| n.to_string_lossy().starts_with("fmu-harness-"))
                })
                .collect()
        })
        .unwrap_or_default()
}

/// `fmu-harness simulate <fmu> -o <dir>/out.csv` with TMPDIR = `<dir>/tmp`, at most `limit`.
pub fn simulate(dir: &Path, fmu: &Path, extra: &[&str], limit: Duration) -> Run {
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    let err = dir.join("stderr.txt");
    let child = Command::new(env!("CARGO_BIN_EXE_fmu-harness"))
        .arg("simulate")
        .arg(fmu)
        .arg("-o")
        .arg(dir.join("out.csv"))
        .args(extra)
        .env("TMPDIR", &tmp)
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&err).unwrap())
        .spawn()
        .expect("run fmu-harness");
    let (status, elapsed) = wait_bounded(child, limit, &fmu.display().to_string());
    Run {
        status,
        stderr: std::fs::read_to_string(&err).unwrap_or_default(),
        elapsed,
        left: leftovers(&tmp),
    }
}

/// A zip of `entries`: (name, bytes) files, or (name, target) symbolic links when `link`.
pub fn fmu_of(path: &Path, entries: &[(&str, &[u8], bool)]) {
    let mut z = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
    for (name, bytes, link) in entries {
        let o = SimpleFileOptions::default();
        if *link {
            z.add_symlink(*name, std::str::from_utf8(bytes).unwrap(), o)
                .unwrap();
        } else {
            z.start_file(*name, o).unwrap();
            z.write_all(bytes).unwrap();
        }
    }
    z.finish().unwrap();
}

pub fn refused(run: &Run, words: &[&str]) {
    assert!(!run.status.success(), "accepted: {}", run.stderr);
    assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
    for w in words {
        assert!(run.stderr.contains(w), "{w:?} not in: {}", run.stderr);
    }
    assert!(run.left.is_empty(), "left behind: {:?}", run.left);
}

pub const QUICK: Duration = Duration::from_secs(20);

pub fn md_fmu(dir: &Path, name: &str, md: &str) -> PathBuf {
    let fmu = dir.join(name);
    fmu_of(&fmu, &[("modelDescription.xml", md.as_bytes(), false)]);
    fmu
}

/// C1 packaged with the release engine into `dir`.
pub fn c1_fmu(dir: &Path) -> PathBuf {
    c1_fmu_of(dir, 2)
}

/// C1 packaged with the release engine into `dir` as an FMI `version` (2 or 3) unit.
pub fn c1_fmu_of(dir: &Path, version: u32) -> PathBuf {
    let out = dir.join(format!("cantilever_free_vibration.v{version}.fmu"));
    let r = harness(&[
        "package".as_ref(),
        c1_path().as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--fmi-version".as_ref(),
        version.to_string().as_ref(),
    ]);
    assert!(
        r.status.success(),
        "packaging C1 with the release engine failed (run `cargo build --release -p fmu-beam`): {}",
        String::from_utf8_lossy(&r.stderr)
    );
    out
}

/// A copy of `fmu` with its modelDescription.xml changed by `edit`.
pub fn with_description(fmu: &Path, out: &Path, edit: impl Fn(&str) -> String) {
    let mut src = zip::ZipArchive::new(std::fs::File::open(fmu).unwrap()).unwrap();
    let mut z = zip::ZipWriter::new(std::fs::File::create(out).unwrap());
    for i in 0..src.len() {
        let mut e = src.by_index(i).unwrap();
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(&mut e, &mut bytes).unwrap();
        if e.name() == "modelDescription.xml" {
            bytes = edit(std::str::from_utf8(&bytes).unwrap()).into_bytes();
        }
        let o =
            SimpleFileOptions::default().unix_permissions(e.unix_mode().unwrap_or(0o644) & 0o777);
        z.start_file(e.name(), o).unwrap();
        z.write_all(&bytes).unwrap();
    }
    z.finish().unwrap();
}
