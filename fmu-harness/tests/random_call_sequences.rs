//! Random FMI call sequences through the project's own master (issue 7): illegal orders,
//! unknown value references, NaN and negative steps, wrong communication points, calls after
//! terminate and after another instance of the same unit was freed. Every call returns a
//! status or a refusal with the FMU's message, nothing crashes, a call refused with fmi2Error
//! changes no value the instance shows (issue 35), and a fresh instance afterwards runs bit
//! for bit as one that never saw them. (Null pointers are sent straight to the exports in
//! fmu-beam/src/fmi2/abi_tests.rs; arrays of mismatched length cannot be sent: the binding
//! refuses to build such a call, and a C master that did would overrun its own arrays.)

use crate::common;
use common::*;
use fmu_harness::fmi2_binding::{FmuState, Status};
use fmu_harness::slave::{Slave, SlaveError};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use std::path::{Path, PathBuf};

fn c1_fmu() -> PathBuf {
    let dir = scratch("random_call_sequences");
    let out = dir.join("cantilever_free_vibration.fmu");
    let r = harness(&[
        "package".as_ref(),
        c1_path().as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    out
}

fn fresh_run(fmu: &Path) -> Vec<u64> {
    let mut s = Slave::load(fmu).unwrap();
    s.instantiate("fresh", false).unwrap();
    s.setup_experiment(None, 0.0, None).unwrap();
    s.enter_initialization_mode().unwrap();
    s.exit_initialization_mode().unwrap();
    let tip = s
        .model_description
        .variable("beam.tip.deflection")
        .unwrap()
        .value_reference;
    let mut bits = Vec::new();
    for k in 0..20 {
        s.do_step(k as f64 * 1e-3, 1e-3, false).unwrap();
        bits.push(s.get_real(&[tip]).unwrap()[0].to_bits());
    }
    bits
}

#[derive(Debug, Clone)]
enum Call {
    Setup(f64),
    Enter,
    Exit,
    DoStep(f64, bool),
    GetReal(u32),
    SetReal(u32, f64),
    /// Several values in one call (all or nothing).
    SetReals(Vec<(u32, f64)>),
    GetInteger(u32),
    SetBoolean(u32, bool),
    StateRoundTrip,
    Reset,
    Terminate,
    FreeTheOther,
}

fn call() -> impl Strategy<Value = Call> {
    let value = prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(-1.0),
        Just(0.0),
        Just(1e-3),
        Just(1e300),
        any::<f64>()
    ];
    prop_oneof![
        value.clone().prop_map(Call::Setup),
        Just(Call::Enter),
        Just(Call::Exit),
        (
            prop_oneof![
                Just(1e-3),
                Just(-1e-3),
                Just(0.0),
                Just(f64::NAN),
                Just(1e-2)
            ],
            any::<bool>()
        )
            .prop_map(|(h, t)| Call::DoStep(h, t)),
        (0u32..60).prop_map(Call::GetReal),
        (0u32..60, value.clone()).prop_map(|(v, x)| Call::SetReal(v, x)),
        prop::collection::vec(
            (
                0u32..60,
                prop_oneof![Just(2e-3), Just(1e-4), Just(0.5), value]
            ),
            2..5
        )
        .prop_map(Call::SetReals),
        (0u32..60).prop_map(Call::GetInteger),
        (0u32..60, any::<bool>()).prop_map(|(v, b)| Call::SetBoolean(v, b)),
        Just(Call::StateRoundTrip),
        Just(Call::Reset),
        Just(Call::Terminate),
        Just(Call::FreeTheOther),
    ]
}

/// What the instance shows: every Real and Integer variable it lets be read now (a refused
/// read is `None`), as bits.
fn observe(a: &mut Slave) -> Vec<Option<u64>> {
    let mut seen = Vec::new();
    for vr in 0u32..60 {
        seen.push(a.get_real(&[vr]).ok().map(|v| v[0].to_bits()));
        seen.push(a.get_integer(&[vr]).ok().map(|v| v[0] as u64));
    }
    let _ = a.take_messages();
    seen
}

#[test]
fn random_sequences_through_the_master_never_crash() {
    let fmu = c1_fmu();
    let reference = fresh_run(&fmu);
    let mut runner = TestRunner::new(Config {
        cases: 60,
        failure_persistence: None,
        ..Config::default()
    });
    let counts = std::cell::RefCell::new((0usize, 0usize));
    let checked = std::cell::Cell::new(0usize);
    runner
        .run(&prop::collection::vec(call(), 1..30), |calls| {
            let mut a = Slave::load(&fmu).unwrap();
            a.instantiate("a", true).unwrap();
            let mut other = Some({
                let mut b = Slave::load(&fmu).unwrap();
                b.instantiate("b", false).unwrap();
                b
            });
            let mut t = 0.0;
            // a refusal must be an error status with the FMU's message
            let check = |r: Result<Status, SlaveError>| -> Result<bool, TestCaseError> {
                match r {
                    Ok(_) => Ok(true),
                    Err(SlaveError::Call {
                        function,
                        status,
                        messages,
                    }) => {
                        prop_assert!(
                            !messages.is_empty(),
                            "{function} returned {status} without a message"
                        );
                        Ok(false)
                    }
                    Err(other) => Err(TestCaseError::fail(format!("unexpected: {other}"))),
                }
            };
            for c in &calls {
                let before = observe(&mut a);
                let refused_with_error = std::cell::Cell::new(false);
                let check = |r: Result<Status, SlaveError>| {
                    if let Err(SlaveError::Call {
                        status: Status::Error,
                        ..
                    }) = &r
                    {
                        refused_with_error.set(true);
                    }
                    check(r)
                };
                let ok = match c {
                    Call::Setup(t0) => check(a.setup_experiment(None, *t0, None))?,
                    Call::Enter => check(a.enter_initialization_mode())?,
                    Call::Exit => check(a.exit_initialization_mode())?,
                    Call::DoStep(h, right) => {
                        let at = if *right { t } else { t + 0.5 };
                        let ok = check(a.do_step(at, *h, false))?;
                        if ok {
                            t = at + h;
                        }
                        ok
                    }
                    Call::GetReal(v) => check(a.get_real(&[*v]).map(|_| Status::Ok))?,
                    Call::SetReal(v, x) => check(a.set_real(&[*v], &[*x]))?,
                    Call::SetReals(vx) => {
                        let (vr, x): (Vec<u32>, Vec<f64>) = vx.iter().copied().unzip();
                        check(a.set_real(&vr, &x))?
                    }
                    Call::GetInteger(v) => check(a.get_integer(&[*v]).map(|_| Status::Ok))?,
                    Call::SetBoolean(v, b) => check(a.set_boolean(&[*v], &[*b]))?,
                    Call::StateRoundTrip => {
                        let mut s = FmuState::empty();
                        let ok = check(a.get_fmu_state(&mut s))? && check(a.set_fmu_state(&s))?;
                        let _ = a.free_fmu_state(&mut s);
                        ok
                    }
                    Call::Reset => {
                        t = 0.0;
                        check(a.reset())?
                    }
                    Call::Terminate => check(a.terminate())?,
                    Call::FreeTheOther => {
                        other = None;
                        true
                    }
                };
                // a refusal changes nothing: every value readable after it is as before (an
                // instance that went to state Error shows none)
                if refused_with_error.get() && !matches!(c, Call::FreeTheOther) {
                    let after = observe(&mut a);
                    for (k, (x, y)) in before.iter().zip(&after).enumerate() {
                        if y.is_some() {
                            prop_assert_eq!(x, y, "{:?} refused but changed value {}", c, k / 2);
                        }
                    }
                    checked.set(checked.get() + 1);
                }
                let mut n = counts.borrow_mut();
                if ok {
                    n.0 += 1
                } else {
                    n.1 += 1
                }
            }
            drop(other);
            Ok(())
        })
        .unwrap();
    let (accepted, refused) = *counts.borrow();
    println!(
        "{accepted} calls accepted, {refused} refused with an error status ({} checked for \
         changes)",
        checked.get()
    );
    assert!(refused > 100 && accepted > 100 && checked.get() > 100);
    assert_eq!(
        fresh_run(&fmu),
        reference,
        "a fresh instance after the random calls differs"
    );
}
