//! Our master runs FMI 3.0 units as it runs 2.0 ones (issue 47 item 5), each scene packaged
//! here in both versions with the release engine:
//! - `simulate` gives the 2.0 unit's CSV bit for bit (C1 and a 3D scene), a shape array as the
//!   2.0 unit's scalar columns (`beam.shape.x[1]` ...);
//! - the slave reads the 3.0 model description (fmiVersion, instantiationToken, arrays with
//!   their dimensions, the capability flags; no input derivatives), and refuses fmi2's input
//!   derivatives by name;
//! - `cosim` by connections gives the 2.0 units' CSV bit for bit (inputs held), and the pin
//!   joint of the split slider-crank couples 3.0 units, within 1e-7 m of the 2.0 coupling over
//!   0.1 s (a 3.0 unit holds the joint force over a step: no input derivatives).
//!
//! The whole runs are `tests/test_fmi3.py`'s (every shipped scene).

use crate::common;
use common::*;
use fmu_harness::cosim::{self, system::System};
use fmu_harness::platform::FmiVersion;
use fmu_harness::simulate::{simulate, Options};
use fmu_harness::slave::{Slave, SlaveError, VarType};
use std::path::{Path, PathBuf};

/// `scene` packaged with the release engine as `<dir>/<scene>.v<version>.fmu`.
fn unit(dir: &Path, scene: &str, version: u32) -> PathBuf {
    let out = dir.join(format!("{scene}.v{version}.fmu"));
    if out.is_file() {
        return out;
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../scenes/{scene}.toml"));
    let r = harness(&[
        "package".as_ref(),
        path.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--fmi-version".as_ref(),
        version.to_string().as_ref(),
    ]);
    assert!(
        r.status.success(),
        "packaging {scene} with the release engine failed (run `cargo build --release -p fmu-beam`): {}",
        String::from_utf8_lossy(&r.stderr)
    );
    out
}

#[test]
fn simulate_gives_the_fmi2_units_csv_bit_for_bit() {
    let dir = scratch("fmi3_master_simulate");
    for (scene, stop) in [("cantilever_free_vibration", 0.05), ("pendulum_3d", 0.1)] {
        let options = Options {
            stop_time: Some(stop),
            ..Options::default()
        };
        let (v2, ended2) = simulate(&unit(&dir, scene, 2), &options).unwrap();
        let (v3, ended3) = simulate(&unit(&dir, scene, 3), &options).unwrap();
        assert!(ended2.is_none() && ended3.is_none());
        assert!(v3.rows.len() > 10, "{scene}: {} rows", v3.rows.len());
        assert_eq!(v3.columns, v2.columns, "{scene}");
        assert_eq!(v3.csv(), v2.csv(), "{scene}: the CSVs differ");
    }
    let (c1, _) = simulate(
        &unit(&dir, "cantilever_free_vibration", 3),
        &Options {
            stop_time: Some(0.01),
            ..Options::default()
        },
    )
    .unwrap();
    let x: Vec<_> = c1
        .columns
        .iter()
        .filter(|c| c.starts_with("beam.shape.x["))
        .collect();
    assert_eq!(x.len(), 11);
    assert_eq!(
        (x[0].as_str(), x[10].as_str()),
        ("beam.shape.x[1]", "beam.shape.x[11]")
    );
}

#[test]
fn the_slave_reads_the_fmi3_description_and_has_no_input_derivatives() {
    let dir = scratch("fmi3_master_slave");
    let mut s = Slave::load(&unit(&dir, "slider_crank_split_rod_force", 3)).unwrap();
    let md = s.model_description.clone();
    assert_eq!(md.fmi_version, FmiVersion::V3);
    assert!(md.can_get_and_set_fmu_state && md.provides_directional_derivative);
    assert!(!md.can_interpolate_inputs);
    let shape = md.variable("rod.shape.x").unwrap();
    assert!(shape.dimensions.len() == 1 && shape.dimensions[0] > 1);
    assert_eq!(shape.var_type, VarType::Real);
    assert_eq!(
        md.variable("time").unwrap().causality,
        fmu_harness::slave::Causality::Independent
    );
    s.instantiate("rod", false).unwrap();
    s.setup_experiment(None, 0.0, Some(1.0)).unwrap();
    s.enter_initialization_mode().unwrap();
    s.exit_initialization_mode().unwrap();
    let fx = md.variable("pin.fx").unwrap().value_reference;
    let e = s
        .set_real_input_derivatives(&[fx], &[1], &[1.0])
        .unwrap_err();
    assert!(matches!(e, SlaveError::NotInFmi3 { .. }), "{e}");
    assert!(
        e.to_string().contains("FMI 3.0 has no such function"),
        "{e}"
    );
    // an array read whole, and a refused call named in FMI 3.0's words
    let values = s.get_real(&[shape.value_reference]).unwrap();
    assert_eq!(values.len(), shape.value_count());
    let e = s.get_real(&[shape.value_reference + 1]).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("fmi3GetFloat64 returned fmi3Error"),
        "{e}"
    );
    s.do_step(0.0, 1e-3, true).unwrap();
    assert!(!s.terminated().unwrap());
    assert_eq!(s.last_successful_time().unwrap(), 1e-3);
}

/// The split slider-crank by connections (held inputs), each unit of `version`.
fn connections(dir: &Path, version: u32) -> (System, PathBuf) {
    let text = format!(
        r#"stop_time = 0.05
step = {{ size = 1e-3 }}
algorithm = "gauss-seidel"
order = ["crank", "rod"]
extrapolation = "none"
connections = [
  "crank.crank.tip.x -> rod.pin_x.drive.position",
  "crank.crank.tip.y -> rod.pin_y.drive.position",
  {{ from = "rod.pin_x.force", to = "crank.pin.fx", factor = -1.0 }},
  {{ from = "rod.pin_y.force", to = "crank.pin.fy", factor = -1.0 }},
]
[[unit]]
name = "crank"
fmu = "{}"
start = {{ "crank.rho" = 55400.0 }}
[[unit]]
name = "rod"
fmu = "{}"
"#,
        unit(dir, "slider_crank_split_crank", version).display(),
        unit(dir, "slider_crank_split_rod", version).display(),
    );
    let path = dir.join(format!("connections.v{version}.toml"));
    std::fs::write(&path, &text).unwrap();
    (System::from_toml_str(&text, &path).unwrap(), path)
}

#[test]
fn cosim_by_connections_gives_the_fmi2_units_csv_bit_for_bit() {
    let dir = scratch("fmi3_master_connections");
    let (s2, p2) = connections(&dir, 2);
    let (s3, p3) = connections(&dir, 3);
    let (r2, _) = cosim::run(&s2, &p2).unwrap();
    let (r3, _) = cosim::run(&s3, &p3).unwrap();
    assert_eq!(r3.rows.len(), 51);
    assert!(r3.columns.contains(&"rod.rod.shape.y[1]".to_string()));
    assert_eq!(r3.csv(), r2.csv());
}

/// The split slider-crank joined at the pin, the crank unit of `crank` and the rod's of `rod`:
/// the slider's position at every communication point.
fn joint(dir: &Path, crank: u32, rod: u32) -> Vec<f64> {
    let start = "\"solver.adaptive\" = false, \"solver.max_step\" = 1e-3";
    let text = format!(
        r#"stop_time = 0.1
step = {{ size = 1e-3 }}
outputs = ["rod.slider.position"]
[[joint]]
name = "pin"
type = "revolute"
frames = ["crank.pin", "rod.pin"]
[[unit]]
name = "crank"
fmu = "{}"
start = {{ {start} }}
[[unit]]
name = "rod"
fmu = "{}"
start = {{ {start} }}
"#,
        unit(dir, "slider_crank_split_crank", crank).display(),
        unit(dir, "slider_crank_split_rod_force", rod).display(),
    );
    let path = dir.join(format!("joint.{crank}{rod}.toml"));
    std::fs::write(&path, &text).unwrap();
    let system = System::from_toml_str(&text, &path).unwrap();
    let (results, summary) = cosim::run(&system, &path).unwrap();
    assert_eq!(summary.joints.unwrap().refusals, 0);
    results.rows.iter().map(|r| r[1]).collect()
}

#[test]
fn the_pin_joint_couples_fmi3_units_near_the_fmi2_coupling() {
    let dir = scratch("fmi3_master_joint");
    let v2 = joint(&dir, 2, 2);
    let differs = |other: &[f64]| {
        assert_eq!(other.len(), v2.len());
        other
            .iter()
            .zip(&v2)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    let both = differs(&joint(&dir, 3, 3));
    let mixed = differs(&joint(&dir, 2, 3));
    println!("slider position against the 2.0 coupling over 0.1 s: both 3.0 {both:.2e} m, mixed {mixed:.2e} m");
    // measured: 1.8e-8 m and 3.8e-7 m over 0.1 s (the reasons: docs/fmi-versions.md)
    assert!(both > 0.0 && both < 1e-7, "{both:e}");
    assert!(both < mixed && mixed < 1e-5, "{mixed:e}");
}
