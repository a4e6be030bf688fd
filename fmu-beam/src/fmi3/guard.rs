//! The guard of the FMI 3.0 exports: the 2.0 layer's ([`guard_with`]: null check, the
//! call-sequence check, `catch_unwind`, the failure's message to the log) over this layer's
//! [`Instance`], with the status mapped to `fmi3Status` (the values agree, 0 to 4). Nothing
//! unwinds across the C boundary and nothing global is touched.

use super::super::fmi2::guard::{guard_with, panic_text, Fault, Guarded};
use super::instance::Instance;
use super::logger::Logger;
use super::state_machine::{check, Call, State};
use super::types::{fmi3Instance, fmi3Status};
use crate::fmi2_types::fmi2Status;
use std::panic::{catch_unwind, AssertUnwindSafe};

impl Guarded for Instance {
    type Call = Call;

    fn check(&self, call: Call) -> Result<(), Fault> {
        check(self.state, call)
    }

    fn name(call: Call) -> &'static str {
        call.name()
    }

    fn report(&self, status: fmi2Status, message: &str) {
        self.logger.status(status3(status), message);
    }

    fn panicked(&mut self) -> &'static str {
        self.state = State::Error;
        "call fmi3Reset, fmi3SetFMUState or fmi3FreeInstance"
    }
}

/// The FMI 3.0 status of the same value (fmi2Pending, never returned, maps to fmi3Error).
pub fn status3(s: fmi2Status) -> fmi3Status {
    match s {
        fmi2Status::fmi2OK => fmi3Status::fmi3OK,
        fmi2Status::fmi2Warning => fmi3Status::fmi3Warning,
        fmi2Status::fmi2Discard => fmi3Status::fmi3Discard,
        fmi2Status::fmi2Error | fmi2Status::fmi2Pending => fmi3Status::fmi3Error,
        fmi2Status::fmi2Fatal => fmi3Status::fmi3Fatal,
    }
}

/// Runs `f` on the instance behind `c` if `call` is legal in its state.
///
/// # Safety
/// `c` is NULL or an instance returned by fmi3InstantiateCoSimulation and not yet freed, used
/// by one thread at a time (as the standard requires of the importer).
pub unsafe fn guard(
    c: fmi3Instance,
    call: Call,
    f: impl FnOnce(&mut Instance) -> Result<(), Fault>,
) -> fmi3Status {
    // SAFETY: the same contract.
    status3(unsafe { guard_with(c, call, f) })
}

/// fmi3InstantiateCoSimulation: builds the instance with `f`, or logs why not and returns NULL.
pub fn guard_instantiate(
    logger: Logger,
    f: impl FnOnce(Logger) -> Result<Instance, Fault>,
) -> fmi3Instance {
    let outcome = catch_unwind(AssertUnwindSafe(|| f(logger.clone())));
    let message = match outcome {
        Ok(Ok(instance)) => return Box::into_raw(Box::new(instance)).cast(),
        Ok(Err(fault)) => format!("fmi3InstantiateCoSimulation: {}", fault.message),
        Err(payload) => format!(
            "fmi3InstantiateCoSimulation: internal error (Rust panic: {})",
            panic_text(&*payload)
        ),
    };
    logger.status(fmi3Status::fmi3Error, &message);
    std::ptr::null_mut()
}
