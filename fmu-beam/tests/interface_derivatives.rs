//! fmi2GetDirectionalDerivative of a unit against finite differences of the unit itself (set
//! the input, read the output): the interface mobility ∂(acceleration)/∂(force) of the frames of
//! input loads, in planar and 3D scenes; every other output's derivative, and ModelStructure's
//! dependencies, against the same differences; references that are not (Real) outputs and
//! inputs refused by name.

use crate::common;

use common::{scene, vr};
use fmu_beam::{Binding, Causality, VarType};
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
/// declared in ModelStructure (an undeclared one is exactly zero, and its difference below
/// 1e-10 of the largest derivative: rounding).
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
    let mut undeclared = Vec::new();
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
                // by rounding only (the 3D joints' acceleration bias is a second difference of
                // the constraints, which carry the motion input's value): checked below
                if fd != 0.0 {
                    undeclared.push((fd.abs(), format!("{} with {}", y.name, u.name)));
                }
            }
        }
    }
    assert!(scale > 0.0, "some output depends on some input");
    for (fd, what) in undeclared {
        assert!(
            fd < 1e-10 * scale,
            "{what}: {fd:e} (largest derivative {scale:e})"
        );
    }
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

/// A uniform bar on a motion-driven revolute joint to the world (input `hub.drive.angle`), no
/// gravity; `rigid` or flexible (4 elements, tangent frame).
fn driven_bar(rigid: bool) -> Scene {
    let text = format!(
        r#"
name = "driven_bar"
[solver]
adaptive = false
max_step = 1e-3
[[beam]]
name = "bar"
length = 0.5
elements = 4
rigid = {rigid}
frame = "tangent"
material = {{ rho = 2700.0, E = 7e10 }}
section = {{ A = 1e-4, J = 1e-9 }}
[[joint]]
name = "hub"
type = "revolute"
frames = ["world", "bar.a"]
drive = {{ kind = "motion", law = "input", value = 0.0 }}
[[load]]
name = "tip"
frame = "bar.b"
input = true
"#
    );
    Scene::from_toml_str(&text, "driven_bar.toml").unwrap()
}

#[test]
fn a_motion_inputs_acceleration_feeds_through_to_its_reaction_as_the_effective_inertia() {
    // the rigid bar pinned at its end: reaction torque = (m L²/3) α at rest, exactly
    let inertia = 2700.0 * 1e-4 * 0.5 * 0.5 * 0.5 / 3.0;
    let mut e = stepped(driven_bar(true), &[], 1e-3, 3);
    let (acc, reaction) = (
        vr(&e, "hub.drive.acceleration"),
        vr(&e, "hub.drive.reaction"),
    );
    let d = e
        .directional_derivative(&[reaction], &[acc], &[1.0])
        .unwrap()[0];
    assert!((d - inertia).abs() < 1e-12 * inertia, "{d} vs {inertia}");
    e.set_real(acc, 2.0).unwrap();
    let r = e.get_real(reaction).unwrap();
    assert!((r - 2.0 * inertia).abs() < 1e-12 * inertia, "{r}");
    // ModelStructure: the reaction on the acceleration and on the tip force, not on the angle
    // or its rate
    let deps = &e.variables().get(reaction).unwrap().dependencies;
    let names: Vec<&str> = deps
        .iter()
        .map(|&d| e.variables().get(d).unwrap().name.as_str())
        .collect();
    assert_eq!(
        names,
        ["hub.drive.acceleration", "tip.fx", "tip.fy", "tip.torque"]
    );

    // the flexible bar, turning under a prescribed motion: its elastic coordinates are free to
    // accelerate at once, so a sudden angular acceleration of the root meets only what the
    // root's slope condition holds (the Schur complement of the elastic block, 2.5e-4 of the
    // rigid inertia with 4 elements: the interface is stiff in position, soft in
    // acceleration, as the crank tip's mobility in the README); every derivative against
    // differences of the unit
    let inputs = [
        ("hub.drive.angle", 0.0),
        ("hub.drive.speed", 3.0),
        ("hub.drive.acceleration", 40.0),
        ("tip.fy", 0.5),
    ];
    let mut e = Engine::new(driven_bar(false));
    e.exit_initialization().unwrap();
    let (acc, reaction) = (
        vr(&e, "hub.drive.acceleration"),
        vr(&e, "hub.drive.reaction"),
    );
    let h = 1e-3;
    for k in 0..20 {
        let t = k as f64 * h;
        let names: Vec<u32> = inputs.iter().map(|(n, _)| vr(&e, n)).collect();
        // the motion a master prescribes: angle, speed and acceleration of a constant
        // acceleration from rest, given in one fmi2SetReal call in any order
        let values = [20.0 * t * t, 40.0 * t, 40.0, 0.5];
        e.set_reals(&names, &values).unwrap();
        e.do_step(t, h).unwrap();
    }
    // set in reverse order: the value still comes first and the derivatives stay
    let names: Vec<u32> = inputs.iter().rev().map(|(n, _)| vr(&e, n)).collect();
    let t = 20.0 * h;
    e.set_reals(&names, &[0.5, 40.0, 40.0 * t, 20.0 * t * t])
        .unwrap();
    assert_eq!(e.get_real(acc).unwrap(), 40.0);
    let d = e
        .directional_derivative(&[reaction], &[acc], &[1.0])
        .unwrap()[0];
    println!("flexible bar: effective inertia {d:.6e} kg m2, rigid {inertia:.6e}");
    assert!(d > 0.0 && d < 1e-2 * inertia, "{d}");
    // the reaction now against the step's own: the step ends with the same motion
    let (now, last) = (
        e.get_real(reaction).unwrap(),
        e.get_real(vr(&e, "hub.torque")).unwrap(),
    );
    println!("flexible bar: reaction {now:.9e} N m, the last step's multiplier {last:.9e}");
    // the same motion on both sides of the point: the two agree to the scheme's error
    assert!((now - last).abs() < 1e-3 * last.abs(), "{now} {last}");
    let err = check_against_differences(&mut e, 1e-3);
    println!("flexible bar: max |dd - fd| / max |dd| = {err:.2e}");
    assert!(err < 1e-8, "{err:e}");
}

#[test]
fn a_unit_in_motion_causality_offers_its_effective_mass_at_the_pin() {
    // the hinged blade's motion-causality unit with a rigid blade (1 m, 0.108 kg) along x from
    // its hinge at rest: the pin's effective mass is m along the blade and m/4 across
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes/hinged_blade_arm_driven.toml"),
    )
    .unwrap()
    .replace("frame = \"tangent\"", "frame = \"tangent\"\nrigid = true");
    let scene = Scene::from_toml_str(&text, "hinged_blade_arm_driven.toml").unwrap();
    let mut e = stepped(scene, &[], 1e-3, 2);
    let m = 2700.0 * 0.02 * 0.002 * 1.0;
    let acc = [
        vr(&e, "pin_x.drive.acceleration"),
        vr(&e, "pin_y.drive.acceleration"),
    ];
    let reaction = [
        vr(&e, "pin_x.drive.reaction"),
        vr(&e, "pin_y.drive.reaction"),
    ];
    let mut mass = [[0.0; 2]; 2];
    for (k, &a) in acc.iter().enumerate() {
        let col = e.directional_derivative(&reaction, &[a], &[1.0]).unwrap();
        mass[0][k] = col[0];
        mass[1][k] = col[1];
    }
    println!("effective mass at the pin: {mass:?} (m = {m})");
    let expect = [[m, 0.0], [0.0, m / 4.0]];
    for i in 0..2 {
        for k in 0..2 {
            assert!((mass[i][k] - expect[i][k]).abs() < 1e-12, "{mass:?}");
        }
    }
    let err = check_against_differences(&mut e, 1e-3);
    assert!(err < 1e-8, "{err:e}");
}

#[test]
fn a_3d_motion_input_feeds_through_to_its_reaction() {
    // the 3D pendulum's beam driven about world y by an input angle: as a rigid bar its
    // reaction's derivative is m L²/3 about the hinge; flexible, every derivative against
    // differences of the unit
    let scene = |rigid: bool| {
        let text = format!(
            r#"
name = "driven_bar_3d"
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
rigid = {rigid}
material = {{ rho = 7800.0, E = 210e9, G = 8.077e10 }}
section = {{ A = 1.257e-3, Iy = 4.138e-7, Iz = 4.19e-8, It = 1.33242e-7 }}
[[joint]]
name = "hinge"
type = "revolute"
frames = ["world", "beam.a"]
axis = [0.0, 1.0, 0.0]
drive = {{ kind = "motion", law = "input", value = 0.0 }}
[[load]]
name = "tip"
frame = "beam.b"
input = true
"#
        );
        Scene::from_toml_str(&text, "driven_bar_3d.toml").unwrap()
    };
    let mut e = stepped(scene(true), &[], 1e-3, 2);
    let (acc, reaction) = (
        vr(&e, "hinge.drive.acceleration"),
        vr(&e, "hinge.drive.reaction"),
    );
    let d = e
        .directional_derivative(&[reaction], &[acc], &[1.0])
        .unwrap()[0];
    let inertia = 7800.0 * 1.257e-3 * 0.2_f64.powi(3) / 3.0;
    println!("3D rigid bar: d(reaction)/d(acceleration) {d:.9e}, m L²/3 {inertia:.9e}");
    assert!((d - inertia).abs() < 1e-12 * inertia, "{d}");
    let mut e = stepped(
        scene(false),
        &[("hinge.drive.acceleration", 5.0), ("tip.fz", 2.0)],
        1e-3,
        10,
    );
    let err = check_against_differences(&mut e, 1e-3);
    println!("3D flexible bar: max |dd - fd| / max |dd| = {err:.2e}");
    assert!(err < 1e-8, "{err:e}");
}
