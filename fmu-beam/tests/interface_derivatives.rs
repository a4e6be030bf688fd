//! fmi2GetDirectionalDerivative of a unit against finite differences of the unit itself (set
//! the input, read the output): the interface mobility ∂(acceleration)/∂(force) of the frames of
//! input loads, in planar and 3D scenes; every other output's derivative, and ModelStructure's
//! dependencies, against the same differences; references that are not (Real) outputs and
//! inputs refused by name.

mod common;

use common::{scene, vr};
use fmu_beam::variables::{Binding, Causality, VarType};
use fmu_beam::{Engine, EngineError, Scene};

/// A running engine of `scene`, stepped `steps` times by `h` with every input at `inputs`.
fn stepped(scene: Scene, inputs: &[(&str, f64)], h: f64, steps: usize) -> Engine {
    let mut e = Engine::new(scene);
    e.exit_initialization().unwrap();
    for (name, v) in inputs {
        let r = vr(&e, name);
        e.set_real(r, *v).unwrap();
    }
    for k in 0..steps {
        e.do_step(k as f64 * h, h).unwrap();
    }
    e
}

/// Largest |directional derivative − central difference| over every Real output and input,
/// relative to the largest derivative; also checks that a derivative that is not zero is
/// declared in ModelStructure (and an undeclared one is exactly zero).
fn check_against_differences(e: &mut Engine, step: f64) -> f64 {
    let vars = e.variables().variables.clone();
    let inputs: Vec<_> = vars
        .iter()
        .filter(|v| v.causality == Causality::Input && v.ty == VarType::Real)
        .collect();
    let outputs: Vec<_> = vars
        .iter()
        .filter(|v| {
            v.causality == Causality::Output
                && v.ty == VarType::Real
                && v.name != "solver.constraint_residual"
        })
        .collect();
    assert!(!inputs.is_empty() && !outputs.is_empty());
    let out_vrs: Vec<u32> = outputs.iter().map(|v| v.vr).collect();
    let (mut worst, mut scale) = (0.0_f64, 0.0_f64);
    for u in &inputs {
        let u0 = e.get_real(u.vr).unwrap();
        let dd = e.directional_derivative(&out_vrs, &[u.vr], &[1.0]).unwrap();
        e.set_real(u.vr, u0 + step).unwrap();
        let plus: Vec<f64> = out_vrs.iter().map(|&r| e.get_real(r).unwrap()).collect();
        e.set_real(u.vr, u0 - step).unwrap();
        let minus: Vec<f64> = out_vrs.iter().map(|&r| e.get_real(r).unwrap()).collect();
        e.set_real(u.vr, u0).unwrap();
        for (k, y) in outputs.iter().enumerate() {
            let fd = (plus[k] - minus[k]) / (2.0 * step);
            worst = worst.max((dd[k] - fd).abs());
            scale = scale.max(dd[k].abs());
            if !y.dependencies.contains(&u.vr) {
                assert_eq!(
                    dd[k], 0.0,
                    "{} depends on {} but ModelStructure does not say so",
                    y.name, u.name
                );
                assert_eq!(fd, 0.0, "{} moves with {}", y.name, u.name);
            }
        }
    }
    assert!(scale > 0.0, "some output depends on some input");
    worst / scale
}

const CRANK_LOADS: [(&str, f64); 2] = [("pin.fx", 0.3), ("pin.fy", -0.2)];

#[test]
fn planar_units_mobility_equals_differences_of_the_unit() {
    for (file, load) in [
        ("slider_crank_split_crank.toml", "pin"),
        ("slider_crank_split_rod_force.toml", "pin"),
        ("hinged_blade_hub.toml", "hinge"),
        ("hinged_blade_arm.toml", "hinge"),
    ] {
        let inputs = [
            (format!("{load}.fx"), CRANK_LOADS[0].1),
            (format!("{load}.fy"), CRANK_LOADS[1].1),
        ];
        let inputs: Vec<(&str, f64)> = inputs.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        let mut e = stepped(scene(file), &inputs, 1e-3, 30);
        let err = check_against_differences(&mut e, 1e-3);
        println!("{file}: max |dd - fd| / max |dd| = {err:.2e}");
        assert!(err < 1e-9, "{file}: {err:e}");
        // the mobility is symmetric (a reciprocity: M⁻¹ restricted to the joints' motions)
        let a = [vr(&e, &format!("{load}.ax")), vr(&e, &format!("{load}.ay"))];
        let f = [vr(&e, &format!("{load}.fx")), vr(&e, &format!("{load}.fy"))];
        let w01 = e.directional_derivative(&[a[0]], &[f[1]], &[1.0]).unwrap()[0];
        let w10 = e.directional_derivative(&[a[1]], &[f[0]], &[1.0]).unwrap()[0];
        assert!(
            (w01 - w10).abs() <= 1e-9 * (w01.abs() + 1.0),
            "{w01} vs {w10}"
        );
    }
}

#[test]
fn an_effort_input_feeds_through_to_its_effort_and_the_motion_inputs_to_the_residual() {
    // the flexible arm: hub torque input; its `hub.torque` output is the input itself
    let mut e = stepped(
        scene("flexible_arm.toml"),
        &[("hub.drive.torque", 2.0)],
        1e-2,
        5,
    );
    let (tau, out) = (vr(&e, "hub.drive.torque"), vr(&e, "hub.torque"));
    assert_eq!(
        e.directional_derivative(&[out], &[tau], &[3.0]).unwrap(),
        [3.0]
    );
    let err = check_against_differences(&mut e, 1e-3);
    assert!(err < 1e-9, "{err:e}");
    // a motion input moves the constraint residual max |g| one to one (one-sided derivative,
    // with the drive row clearly the largest)
    let mut e = stepped(
        scene("slider_crank_split_rod.toml"),
        &[("pin_x.drive.position", 0.152)],
        1e-3,
        3,
    );
    let (u, g) = (
        vr(&e, "pin_x.drive.position"),
        vr(&e, "solver.constraint_residual"),
    );
    e.set_real(u, 0.153).unwrap();
    let d = e.directional_derivative(&[g], &[u], &[1.0]).unwrap()[0];
    let (g0, _) = (e.get_real(g).unwrap(), e.set_real(u, 0.153 + 1e-6).unwrap());
    let fd = (e.get_real(g).unwrap() - g0) / 1e-6;
    assert!(
        (d - fd).abs() < 1e-6 && (d.abs() - 1.0).abs() < 1e-9,
        "{d} {fd}"
    );
    let deps = &e.variables().get(g).unwrap().dependencies;
    assert!(deps.contains(&u), "{deps:?}");
}

/// A 3D pendulum (C6's beam, spherical joint at the root, spatial element forced) with an input
/// load at its tip.
fn pendulum_3d_with_tip_load() -> Scene {
    let text = r#"
name = "pendulum_3d_loaded"
dimensions = 3
formulation = "spatial"
[world]
gravity = [0.0, 0.0, -9.81]
[solver]
adaptive = false
max_step = 1e-3
[[beam]]
name = "beam"
length = 0.2
elements = 2
axis = [1.0, 0.0, 0.2]
normal = [-0.2, 0.0, 1.0]
material = { rho = 7800.0, E = 210e9, G = 8.077e10 }
section = { A = 1.257e-3, Iy = 4.138e-7, Iz = 4.19e-8, It = 1.33242e-7 }
[[joint]]
name = "root"
type = "spherical"
frames = ["world", "beam.a"]
[[load]]
name = "tip"
frame = "beam.b"
input = true
"#;
    Scene::from_toml_str(text, "pendulum_3d_loaded.toml").unwrap()
}

#[test]
fn spatial_unit_mobility_equals_differences_of_the_unit() {
    let inputs = [
        ("tip.fx", 1.0),
        ("tip.fy", -2.0),
        ("tip.fz", 0.5),
        ("tip.tx", 0.01),
        ("tip.ty", 0.02),
        ("tip.tz", -0.01),
    ];
    let mut e = stepped(pendulum_3d_with_tip_load(), &inputs, 1e-3, 40);
    let err = check_against_differences(&mut e, 1e-3);
    println!("3D pendulum: max |dd - fd| / max |dd| = {err:.2e}");
    assert!(err < 1e-8, "{err:e}");
}

#[test]
fn the_frame_acceleration_is_the_rate_of_the_frame_velocity() {
    // the acceleration outputs (with their velocity-dependent part) against the difference of
    // the velocity outputs over a short step of the unit (10 internal steps), in smooth motions:
    // a torque-driven rigid hub, the flexible C3 crank under its torque (from zero), a 3D
    // pendulum as a rigid bar (quaternion coordinates) under gravity out of its plane. (A
    // flexible beam released under gravity rings at tens of kHz, and the difference of its
    // velocities is then rounding noise; the 3D frame Jacobian is the closed-form pose
    // derivative that tests/spatial_jacobians.rs checks.)
    // gravity out of the plane of the beam and the joint: a motion in 3D
    let rigid_3d = pendulum_3d_with_tip_load()
        .to_toml_string()
        .replace("rigid = false", "rigid = true")
        .replace(
            "gravity = [0.0, 0.0, -9.81]",
            "gravity = [2.0, -3.0, -9.81]",
        );
    let rigid_3d = Scene::from_toml_str(&rigid_3d, "rigid.toml").unwrap();
    let tip = vec![
        ("tip.vx", "tip.ax"),
        ("tip.vy", "tip.ay"),
        ("tip.vz", "tip.az"),
        ("tip.wx", "tip.alphax"),
        ("tip.wy", "tip.alphay"),
        ("tip.wz", "tip.alphaz"),
    ];
    // (scene, (velocity, acceleration) pairs, the short step)
    type Case<'a> = (Scene, Vec<(&'a str, &'a str)>, f64);
    let cases: Vec<Case> = vec![
        (
            scene("hinged_blade_hub.toml"),
            vec![
                ("hinge.vx", "hinge.ax"),
                ("hinge.vy", "hinge.ay"),
                ("hinge.omega", "hinge.alpha"),
            ],
            1e-5,
        ),
        (
            scene("slider_crank_split_crank.toml"),
            vec![
                ("pin.vx", "pin.ax"),
                ("pin.vy", "pin.ay"),
                ("pin.omega", "pin.alpha"),
            ],
            1e-6,
        ),
        (rigid_3d, tip, 1e-5),
    ];
    for (sc, pairs, dt) in cases {
        let name = sc.name.clone();
        let mut e = Engine::new(sc);
        let fixed = [
            ("solver.adaptive", 0.0),
            ("solver.max_step", dt / 10.0),
            ("solver.tolerance", 1e-12),
        ];
        for (n, v) in fixed {
            let var = e.variables().by_name(n).unwrap().clone();
            if var.ty == VarType::Boolean {
                e.set_boolean(var.vr, v != 0.0).unwrap();
            } else {
                e.set_real(var.vr, v).unwrap();
            }
        }
        e.exit_initialization().unwrap();
        let h = 1e-4;
        for k in 0..20 {
            e.do_step(k as f64 * h, h).unwrap();
        }
        let t = 20.0 * h;
        for (v, a) in pairs {
            let (rv, ra) = (vr(&e, v), vr(&e, a));
            let (v0, a0) = (e.get_real(rv).unwrap(), e.get_real(ra).unwrap());
            let snap = e.snapshot();
            e.do_step(t, dt).unwrap();
            let (v1, a1) = (e.get_real(rv).unwrap(), e.get_real(ra).unwrap());
            e.restore(&snap).unwrap();
            let rate = (v1 - v0) / dt;
            let mid = 0.5 * (a0 + a1);
            println!("{name}: d{v}/dt = {rate:.6e}, {a} = {mid:.6e}");
            assert!(
                (rate - mid).abs() <= 1e-4 * mid.abs().max(1.0),
                "{name}: {v}: {rate} vs {a}: {mid}"
            );
        }
    }
}

#[test]
fn references_that_are_not_outputs_and_inputs_are_refused_by_name() {
    let mut e = stepped(
        scene("slider_crank_split_crank.toml"),
        &CRANK_LOADS,
        1e-3,
        2,
    );
    let (ax, fx, x, rho) = (
        vr(&e, "pin.ax"),
        vr(&e, "pin.fx"),
        vr(&e, "pin.x"),
        vr(&e, "crank.rho"),
    );
    let unknown = e.variables().variables.len() as u32 + 7;
    let cases = [
        (vec![ax], vec![x], "known", Some("pin.x")),
        (vec![ax], vec![rho], "known", Some("crank.rho")),
        (vec![fx], vec![fx], "unknown", Some("pin.fx")),
        (vec![ax], vec![unknown], "known", None),
        (vec![unknown], vec![fx], "unknown", None),
    ];
    for (unknowns, knowns, role, name) in cases {
        let err = e
            .directional_derivative(&unknowns, &knowns, &vec![1.0; knowns.len()])
            .unwrap_err();
        let text = err.to_string();
        assert!(
            matches!(&err, EngineError::DirectionalDerivative { role: r, .. } if *r == role),
            "{text}"
        );
        if let Some(n) = name {
            assert!(text.contains(n), "{text}");
        } else {
            assert!(text.contains("no variable"), "{text}");
        }
    }
    // refused requests change nothing: the unit still answers
    assert!(e.directional_derivative(&[ax], &[fx], &[1.0]).is_ok());
}

#[test]
fn model_structure_lists_exactly_the_force_inputs_of_the_joined_bodies() {
    let e = Engine::new(scene("slider_crank_split_crank.toml"));
    let t = e.variables();
    let inputs: Vec<u32> = t
        .variables
        .iter()
        .filter(|v| matches!(v.binding, Binding::Input(_)))
        .map(|v| v.vr)
        .collect();
    for v in &t.variables {
        let expect_all = v.name.starts_with("pin.a") || v.name == "pin.alpha";
        if expect_all {
            assert_eq!(v.dependencies, inputs, "{}", v.name);
        } else {
            assert!(
                v.dependencies.is_empty(),
                "{}: {:?}",
                v.name,
                v.dependencies
            );
        }
    }
}
