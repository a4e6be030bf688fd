//! Shared helpers of the harness integration tests: the C1 scene, scratch directories, and
//! running the built `fmu-harness` binary.
#![allow(dead_code)]

pub mod hostile;

use fmu_harness::platform::{library_header, Platform};
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

/// A stand-in for the Linux engine library: an ELF x86-64 shared object's header, then
/// `content` (packaging reads the header for the platform and copies the bytes).
pub fn fake_engine(dir: &Path, content: &[u8]) -> PathBuf {
    fake_library(dir, Platform::Linux64, content)
}

/// A stand-in engine library of `platform` (`libfmu_beam.so` or `fmu_beam.dll` in `dir`).
pub fn fake_library(dir: &Path, platform: Platform, content: &[u8]) -> PathBuf {
    let name = match platform {
        Platform::Linux64 => "libfmu_beam.so",
        Platform::Win64 => "fmu_beam.dll",
    };
    let p = dir.join(name);
    let mut bytes = library_header(platform, 0);
    bytes.extend_from_slice(content);
    std::fs::write(&p, bytes).expect("write fake engine");
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

/// `fmu-harness package <scene> -o <out> --binary <b>...` with each `b` as given
/// (`[PLATFORM=]PATH`).
pub fn package_binaries(scene: &Path, out: &Path, binaries: &[String]) -> Output {
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "package".as_ref(),
        scene.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ];
    for b in binaries {
        args.extend(["--binary".as_ref(), std::ffi::OsStr::new(b)]);
    }
    harness(&args)
}

/// The bytes of one file inside a zip archive.
pub fn read_entry_bytes(fmu: &Path, name: &str) -> Vec<u8> {
    let f = std::fs::File::open(fmu).expect("open fmu");
    let mut z = zip::ZipArchive::new(f).expect("fmu is a zip");
    let mut e = z.by_name(name).expect("entry exists");
    let mut b = Vec::new();
    std::io::Read::read_to_end(&mut e, &mut b).expect("readable entry");
    b
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

/// Waits for a spawned `fmu-harness` at most `limit` (a hang fails the test, naming `what`):
/// its exit status and how long it took.
pub fn wait_bounded(
    mut child: std::process::Child,
    limit: std::time::Duration,
    what: &str,
) -> (std::process::ExitStatus, std::time::Duration) {
    let start = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("wait for fmu-harness") {
            return (status, start.elapsed());
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what}: fmu-harness did not return within {limit:?}");
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}
