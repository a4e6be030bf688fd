//! `fmu-harness simulate` shows what a unit warns about on standard error, as it runs (a unit's
//! fmi2Warning messages went nowhere before: a motion drive that turned a beam at
//! initialization did so silently), and the CSV on standard output stays clean.

use crate::common;
use common::*;

#[test]
fn simulate_prints_the_unit_s_warnings_on_standard_error() {
    let dir = scratch("simulate_warnings");
    let scene = dir.join("driven.toml");
    std::fs::write(
        &scene,
        r#"
name = "driven"
[[beam]]
name = "arm"
length = 0.5
elements = 2
material = { rho = 2700.0, E = 7e10 }
section = { shape = "rectangle", a = 0.02, b = 0.01 }
[[joint]]
name = "hinge"
type = "revolute"
frames = ["world", "arm.a"]
drive = { kind = "motion", law = "table", table = [[0.0, 0.5], [1.0, 0.6]] }
"#,
    )
    .unwrap();
    let fmu = dir.join("driven.fmu");
    let r = harness(&[
        "package".as_ref(),
        scene.as_os_str(),
        "-o".as_ref(),
        fmu.as_os_str(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let r = harness(&[
        "simulate".as_ref(),
        fmu.as_os_str(),
        "--stop".as_ref(),
        "0.01".as_ref(),
        "--step".as_ref(),
        "0.01".as_ref(),
        "--output".as_ref(),
        "hinge.angle".as_ref(),
    ]);
    assert!(r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(err.matches("warning from the FMU: ").count(), 1, "{err}");
    assert!(
        err.contains("initialization moved beam \"arm\" by 0 m, turned by 0.5 rad")
            && err.contains("joint \"hinge\""),
        "{err}"
    );
    let csv = String::from_utf8_lossy(&r.stdout);
    assert_eq!(csv.lines().next(), Some("time,hinge.angle"), "{csv}");
    assert_eq!(csv.lines().count(), 3, "{csv}");
}
