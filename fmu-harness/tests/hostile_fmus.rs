//! The master treats an FMU as untrusted (issue 35, item 7): `fmu-harness simulate` refuses an
//! FMU with a symbolic link entry, an entry outside its folder (`../`, absolute), too many
//! entries, a zip bomb (declared, or hidden behind a header that lies), a modelIdentifier that
//! is no plain identifier, duplicate value references, malformed XML (without quoting it) and
//! an absurd number of communication steps; each refusal names what it refused, quickly, and
//! leaves no `fmu-harness-<pid>-*` folder behind, also when SIGTERM ends a run.
//!
//! Each run is a child process with its own TMPDIR, bounded in time: a hang fails the test.

use crate::common;
use common::hostile::*;
use common::*;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const MD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="m" guid="{0}">
  <CoSimulation modelIdentifier="m"/>
  <DefaultExperiment startTime="0" stopTime="1" stepSize="0.1"/>
  <ModelVariables>
    <ScalarVariable name="u" valueReference="1" causality="input"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="2" causality="output"><Real/></ScalarVariable>
  </ModelVariables>
</fmiModelDescription>"#;

#[test]
fn a_symbolic_link_entry_is_refused_and_never_followed() {
    let dir = scratch("hostile_symlink");
    let fmu = dir.join("link.fmu");
    fmu_of(
        &fmu,
        &[
            ("modelDescription.xml", MD.as_bytes(), false),
            ("resources/scene.toml", b"/etc/passwd", true),
        ],
    );
    let run = simulate(&dir, &fmu, &[], QUICK);
    refused(&run, &["resources/scene.toml", "symbolic link"]);
    assert!(!run.stderr.contains("root:"), "{}", run.stderr);

    let fmu = dir.join("binary_link.fmu");
    fmu_of(
        &fmu,
        &[
            ("modelDescription.xml", MD.as_bytes(), false),
            (
                "binaries/linux64/m.so",
                b"/lib/x86_64-linux-gnu/libm.so.6",
                true,
            ),
        ],
    );
    let run = simulate(&dir, &fmu, &[], QUICK);
    refused(&run, &["binaries/linux64/m.so", "symbolic link"]);

    // cosim loads its units the same way.
    let system = dir.join("system.toml");
    std::fs::write(
        &system,
        format!(
            "stop_time = 1.0\nstep = {{ size = 1e-3 }}\n\n[[unit]]\nname = \"a\"\nfmu = \"{}\"\n",
            fmu.display()
        ),
    )
    .unwrap();
    let tmp = dir.join("tmp");
    let r = Command::new(env!("CARGO_BIN_EXE_fmu-harness"))
        .arg("cosim")
        .arg(&system)
        .env("TMPDIR", &tmp)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success());
    assert!(
        stderr.contains("unit `a`") && stderr.contains("symbolic link"),
        "{stderr}"
    );
    assert!(leftovers(&tmp).is_empty());
}

/// The model's binary is read before the system's loader sees it: a file that is no shared
/// library of this platform, or one that does not export the co-simulation entry points, is
/// refused by name (a real library without them, libm, would load: its code would run).
#[test]
fn a_binary_that_is_no_fmu_library_of_this_platform_is_refused_before_loading() {
    use fmu_harness::platform::{library_header, Platform};
    let dir = scratch("hostile_binary_kind");
    let libm =
        std::fs::read("/lib/x86_64-linux-gnu/libm.so.6").expect("libm, as on every glibc Linux");
    let cases: [(&str, Vec<u8>, &str); 3] = [
        (
            "text.fmu",
            b"#!/bin/sh\necho hello\n".to_vec(),
            "not a 64-bit shared library",
        ),
        (
            "dll.fmu",
            library_header(Platform::Win64, 0),
            "not a 64-bit shared library",
        ),
        ("libm.fmu", libm, "does not export fmi2Instantiate"),
    ];
    for (name, bytes, words) in cases {
        let fmu = dir.join(name);
        fmu_of(
            &fmu,
            &[
                ("modelDescription.xml", MD.as_bytes(), false),
                ("binaries/linux64/m.so", &bytes, false),
            ],
        );
        let run = simulate(&dir, &fmu, &[], QUICK);
        refused(&run, &["binaries/linux64/m.so", words]);
    }
}

#[test]
fn entries_outside_the_extraction_folder_are_refused() {
    let dir = scratch("hostile_outside");
    let outside = dir.join("escaped.txt");
    let absolute = "/tmp/fmu_harness_hostile_escaped.txt";
    for name in [
        "../escaped.txt",
        "../../escaped.txt",
        "a/../../escaped.txt",
        absolute,
        "C:/escaped.txt",
    ] {
        let fmu = dir.join("outside.fmu");
        fmu_of(
            &fmu,
            &[
                ("modelDescription.xml", MD.as_bytes(), false),
                (name, b"written outside", false),
            ],
        );
        let run = simulate(&dir, &fmu, &[], QUICK);
        let reason = if name.contains("..") {
            "climbs out"
        } else {
            "absolute path"
        };
        refused(&run, &[name, reason]);
        assert!(
            !outside.exists(),
            "{name} was written to {}",
            outside.display()
        );
        assert!(
            !Path::new(absolute).exists(),
            "{name} was written to {absolute}"
        );
        assert!(!dir.join("tmp/escaped.txt").exists(), "{name} was written");
    }
}

#[test]
fn too_many_entries_are_refused_before_any_is_written() {
    let dir = scratch("hostile_entries");
    let fmu = dir.join("many.fmu");
    let names: Vec<String> = (0..10_001).map(|i| format!("resources/{i}")).collect();
    let mut entries: Vec<(&str, &[u8], bool)> =
        vec![("modelDescription.xml", MD.as_bytes(), false)];
    entries.extend(names.iter().map(|n| (n.as_str(), &b""[..], false)));
    fmu_of(&fmu, &entries);
    let run = simulate(&dir, &fmu, &[], QUICK);
    refused(&run, &["10002 entries", "at most 10000"]);
}

/// A raw deflate stream (fixed Huffman codes) that inflates to `zeros` zero bytes, about 1000
/// times smaller: a literal 0, then matches of length 258 at distance 1.
fn deflated_zeros(zeros: u64) -> Vec<u8> {
    struct Bits {
        out: Vec<u8>,
        acc: u64,
        n: u32,
    }
    impl Bits {
        fn put(&mut self, value: u64, bits: u32) {
            self.acc |= value << self.n;
            self.n += bits;
            while self.n >= 8 {
                self.out.push(self.acc as u8);
                self.acc >>= 8;
                self.n -= 8;
            }
        }
        /// A Huffman code: most significant bit first.
        fn code(&mut self, code: u64, bits: u32) {
            let mut rev = 0;
            for i in 0..bits {
                rev |= ((code >> i) & 1) << (bits - 1 - i);
            }
            self.put(rev, bits);
        }
    }
    let mut b = Bits {
        out: Vec::new(),
        acc: 0,
        n: 0,
    };
    b.put(1, 1); // BFINAL
    b.put(1, 2); // fixed Huffman
    b.code(0x30, 8); // literal 0
    let mut left = zeros - 1;
    while left >= 258 {
        b.code(0xc5, 8); // length code 285 (258): 11000101
        b.code(0, 5); // distance code 0 (1)
        left -= 258;
    }
    for _ in 0..left {
        b.code(0x30, 8);
    }
    b.code(0, 7); // end of block
    b.put(0, 7);
    b.out
}

/// A zip with modelDescription.xml (stored) and one deflated entry whose header declares
/// `declared` bytes while its data inflates to `zeros`.
fn bomb(path: &Path, zeros: u64, declared: u32) {
    let data = deflated_zeros(zeros);
    let mut out = Vec::new();
    let mut central = Vec::new();
    let entries: [(&[u8], u16, u32, &[u8]); 2] = [
        (b"modelDescription.xml", 0, MD.len() as u32, MD.as_bytes()),
        (b"resources/zeros.bin", 8, declared, &data),
    ];
    for (name, method, size, bytes) in entries {
        let at = out.len() as u32;
        let crc = if method == 0 { crc32(bytes) } else { 0 };
        let mut common = Vec::new();
        common.extend_from_slice(&20u16.to_le_bytes()); // version needed
        common.extend_from_slice(&0u16.to_le_bytes()); // flags
        common.extend_from_slice(&method.to_le_bytes());
        common.extend_from_slice(&0u32.to_le_bytes()); // time, date
        common.extend_from_slice(&crc.to_le_bytes());
        common.extend_from_slice(&(bytes.len() as u32).to_le_bytes());
        common.extend_from_slice(&size.to_le_bytes());
        common.extend_from_slice(&(name.len() as u16).to_le_bytes());
        common.extend_from_slice(&0u16.to_le_bytes()); // extra
        out.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        out.extend_from_slice(&common);
        out.extend_from_slice(name);
        out.extend_from_slice(bytes);
        central.extend_from_slice(&0x0201_4b50u32.to_le_bytes());
        central.extend_from_slice(&0x0314u16.to_le_bytes()); // made by Unix
        central.extend_from_slice(&common);
        central.extend_from_slice(&[0u8; 6]); // comment length, disk, internal attributes
        central.extend_from_slice(&(0o100_644u32 << 16).to_le_bytes());
        central.extend_from_slice(&at.to_le_bytes());
        central.extend_from_slice(name);
    }
    let cd_at = out.len() as u32;
    out.extend_from_slice(&central);
    out.extend_from_slice(&0x0605_4b50u32.to_le_bytes());
    out.extend_from_slice(&[0u8; 4]); // disk numbers
    out.extend_from_slice(&2u16.to_le_bytes());
    out.extend_from_slice(&2u16.to_le_bytes());
    out.extend_from_slice(&(central.len() as u32).to_le_bytes());
    out.extend_from_slice(&cd_at.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    std::fs::write(path, out).unwrap();
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

#[test]
fn a_zip_bomb_is_refused_quickly_whatever_its_header_says() {
    let dir = scratch("hostile_bomb");
    let limit = fmu_harness::slave::MAX_EXTRACTED_BYTES;
    let fmu = dir.join("bomb.fmu");
    // 600 MiB in 4.0 MB (fixed Huffman codes: 159 to 1), declared: refused from the header.
    let zeros = 600 << 20;
    bomb(&fmu, zeros, zeros as u32);
    let size = std::fs::metadata(&fmu).unwrap().len();
    assert!(size < 5_000_000, "{size}");
    let run = simulate(&dir, &fmu, &[], QUICK);
    refused(
        &run,
        &["resources/zeros.bin", &limit.to_string(), "declares"],
    );
    assert!(run.elapsed < Duration::from_secs(2), "{:?}", run.elapsed);
    eprintln!("declared bomb ({size} bytes) refused in {:?}", run.elapsed);

    // The same stream behind a header that declares 1000 bytes: counted while inflating.
    bomb(&fmu, zeros, 1000);
    let run = simulate(&dir, &fmu, &[], QUICK);
    refused(
        &run,
        &[
            "resources/zeros.bin",
            &limit.to_string(),
            "expands to at least",
        ],
    );
    assert!(run.elapsed < Duration::from_secs(10), "{:?}", run.elapsed);
    eprintln!("lying bomb refused in {:?}", run.elapsed);
}

#[test]
fn a_model_identifier_that_is_no_plain_identifier_is_refused() {
    let dir = scratch("hostile_identifier");
    for (id, words) in [
        (
            "../../x",
            &["\"../../x\"", "does not start with a letter"][..],
        ),
        ("a/../../x", &["\"a/../../x\"", "character other than"]),
        ("/tmp/x", &["\"/tmp/x\""]),
        ("", &["is empty"]),
        ("9lives", &["does not start with a letter"]),
    ] {
        let md = MD.replace(
            "modelIdentifier=\"m\"",
            &format!("modelIdentifier=\"{id}\""),
        );
        let run = simulate(&dir, &md_fmu(&dir, "id.fmu", &md), &[], QUICK);
        refused(&run, words);
        assert!(run.stderr.contains("modelIdentifier"), "{}", run.stderr);
    }
    let long = "a".repeat(252);
    let md = MD.replace(
        "modelIdentifier=\"m\"",
        &format!("modelIdentifier=\"{long}\""),
    );
    let run = simulate(&dir, &md_fmu(&dir, "id.fmu", &md), &[], QUICK);
    refused(&run, &["252 bytes", "at most 251"]);
}

#[test]
fn duplicate_value_references_are_refused_naming_both_variables() {
    let dir = scratch("hostile_duplicates");
    let two_inputs = MD.replace(
        r#"name="y" valueReference="2" causality="output""#,
        r#"name="v" valueReference="1" causality="input""#,
    );
    let run = simulate(&dir, &md_fmu(&dir, "dup.fmu", &two_inputs), &[], QUICK);
    refused(&run, &["valueReference 1", "`u`", "`v`"]);
    let input_and_output = MD.replace(r#"valueReference="2""#, r#"valueReference="1""#);
    let run = simulate(
        &dir,
        &md_fmu(&dir, "dup.fmu", &input_and_output),
        &[],
        QUICK,
    );
    refused(&run, &["valueReference 1", "`u`", "`y`"]);
}

#[test]
fn a_malformed_model_description_is_located_not_quoted() {
    let dir = scratch("hostile_xml");
    let secret = "root:x:0:0:SECRET";
    for md in [
        format!("<fmiModelDescription guid=\"g\">\n  <CoSimulation modelIdentifier=\"m\">\n{secret}\n</{secret}>"),
        format!("<fmiModelDescription guid=\"g\">\n<a b=\"{secret}\" b=\"{secret}\"/>"),
        MD.replace("modelIdentifier=\"m\"", &format!("modelIdentifier=\"&{secret};\"")),
        MD.replace("stepSize=\"0.1\"", &format!("stepSize=\"{secret}\"")),
        MD.replace("name=\"u\"", &format!("name=\"u\" causality=\"{secret}\"")).replace("causality=\"input\"", ""),
    ] {
        let run = simulate(&dir, &md_fmu(&dir, "xml.fmu", &md), &[], QUICK);
        refused(&run, &["modelDescription.xml"]);
        assert!(!run.stderr.contains("root:x"), "{}", run.stderr);
    }
    let md = format!("<fmiModelDescription guid=\"g\">\n  <CoSimulation modelIdentifier=\"m\">\n{secret}\n</{secret}>");
    let run = simulate(&dir, &md_fmu(&dir, "xml.fmu", &md), &[], QUICK);
    refused(&run, &["line 4, column 1", "the end tag `</CoSimulation>`"]);
}

#[test]
fn an_absurd_number_of_communication_steps_is_refused_at_once() {
    let dir = scratch("hostile_steps");
    let c1 = c1_fmu(&dir);
    let tiny = dir.join("tiny_step.fmu");
    with_description(&c1, &tiny, |md| {
        let at = md.find("stepSize=\"").expect("C1 has a stepSize") + 10;
        let end = at + md[at..].find('"').unwrap();
        format!("{}1e-300{}", &md[..at], &md[end..])
    });
    let run = simulate(&dir, &tiny, &[], QUICK);
    refused(&run, &["communication steps", "at most 1e8"]);
    assert!(run.elapsed < Duration::from_secs(10), "{:?}", run.elapsed);
    let run = simulate(&dir, &c1, &["--step", "1e-12"], QUICK);
    refused(&run, &["communication steps", "at most 1e8"]);
    // The bound leaves an ordinary run alone, and the streamed CSV is Results::csv's bytes.
    let run = simulate(&dir, &c1, &["--stop", "0.01"], QUICK);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(run.left.is_empty(), "{:?}", run.left);
    let options = fmu_harness::simulate::Options {
        stop_time: Some(0.01),
        ..Default::default()
    };
    let kept = fmu_harness::simulate::simulate(&c1, &options)
        .unwrap()
        .0
        .csv();
    assert!(kept.lines().count() > 2);
    assert!(std::fs::read_to_string(dir.join("out.csv")).unwrap() == kept);

    // cosim: a fixed step refused by the system file's check, before any unit is loaded.
    let system = dir.join("system.toml");
    std::fs::write(
        &system,
        format!(
            "start_time = 0.0\nstop_time = 1.0\nstep = {{ size = 1e-300 }}\n\n\
             [[unit]]\nname = \"c1\"\nfmu = \"{}\"\n",
            c1.display()
        ),
    )
    .unwrap();
    let r = harness(&["cosim".as_ref(), system.as_os_str()]);
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success());
    assert!(
        stderr.contains("step.size") && stderr.contains("at most 1e8"),
        "{stderr}"
    );

    // a variable step whose smallest step could take more than 1e8 steps: refused the same way
    std::fs::write(
        &system,
        format!(
            "start_time = 0.0\nstop_time = 1.0\n\
             step = {{ size = 1e-3, variable = {{ min = 1e-300, max = 1e-2, tolerance = 1e-4 }} }}\n\n\
             [[unit]]\nname = \"c1\"\nfmu = \"{}\"\n",
            c1.display()
        ),
    )
    .unwrap();
    let r = harness(&["cosim".as_ref(), system.as_os_str()]);
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success());
    assert!(
        stderr.contains("step.variable.min") && stderr.contains("at most 1e8"),
        "{stderr}"
    );
}

#[test]
fn sigterm_or_sigint_during_a_run_leaves_no_extraction_folder() {
    let dir = scratch("hostile_sigterm");
    let c1 = c1_fmu(&dir);
    let system = dir.join("system.toml");
    std::fs::write(
        &system,
        format!(
            "stop_time = 1e4\nstep = {{ size = 1e-3 }}\n\n[[unit]]\nname = \"c1\"\nfmu = \"{}\"\n",
            c1.display()
        ),
    )
    .unwrap();
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    let csv = dir.join("long.csv");
    let half_written = || -> Vec<PathBuf> {
        std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.to_string_lossy().contains(".long.csv.tmp-"))
            .collect()
    };
    for (command, run, signal, number) in [
        ("simulate", &c1, "TERM", 15),
        ("simulate", &c1, "INT", 2),
        ("cosim", &system, "TERM", 15),
    ] {
        let child = Command::new(env!("CARGO_BIN_EXE_fmu-harness"))
            .arg(command)
            .arg(run)
            .args(if command == "simulate" {
                &["--stop", "1e4"][..]
            } else {
                &[]
            })
            .arg("-o")
            .arg(&csv)
            .env("TMPDIR", &tmp)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let pid = child.id();
        let start = Instant::now();
        while leftovers(&tmp).is_empty() {
            assert!(
                start.elapsed() < QUICK,
                "{command}: no extraction folder appeared"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
        // Well into the run: the CSV is being written.
        std::thread::sleep(Duration::from_millis(300));
        assert_eq!(half_written().len(), 1, "{command}: no CSV being written");
        let kill = Command::new("kill")
            .args([&format!("-{signal}"), &pid.to_string()])
            .status()
            .unwrap();
        assert!(kill.success());
        let (status, _) = wait_bounded(child, QUICK, command);
        assert!(!status.success());
        assert_eq!(leftovers(&tmp), Vec::<PathBuf>::new(), "{command} {signal}");
        assert_eq!(half_written(), Vec::<PathBuf>::new(), "{command} {signal}");
        assert!(!csv.exists());
        #[cfg(unix)]
        {
            use std::os::unix::process::ExitStatusExt;
            assert_eq!(status.signal(), Some(number), "{command}: {status:?}");
        }
    }
}
