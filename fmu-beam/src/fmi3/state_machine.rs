//! The co-simulation state machine of FMI 3.0 (standard §4.2.1) as this unit uses it: no event
//! mode (`hasEventMode = false`), no configuration mode (no structural parameters), no
//! intermediate update. Which call is legal in which state is one table ([`Call::allowed`]),
//! checked in one place ([`check`]).
//!
//! `StepDiscarded` is entered when fmi3DoStep returns fmi3Discard with terminateSimulation =
//! true (no retry can get past the failure); a Discard a smaller step may overcome leaves the
//! instance in `StepMode`, back at the step's start. `Error` stands for the standard's error
//! reaction: only fmi3Reset, fmi3SetFMUState, the getters and fmi3FreeInstance are left.

use super::super::fmi2::guard::Fault;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum State {
    Instantiated,
    InitializationMode,
    StepMode,
    StepDiscarded,
    Terminated,
    Error,
}

impl State {
    const fn bit(self) -> u8 {
        1 << self as u8
    }
}

/// Every function that takes an instance; `Unsupported` stands for the functions of the
/// standard this unit refuses in every state (each with its own message).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Call {
    SetDebugLogging,
    EnterInitializationMode,
    ExitInitializationMode,
    Terminate,
    Reset,
    /// A getter, by its C name (fmi3GetFloat64 ...).
    Get(&'static str),
    /// A setter, by its C name.
    Set(&'static str),
    GetFMUState,
    SetFMUState,
    FreeFMUState,
    SerializedFMUStateSize,
    SerializeFMUState,
    DeserializeFMUState,
    GetDirectionalDerivative,
    DoStep,
    /// A function the unit does not provide, by its C name.
    Unsupported(&'static str),
}

use State as S;

const INSTANTIATED: u8 = S::Instantiated.bit();
const INIT: u8 = S::InitializationMode.bit();
const STEPPING: u8 = S::StepMode.bit() | S::StepDiscarded.bit();
const TERMINATED: u8 = S::Terminated.bit();
const ERROR: u8 = S::Error.bit();
const ANY: u8 = INSTANTIATED | INIT | STEPPING | TERMINATED | ERROR;

impl Call {
    /// The C name, for messages.
    pub fn name(self) -> &'static str {
        use Call as C;
        match self {
            C::SetDebugLogging => "fmi3SetDebugLogging",
            C::EnterInitializationMode => "fmi3EnterInitializationMode",
            C::ExitInitializationMode => "fmi3ExitInitializationMode",
            C::Terminate => "fmi3Terminate",
            C::Reset => "fmi3Reset",
            C::Get(name) | C::Set(name) => name,
            C::GetFMUState => "fmi3GetFMUState",
            C::SetFMUState => "fmi3SetFMUState",
            C::FreeFMUState => "fmi3FreeFMUState",
            C::SerializedFMUStateSize => "fmi3SerializedFMUStateSize",
            C::SerializeFMUState => "fmi3SerializeFMUState",
            C::DeserializeFMUState => "fmi3DeserializeFMUState",
            C::GetDirectionalDerivative => "fmi3GetDirectionalDerivative",
            C::DoStep => "fmi3DoStep",
            C::Unsupported(name) => name,
        }
    }

    /// The states in which the call is legal (a mask of [`State`] bits).
    ///
    /// As in the 2.0 unit, fmi3GetFMUState is refused in `Error` (a state taken from an
    /// instance that failed is not one to return to), and fmi3DoStep is taken in
    /// `StepDiscarded` only to say why the unit ended.
    pub fn allowed(self) -> u8 {
        use Call as C;
        match self {
            C::SetDebugLogging | C::Reset | C::Unsupported(_) => ANY,
            C::EnterInitializationMode => INSTANTIATED,
            C::ExitInitializationMode => INIT,
            C::Terminate => STEPPING,
            C::Get(_) | C::GetDirectionalDerivative => INIT | STEPPING | TERMINATED | ERROR,
            C::Set(_) => INSTANTIATED | INIT | S::StepMode.bit(),
            C::GetFMUState => INSTANTIATED | INIT | STEPPING | TERMINATED,
            C::SetFMUState
            | C::FreeFMUState
            | C::SerializedFMUStateSize
            | C::SerializeFMUState
            | C::DeserializeFMUState => ANY,
            C::DoStep => STEPPING,
        }
    }
}

/// Refuses a call that is illegal in `state` (fmi3Error; the state does not change).
pub fn check(state: State, call: Call) -> Result<(), Fault> {
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
        assert!(check(S::StepMode, Call::DoStep).is_ok());
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
    fn setters_not_after_a_failure_or_the_end() {
        for s in [S::StepDiscarded, S::Terminated, S::Error] {
            assert!(check(s, Call::Set("fmi3SetFloat64")).is_err(), "{s:?}");
        }
    }
}
