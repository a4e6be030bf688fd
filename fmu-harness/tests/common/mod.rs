//! Shared helpers of the harness integration tests: the C1 scene, scratch directories, and
//! running the built `fmu-harness` binary.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Output;

pub const C1_SCENE: &str = "../scenes/cantilever_free_vibration.toml";

pub fn c1_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(C1_SCENE)
}

pub fn c1_text() -> String {
    std::fs::read_to_string(c1_path()).expect("scenes/cantilever_free_vibration.toml exists")
}

/// A fresh, empty scratch directory for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("fmu-harness-tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}

/// A stand-in for the engine library: packaging only copies its bytes.
pub fn fake_engine(dir: &Path, content: &[u8]) -> PathBuf {
    let p = dir.join("libfmu_beam.so");
    std::fs::write(&p, content).expect("write fake engine");
    p
}

pub fn harness(args: &[&std::ffi::OsStr]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_fmu-harness"))
        .args(args)
        .output()
        .expect("run fmu-harness")
}

/// `fmu-harness package <scene> -o <out> --binary <engine>`.
pub fn package(scene: &Path, out: &Path, engine: &Path) -> Output {
    harness(&[
        "package".as_ref(),
        scene.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--binary".as_ref(),
        engine.as_os_str(),
    ])
}

/// The text of one file inside a zip archive.
pub fn read_entry(fmu: &Path, name: &str) -> String {
    let f = std::fs::File::open(fmu).expect("open fmu");
    let mut z = zip::ZipArchive::new(f).expect("fmu is a zip");
    let mut e = z.by_name(name).expect("entry exists");
    let mut s = String::new();
    std::io::Read::read_to_string(&mut e, &mut s).expect("utf-8 entry");
    s
}
