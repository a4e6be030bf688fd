//! The master's `Slave` runs the packaged C1 unit (the real engine, target/release/libfmu_beam.so:
//! `cargo build --release --workspace` first): the initial tip deflection is C1's 0.01 m, 0.5 s
//! at h = 1e-3 completes, an FMU state rolls back bit for bit, a refused call carries the FMU's
//! message, and `fmu-harness simulate` writes the CSV.

use crate::common;
use common::*;
use fmu_harness::fmi2_binding::{FmuState, Status};
use fmu_harness::slave::{Slave, SlaveError};
use std::path::PathBuf;

/// C1 packaged with the release engine into this test's scratch directory.
fn c1_fmu(name: &str) -> PathBuf {
    let dir = scratch(name);
    let out = dir.join("cantilever_free_vibration.fmu");
    let r = harness(&[
        "package".as_ref(),
        c1_path().as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(
        r.status.success(),
        "packaging C1 with the release engine failed (run `cargo build --release --workspace`): {}",
        String::from_utf8_lossy(&r.stderr)
    );
    out
}

fn initialized(fmu: &std::path::Path, stop: f64) -> Slave {
    let mut s = Slave::load(fmu).expect("load C1");
    s.instantiate("c1", true).expect("instantiate");
    let tol = s.model_description.default_experiment.tolerance;
    s.setup_experiment(tol, 0.0, Some(stop)).unwrap();
    s.enter_initialization_mode().unwrap();
    s.exit_initialization_mode().unwrap();
    s
}

#[test]
fn c1_starts_at_its_tip_displacement_and_runs_half_a_second() {
    let fmu = c1_fmu("slave_c1_run");
    let mut s = initialized(&fmu, 0.5);
    let tip = s
        .model_description
        .variable("beam.tip.deflection")
        .unwrap()
        .value_reference;
    let extracted = s.directory().to_path_buf();
    assert!(extracted.join("modelDescription.xml").is_file());

    let y0 = s.get_real(&[tip]).unwrap()[0];
    assert!((y0 - 0.01).abs() < 1e-12, "initial tip deflection {y0}");
    let h = 1e-3;
    let mut min = y0;
    for n in 0..500 {
        s.do_step(n as f64 * h, h, true).unwrap();
        let y = s.get_real(&[tip]).unwrap()[0];
        assert!(
            y.is_finite() && y.abs() <= 0.0101,
            "t = {}: {y}",
            (n + 1) as f64 * h
        );
        min = min.min(y);
    }
    // C1's first period is about 0.12 s: by 0.5 s the tip has swung to the other side.
    assert!(min < -0.009, "the tip never swung back: min {min}");
    assert_eq!(s.terminate().unwrap(), Status::Ok);
    drop(s);
    assert!(!extracted.exists(), "{} left behind", extracted.display());
}

#[test]
fn an_fmu_state_rolls_a_step_back_bit_for_bit() {
    let fmu = c1_fmu("slave_c1_state");
    let mut s = initialized(&fmu, 1.0);
    let tip = s
        .model_description
        .variable("beam.tip.deflection")
        .unwrap()
        .value_reference;
    s.do_step(0.0, 1e-3, false).unwrap();
    let mut state = FmuState::empty();
    s.get_fmu_state(&mut state).unwrap();
    s.do_step(1e-3, 1e-3, false).unwrap();
    let first = s.get_real(&[tip]).unwrap()[0];
    s.set_fmu_state(&state).unwrap();
    s.do_step(1e-3, 1e-3, false).unwrap();
    assert_eq!(s.get_real(&[tip]).unwrap()[0].to_bits(), first.to_bits());
    s.free_fmu_state(&mut state).unwrap();
    assert!(state.is_empty());
}

#[test]
fn do_step_before_initialization_is_refused_with_the_logged_message() {
    let fmu = c1_fmu("slave_c1_refused");
    let mut s = Slave::load(&fmu).unwrap();
    s.instantiate("c1", true).unwrap();
    match s.do_step(0.0, 1e-3, true) {
        Err(SlaveError::Call {
            function,
            status,
            messages,
        }) => {
            assert_eq!(function, "fmi2DoStep");
            assert_eq!(status, Status::Error);
            assert!(
                messages
                    .iter()
                    .any(|m| m.status == Status::Error
                        && m.message.contains("illegal call sequence")),
                "{messages:?}"
            );
        }
        other => panic!("fmi2DoStep before initialization: {other:?}"),
    }
}

#[test]
fn simulate_writes_time_and_the_chosen_outputs() {
    let fmu = c1_fmu("slave_c1_simulate");
    let csv = fmu.with_extension("csv");
    let r = harness(&[
        "simulate".as_ref(),
        fmu.as_os_str(),
        "--stop".as_ref(),
        "0.01".as_ref(),
        "--step".as_ref(),
        "0.001".as_ref(),
        "--output".as_ref(),
        "beam.tip.deflection,solver.steps".as_ref(),
        "-o".as_ref(),
        csv.as_os_str(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "time,beam.tip.deflection,solver.steps");
    assert_eq!(lines.len(), 12, "{text}");
    let last: Vec<f64> = lines[11].split(',').map(|x| x.parse().unwrap()).collect();
    assert!(
        (last[0] - 0.01).abs() < 1e-15 && last[1] < 0.01,
        "{}",
        lines[11]
    );
}
