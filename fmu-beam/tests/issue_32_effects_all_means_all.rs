//! Issue 32, item 5: `effects = "all"` means every effect, geometric stiffening included (it
//! used to leave stiffening off where `auto` turned it on); the default is named for what it
//! is, `"scene"` (every term, stiffening where a beam asks for it); and `explain` lists, for
//! every flexible beam, each effect exactly once with the setting the unit is built with.

use fmu_beam::{resolve_effects, Scene};

/// Two flexible beams pinned in a chain under gravity, `plain` not asking for stiffening and
/// `stiff` asking; `effects` the scene's line (empty: the default); a 3D variant out of plane.
fn arm(effects: &str, dims: usize) -> Scene {
    let (head, gravity, section, axis) = if dims == 2 {
        (
            "",
            "[0.0, -9.81]",
            "{ shape = \"rectangle\", a = 0.01, b = 0.02 }",
            "",
        )
    } else {
        (
            "dimensions = 3\n",
            "[0.0, 0.0, -9.81]",
            "{ A = 2e-4, Iy = 1.7e-9, Iz = 6.7e-9, It = 5e-10 }",
            "axis = [0.0, 1.0, 0.0]",
        )
    };
    let stiff = if dims == 2 {
        "geometric_stiffening = true"
    } else {
        ""
    };
    let text = format!(
        r#"name = "arm"
{head}{effects}
[world]
gravity = {gravity}

[[beam]]
name = "plain"
length = 1.0
elements = 4
material = {{ rho = 2700.0, E = 70e9, G = 26e9 }}
section = {section}
rayleigh = {{ alpha = 1.0 }}

[[beam]]
name = "stiff"
length = 1.0
elements = 4
position = [1.0, 0.0{z}]
material = {{ rho = 2700.0, E = 70e9, G = 26e9 }}
section = {section}
{stiff}

[[joint]]
name = "shoulder"
type = "revolute"
frames = ["world", "plain.a"]
{axis}

[[joint]]
name = "elbow"
type = "revolute"
frames = ["plain.b", "stiff.a"]
{axis}
"#,
        z = if dims == 2 { "" } else { ", 0.0" }
    );
    Scene::from_toml_str(&text, "arm").expect("a valid scene")
}

const BEAM_EFFECTS: [&str; 5] = [
    "flexibility",
    "axial",
    "quadratic_velocity",
    "geometric_stiffening",
    "rayleigh_damping",
];

/// The setting `explain` gives `effect` of `beam`: exactly one line for it.
fn setting(scene: &Scene, effect: &str, beam: &str) -> String {
    let r = resolve_effects(scene);
    let found: Vec<_> = r
        .decisions
        .iter()
        .filter(|d| d.effect == effect && d.subject == beam)
        .collect();
    assert_eq!(found.len(), 1, "{effect} of {beam}: {found:?}");
    let text = r.explain(scene);
    let line = format!("{effect} ({beam})");
    assert!(text.contains(&line), "explain lists {line}:\n{text}");
    found[0].setting.clone()
}

#[test]
fn all_turns_geometric_stiffening_on_for_every_flexible_beam() {
    let r = resolve_effects(&arm("effects = \"all\"\n", 2));
    assert_eq!(r.mode, "all");
    for b in &r.effects.beams {
        let o = b.options;
        assert!(!b.rigid && o.axial && o.quadratic_velocity && o.damping);
        assert!(o.geometric_stiffening, "all means all: stiffening on");
    }
    let s = arm("effects = \"all\"\n", 2);
    for beam in ["plain", "stiff"] {
        for effect in BEAM_EFFECTS {
            let want = if effect == "flexibility" {
                "4 elements"
            } else {
                "on"
            };
            assert_eq!(setting(&s, effect, beam), want, "{effect} of {beam}");
        }
    }
}

#[test]
fn the_default_is_the_scene_as_written() {
    for line in ["", "effects = \"scene\"\n"] {
        let s = arm(line, 2);
        let r = resolve_effects(&s);
        assert_eq!(r.mode, "scene");
        let stiff: Vec<bool> = r
            .effects
            .beams
            .iter()
            .map(|b| b.options.geometric_stiffening)
            .collect();
        assert_eq!(
            stiff,
            [false, true],
            "stiffening where the beam asks for it"
        );
        assert_eq!(setting(&s, "geometric_stiffening", "plain"), "off");
        assert_eq!(setting(&s, "geometric_stiffening", "stiff"), "on");
        assert!(r.explain(&s).contains("effects = scene"));
    }
}

#[test]
fn explain_lists_every_effect_of_a_3d_beam() {
    for line in ["", "effects = \"all\"\n"] {
        let s = arm(line, 3);
        let r = resolve_effects(&s);
        assert!(r
            .decisions
            .iter()
            .any(|d| d.effect == "formulation" && d.setting == "spatial"));
        for beam in ["plain", "stiff"] {
            let got: Vec<String> = BEAM_EFFECTS.iter().map(|e| setting(&s, e, beam)).collect();
            // the 3D element has geometric stiffening too: "all" turns it on
            let stiff = if line.is_empty() { "off" } else { "on" };
            assert_eq!(got, ["on", "on", "on", stiff, "on"], "{beam}");
        }
    }
}
