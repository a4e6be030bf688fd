//! One engine library per platform (issue 14): `--binary` takes a Linux and a Windows library,
//! the FMU carries each under its folder (`binaries/linux64/<id>.so`, `binaries/win64/<id>.dll`),
//! the GUID changes when either changes, and a library that is not what its platform needs, or
//! a platform given twice, is refused before anything is written.

use crate::common;
use common::*;
use fmu_harness::platform::Platform;

const ID: &str = "cantilever_free_vibration";

fn entry_names(fmu: &std::path::Path) -> Vec<String> {
    let mut z = zip::ZipArchive::new(std::fs::File::open(fmu).unwrap()).unwrap();
    (0..z.len())
        .map(|i| z.by_index(i).unwrap().name().to_string())
        .collect()
}

fn arg(path: &std::path::Path) -> String {
    path.display().to_string()
}

#[test]
fn both_platforms_go_under_their_folders_in_any_order_of_arguments() {
    let dir = scratch("platforms_both");
    let so = fake_library(&dir, Platform::Linux64, b"linux engine");
    let dll = fake_library(&dir, Platform::Win64, b"windows engine");
    let (a, b) = (dir.join("a.fmu"), dir.join("b.fmu"));
    let r = package_binaries(&c1_path(), &a, &[arg(&so), format!("win64={}", arg(&dll))]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let stdout = String::from_utf8_lossy(&r.stdout);
    assert!(
        stdout.contains("linux64 ") && stdout.contains("win64 "),
        "{stdout}"
    );
    let r = package_binaries(&c1_path(), &b, &[arg(&dll), arg(&so)]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap());

    assert_eq!(
        entry_names(&a),
        [
            "modelDescription.xml".to_string(),
            format!("binaries/linux64/{ID}.so"),
            format!("binaries/win64/{ID}.dll"),
            "resources/scene.toml".to_string(),
            "resources/guid.txt".to_string(),
            "documentation/index.html".to_string(),
        ]
    );
    assert_eq!(
        read_entry_bytes(&a, &format!("binaries/win64/{ID}.dll")),
        std::fs::read(&dll).unwrap()
    );
    assert_eq!(
        read_entry_bytes(&a, &format!("binaries/linux64/{ID}.so")),
        std::fs::read(&so).unwrap()
    );
    let mut z = zip::ZipArchive::new(std::fs::File::open(&a).unwrap()).unwrap();
    let dll_entry = z.by_name(&format!("binaries/win64/{ID}.dll")).unwrap();
    assert_eq!(dll_entry.unix_mode().map(|m| m & 0o777), Some(0o755));
}

#[test]
fn the_guid_changes_when_either_binary_changes() {
    let dir = scratch("platforms_guid");
    let guid_of = |so: &[u8], dll: Option<&[u8]>, name: &str| {
        let sub = dir.join(name);
        std::fs::create_dir_all(&sub).unwrap();
        let mut args = vec![arg(&fake_library(&sub, Platform::Linux64, so))];
        if let Some(dll) = dll {
            args.push(arg(&fake_library(&sub, Platform::Win64, dll)));
        }
        let out = sub.join("x.fmu");
        let r = package_binaries(&c1_path(), &out, &args);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let guid = read_entry(&out, "resources/guid.txt");
        assert!(read_entry(&out, "modelDescription.xml").contains(&format!("guid=\"{guid}\"")));
        guid
    };
    let base = guid_of(b"A", Some(b"B"), "base");
    assert_eq!(guid_of(b"A", Some(b"B"), "same"), base);
    assert_ne!(guid_of(b"A", Some(b"C"), "dll"), base);
    assert_ne!(guid_of(b"C", Some(b"B"), "so"), base);
    assert_ne!(guid_of(b"A", None, "linux_only"), base);
}

#[test]
fn a_library_of_another_platform_or_none_or_twice_is_refused() {
    let dir = scratch("platforms_refused");
    let so = fake_library(&dir, Platform::Linux64, b"linux engine");
    let dll = fake_library(&dir, Platform::Win64, b"windows engine");
    let text = dir.join("notes.txt");
    std::fs::write(&text, "not a library").unwrap();
    let other = dir.join("other");
    std::fs::create_dir_all(&other).unwrap();
    let so2 = fake_library(&other, Platform::Linux64, b"another linux engine");
    let out = dir.join("x.fmu");
    let cases: [(Vec<String>, Vec<String>); 5] = [
        (
            vec![format!("win64={}", arg(&so))],
            vec![arg(&so), "win64 engine".into(), "linux64 library".into()],
        ),
        (
            vec![format!("linux64={}", arg(&dll))],
            vec![arg(&dll), "PE32+".into(), "win64 library".into()],
        ),
        (
            vec![arg(&so), arg(&text)],
            vec![arg(&text), "not an engine library".into()],
        ),
        (
            vec![arg(&so), arg(&so2)],
            vec!["two engine libraries for linux64".into(), arg(&so2)],
        ),
        (
            vec![format!("darwin64={}", arg(&so))],
            vec!["unknown platform 'darwin64'".into()],
        ),
    ];
    for (args, words) in cases {
        let r = package_binaries(&c1_path(), &out, &args);
        let stderr = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success(), "{args:?} was accepted");
        assert!(!stderr.contains("panicked"), "{stderr}");
        for w in &words {
            assert!(stderr.contains(w.as_str()), "{w:?} not in: {stderr}");
        }
        assert!(!out.exists(), "{args:?} left {}", out.display());
    }
}
