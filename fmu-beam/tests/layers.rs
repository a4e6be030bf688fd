//! The engine's layers import only downwards (ARCHITECTURE.md, "Layers"): every `crate::x`
//! path in the code of a module (comments left out) names a module of its own layer or of one
//! below it. Fails with the file, the line and the two layers. The element layer
//! (`mechanics/beam/`: sections and finite elements) is the floor: it imports nothing, not even
//! the scene format, so a newcomer can read it first.

use std::path::{Path, PathBuf};

/// The layers from the bottom up; a top-level module belongs to one of them.
const LAYERS: [(&str, &[&str]); 8] = [
    ("elements", &["mechanics/beam"]),
    ("scene format", &["scene"]),
    ("errors", &["error"]),
    ("mechanics", &["mechanics"]),
    ("integrator", &["integrator"]),
    ("unit", &["unit"]),
    ("fmi", &["fmi2", "fmi3"]),
    ("in-crate tests", &["tests"]),
];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|(_, ms)| ms.contains(&module))
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).expect("src is readable") {
        let p = e.expect("entry").path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The top-level module a file of `src/` belongs to (`None` for lib.rs, the crate root).
fn module_of(file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src()).expect("below src");
    let mut parts = rel
        .components()
        .map(|c| c.as_os_str().to_str().unwrap_or(""));
    let first = parts.next()?.to_string();
    if first == "mechanics" && parts.next() == Some("beam") {
        return Some("mechanics/beam".to_string());
    }
    match first.strip_suffix(".rs") {
        Some("lib") => None,
        Some(m) => Some(m.to_string()),
        None => Some(first),
    }
}

/// The modules a line of code names through `crate::` (`crate::a::b`, `crate::{a, b::c}`).
fn crate_paths(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(i) = rest.find("crate::") {
        let before = rest[..i].chars().last();
        rest = &rest[i + "crate::".len()..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue; // `my_crate::`, not this crate
        }
        // the module a path names: its first segment, or `mechanics/beam` for the element layer
        let ident = |s: &str| -> String {
            let s = s.trim_start();
            let first: String = s
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if first == "mechanics" && s[first.len()..].starts_with("::beam") {
                return "mechanics/beam".to_string();
            }
            first
        };
        if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            out.extend(group[..end].split(',').map(ident).filter(|s| !s.is_empty()));
        } else {
            out.push(ident(rest));
        }
    }
    out
}

#[test]
fn every_module_imports_only_from_its_layer_or_below() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    files.sort();
    let mut upward = Vec::new();
    let mut checked = 0;
    for file in &files {
        let Some(module) = module_of(file) else {
            continue;
        };
        let own = layer_of(&module).unwrap_or_else(|| {
            panic!(
                "{}: top-level module `{module}` is in no layer (add it to LAYERS and to \
                 ARCHITECTURE.md)",
                file.display()
            )
        });
        let text = std::fs::read_to_string(file).expect("readable");
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            for target in crate_paths(code) {
                checked += 1;
                let Some(to) = layer_of(&target) else {
                    continue; // a crate-root item (re-export), not a layer
                };
                if to > own {
                    upward.push(format!(
                        "{}:{}: {} ({}) imports `crate::{target}` ({})",
                        file.strip_prefix(src()).unwrap().display(),
                        n + 1,
                        module,
                        LAYERS[own].0,
                        LAYERS[to].0
                    ));
                }
            }
        }
    }
    assert!(
        checked > 100,
        "only {checked} crate paths found: is the scan broken?"
    );
    assert!(
        upward.is_empty(),
        "imports that climb a layer:\n{}",
        upward.join("\n")
    );
}

/// The mechanics are built from their own types (issue 33): inside `mechanics/`, only the
/// adapter `mechanics/from_scene/` names the scene format; the elements, the systems, their
/// joints and laws take the mechanics' own `JointKind`, `DriveKind`, `TimeLaw`, `Section`.
#[test]
fn the_mechanics_read_the_scene_format_only_through_from_scene() {
    let mechanics = src().join("mechanics");
    let adapter = mechanics.join("from_scene");
    let mut files = Vec::new();
    rust_files(&mechanics, &mut files);
    files.sort();
    assert!(files.len() > 30, "only {} files in mechanics/", files.len());
    let mut readers = Vec::new();
    for file in files.iter().filter(|f| !f.starts_with(&adapter)) {
        let text = std::fs::read_to_string(file).expect("readable");
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if crate_paths(code).iter().any(|m| m == "scene") {
                readers.push(format!(
                    "{}:{}: {}",
                    file.strip_prefix(src()).unwrap().display(),
                    n + 1,
                    line.trim()
                ));
            }
        }
    }
    assert!(
        readers.is_empty(),
        "mechanics files that read the scene format (go through mechanics/from_scene/):\n{}",
        readers.join("\n")
    );
}

#[test]
fn the_scan_sees_paths_groups_and_skips_other_crates() {
    assert_eq!(crate_paths("use crate::unit::engine::Engine;"), ["unit"]);
    assert_eq!(
        crate_paths("use crate::{scene::Scene, mechanics};"),
        ["scene", "mechanics"]
    );
    assert_eq!(
        crate_paths("x = my_crate::unit::f() + crate::scene::g()"),
        ["scene"]
    );
    assert_eq!(
        crate_paths("use crate::mechanics::beam::section::Section;"),
        ["mechanics/beam"]
    );
    assert!(layer_of("unit") > layer_of("integrator"));
    assert!(layer_of("mechanics/beam") < layer_of("scene"));
}

/// Files a person can hold (issue 33): a source file of the workspace longer than
/// [`LONG_FILE`] lines says why in its first doc comment (a line with "Over 600 lines").
const LONG_FILE: usize = 650;

#[test]
fn every_long_file_says_why_in_its_first_comment() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for krate in ["fmu-beam/src", "fmu-harness/src", "bench/src"] {
        rust_files(&root.join(krate), &mut files);
    }
    assert!(files.len() > 100, "only {} files found", files.len());
    let silent: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let text = std::fs::read_to_string(f).expect("readable");
            let lines = text.lines().count();
            let says = text
                .lines()
                .take_while(|l| l.starts_with("//!") || l.trim().is_empty())
                .any(|l| l.contains("Over 600 lines"));
            (lines > LONG_FILE && !says).then(|| format!("{} ({lines} lines)", f.display()))
        })
        .collect();
    assert!(
        silent.is_empty(),
        "long files that do not say why:\n{}",
        silent.join("\n")
    );
}
