//! The shape outputs (`<beam>.shape.*`): the points of each beam's deformed centre line, the
//! axis its deflections are measured from, the joints' positions and the 3D bodies' rotations,
//! checked against the unit's other outputs, a closed form and each other; reading them does
//! not change the run.

use crate::common;
use common::*;
use fmu_beam::{Engine, Scene};

fn get(e: &mut Engine, name: &str) -> f64 {
    let v = vr(e, name);
    e.get_real(v).unwrap()
}

fn point(e: &mut Engine, beam: &str, i: usize, dims: &[&str]) -> Vec<f64> {
    dims.iter()
        .map(|c| get(e, &format!("{beam}.shape.{c}[{i}]")))
        .collect()
}

/// Transverse offset of world point p from the line through `root` along unit `axis` (planar).
fn transverse(p: &[f64], root: &[f64], axis: &[f64]) -> f64 {
    let d = [p[0] - root[0], p[1] - root[1]];
    axis[0] * d[1] - axis[1] * d[0]
}

#[test]
fn c1_shape_is_the_static_cantilever_curve_at_the_nodes() {
    // released from the static shape under a tip force: v(x) = δ (3 L x² − x³) / (2 L³), which
    // the cubic Hermite elements represent exactly
    let mut e = Engine::new(scene("cantilever_free_vibration.toml"));
    e.exit_initialization().unwrap();
    let (l, delta, n) = (2.0, 0.01, 11);
    assert!(e.variables().by_name("beam.shape.x[11]").is_some());
    assert!(e.variables().by_name("beam.shape.x[12]").is_none());
    let mut worst: f64 = 0.0;
    for i in 1..=n {
        let p = point(&mut e, "beam", i, &["x", "y"]);
        let x = l * (i - 1) as f64 / (n - 1) as f64;
        let v = delta * (3.0 * l * x * x - x * x * x) / (2.0 * l * l * l);
        worst = worst.max((p[1] - v).abs());
    }
    println!("C1 initial shape: largest |y − δ(3Lx² − x³)/2L³| = {worst:.2e} m");
    assert!(worst < 1e-9 * delta, "{worst}");
}

#[test]
fn c1_shape_ends_at_the_tip_and_passes_mid_span_while_vibrating() {
    let mut e = Engine::new(scene("cantilever_free_vibration.toml"));
    e.exit_initialization().unwrap();
    for k in 0..37 {
        e.do_step(k as f64 * 1e-3, 1e-3).unwrap();
    }
    let tip = [get(&mut e, "beam.tip.x"), get(&mut e, "beam.tip.y")];
    let last = point(&mut e, "beam", 11, &["x", "y"]);
    let root = point(&mut e, "beam", 1, &["x", "y"]);
    let mid = point(&mut e, "beam", 6, &["x", "y"]);
    let axis = [get(&mut e, "beam.axis.x"), get(&mut e, "beam.axis.y")];
    assert!((tip[0] - last[0]).abs() < 1e-14 && (tip[1] - last[1]).abs() < 1e-14);
    assert!(root[0].abs() < 1e-14 && root[1].abs() < 1e-14, "{root:?}");
    assert!(
        (axis[0] - 1.0).abs() < 1e-14 && axis[1].abs() < 1e-14,
        "{axis:?}"
    );
    let (d_tip, d_mid) = (
        get(&mut e, "beam.tip.deflection"),
        get(&mut e, "beam.mid.deflection"),
    );
    assert!(d_tip.abs() > 1e-3, "the beam is bent: {d_tip}");
    assert!((transverse(&last, &root, &axis) - d_tip).abs() < 1e-15);
    assert!((transverse(&mid, &root, &axis) - d_mid).abs() < 1e-15);
}

/// Nodes of a single-frame beam of a scene (its elements + 1).
fn nodes(s: &fmu_beam::Scene, beam: &str) -> usize {
    let b = s.beams.iter().find(|b| b.name == beam).expect("the beam");
    b.elements.expect("a single frame") + 1
}

#[test]
fn c3_beams_meet_at_their_joints_and_the_rod_axis_is_its_chord() {
    let s = scene("slider_crank.toml");
    let (crank_nodes, rod_nodes) = (nodes(&s, "crank"), nodes(&s, "rod"));
    let mut e = Engine::new(s);
    e.exit_initialization().unwrap();
    for k in 0..300 {
        e.do_step(k as f64 * 1e-3, 1e-3).unwrap();
    }
    let xy = ["x", "y"];
    let crank_tip = point(&mut e, "crank", crank_nodes, &xy);
    let rod_root = point(&mut e, "rod", 1, &xy);
    let rod_tip = point(&mut e, "rod", rod_nodes, &xy);
    let pin = [get(&mut e, "crank_rod.x"), get(&mut e, "crank_rod.y")];
    let block = [get(&mut e, "block.x"), get(&mut e, "block.y")];
    let slider = [get(&mut e, "slider.x"), get(&mut e, "slider.y")];
    let gap = |a: &[f64], b: &[f64]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
    println!(
        "C3 at 0.3 s: crank tip to rod root {:.1e} m, pin output to rod root {:.1e} m, rod tip \
         to block {:.1e} m",
        gap(&crank_tip, &rod_root),
        gap(&pin, &rod_root),
        gap(&rod_tip, &block)
    );
    assert!(crank_tip[1] > 0.02, "the crank has turned: {crank_tip:?}");
    // the unit steps across communication points and interpolates the state there: the joints
    // hold to the integrator's tolerance (1e-6 of the 0.456 m mechanism), not to the residual
    let held = 1e-6 * 0.456;
    assert!(gap(&crank_tip, &rod_root) < held);
    assert!(
        gap(&pin, &rod_root) < 1e-15,
        "the pin is the rod's flange a"
    );
    assert!(gap(&rod_tip, &block) < held);
    assert!(gap(&slider, &block) < 1e-15);
    // the rod's frame is pinned: its axis is the chord, its deflection measured from it
    let axis = [get(&mut e, "rod.axis.x"), get(&mut e, "rod.axis.y")];
    let chord = [rod_tip[0] - rod_root[0], rod_tip[1] - rod_root[1]];
    let len = chord[0].hypot(chord[1]);
    assert!((axis[0] - chord[0] / len).abs() < 1e-12 && (axis[1] - chord[1] / len).abs() < 1e-12);
    let mid = point(&mut e, "rod", rod_nodes.div_ceil(2), &xy);
    let d_mid = get(&mut e, "rod.mid.deflection");
    assert!(d_mid.abs() > 1e-5, "the rod bends: {d_mid}");
    assert!((transverse(&mid, &rod_root, &axis) - d_mid).abs() < 1e-15);
}

#[test]
fn reading_the_shape_outputs_does_not_change_the_run() {
    let s = scene("slider_crank.toml");
    let (crank_nodes, rod_nodes) = (nodes(&s, "crank"), nodes(&s, "rod"));
    let run = |read: bool| {
        let mut e = Engine::new(s.clone());
        e.exit_initialization().unwrap();
        let shape: Vec<u32> = e
            .variables()
            .variables
            .iter()
            .filter(|v| v.name.contains(".shape.") || v.name.contains(".axis."))
            .map(|v| v.vr)
            .collect();
        assert_eq!(shape.len(), 2 * (crank_nodes + rod_nodes) + 4);
        let slider = vr(&e, "slider.position");
        let mut out = Vec::new();
        for k in 0..200 {
            e.do_step(k as f64 * 1e-3, 1e-3).unwrap();
            if read {
                for &v in &shape {
                    e.get_real(v).unwrap();
                }
            }
            out.push(e.get_real(slider).unwrap().to_bits());
        }
        out
    };
    assert_eq!(run(true), run(false));
}

#[test]
fn c4_shape_points_set_by_the_scene_are_equally_spaced_material_points() {
    // 10 substructures of 0.8 m: 11 nodes; 6 points (every 1.6 m) are every second node
    let mut s = scene("spin_up_omega10.toml");
    s.beams[0].shape_points = Some(6);
    let mut six = Engine::new(s);
    let mut nodes = Engine::new(scene("spin_up_omega10.toml"));
    assert!(six.variables().by_name("beam.shape.x[6]").is_some());
    assert!(six.variables().by_name("beam.shape.x[7]").is_none());
    for e in [&mut six, &mut nodes] {
        e.exit_initialization().unwrap();
        for k in 0..80 {
            e.do_step(k as f64 * 0.1, 0.1).unwrap();
        }
    }
    let tip_y = get(&mut nodes, "beam.tip.y");
    assert!(tip_y.abs() > 1.0, "the beam has turned: {tip_y}");
    for i in 1..=6 {
        let a = point(&mut six, "beam", i, &["x", "y"]);
        let b = point(&mut nodes, "beam", 2 * i - 1, &["x", "y"]);
        assert!(
            (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12,
            "point {i}: {a:?} against node {}: {b:?}",
            2 * i - 1
        );
    }
}

#[test]
fn shape_points_and_the_outputs_list_decide_what_is_offered() {
    let base = scene("spin_up_omega10.toml");
    let offered = |s: &Scene| {
        fmu_beam::VariableTable::build(s)
            .variables
            .iter()
            .filter(|v| v.name.starts_with("beam.shape.") || v.name.starts_with("beam.axis."))
            .count()
    };
    assert_eq!(offered(&base), 2 * 11 + 2);
    let mut off = base.clone();
    off.beams[0].shape_points = Some(0);
    assert_eq!(offered(&off), 0);
    let mut listed = base.clone();
    listed.beams[0].outputs = vec!["tip.x".into()];
    assert_eq!(offered(&listed), 0);
    listed.beams[0].outputs.push("shape".into());
    assert_eq!(offered(&listed), 2 * 11 + 2);
    let text = base
        .to_toml_string()
        .replace("name = \"beam\"", "name = \"beam\"\nshape_points = 1");
    let err = Scene::from_toml_str(&text, "one_point.toml").unwrap_err();
    assert!(
        err.to_string().contains("beam \"beam\".shape_points"),
        "{err}"
    );
}

#[test]
fn rollup_3d_shape_ends_at_the_tip_and_its_axis_is_a_unit_vector() {
    let s = scene("rollup_3d.toml");
    // a point at every node: the last one is the tip
    let (per_frame, frames) = Scene::beam_layout(&s.beams[0]);
    let nodes = per_frame * frames + 1;
    let mut e = Engine::new(s);
    e.exit_initialization().unwrap();
    for k in 0..100 {
        e.do_step(k as f64 * 1e-2, 1e-2).unwrap();
    }
    let xyz = ["x", "y", "z"];
    let tip: Vec<f64> = xyz
        .iter()
        .map(|c| get(&mut e, &format!("beam.tip.{c}")))
        .collect();
    let last = point(&mut e, "beam", nodes, &xyz);
    let root = point(&mut e, "beam", 1, &xyz);
    for k in 0..3 {
        assert!((tip[k] - last[k]).abs() < 1e-12, "{tip:?} {last:?}");
        assert!(root[k].abs() < 1e-12, "{root:?}");
    }
    assert!(
        tip[2].abs() > 0.1,
        "the beam rolls up out of the x-y plane: {tip:?}"
    );
    let axis: Vec<f64> = xyz
        .iter()
        .map(|c| get(&mut e, &format!("beam.axis.{c}")))
        .collect();
    let norm = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
    assert!((norm - 1.0).abs() < 1e-12, "{axis:?}");
    // the deflection outputs are the tip's offsets across that axis
    let d = [tip[0] - root[0], tip[1] - root[1], tip[2] - root[2]];
    let along: f64 = (0..3).map(|k| d[k] * axis[k]).sum();
    let across = (d.iter().map(|x| x * x).sum::<f64>() - along * along).sqrt();
    let (dy, dz) = (
        get(&mut e, "beam.tip.deflection_y"),
        get(&mut e, "beam.tip.deflection_z"),
    );
    assert!((across - dy.hypot(dz)).abs() < 1e-12, "{across} {dy} {dz}");
}

#[test]
fn a_3d_body_rotation_carries_its_pivot_frame_to_the_joint() {
    // a rigid body swinging on a spherical joint in the x–z plane: body position + R · (its
    // pivot in body axes) stays at the world origin, and R stays a rotation
    let text = r#"
name = "ball"
dimensions = 3
[world]
gravity = [0.0, 0.0, -9.81]
[experiment]
stop_time = 1.0
step_size = 1e-2
[[body]]
name = "ball"
mass = 1.0
inertia = [0.01, 0.02, 0.03]
position = [0.5, 0.0, 0.0]
frames = { pivot = [-0.5, 0.0, 0.0] }
[[beam]]
name = "post"
length = 0.1
elements = 1
rigid = true
material = { rho = 7800.0, E = 2e11, G = 8e10 }
section = { A = 1e-4, Iy = 1e-9, Iz = 1e-9, It = 2e-9 }
[[joint]]
name = "base"
type = "weld"
frames = ["world", "post.a"]
[[joint]]
name = "pivot"
type = "spherical"
frames = ["world", "ball.pivot"]
"#;
    let mut e = Engine::new(Scene::from_toml_str(text, "ball.toml").unwrap());
    e.exit_initialization().unwrap();
    for k in 0..30 {
        e.do_step(k as f64 * 1e-2, 1e-2).unwrap();
    }
    let r: Vec<Vec<f64>> = (1..=3)
        .map(|i| {
            (1..=3)
                .map(|j| get(&mut e, &format!("ball.R[{i},{j}]")))
                .collect()
        })
        .collect();
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
            // A(p) of the quaternion, whose norm is held to the integrator's tolerance
            assert!((dot - f64::from(u8::from(i == j))).abs() < 1e-6, "{r:?}");
        }
    }
    let pos = [
        get(&mut e, "ball.x"),
        get(&mut e, "ball.y"),
        get(&mut e, "ball.z"),
    ];
    assert!(pos[2] < -0.1, "the ball has swung down: {pos:?}");
    for k in 0..3 {
        let pivot = pos[k] + r[k][0] * -0.5;
        // held to the integrator's tolerance (interpolated between its steps)
        assert!(pivot.abs() < 1e-6, "{k}: {pivot}");
        let joint = get(&mut e, &format!("pivot.{}", ["x", "y", "z"][k]));
        assert!((joint - pivot).abs() < 1e-12, "{joint} {pivot}");
    }
}
