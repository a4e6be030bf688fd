//! `fmu-harness explain`: the accuracy the scene was tuned for, each resolved effect with its
//! setting, reason and cost share; the same text is the FMU's documentation; a wrong `effects`
//! or an accuracy statement for no output is refused naming the field.

use crate::common;
use common::*;

#[test]
fn explain_prints_every_effect_with_its_reason() {
    let scene = c1_path().with_file_name("spin_up_omega4_auto.toml");
    let r = harness(&["explain".as_ref(), scene.as_os_str()]);
    let text = String::from_utf8_lossy(&r.stdout);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(text.contains("(effects = auto)"), "{text}");
    // C4 under auto: no gravity, rotating substructures spun above their first bending
    // frequency: geometric stiffening, which needs the axial strain
    for (line_start, words) in [
        ("gravity (scene)", &["off", "no gravity field"][..]),
        (
            "geometric_stiffening (beam)",
            &["on", "first bending frequency"],
        ),
        ("axial (beam)", &["on", "geometric stiffening needs"]),
        ("quadratic_velocity (beam)", &["on", "rotates"]),
        (
            "flexibility (beam)",
            &["5 x 1 elements", "first bending frequency"],
        ),
    ] {
        let line = text
            .lines()
            .find(|l| l.starts_with(line_start))
            .unwrap_or_else(|| panic!("no line {line_start:?} in\n{text}"));
        for w in words {
            assert!(line.contains(w), "{w:?} not in {line:?}");
        }
    }
    // one row per effect, each with a cost share in percent
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| {
            fmu_beam::EFFECTS
                .iter()
                .any(|(e, _)| l.starts_with(&format!("{e} (")))
        })
        .collect();
    assert_eq!(rows.len(), 6, "{text}");
    assert!(rows.iter().all(|l| l.contains('%')), "{text}");
}

/// Every shipped scene with an `[accuracy]` table (issue 46 item 2: 17 of them) is stated
/// first by `explain`: its output, its target and the study's estimate.
#[test]
fn explain_states_every_shipped_scene_s_accuracy_first() {
    let dir = c1_path().parent().expect("scenes/").to_path_buf();
    let mut stated = 0;
    for entry in std::fs::read_dir(&dir).expect("scenes/") {
        let path = entry.expect("an entry").path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let scene = fmu_beam::Scene::load(&path).expect("a valid scene");
        let Some(acc) = scene.accuracy else { continue };
        let r = harness(&["explain".as_ref(), path.as_os_str()]);
        let text = String::from_utf8_lossy(&r.stdout);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let first = text.lines().next().unwrap_or_default();
        let estimate = format!("{:.1e}", acc.estimate.expect("an estimate"));
        assert!(
            first.starts_with("Accuracy:")
                && first.contains(&acc.output)
                && first.contains(&format!("at most {:e}", acc.target))
                && first.contains(&estimate),
            "{path:?}: {first}"
        );
        stated += 1;
    }
    assert_eq!(stated, 17, "the shipped scenes with an [accuracy] table");
}

#[test]
fn a_wrong_effects_entry_is_refused_naming_the_field() {
    let dir = scratch("explain_refused");
    let scene = dir.join("warp.toml");
    std::fs::write(
        &scene,
        format!("effects = [\"gravity\", \"warp\"]\n{}", c1_text()),
    )
    .unwrap();
    let r = harness(&["explain".as_ref(), scene.as_os_str()]);
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("effects[1]") && stderr.contains("is not an effect"),
        "{stderr}"
    );
}

/// C1 with its own `[accuracy]` statement for `output` replaced by one for `output`.
fn with_accuracy(dir: &std::path::Path, output: &str) -> std::path::PathBuf {
    let scene = dir.join("tuned.toml");
    let text = c1_text();
    let (head, rest) = text
        .split_once("[accuracy]\n")
        .expect("C1 states its accuracy");
    let (_, tail) = rest
        .split_once("\n\n")
        .expect("a blank line after the table");
    std::fs::write(
        &scene,
        format!(
            "{head}{tail}\n[accuracy]\noutput = \"{output}\"\ntarget = 1e-3\nestimate = 4e-4\n"
        ),
    )
    .unwrap();
    scene
}

#[test]
fn explain_states_the_accuracy_the_scene_was_tuned_for_and_the_fmu_carries_it() {
    let dir = scratch("explain_accuracy");
    let scene = with_accuracy(&dir, "beam.tip.deflection");
    let r = harness(&["explain".as_ref(), scene.as_os_str()]);
    let text = String::from_utf8_lossy(&r.stdout);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let first = text.lines().next().unwrap_or_default();
    for w in [
        "Accuracy:",
        "beam.tip.deflection",
        "relative to its largest magnitude",
        "at most 1e-3",
        "estimate for these settings: 4.0e-4",
    ] {
        assert!(first.contains(w), "{w:?} not in {first:?}");
    }
    let fmu = dir.join("tuned.fmu");
    let r = package(&scene, &fmu, &fake_engine(&dir, b"engine"));
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let doc = read_entry(&fmu, "documentation/index.html");
    assert!(
        doc.contains("<p>Accuracy: these settings were tuned"),
        "{doc}"
    );
}

#[test]
fn an_accuracy_statement_for_no_output_of_the_unit_is_refused() {
    let dir = scratch("explain_accuracy_refused");
    // `beam` is a part of the scene, `tip.spin` no output of it
    let scene = with_accuracy(&dir, "beam.tip.spin");
    for command in ["explain", "package"] {
        let fmu = dir.join("tuned.fmu");
        let r = if command == "explain" {
            harness(&[command.as_ref(), scene.as_os_str()])
        } else {
            package(&scene, &fmu, &fake_engine(&dir, b"engine"))
        };
        let stderr = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{command}: {stderr}");
        assert!(
            stderr.contains("accuracy.output = \"beam.tip.spin\" is not a Real output")
                && stderr.contains("beam.tip.deflection"),
            "{command}: {stderr}"
        );
        assert!(!fmu.exists(), "{command}: an FMU was written");
    }
}
