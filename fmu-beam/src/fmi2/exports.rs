//! Every function of the FMI 2.0 co-simulation interface, exported under its C name. Each is a
//! line or two: pointers become slices or values (NULL refused with a message) and the call
//! goes through [`guard`] to a safe [`Instance`] method.

#![allow(non_snake_case)]

use super::fmu_state;
use super::guard::{guard, guard_free, guard_instantiate, put, slice, slice_mut, text, texts};
use super::instance::Instance;
use super::state_machine::Call;
use super::types::*;
use std::os::raw::c_char;

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    let on = loggingOn != fmi2False;
    unsafe {
        guard(c, Call::SetDebugLogging, |s| {
            s.set_debug_logging(on, &texts(categories, nCategories, "categories")?)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    unsafe {
        guard_instantiate(functions, instanceName, loggingOn != fmi2False, |logger| {
            let guid = text(fmuGUID, "fmuGUID")?;
            let location = text(fmuResourceLocation, "fmuResourceLocation")?;
            Instance::instantiate(fmuType, &guid, &location, logger)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    unsafe { guard_free::<Instance>(c) }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    let tolerance = (toleranceDefined != fmi2False).then_some(tolerance);
    let stop = (stopTimeDefined != fmi2False).then_some(stopTime);
    unsafe {
        guard(c, Call::SetupExperiment, |s| {
            s.setup_experiment(tolerance, startTime, stop)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    unsafe {
        guard(c, Call::EnterInitializationMode, |s| {
            s.enter_initialization_mode()
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    unsafe {
        guard(c, Call::ExitInitializationMode, |s| {
            s.exit_initialization_mode()
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    unsafe { guard(c, Call::Terminate, |s| s.terminate()) }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    unsafe { guard(c, Call::Reset, |s| s.reset()) }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    unsafe {
        guard(c, Call::GetReal, |s| {
            s.get_real(slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    unsafe {
        guard(c, Call::GetInteger, |s| {
            s.get_integer(slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    unsafe {
        guard(c, Call::GetBoolean, |s| {
            s.get_boolean(slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    unsafe {
        guard(c, Call::GetString, |s| {
            slice_mut(value, nvr, "value")?;
            s.string_access(slice(vr, nvr, "vr")?)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    unsafe {
        guard(c, Call::SetReal, |s| {
            s.set_real(slice(vr, nvr, "vr")?, slice(value, nvr, "value")?)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    unsafe {
        guard(c, Call::SetInteger, |s| {
            s.set_integer(slice(vr, nvr, "vr")?, slice(value, nvr, "value")?)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    unsafe {
        guard(c, Call::SetBoolean, |s| {
            s.set_boolean(slice(vr, nvr, "vr")?, slice(value, nvr, "value")?)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    unsafe {
        guard(c, Call::SetString, |s| {
            slice(value, nvr, "value")?;
            s.string_access(slice(vr, nvr, "vr")?)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    unsafe {
        guard(c, Call::GetFMUstate, |s| {
            fmu_state::store(FMUstate, s.get_fmu_state())
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    unsafe {
        guard(c, Call::SetFMUstate, |s| {
            s.set_fmu_state(fmu_state::borrow(FMUstate)?)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    unsafe { guard(c, Call::FreeFMUstate, |_| fmu_state::free(FMUstate)) }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    unsafe {
        guard(c, Call::SerializedFMUstateSize, |s| {
            let bytes = s.serialize_fmu_state(fmu_state::borrow(FMUstate)?);
            put(size, bytes.len(), "size")
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    unsafe {
        guard(c, Call::SerializeFMUstate, |s| {
            let bytes = s.serialize_fmu_state(fmu_state::borrow(FMUstate)?);
            fmu_state::copy_out(
                &bytes,
                slice_mut(serializedState.cast::<u8>(), size, "serializedState")?,
            )
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    unsafe {
        guard(c, Call::DeSerializeFMUstate, |s| {
            let bytes = slice(serializedState.cast::<u8>(), size, "serializedState")?;
            fmu_state::store(FMUstate, s.deserialize_fmu_state(bytes)?)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    vUnknown_ref: *const fmi2ValueReference,
    nUnknown: usize,
    vKnown_ref: *const fmi2ValueReference,
    nKnown: usize,
    dvKnown: *const fmi2Real,
    dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    unsafe {
        guard(c, Call::GetDirectionalDerivative, |s| {
            // copied first: a master may pass overlapping arrays (dvKnown = dvUnknown)
            let unknowns = slice(vUnknown_ref, nUnknown, "vUnknown_ref")?.to_vec();
            let knowns = slice(vKnown_ref, nKnown, "vKnown_ref")?.to_vec();
            let dv = slice(dvKnown, nKnown, "dvKnown")?.to_vec();
            let d = s.get_directional_derivative(&unknowns, &knowns, &dv)?;
            slice_mut(dvUnknown, nUnknown, "dvUnknown")?.copy_from_slice(&d);
            Ok(())
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    unsafe {
        guard(c, Call::SetRealInputDerivatives, |s| {
            s.set_real_input_derivatives(
                slice(vr, nvr, "vr")?,
                slice(order, nvr, "order")?,
                slice(value, nvr, "value")?,
            )
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *mut fmi2Real,
) -> fmi2Status {
    unsafe {
        guard(c, Call::GetRealOutputDerivatives, |s| {
            s.get_real_output_derivatives()
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    unsafe {
        guard(c, Call::DoStep, |s| {
            s.do_step(currentCommunicationPoint, communicationStepSize)
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    unsafe { guard(c, Call::CancelStep, |s| s.cancel_step()) }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Status,
) -> fmi2Status {
    unsafe {
        guard(c, Call::GetStatus, |s| {
            put(value, s.get_status(kind)?, "value")
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    unsafe {
        guard(c, Call::GetRealStatus, |s| {
            put(value, s.get_real_status(kind)?, "value")
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Integer,
) -> fmi2Status {
    unsafe {
        guard(c, Call::GetIntegerStatus, |s| {
            put(value, s.get_integer_status(kind)?, "value")
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    unsafe {
        guard(c, Call::GetBooleanStatus, |s| {
            put(value, s.get_boolean_status(kind)?, "value")
        })
    }
}

/// # Safety
/// The FMI 2.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    _value: *mut fmi2String,
) -> fmi2Status {
    unsafe { guard(c, Call::GetStringStatus, |s| s.get_string_status(kind)) }
}
