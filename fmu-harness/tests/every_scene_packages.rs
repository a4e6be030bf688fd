//! Every scene of `scenes/` packages: it loads, and each unit its variables use is declared in
//! UnitDefinitions (an undeclared unit would fail fmpy's validate_fmu).

mod common;
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
}
