//! The effective inertia a force or torque input acts on (`unit::input_inertia`) against
//! closed forms: a rigid body on a revolute joint, I + m d² about the joint, in the plane and in
//! 3D; a bare beam root (scenes/flexible_arm.toml), held rigid ρAL³/3 (34.47 kg m²) and free
//! below the first element's own ρAL_e³/105; a force input on a load of a rigid body, its mass;
//! a co-simulation cut measured but not warned about.

use crate::integrator::{initial_state, Settings};
use crate::mechanics::Mechanics;
use crate::scene::Scene;
use crate::unit::effects::resolve;
use crate::unit::input_inertia::{input_inertias, InputInertia, SMALL_SHARE};
use crate::unit::variables::VariableTable;

fn inertias(scene: &Scene) -> Vec<InputInertia> {
    let effects = resolve(scene).effects;
    let sys = Mechanics::build(scene, &effects);
    let st = initial_state(&sys, 0.0, &Settings::from_scene(scene)).unwrap();
    input_inertias(&sys, &st, &VariableTable::build_with(scene, &effects))
}

/// A beam welded to the world, apart: a scene needs one.
const POST: &str = r#"
[[beam]]
name = "post"
length = 1.0
elements = 1
material = { rho = 2700.0, E = 7e10, G = 2.6e10 }
section = { shape = "rectangle", a = 0.02, b = 0.02 }
[[joint]]
name = "clamp"
type = "weld"
frames = ["world", "post.a"]
"#;

fn pendulum(dimensions: &str, com: &str, load: &str) -> Scene {
    let text = format!(
        r#"
name = "p"
{dimensions}
{post}
[[body]]
name = "bob"
mass = 2.0
inertia = {inertia}
com = {com}
[[joint]]
name = "pivot"
type = "revolute"
frames = ["world", "bob.origin"]
{axis}
drive = {{ kind = "effort", law = "input", value = 0.0 }}
{load}
"#,
        inertia = if dimensions.is_empty() {
            "0.3"
        } else {
            "[0.3, 0.3, 0.3]"
        },
        axis = if dimensions.is_empty() {
            ""
        } else {
            "axis = [0.0, 0.0, 1.0]"
        },
        post = POST,
    );
    Scene::from_toml_str(&text, "pendulum.toml").unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_rigid_body_on_a_revolute_joint_is_its_inertia_about_the_joint() {
    // I + m d² = 0.3 + 2 × 0.5² = 0.8 kg m², planar and 3D, with and without the beam locking
    for (dims, com) in [("", "[0.5, 0.0]"), ("dimensions = 3", "[0.5, 0.0, 0.0]")] {
        let found = inertias(&pendulum(dims, com, ""));
        let [i] = found.as_slice() else {
            panic!("{found:?}")
        };
        assert_eq!(i.name, "pivot.drive.torque");
        assert!(i.torque);
        assert!((i.effective - 0.8).abs() < 1e-12, "{dims}: {}", i.effective);
        assert!((i.rigid - 0.8).abs() < 1e-12, "{dims}: {}", i.rigid);
        assert!(!i.is_small());
    }
}

#[test]
fn a_force_on_a_body_sliding_freely_acts_on_its_mass() {
    // a force input along x at the body's origin; the pivot holds the origin: no motion, no
    // entry. A free body (no joint) under an input force fx: its mass, 2 kg.
    let text = r#"
name = "p"
[[beam]]
name = "post"
length = 1.0
elements = 1
material = { rho = 2700.0, E = 7e10, G = 2.6e10 }
section = { shape = "rectangle", a = 0.02, b = 0.02 }
[[joint]]
name = "clamp"
type = "weld"
frames = ["world", "post.a"]
[[body]]
name = "puck"
mass = 2.0
inertia = 0.3
[[load]]
name = "push"
frame = "puck.origin"
input = true
"#;
    let scene = Scene::from_toml_str(text, "puck.toml").unwrap_or_else(|e| panic!("{e}"));
    let found = inertias(&scene);
    let fx = found
        .iter()
        .find(|i| i.name == "push.fx")
        .expect("fx measured");
    assert!(!fx.torque && !fx.drive);
    assert!((fx.effective - 2.0).abs() < 1e-12, "{}", fx.effective);
    let tz = found
        .iter()
        .find(|i| i.name == "push.torque")
        .expect("torque measured");
    assert!((tz.effective - 0.3).abs() < 1e-12, "{}", tz.effective);
}

#[test]
fn a_bare_beam_root_acts_on_a_tiny_share_of_the_beam() {
    let scene = crate::tests::common::scene("flexible_arm.toml");
    let found = inertias(&scene);
    let [i] = found.as_slice() else {
        panic!("{found:?}")
    };
    let b = &scene.beams[0];
    let mu = b.material.rho * 7.299e-5;
    // held rigid: a rod about its end, ρAL³/3 = 34.47 kg m²
    let rod = mu * b.length.powi(3) / 3.0;
    assert!(
        (i.rigid / rod - 1.0).abs() < 1e-9,
        "{} against {rod}",
        i.rigid
    );
    // free: below the first element's own rotary term ρAL_e³/105 = 7.9e-3 kg m² (the Schur
    // complement over the beam's other coordinates), above half of it
    let element = mu * (b.length / 5.0).powi(3) / 105.0;
    println!(
        "bare root: J_eff = {:.4e} kg m², element {element:.4e}",
        i.effective
    );
    assert!(i.effective < element && i.effective > 0.2 * element);
    assert!(i.is_small() && i.share() < 3e-4, "{}", i.share());
}

#[test]
fn the_arm_on_its_5_kg_m2_rotor_is_not_small() {
    let found = inertias(&crate::tests::common::scene("flexible_arm_hub.toml"));
    let [i] = found.as_slice() else {
        panic!("{found:?}")
    };
    // the rotor's 5 kg m² and a little of the beam: the same 34.47 + 5 held rigid
    assert!(i.effective > 5.0 && i.effective < 5.1, "{}", i.effective);
    assert!((i.rigid - 39.47).abs() < 0.01, "{}", i.rigid);
    assert!(!i.is_small());
}

#[test]
fn a_co_simulation_cut_is_measured_but_not_small() {
    // the split slider-crank's crank unit takes the rod's pin force and torque at its tip: a
    // beam's end by design (the master couples it implicitly), not an actuator; held rigid, the
    // crank pinned to the world cannot move its tip along x: no finite rigid value
    let found = inertias(&crate::tests::common::scene(
        "slider_crank_split_crank.toml",
    ));
    let fx = found
        .iter()
        .find(|i| i.name == "pin.fx")
        .expect("fx measured");
    let torque = found
        .iter()
        .find(|i| i.name == "pin.torque")
        .expect("torque measured");
    assert!(fx.rigid.is_nan(), "{}", fx.rigid);
    assert!(torque.share() < SMALL_SHARE, "{}", torque.share());
    assert!(found.iter().all(|i| !i.drive && !i.is_small()), "{found:?}");
}
