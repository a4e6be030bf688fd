//! `cosim` joins units mechanically ([[joint]]): the C3 slider-crank split at the pin, both units
//! taking the pin force (the release engine, packaged here), against the monolithic unit run
//! with the same fixed step through the master's `Slave`:
//! - C3's own masses and the crank 20 times lighter couple, equal to the monolithic run to
//!   1e-8 m, in about two iterations per step;
//! - the torque cut at 0.7 s is an event of the crank unit: the master lands on it and the pin
//!   force jumps there;
//! - a unit that provides no directional derivatives is refused by name, as is a joint frame
//!   without the force, position or acceleration variables;
//! - a 3D pair, the double pendulum split at its spherical pin (the lower beam swinging out of
//!   the upper one's plane), equals its monolithic twin to the pin tolerance.

use crate::common;
use common::*;
use fmu_harness::cosim::{self, system::System, CosimError};
use fmu_harness::slave::Slave;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../scenes/{name}.toml"))
}

/// The split slider-crank and its monolithic twin, packaged with the release engine.
fn fmus(dir: &Path) {
    package(
        dir,
        &[
            "slider_crank",
            "slider_crank_split_crank",
            "slider_crank_split_rod_force",
        ],
    );
}

/// Each scene as `<dir>/<scene>.fmu`, with the release engine.
fn package(dir: &Path, scenes: &[&str]) {
    for &s in scenes {
        let out = dir.join(format!("{s}.fmu"));
        let r = harness(&[
            "package".as_ref(),
            scene(s).as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ]);
        assert!(
            r.status.success(),
            "packaging {s} with the release engine failed (run `cargo build --release --workspace`): {}",
            String::from_utf8_lossy(&r.stderr)
        );
    }
}

fn system(dir: &Path, h: f64, stop: f64, rho: f64, crank_fmu: &str) -> (System, PathBuf) {
    let start = format!("\"solver.adaptive\" = false, \"solver.max_step\" = {h:?}");
    let text = format!(
        r#"stop_time = {stop:?}
step = {{ size = {h:?} }}
outputs = ["rod.slider.position", "crank.pin.fx"]
[[joint]]
name = "pin"
type = "revolute"
frames = ["crank.pin", "rod.pin"]
[[unit]]
name = "crank"
fmu = "{crank_fmu}"
start = {{ "crank.rho" = {rho:?}, {start} }}
[[unit]]
name = "rod"
fmu = "slider_crank_split_rod_force.fmu"
start = {{ {start} }}
"#
    );
    let path = dir.join("joint.toml");
    std::fs::write(&path, &text).unwrap();
    (System::from_toml_str(&text, &path).unwrap(), path)
}

/// The monolithic unit's slider position at every communication point, same fixed step.
fn monolithic(dir: &Path, h: f64, stop: f64, rho: f64) -> Vec<f64> {
    let fmu = dir.join("slider_crank.fmu");
    let rows = run_alone(&fmu, h, stop, &[("crank.rho", rho)], &["slider.position"]);
    rows.into_iter().map(|r| r[0]).collect()
}

/// One unit alone at a fixed step `h` (internal step and communication step), Real parameters
/// set: `outputs` at every communication point.
fn run_alone(
    fmu: &Path,
    h: f64,
    stop: f64,
    reals: &[(&str, f64)],
    outputs: &[&str],
) -> Vec<Vec<f64>> {
    let mut s = Slave::load(fmu).unwrap();
    s.instantiate("alone", false).unwrap();
    let md = s.model_description.clone();
    let vr = |n: &str| md.variable(n).unwrap().value_reference;
    for &(name, value) in reals.iter().chain(&[("solver.max_step", h)]) {
        s.set_real(&[vr(name)], &[value]).unwrap();
    }
    s.set_boolean(&[vr("solver.adaptive")], &[false]).unwrap();
    s.setup_experiment(None, 0.0, Some(stop)).unwrap();
    s.enter_initialization_mode().unwrap();
    s.exit_initialization_mode().unwrap();
    let vrs: Vec<u32> = outputs.iter().map(|o| vr(o)).collect();
    let n = (stop / h).round() as usize;
    let mut out = vec![s.get_real(&vrs).unwrap()];
    for k in 0..n {
        s.do_step(k as f64 * h, h, false).unwrap();
        out.push(s.get_real(&vrs).unwrap());
    }
    out
}

#[test]
fn the_split_slider_crank_couples_at_any_crank_density_as_the_monolithic_unit_runs() {
    let dir = scratch("cosim_joints_density");
    fmus(&dir);
    let (h, stop) = (1e-3, 0.1);
    for factor in [1.0, 0.05] {
        let rho = 2770.0 * factor;
        let (sys, path) = system(&dir, h, stop, rho, "slider_crank_split_crank.fmu");
        let (results, summary) = cosim::run(&sys, &path).unwrap();
        let mono = monolithic(&dir, h, stop, rho);
        assert_eq!(results.rows.len(), mono.len());
        let err = results
            .rows
            .iter()
            .zip(&mono)
            .map(|(r, m)| (r[1] - m).abs())
            .fold(0.0, f64::max);
        let joints = summary.joints.unwrap();
        let per_step = joints.iterations as f64 / summary.accepted_steps as f64;
        println!("crank density x{factor}: max |slider error| {err:.2e} m, {per_step:.2} iterations per step");
        assert!(err < 1e-8, "{err:e}");
        assert!(per_step < 3.0 && joints.refusals == 0, "{joints:?}");
        assert!(joints.largest_mismatch <= 1e-9);
        assert_eq!(summary.unit_steps, 2 * joints.iterations);
    }
}

#[test]
fn the_master_lands_on_the_torque_cut_and_the_pin_force_jumps_there() {
    let dir = scratch("cosim_joints_event");
    fmus(&dir);
    // h = 3 ms: 0.7 s is not a communication point
    let (sys, path) = system(&dir, 3e-3, 0.72, 2770.0, "slider_crank_split_crank.fmu");
    let (results, summary) = cosim::run(&sys, &path).unwrap();
    let joints = summary.joints.unwrap();
    // the force jumps at the start and where a step lands on the cut, which splits the step
    // from 0.699 to 0.702 s (after the cut the crank's Newton may need shorter steps: halved)
    assert_eq!(joints.jumps, 2, "{joints:?}");
    assert!(summary.accepted_steps > 240, "{}", summary.text());
    assert!(summary.min_step < 1.5e-3, "{}", summary.text());
    assert!((results.rows.last().unwrap()[0] - 0.72).abs() < 1e-12);
}

/// A copy of the crank FMU whose model description says it provides no directional derivatives.
fn without_derivatives(dir: &Path) -> String {
    let src = std::fs::File::open(dir.join("slider_crank_split_crank.fmu")).unwrap();
    let mut zin = zip::ZipArchive::new(src).unwrap();
    let out = std::fs::File::create(dir.join("no_derivatives.fmu")).unwrap();
    let mut zout = zip::ZipWriter::new(out);
    for i in 0..zin.len() {
        let mut e = zin.by_index(i).unwrap();
        let mut bytes = Vec::new();
        e.read_to_end(&mut bytes).unwrap();
        if e.name() == "modelDescription.xml" {
            let xml = String::from_utf8(bytes).unwrap().replace(
                "providesDirectionalDerivative=\"true\"",
                "providesDirectionalDerivative=\"false\"",
            );
            bytes = xml.into_bytes();
        }
        zout.start_file(e.name(), zip::write::SimpleFileOptions::default())
            .unwrap();
        zout.write_all(&bytes).unwrap();
    }
    zout.finish().unwrap();
    "no_derivatives.fmu".into()
}

#[test]
fn units_and_frames_a_joint_cannot_use_are_refused_by_name() {
    let dir = scratch("cosim_joints_refused");
    fmus(&dir);
    let fmu = without_derivatives(&dir);
    let (sys, path) = system(&dir, 1e-3, 0.01, 2770.0, &fmu);
    let e = cosim::run(&sys, &path).unwrap_err();
    assert!(
        matches!(&e, CosimError::JointUnit { unit, joint } if unit == "crank" && joint == "pin"),
        "{e}"
    );
    assert!(
        e.to_string().contains("providesDirectionalDerivative"),
        "{e}"
    );

    let (mut sys, path) = system(&dir, 1e-3, 0.01, 2770.0, "slider_crank_split_crank.fmu");
    sys.joints[0].frames[1] = "rod.slider".into();
    let e = cosim::run(&sys, &path).unwrap_err().to_string();
    assert!(e.contains("rod.slider.fx"), "{e}");
}

/// Max |difference| of two equally long histories of vectors.
fn largest_difference(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| (p - q).abs()))
        .fold(0.0, f64::max)
}

#[test]
fn a_3d_pair_joined_at_a_spherical_pin_runs_as_its_monolithic_twin() {
    let dir = scratch("cosim_joints_spherical");
    package(
        &dir,
        &[
            "pendulum_3d_double",
            "pendulum_3d_double_upper",
            "pendulum_3d_double_lower",
        ],
    );
    let (h, stop) = (1e-3, 0.5);
    let start = format!("\"solver.adaptive\" = false, \"solver.max_step\" = {h:?}");
    let text = format!(
        r#"stop_time = {stop:?}
step = {{ size = {h:?} }}
outputs = ["lower.lower.tip.x", "lower.lower.tip.y", "lower.lower.tip.z"]
[[joint]]
name = "pin"
type = "spherical"
frames = ["upper.pin", "lower.pin"]
[[unit]]
name = "upper"
fmu = "pendulum_3d_double_upper.fmu"
start = {{ {start} }}
[[unit]]
name = "lower"
fmu = "pendulum_3d_double_lower.fmu"
start = {{ {start} }}
"#
    );
    let path = dir.join("spherical.toml");
    std::fs::write(&path, &text).unwrap();
    let sys = System::from_toml_str(&text, &path).unwrap();
    let (results, summary) = cosim::run(&sys, &path).unwrap();
    let coupled: Vec<Vec<f64>> = results.rows.iter().map(|r| r[1..].to_vec()).collect();

    let mono = run_alone(
        &dir.join("pendulum_3d_double.fmu"),
        h,
        stop,
        &[],
        &["lower.tip.x", "lower.tip.y", "lower.tip.z"],
    );

    // the lower beam leaves the upper one's x-z plane (y falls from 0.2 m through zero)
    let least_y = mono.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
    assert!(least_y < -0.05, "{least_y}");
    let err = largest_difference(&coupled, &mono);
    let joints = summary.joints.unwrap();
    let per_step = joints.iterations as f64 / summary.accepted_steps as f64;
    println!("spherical pin: max |tip difference| {err:.2e} m, {per_step:.2} iterations per step");
    // the pin closes to 1e-9 m per step (the joint's default tolerance); over 500 steps the
    // lower tip, 0.2 m beyond the pin, stays within 1e-8 m of the monolithic run
    assert!(err < 1e-8, "{err:e}");
    assert!(per_step < 4.0 && joints.refusals == 0, "{joints:?}");
}
