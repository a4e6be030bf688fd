//! Assembly said out loud (issue 32): joint frames that do not meet at t = 0 are refused, the
//! message naming the joint by its name, the frames and the gap; with `assemble = true` the
//! unit moves the parts together and logs which part it moved and by how much. Messages name
//! the scene's parts by the names the user gave them.

use crate::common;

use fmu_beam::scene::SceneError;
use fmu_beam::{Engine, Scene};

/// A planar two-link arm: `upper` from the origin along x, `lower` from `lower_at`, an elbow
/// between them; `extra` goes into the elbow joint's table.
fn arm(lower_at: &str, extra: &str) -> String {
    format!(
        r#"
name = "arm"
[world]
gravity = [0.0, -9.81]
[[beam]]
name = "upper"
length = 0.5
elements = 2
material = {{ rho = 2700.0, E = 7e10 }}
section = {{ shape = "rectangle", a = 0.02, b = 0.01 }}
[[beam]]
name = "lower"
length = 0.4
elements = 2
position = {lower_at}
material = {{ rho = 2700.0, E = 7e10 }}
section = {{ shape = "rectangle", a = 0.02, b = 0.01 }}
[[joint]]
name = "shoulder"
type = "revolute"
frames = ["world", "upper.a"]
[[joint]]
name = "elbow"
type = "revolute"
frames = ["upper.b", "lower.a"]
{extra}
"#
    )
}

fn refusal(text: &str) -> (String, String, &'static str) {
    match Scene::from_toml_str(text, "arm.toml") {
        Err(SceneError::Invalid {
            field, rule, code, ..
        }) => (field, rule, code),
        other => panic!("not refused by a rule: {other:?}"),
    }
}

#[test]
fn an_elbow_gap_is_refused_naming_the_joint_the_frames_and_the_gap() {
    let (field, rule, code) = refusal(&arm("[0.6, 0.0]", ""));
    assert_eq!(code, "joint_gap");
    assert_eq!(field, "joint \"elbow\".frames");
    assert!(
        rule.contains("\"upper.b\" is at [0.5, 0, 0] m")
            && rule.contains("\"lower.a\" at [0.6, 0, 0] m")
            && rule.contains("0.1 m apart")
            && rule.contains("assemble = true"),
        "{rule}"
    );
    // within the tolerance (1e-6 of the longest beam, 0.5 m): accepted
    Scene::from_toml_str(&arm("[0.5000004, 0.0]", ""), "arm.toml").unwrap();
    let (_, rule, code) = refusal(&arm("[0.5000006, 0.0]", ""));
    assert_eq!(code, "joint_gap");
    assert!(
        rule.contains("6e-7 m apart") && rule.contains("5e-7 m allowed"),
        "{rule}"
    );
}

#[test]
fn a_beam_placed_off_its_world_pin_is_refused() {
    let text = arm("[0.5, 0.0]", "").replace(
        "name = \"upper\"\nlength = 0.5",
        "name = \"upper\"\nposition = [0.3, 0.0]\nlength = 0.5",
    );
    let (field, rule, code) = refusal(&text);
    assert_eq!(
        (field.as_str(), code),
        ("joint \"shoulder\".frames", "joint_gap")
    );
    assert!(rule.contains("0.3 m apart"), "{rule}");
}

#[test]
fn a_prismatic_joint_needs_its_frames_on_the_sliding_axis_only() {
    let slider = |at: &str| {
        format!(
            r#"{}
[[body]]
name = "slider"
mass = 1.0
inertia = 0.01
position = {at}
[[joint]]
name = "rail"
type = "prismatic"
frames = ["world", "slider.origin"]
axis_angle = 0.5
"#,
            arm("[0.5, 0.0]", "")
        )
    };
    // 2 m along the axis at 0.5 rad: a slide the joint allows
    let along = format!("[{}, {}]", 2.0 * 0.5f64.cos(), 2.0 * 0.5f64.sin());
    Scene::from_toml_str(&slider(&along), "arm.toml").unwrap();
    let (field, rule, code) = refusal(&slider("[2.0, 0.0]"));
    assert_eq!(
        (field.as_str(), code),
        ("joint \"rail\".frames", "joint_gap")
    );
    // 2 m along x is 2 sin(0.5) = 0.958851 m off the axis
    assert!(
        rule.contains("0.958851 m apart across the sliding axis"),
        "{rule}"
    );
}

#[test]
fn assemble_true_moves_the_lower_link_and_says_by_how_much() {
    let text = arm("[0.6, 0.0]", "assemble = true");
    let scene = Scene::from_toml_str(&text, "arm.toml").unwrap();
    // the key survives packaging (the canonical text), and is left out where it is false
    let packaged = scene.to_toml_string();
    assert_eq!(packaged.matches("assemble = true").count(), 1, "{packaged}");
    let mut e = Engine::new(scene);
    e.exit_initialization().unwrap();
    let log = e.take_messages();
    assert_eq!(log.len(), 1, "{log:?}");
    let m = &log[0];
    assert!(
        m.contains("joint \"elbow\" (\"upper.b\" and \"lower.a\") 0.1 m apart")
            && m.contains("beam \"lower\" by 0.1 m, turned by 0 rad")
            && !m.contains("beam \"upper\""),
        "{m}"
    );
    // where it went: the lower tip at x = 0.5 + 0.4, not 0.6 + 0.4
    let tip = common::vr(&e, "lower.tip.x");
    let x = e.get_real(tip).unwrap();
    assert!((x - 0.9).abs() < 1e-9, "lower tip at x = {x}");
    // said once: a run goes on without repeating it
    e.do_step(0.0, 1e-3).unwrap();
    assert!(e.take_messages().is_empty());
}

#[test]
fn a_3d_gap_is_refused_and_assembled_on_request() {
    let text = |extra: &str| {
        format!(
            r#"
name = "arm3"
dimensions = 3
[[beam]]
name = "upper"
length = 0.5
elements = 2
material = {{ rho = 2700.0, E = 7e10, G = 2.6e10 }}
section = {{ shape = "rectangle", a = 0.02, b = 0.01 }}
[[body]]
name = "hand"
mass = 1.0
inertia = [0.01, 0.01, 0.01]
position = [0.5, 0.0, 0.1]
[[joint]]
name = "root"
type = "weld"
frames = ["world", "upper.a"]
[[joint]]
name = "wrist"
type = "spherical"
frames = ["upper.b", "hand.origin"]
{extra}
"#
        )
    };
    let (field, rule, code) = refusal(&text(""));
    assert_eq!(
        (field.as_str(), code),
        ("joint \"wrist\".frames", "joint_gap")
    );
    assert!(
        rule.contains("\"hand.origin\" at [0.5, 0, 0.1] m, 0.1 m apart"),
        "{rule}"
    );
    let mut e = Engine::new(Scene::from_toml_str(&text("assemble = true"), "arm3").unwrap());
    e.exit_initialization().unwrap();
    let log = e.take_messages();
    assert!(
        log.iter()
            .any(|m| m.contains("body \"hand\" by 0.1 m") && !m.contains("beam \"upper\" by")),
        "{log:?}"
    );
}

#[test]
fn a_weld_holds_the_relative_angle_it_is_placed_with() {
    // a body turned by 0.3 rad welded to the beam's tip: no mismatch, nothing moves
    let text = format!(
        r#"{}
[[body]]
name = "tool"
mass = 0.5
inertia = 0.001
position = [0.9, 0.0]
angle = 0.3
[[joint]]
name = "grip"
type = "weld"
frames = ["lower.b", "tool.origin"]
assemble = true
"#,
        arm("[0.5, 0.0]", "")
    );
    let mut e = Engine::new(Scene::from_toml_str(&text, "arm.toml").unwrap());
    e.exit_initialization().unwrap();
    let log = e.take_messages();
    assert!(
        log.len() == 1 && log[0].contains("0 m apart") && log[0].contains("moved no part"),
        "{log:?}"
    );
}

#[test]
fn messages_name_parts_by_their_names_or_by_index_when_the_name_cannot() {
    let (field, _, code) = refusal(&arm("[0.5, 0.0]", "").replace("length = 0.4", "length = -0.4"));
    assert_eq!(
        (field.as_str(), code),
        ("beam \"lower\".length", "positive")
    );
    // a name that is not an identifier is named by its index
    let (field, _, code) =
        refusal(&arm("[0.5, 0.0]", "").replace("name = \"elbow\"", "name = \"el bow\""));
    assert_eq!((field.as_str(), code), ("joint[1].name", "part_name"));
    let (field, _, _) = refusal(&arm("[0.5, 0.0]", "").replace(
        "frames = [\"upper.b\", \"lower.a\"]",
        "frames = [\"upper.b\", \"lower.c\"]",
    ));
    assert_eq!(field, "joint \"elbow\".frames[1]");
}

#[test]
fn a_planar_vector_in_a_3d_scene_is_refused_and_a_spatial_one_in_a_planar_scene() {
    let spatial = |position: &str| {
        format!(
            r#"
name = "s"
dimensions = 3
[[beam]]
name = "blade"
length = 2.0
elements = 2
position = {position}
material = {{ rho = 2700.0, E = 7e10, G = 2.6e10 }}
section = {{ shape = "rectangle", a = 0.02, b = 0.01 }}
"#
        )
    };
    Scene::from_toml_str(&spatial("[0.0, 0.0, 0.0]"), "s.toml").unwrap();
    let (field, rule, code) = refusal(&spatial("[0.0, 0.0]"));
    assert_eq!(
        (field.as_str(), code),
        ("beam \"blade\".position", "spatial_vector")
    );
    assert!(rule.contains("3 components"), "{rule}");
    // a planar scene takes [x, y, 0] (the packaged form) but no z
    Scene::from_toml_str(&arm("[0.5, 0.0, 0.0]", ""), "arm.toml").unwrap();
    let (field, _, code) = refusal(&arm("[0.5, 0.0, 0.1]", ""));
    assert_eq!(
        (field.as_str(), code),
        ("beam \"lower\".position[2]", "in_plane")
    );
}

/// A motion drive whose law starts away from the joint's placed coordinate turns the parts to
/// meet it at initialization: said once, naming the parts, their turns and the drive's joint; a
/// law that starts where the joint is placed moves nothing and says nothing.
#[test]
fn a_motion_drive_that_starts_elsewhere_says_what_it_moved() {
    let driven = |start: f64| {
        arm(
            "[0.5, 0.0]",
            &format!(
                r#"drive = {{ kind = "motion", law = "table", table = [[0.0, {start}], [1.0, 0.6]] }}"#
            ),
        )
    };
    let mut e = Engine::new(Scene::from_toml_str(&driven(0.5), "arm.toml").unwrap());
    e.exit_initialization().unwrap();
    let log = e.take_messages();
    assert_eq!(log.len(), 1, "{log:?}");
    let m = &log[0];
    // the free shoulder shares the 0.5 rad with the elbow (a least-squares assembly): measured
    // upper turned 0.2218 rad, lower 0.2782 rad
    assert!(
        m.starts_with("initialization moved beam \"upper\"")
            && m.contains("beam \"lower\" by 0.11")
            && m.contains("motion drives of joint \"elbow\""),
        "{m}"
    );
    e.do_step(0.0, 1e-3).unwrap();
    assert!(e.take_messages().is_empty());
    let mut e = Engine::new(Scene::from_toml_str(&driven(0.0), "arm.toml").unwrap());
    e.exit_initialization().unwrap();
    assert!(e.take_messages().is_empty());
}
