//! `cosim` joins units mechanically ([[joint]]): the C3 slider-crank split at the pin, both units
//! taking the pin force (the release engine, packaged here), against the monolithic unit run
//! with the same fixed step through the master's `Slave`:
//! - C3's own masses and the crank 20 times lighter couple, equal to the monolithic run to
//!   1e-8 m, in about two iterations per step;
//! - the torque cut at 0.7 s is an event of the crank unit: the master lands on it and the pin
//!   force jumps there;
//! - a unit that provides no directional derivatives is refused by name, as is a joint frame
//!   without the force, position or acceleration variables.

mod common;
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
    for s in [
        "slider_crank",
        "slider_crank_split_crank",
        "slider_crank_split_rod_force",
    ] {
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
    let mut s = Slave::load(&dir.join("slider_crank.fmu")).unwrap();
    s.instantiate("mono", false).unwrap();
    let md = s.model_description.clone();
    let vr = |n: &str| md.variable(n).unwrap().value_reference;
    s.set_real(&[vr("crank.rho"), vr("solver.max_step")], &[rho, h])
        .unwrap();
    s.set_boolean(&[vr("solver.adaptive")], &[false]).unwrap();
    s.setup_experiment(None, 0.0, Some(stop)).unwrap();
    s.enter_initialization_mode().unwrap();
    s.exit_initialization_mode().unwrap();
    let slider = vr("slider.position");
    let n = (stop / h).round() as usize;
    let mut out = vec![s.get_real(&[slider]).unwrap()[0]];
    for k in 0..n {
        s.do_step(k as f64 * h, h, false).unwrap();
        out.push(s.get_real(&[slider]).unwrap()[0]);
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
