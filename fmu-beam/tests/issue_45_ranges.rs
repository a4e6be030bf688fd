//! Issue 45, items 6 and 8: ranges with a physical reason, numbers in messages in short form,
//! and text that XML 1.0 cannot hold refused by the scene's rules (so the command line, Python
//! and the unit refuse it alike). Each scene below was accepted before; each message printed
//! 1e300 as a number of 301 digits (cut to 80 characters).

use crate::common;
use common::{scene, vr};
use fmu_beam::{Engine, Scene, SceneError};

/// The refusal of the pendulum scene changed by `change`, read back from its text.
fn refusal(change: impl FnOnce(&mut Scene)) -> (String, &'static str, String) {
    let mut s = scene("flexible_pendulum.toml");
    change(&mut s);
    match Scene::from_toml_str(&s.to_toml_string(), "changed") {
        Err(SceneError::Invalid {
            field, code, value, ..
        }) => (field, code, value),
        other => panic!("not refused by a rule: {other:?}"),
    }
}

/// A change of a scene.
type Change = Box<dyn FnOnce(&mut Scene)>;

#[test]
fn ranges_with_a_physical_reason() {
    let cases: [(&str, Change, &str); 7] = [
        (
            "tolerance_floor",
            Box::new(|s| s.solver.tolerance = 5e-324),
            "5e-324",
        ),
        (
            "area_range",
            Box::new(|s| s.beams[0].section.area = Some(1.0001e16)),
            "1.0001e16",
        ),
        (
            "second_moment_range",
            Box::new(|s| s.beams[0].section.second_moment = Some(1.0001e16)),
            "1.0001e16",
        ),
        (
            "rayleigh_alpha_range",
            Box::new(|s| s.beams[0].rayleigh.alpha = 1e300),
            "1e300",
        ),
        (
            "rayleigh_beta_range",
            Box::new(|s| s.beams[0].rayleigh.beta = 1e300),
            "1e300",
        ),
        (
            "density_floor",
            Box::new(|s| s.beams[0].material.rho = 1e-300),
            "1e-300",
        ),
        (
            "density_range",
            Box::new(|s| s.beams[0].material.rho = 1e300),
            "1e300",
        ),
    ];
    for (code, change, value) in cases {
        let (field, got, shown) = refusal(change);
        assert_eq!(got, code, "{field}");
        assert_eq!(shown, value, "{code}: the value in short form");
    }
}

/// The ranges with the least bound (1e4: gravity and lengths) refuse a number just past it and
/// take the bound itself: validation looks a field's range up only for numbers past the least
/// bound of all ranges, and the edge of that shortcut is the edge of these rules.
#[test]
fn the_least_bound_is_kept_at_its_edge() {
    let (field, code, _) = refusal(|s| s.world.gravity[1] = -1.0001e4);
    assert_eq!(
        (field.as_str(), code),
        ("world.gravity[1]", "gravity_range")
    );
    let (field, code, _) = refusal(|s| s.beams[0].length = 1.0001e4);
    assert_eq!(
        (field.as_str(), code),
        ("beam \"beam\".length", "length_range")
    );
    let mut s = scene("flexible_pendulum.toml");
    s.world.gravity[1] = -1e4;
    Scene::from_toml_str(&s.to_toml_string(), "at the bound")
        .expect("the bound itself is in range");
}

/// The same rules refuse the values set on an instance, in short form too.
#[test]
fn values_set_on_an_instance_are_refused_in_short_form() {
    let mut e = Engine::new(scene("flexible_pendulum.toml"));
    for (name, value, shown) in [
        ("solver.tolerance", 5e-324, "5e-324"),
        ("beam.rho", 1e-300, "1e-300"),
        ("beam.rho", 1e300, "1e300"),
    ] {
        let text = e.set_real(vr(&e, name), value).unwrap_err().to_string();
        assert!(text.contains(&format!("value {shown} ")), "{text}");
        assert!(text.len() < 600, "{text}");
    }
    e.exit_initialization().unwrap();
    e.do_step(0.0, 0.01).unwrap();
}

/// U+FFFE, U+FFFF and control characters (but tab, LF, CR) are refused in the description,
/// naming the field and the character; a tab, an accent and a character past the BMP are not.
#[test]
fn a_description_xml_cannot_hold_is_refused() {
    for bad in ['\u{FFFE}', '\u{FFFF}', '\u{7}', '\u{1B}'] {
        let (field, code, value) = refusal(|s| s.description = format!("a {bad} b"));
        assert_eq!((field.as_str(), code), ("description", "xml_text"));
        assert!(
            value.contains(&format!("U+{:04X} at character 3", bad as u32)),
            "{value}"
        );
    }
    let mut s = scene("flexible_pendulum.toml");
    s.description = "tab\there, line\nbreak, é, \u{10FFFF}".into();
    Scene::from_toml_str(&s.to_toml_string(), "fine").expect("XML 1.0 holds these");
}
