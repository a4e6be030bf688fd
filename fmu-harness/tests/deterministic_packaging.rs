//! Packaging is a pure function of the scene and the engine binary: the same inputs give a
//! byte-identical FMU (fixed zip timestamps, order and permissions; no generation date), and a
//! different binary gives a different GUID.

use crate::common;
use common::*;

#[test]
fn same_scene_and_binary_give_identical_fmus() {
    let dir = scratch("deterministic");
    let engine = fake_engine(&dir, b"not really an engine");
    let (a, b) = (dir.join("a.fmu"), dir.join("sub/b.fmu"));
    for out in [&a, &b] {
        let r = package(&c1_path(), out, &engine);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    }
    let (ba, bb) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert!(!ba.is_empty());
    assert!(ba == bb, "two packagings of the same scene differ");

    // the GUID is in the XML and in resources/guid.txt, and nothing else is left in the dir
    let guid = read_entry(&a, "resources/guid.txt");
    assert!(read_entry(&a, "modelDescription.xml").contains(&format!("guid=\"{guid}\"")));
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(
        names.iter().all(|n| !n.to_string_lossy().contains(".tmp")),
        "{names:?}"
    );

    let other = dir.join("other");
    std::fs::create_dir_all(&other).unwrap();
    let engine2 = fake_engine(&other, b"another engine");
    let c = dir.join("c.fmu");
    assert!(package(&c1_path(), &c, &engine2).status.success());
    assert_ne!(read_entry(&c, "resources/guid.txt"), guid);
}

#[test]
fn archive_holds_the_fmi_layout_with_fixed_metadata() {
    let dir = scratch("layout");
    let engine = fake_engine(&dir, b"engine bytes");
    let out = dir.join("c1.fmu");
    assert!(package(&c1_path(), &out, &engine).status.success());
    let mut z = zip::ZipArchive::new(std::fs::File::open(&out).unwrap()).unwrap();
    let names: Vec<String> = (0..z.len())
        .map(|i| z.by_index(i).unwrap().name().to_string())
        .collect();
    assert_eq!(
        names,
        [
            "modelDescription.xml",
            "binaries/linux64/cantilever_free_vibration.so",
            "resources/scene.toml",
            "resources/guid.txt",
            "documentation/index.html"
        ]
    );
    // the documentation is the explanation of the resolved effects
    let doc = read_entry(&out, "documentation/index.html");
    assert!(
        doc.contains("quadratic_velocity (beam)") && doc.contains("effects = scene"),
        "{doc}"
    );
    for i in 0..z.len() {
        let f = z.by_index(i).unwrap();
        let t = f.last_modified().unwrap();
        assert_eq!(
            (t.year(), t.month(), t.day(), t.hour(), t.minute()),
            (1980, 1, 1, 0, 0)
        );
        // engines are stored (fmpy extracts a unit on every run), the rest deflated
        let expected = if f.name().starts_with("binaries/") {
            zip::CompressionMethod::Stored
        } else {
            zip::CompressionMethod::Deflated
        };
        assert_eq!(f.compression(), expected, "{}", f.name());
    }
    let mut so = z
        .by_name("binaries/linux64/cantilever_free_vibration.so")
        .unwrap();
    assert_eq!(so.unix_mode().map(|m| m & 0o777), Some(0o755));
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(&mut so, &mut bytes).unwrap();
    assert_eq!(bytes, std::fs::read(&engine).unwrap());
    drop(so);
    let scene = read_entry(&out, "resources/scene.toml");
    let parsed = fmu_beam::Scene::from_toml_str(&scene, "resources/scene.toml").unwrap();
    assert_eq!(parsed, fmu_beam::Scene::load(&c1_path()).unwrap());
}
