//! Issue 32: a failed step whose cause the unit cannot see says so. C1 (a cantilever with no
//! input, no spin and small deflections) under a work budget of one internal step cannot pass a
//! 10 ms communication step: the Discard names none of the causes the unit checks (an input on
//! a small effective inertia, a spin near the bending frequency, a runaway deflection), says the
//! cause is unknown and gives the step and its time. The causes that hold are tested in
//! `c4_spin_up.rs` (spin) and `tests/test_diagnosis.py` (inputs on small inertias).

use crate::common;

use common::scene;
use fmu_beam::{Engine, EngineError};

#[test]
fn a_failure_without_a_cause_the_unit_sees_says_the_cause_is_unknown() {
    let mut e = Engine::new(scene("cantilever_free_vibration.toml"));
    let budget = common::vr(&e, "solver.step_budget");
    e.exit_initialization().unwrap();
    e.set_integer(budget, 1).unwrap();
    let err = e.do_step(0.0, 1e-2).unwrap_err();
    assert!(
        matches!(err.cause(), EngineError::WorkBudget { .. }),
        "{err}"
    );
    assert!(err.is_discard() && !err.ends_run());
    let text = err.to_string();
    assert!(
        text.contains("the cause is unknown (the step from t = 0 s of 1.000e-2 s failed"),
        "{text}"
    );
    assert!(!text.contains("Cause found"), "{text}");
}
