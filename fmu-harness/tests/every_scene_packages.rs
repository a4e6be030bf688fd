//! Every scene of `scenes/` packages: it loads, each unit its variables use is declared in
//! UnitDefinitions (an undeclared unit would fail fmpy's validate_fmu), and its
//! modelDescription.xml is well-formed XML 1.0 (issue 45: U+FFFE in a description made fmpy
//! raise XMLSyntaxError).

use crate::common;
use common::*;
use std::path::Path;

#[test]
fn every_scene_in_the_repository_packages() {
    let dir = scratch("every_scene");
    let engine = fake_engine(&dir, b"engine");
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let mut paths: Vec<_> = std::fs::read_dir(&scenes)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    assert!(paths
        .iter()
        .any(|p| p.ends_with("cantilever_free_vibration.toml")));
    let failures: Vec<String> = paths
        .iter()
        .filter_map(|scene| {
            let out = dir.join(scene.with_extension("fmu").file_name().unwrap());
            let r = package(scene, &out, &engine);
            (!r.status.success()).then(|| String::from_utf8_lossy(&r.stderr).into_owned())
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join(""));
    for scene in &paths {
        let fmu = dir.join(scene.with_extension("fmu").file_name().unwrap());
        let xml = model_description(&fmu);
        well_formed(&xml).unwrap_or_else(|e| panic!("{}: {e}", fmu.display()));
    }
}

/// The modelDescription.xml of the FMU at `path`.
fn model_description(path: &Path) -> String {
    let mut zip = zip::ZipArchive::new(std::fs::File::open(path).unwrap()).unwrap();
    let mut text = String::new();
    std::io::Read::read_to_string(&mut zip.by_name("modelDescription.xml").unwrap(), &mut text)
        .unwrap();
    text
}

/// Whether `xml` is a well-formed document: quick-xml reads it to the end with its end tags
/// checked, and every character is one XML 1.0 holds (quick-xml does not check that).
fn well_formed(xml: &str) -> Result<(), String> {
    if let Some(c) = xml.chars().find(|&c| !fmu_beam::scene::rules::xml_char(c)) {
        return Err(format!("U+{:04X} is no XML 1.0 character", c as u32));
    }
    let mut reader = quick_xml::Reader::from_str(xml);
    reader.config_mut().check_end_names = true;
    let mut depth = 0i64;
    loop {
        match reader.read_event() {
            Err(e) => return Err(e.to_string()),
            Ok(quick_xml::events::Event::Eof) => break,
            Ok(quick_xml::events::Event::Start(_)) => depth += 1,
            Ok(quick_xml::events::Event::End(_)) => depth -= 1,
            Ok(_) => {}
        }
    }
    (depth == 0)
        .then_some(())
        .ok_or_else(|| "unclosed elements".into())
}

#[test]
fn a_description_xml_cannot_hold_is_refused_naming_the_field() {
    let dir = scratch("xml_text");
    let engine = fake_engine(&dir, b"engine");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/flexible_pendulum.toml"),
    )
    .unwrap();
    let description = text.lines().find(|l| l.starts_with("description")).unwrap();
    for bad in ["\\uFFFE", "\\uFFFF", "\\u0007"] {
        let scene = dir.join("bad.toml");
        std::fs::write(
            &scene,
            text.replace(description, &format!("description = \"a {bad} b\"")),
        )
        .unwrap();
        let r = package(&scene, &dir.join("bad.fmu"), &engine);
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(
            !r.status.success() && err.contains("`description`"),
            "{err}"
        );
        assert!(err.contains("XML 1.0"), "{err}");
        assert!(!dir.join("bad.fmu").exists());
    }
}
