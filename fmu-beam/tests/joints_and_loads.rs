//! Loads, Rayleigh damping and the refusal of mechanisms that cannot be built: checks against
//! closed forms, and the messages that name the joints.

use crate::common;
use common::run;
use fmu_beam::{Engine, EngineError, Scene};

fn cantilever(extra: &str, joints: &str) -> Scene {
    cantilever_in("tangent", "alpha = 40.0", extra, joints)
}

fn cantilever_in(frame: &str, damping: &str, extra: &str, joints: &str) -> Scene {
    let text = format!(
        r#"
name = "loaded"
[solver]
tolerance = 1e-8
max_step = 1e-2
[[beam]]
name = "beam"
length = 1.0
elements = 4
frame = "{frame}"
material = {{ rho = 7800.0, E = 210e9 }}
section = {{ shape = "rectangle", a = 0.02, b = 0.01 }}
rayleigh = {{ {damping} }}
{joints}
{extra}
"#
    );
    Scene::from_toml_str(&text, "loaded.toml").unwrap()
}

const CLAMP: &str = r#"
[[joint]]
name = "clamp"
type = "weld"
frames = ["world", "beam.a"]
"#;

/// Tip deflection and rotation of a damped cantilever scene, settled.
fn settled(scene: Scene) -> (f64, f64) {
    let outs = ["beam.tip.deflection", "beam.tip.phi"];
    let r = run(scene, &[], &outs, 0.05, 3.0);
    (r.last(1), r.last(2))
}

/// Tip deflection and rotation of the damped cantilever settled under `load`.
fn settled_tip(load: &str) -> (f64, f64) {
    settled(cantilever(load, CLAMP))
}

/// Small-deflection FE of the linear element: exact at the nodes, up to the axial shortening
/// the floating frame neglects and the remaining decay of the damped vibration.
fn assert_close(what: &str, got: f64, want: f64) {
    println!("{what}: {got:.6e} (closed form {want:.6e})");
    assert!((got - want).abs() < 1e-4 * want.abs(), "{what}");
}

/// A transverse tip force F on the cantilever that `scene` builds around a load: deflection
/// F L³ / (3 E J), rotation F L² / (2 E J).
fn assert_tip_force_response(frame: &str, scene: impl Fn(&str) -> Scene) {
    let f = 50.0;
    let (d, phi) = settled(scene(&format!(
        "[[load]]\nname = \"push\"\nframe = \"beam.b\"\nforce = [0.0, {f}]\n"
    )));
    let ej = 210e9 * 0.01 * 0.02f64.powi(3) / 12.0;
    assert_close(
        &format!("tip deflection under F, {frame} frame (m)"),
        d,
        f / (3.0 * ej),
    );
    assert_close(
        &format!("tip rotation under F, {frame} frame (rad)"),
        phi,
        f / (2.0 * ej),
    );
}

#[test]
fn tip_force_settles_at_the_static_deflection() {
    assert_tip_force_response("tangent", |load| cantilever(load, CLAMP));
}

/// A pinned frame's axis is the chord, but the tip deflection is measured from the tangent at
/// flange a in every frame (it used to read 0, the tip on the chord). Mass-proportional damping
/// acts on the motion relative to the frame, and a pinned frame turns with the cantilever's
/// first mode, so the damping here is stiffness-proportional (on the strain rate, the same in
/// every frame): ζ ≈ 0.5 on that mode.
#[test]
fn a_pinned_frame_measures_the_tip_deflection_from_the_root_tangent() {
    assert_tip_force_response("pinned", |load| {
        cantilever_in("pinned", "beta = 0.01", load, CLAMP)
    });
}

/// A tip torque M: deflection M L² / (2 E J), rotation M L / (E J).
#[test]
fn tip_torque_bends_the_beam() {
    let m = 20.0;
    let (d, phi) = settled_tip(&format!(
        "[[load]]\nname = \"twist\"\nframe = \"beam.b\"\ntorque = {m}\n"
    ));
    let ej = 210e9 * 0.01 * 0.02f64.powi(3) / 12.0;
    assert_close("tip deflection under M (m)", d, m / (2.0 * ej));
    assert_close("tip rotation under M (rad)", phi, m / ej);
}

/// Two welds on the same flange fix the same motion twice: refused, naming the joints.
#[test]
fn redundant_joints_are_refused_naming_them() {
    let twice = format!(
        "{CLAMP}\n[[joint]]\nname = \"again\"\ntype = \"weld\"\nframes = [\"world\", \"beam.a\"]\n"
    );
    let mut e = Engine::new(cantilever("", &twice));
    let err = e.exit_initialization().unwrap_err();
    println!("{err}");
    assert!(matches!(err, EngineError::InitialState { .. }));
    let text = err.to_string();
    assert!(
        text.contains("redundant") && text.contains("clamp") && text.contains("again"),
        "{text}"
    );
}

/// Flange b pinned to a world point 1.5 m away from a 1 m beam hinged at the origin: no
/// configuration satisfies both joints. Validation refuses the 0.5 m gap; asked to assemble it
/// (`assemble = true`), the unit refuses at initialization, naming the joint that stays violated.
#[test]
fn a_mechanism_that_cannot_be_assembled_is_refused_naming_the_joints() {
    let text = r#"
name = "impossible"
[[beam]]
name = "beam"
length = 1.0
elements = 2
material = { rho = 7800.0, E = 210e9 }
section = { A = 1e-4, J = 1e-9 }
[[body]]
name = "post"
mass = 1.0
inertia = 0.1
position = [1.5, 0.0]
frames = { anchor = [-1.5, 0.0] }
[[joint]]
name = "hinge"
type = "revolute"
frames = ["world", "beam.a"]
[[joint]]
name = "post_fixed"
type = "weld"
frames = ["world", "post.anchor"]
[[joint]]
name = "reach"
type = "revolute"
frames = ["beam.b", "post.origin"]
"#;
    let refused = Scene::from_toml_str(text, "impossible.toml").unwrap_err();
    assert!(
        refused.to_string().contains("joint \"reach\".frames")
            && refused.to_string().contains("0.5 m apart"),
        "{refused}"
    );
    let text = format!("{text}assemble = true\n");
    let mut e = Engine::new(Scene::from_toml_str(&text, "impossible.toml").unwrap());
    let err = e.exit_initialization().unwrap_err();
    println!("{err}");
    assert!(matches!(err, EngineError::Assembly { .. }));
    assert!(err.to_string().contains("reach"));
}

/// A joint's motion from an FMU input with its derivatives: the joint follows the
/// extrapolated input u0 + u1 (t - t0) + u2 (t - t0)² / 2 exactly at every communication point,
/// and the reaction torque that drives it is an output.
#[test]
fn motion_input_with_derivatives_is_followed() {
    let text = r#"
name = "driven"
[[beam]]
name = "beam"
length = 1.0
elements = 3
material = { rho = 2700.0, E = 70e9 }
section = { shape = "circle", d = 0.02 }
[[joint]]
name = "hub"
type = "revolute"
frames = ["world", "beam.a"]
drive = { kind = "motion", law = "input" }
"#;
    let mut e = Engine::new(Scene::from_toml_str(text, "driven.toml").unwrap());
    let vr = |e: &Engine, n: &str| e.variables().by_name(n).unwrap().vr;
    let (input, angle, torque) = (
        vr(&e, "hub.drive.angle"),
        vr(&e, "hub.angle"),
        vr(&e, "hub.torque"),
    );
    e.exit_initialization().unwrap();
    let h = 0.05;
    for k in 0..10 {
        let t0 = k as f64 * h;
        // the master's guess of the motion over the step: u = t^2 (starting values)
        e.set_real(input, t0 * t0).unwrap();
        e.set_input_derivative(input, 1, 2.0 * t0).unwrap();
        e.set_input_derivative(input, 2, 2.0).unwrap();
        e.do_step(t0, h).unwrap();
        let t1 = t0 + h;
        let got = e.get_real(angle).unwrap();
        assert!(
            (got - t1 * t1).abs() < 1e-9,
            "t = {t1}: angle {got} vs {}",
            t1 * t1
        );
    }
    // the reaction torque of the motion drive does the work that the beam stores (its power
    // is integrated by the engine): energy.work = kinetic + strain
    let work = e.get_real(vr(&e, "energy.work")).unwrap();
    let stored = e.get_real(vr(&e, "energy.kinetic")).unwrap()
        + e.get_real(vr(&e, "energy.strain")).unwrap();
    // a rigid bar at 1 rad/s: m L^2/3 / 2
    let rigid = 2700.0 * std::f64::consts::PI * 0.01f64.powi(2) / 3.0 / 2.0;
    println!("hub torque {:.4} N m; drive work {work:.6e} J, stored {stored:.6e} J (rigid bar {rigid:.6e} J)", e.get_real(torque).unwrap());
    assert!((work - stored).abs() < 1e-3 * stored);
    assert!((stored - rigid).abs() < 0.05 * rigid);
}
