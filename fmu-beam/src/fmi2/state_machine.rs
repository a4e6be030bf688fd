//! The co-simulation state machine of FMI 2.0 (standard §4.2.4): which call is legal in which
//! state, in one table ([`Call::allowed`]) checked in one place ([`check`]).
//!
//! `StepInProgress` does not exist (steps are synchronous) and `StepCanceled` is never entered;
//! `Fatal` is never entered either, because nothing one instance does can corrupt another
//! (a Rust panic inside a call puts only that instance into `Error`).

use super::guard::Fault;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelState {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    StepCanceled,
    Terminated,
    Error,
    Fatal,
}

impl ModelState {
    const fn bit(self) -> u16 {
        1 << self as u16
    }
}

/// Every function that takes an instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Call {
    SetDebugLogging,
    /// The table's row for fmi2FreeInstance, legal in every state: `guard::guard_free` frees without
    /// asking the table (a NULL or fatal instance is freed too); the row keeps the table whole.
    #[allow(dead_code)]
    FreeInstance,
    SetupExperiment,
    EnterInitializationMode,
    ExitInitializationMode,
    Terminate,
    Reset,
    GetReal,
    GetInteger,
    GetBoolean,
    GetString,
    SetReal,
    SetInteger,
    SetBoolean,
    SetString,
    GetFMUstate,
    SetFMUstate,
    FreeFMUstate,
    SerializedFMUstateSize,
    SerializeFMUstate,
    DeSerializeFMUstate,
    GetDirectionalDerivative,
    SetRealInputDerivatives,
    GetRealOutputDerivatives,
    DoStep,
    CancelStep,
    GetStatus,
    GetRealStatus,
    GetIntegerStatus,
    GetBooleanStatus,
    GetStringStatus,
}

use ModelState as S;

const INSTANTIATED: u16 = S::Instantiated.bit();
const INIT: u16 = S::InitializationMode.bit();
/// The standard's "slaveInitialized" super-state.
const STEPPING: u16 = S::StepComplete.bit() | S::StepFailed.bit() | S::StepCanceled.bit();
const TERMINATED: u16 = S::Terminated.bit();
const ERROR: u16 = S::Error.bit();
const FATAL: u16 = S::Fatal.bit();
const ANY_BUT_FATAL: u16 = INSTANTIATED | INIT | STEPPING | TERMINATED | ERROR;

impl Call {
    /// The C name, for messages.
    pub fn name(self) -> &'static str {
        use Call as C;
        match self {
            C::SetDebugLogging => "fmi2SetDebugLogging",
            C::FreeInstance => "fmi2FreeInstance",
            C::SetupExperiment => "fmi2SetupExperiment",
            C::EnterInitializationMode => "fmi2EnterInitializationMode",
            C::ExitInitializationMode => "fmi2ExitInitializationMode",
            C::Terminate => "fmi2Terminate",
            C::Reset => "fmi2Reset",
            C::GetReal => "fmi2GetReal",
            C::GetInteger => "fmi2GetInteger",
            C::GetBoolean => "fmi2GetBoolean",
            C::GetString => "fmi2GetString",
            C::SetReal => "fmi2SetReal",
            C::SetInteger => "fmi2SetInteger",
            C::SetBoolean => "fmi2SetBoolean",
            C::SetString => "fmi2SetString",
            C::GetFMUstate => "fmi2GetFMUstate",
            C::SetFMUstate => "fmi2SetFMUstate",
            C::FreeFMUstate => "fmi2FreeFMUstate",
            C::SerializedFMUstateSize => "fmi2SerializedFMUstateSize",
            C::SerializeFMUstate => "fmi2SerializeFMUstate",
            C::DeSerializeFMUstate => "fmi2DeSerializeFMUstate",
            C::GetDirectionalDerivative => "fmi2GetDirectionalDerivative",
            C::SetRealInputDerivatives => "fmi2SetRealInputDerivatives",
            C::GetRealOutputDerivatives => "fmi2GetRealOutputDerivatives",
            C::DoStep => "fmi2DoStep",
            C::CancelStep => "fmi2CancelStep",
            C::GetStatus => "fmi2GetStatus",
            C::GetRealStatus => "fmi2GetRealStatus",
            C::GetIntegerStatus => "fmi2GetIntegerStatus",
            C::GetBooleanStatus => "fmi2GetBooleanStatus",
            C::GetStringStatus => "fmi2GetStringStatus",
        }
    }

    /// The states in which the call is legal (a mask of [`ModelState`] bits).
    ///
    /// Deviation from the standard's table: fmi2GetFMUstate is refused in `Error`, since a
    /// state taken from an instance that failed is not one to return to.
    pub fn allowed(self) -> u16 {
        use Call as C;
        match self {
            C::FreeInstance => ANY_BUT_FATAL | FATAL,
            C::SetDebugLogging | C::Reset => ANY_BUT_FATAL,
            C::SetupExperiment | C::EnterInitializationMode => INSTANTIATED,
            C::ExitInitializationMode => INIT,
            C::Terminate => STEPPING,
            C::GetReal | C::GetInteger | C::GetBoolean | C::GetString => {
                INIT | STEPPING | TERMINATED | ERROR
            }
            C::SetReal | C::SetInteger | C::SetBoolean | C::SetString => {
                INSTANTIATED | INIT | S::StepComplete.bit()
            }
            C::GetFMUstate => INSTANTIATED | INIT | STEPPING | TERMINATED,
            C::SetFMUstate
            | C::FreeFMUstate
            | C::SerializedFMUstateSize
            | C::SerializeFMUstate
            | C::DeSerializeFMUstate => ANY_BUT_FATAL,
            C::GetDirectionalDerivative => INIT | STEPPING | TERMINATED | ERROR,
            C::SetRealInputDerivatives => INSTANTIATED | INIT | S::StepComplete.bit(),
            C::GetRealOutputDerivatives => STEPPING | TERMINATED | ERROR,
            // From StepFailed only to be told why the unit ended (`Instance::do_step`).
            C::DoStep => S::StepComplete.bit() | S::StepFailed.bit(),
            C::CancelStep => STEPPING,
            C::GetStatus
            | C::GetRealStatus
            | C::GetIntegerStatus
            | C::GetBooleanStatus
            | C::GetStringStatus => STEPPING | TERMINATED,
        }
    }
}

/// Refuses a call that is illegal in `state` (fmi2Error; the state does not change).
pub fn check(state: ModelState, call: Call) -> Result<(), Fault> {
    if call.allowed() & state.bit() != 0 {
        Ok(())
    } else {
        Err(Fault::refused(format!(
            "illegal call sequence: not allowed in state {state:?}"
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn do_step_only_after_initialization() {
        assert!(check(S::StepComplete, Call::DoStep).is_ok());
        for s in [
            S::Instantiated,
            S::InitializationMode,
            S::Terminated,
            S::Error,
        ] {
            assert!(check(s, Call::DoStep).is_err(), "{s:?}");
        }
    }

    #[test]
    fn free_instance_always_legal() {
        for s in [S::Instantiated, S::StepFailed, S::Error, S::Fatal] {
            assert!(check(s, Call::FreeInstance).is_ok(), "{s:?}");
        }
    }
}
