//! Every function of the FMI 3.0 standard, exported under its C name, so that any importer
//! that resolves all symbols loads the unit. Each is a line or two: pointers become slices or
//! values (NULL refused with a message) and the call goes through [`guard`] to a safe
//! [`Instance`] method. The functions of what this unit does not provide (model exchange,
//! scheduled execution, event mode, clocks, configuration mode, adjoint derivatives, output
//! derivatives, types it has no variables of) return fmi3Error with a message that says why
//! ([`unsupported!`]).
//!
//! Over 600 lines on purpose: the standard's whole list of functions, read as one list.

#![allow(non_snake_case)]

use super::super::fmi2::fmu_state;
use super::super::fmi2::guard::{guard_free, put, slice, slice_mut, text, texts, Fault};
use super::guard::{guard, guard_instantiate};
use super::instance::Instance;
use super::logger::Logger;
use super::state_machine::Call;
use super::types::*;
use crate::unit::variables::VarType;
use std::os::raw::c_char;

#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    instance: fmi3Instance,
    loggingOn: fmi3Boolean,
    nCategories: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    let on = loggingOn != fmi3False;
    unsafe {
        guard(instance, Call::SetDebugLogging, |s| {
            s.set_debug_logging(on, &texts(categories, nCategories, "categories")?)
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    _visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    eventModeUsed: fmi3Boolean,
    _earlyReturnAllowed: fmi3Boolean,
    _requiredIntermediateVariables: *const fmi3ValueReference,
    nRequiredIntermediateVariables: usize,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: Option<fmi3LogMessageCallback>,
    _intermediateUpdate: fmi3OpaqueCallback,
) -> fmi3Instance {
    let logger = Logger::new(logMessage, instanceEnvironment, loggingOn != fmi3False);
    guard_instantiate(logger, |logger| {
        // SAFETY: each is NULL or a C string, by the standard's contract.
        let (_, token, path) = unsafe {
            (
                text(instanceName, "instanceName")?,
                text(instantiationToken, "instantiationToken")?,
                text(resourcePath, "resourcePath")?,
            )
        };
        Instance::instantiate(
            &token,
            &path,
            eventModeUsed != fmi3False,
            nRequiredIntermediateVariables,
            logger,
        )
    })
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    _instanceName: fmi3String,
    _instantiationToken: fmi3String,
    _resourcePath: fmi3String,
    _visible: fmi3Boolean,
    _loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: Option<fmi3LogMessageCallback>,
) -> fmi3Instance {
    Logger::new(logMessage, instanceEnvironment, false).status(
        fmi3Status::fmi3Error,
        "fmi3InstantiateModelExchange: this FMU supports co-simulation only",
    );
    std::ptr::null_mut()
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    _instanceName: fmi3String,
    _instantiationToken: fmi3String,
    _resourcePath: fmi3String,
    _visible: fmi3Boolean,
    _loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: Option<fmi3LogMessageCallback>,
    _clockUpdate: fmi3OpaqueCallback,
    _lockPreemption: fmi3OpaqueCallback,
    _unlockPreemption: fmi3OpaqueCallback,
) -> fmi3Instance {
    Logger::new(logMessage, instanceEnvironment, false).status(
        fmi3Status::fmi3Error,
        "fmi3InstantiateScheduledExecution: this FMU supports co-simulation only",
    );
    std::ptr::null_mut()
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(instance: fmi3Instance) {
    unsafe { guard_free::<Instance>(instance) }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: fmi3Instance,
    toleranceDefined: fmi3Boolean,
    tolerance: fmi3Float64,
    startTime: fmi3Float64,
    stopTimeDefined: fmi3Boolean,
    stopTime: fmi3Float64,
) -> fmi3Status {
    let tolerance = (toleranceDefined != fmi3False).then_some(tolerance);
    let stop = (stopTimeDefined != fmi3False).then_some(stopTime);
    unsafe {
        guard(instance, Call::EnterInitializationMode, |s| {
            s.enter_initialization_mode(tolerance, startTime, stop)
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status {
    unsafe {
        guard(instance, Call::ExitInitializationMode, |s| {
            s.exit_initialization_mode()
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3Terminate(instance: fmi3Instance) -> fmi3Status {
    unsafe { guard(instance, Call::Terminate, |s| s.terminate()) }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(instance: fmi3Instance) -> fmi3Status {
    unsafe { guard(instance, Call::Reset, |s| s.reset()) }
}

/// A getter of a type the unit has variables of: every value read first, then written.
///
/// # Safety
/// As for the fmi3Get functions.
unsafe fn get<T>(
    name: &'static str,
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut T,
    n: usize,
    ty: VarType,
    convert: impl Fn(f64) -> T,
) -> fmi3Status {
    unsafe {
        guard(instance, Call::Get(name), |s| {
            let vr = slice(vr, nvr, "valueReferences")?;
            let out = slice_mut(values, n, "values")?;
            let got = s.get(vr, ty, n)?;
            for (o, v) in out.iter_mut().zip(got) {
                *o = convert(v);
            }
            Ok(())
        })
    }
}

/// A setter of a type the unit has variables of: all or nothing.
///
/// # Safety
/// As for the fmi3Set functions.
unsafe fn set<T: Copy>(
    name: &'static str,
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const T,
    n: usize,
    ty: VarType,
    convert: impl Fn(T) -> f64,
) -> fmi3Status {
    unsafe {
        guard(instance, Call::Set(name), |s| {
            let vr = slice(vr, nvr, "valueReferences")?;
            let values: Vec<f64> = slice(values, n, "values")?
                .iter()
                .map(|&v| convert(v))
                .collect();
            s.set(vr, ty, &values)
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    let (vr, nvr) = (valueReferences, nValueReferences);
    unsafe {
        get(
            "fmi3GetFloat64",
            instance,
            vr,
            nvr,
            values,
            nValues,
            VarType::Real,
            |v| v,
        )
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    let (vr, nvr) = (valueReferences, nValueReferences);
    unsafe {
        set(
            "fmi3SetFloat64",
            instance,
            vr,
            nvr,
            values,
            nValues,
            VarType::Real,
            |v| v,
        )
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    let (vr, nvr) = (valueReferences, nValueReferences);
    // the engine's integers are i32, carried exactly by f64
    unsafe {
        get(
            "fmi3GetInt32",
            instance,
            vr,
            nvr,
            values,
            nValues,
            VarType::Integer,
            |v| v as i32,
        )
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    let (vr, nvr) = (valueReferences, nValueReferences);
    unsafe {
        set(
            "fmi3SetInt32",
            instance,
            vr,
            nvr,
            values,
            nValues,
            VarType::Integer,
            f64::from,
        )
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    let (vr, nvr) = (valueReferences, nValueReferences);
    let to_bool = |v: f64| if v != 0.0 { fmi3True } else { fmi3False };
    unsafe {
        get(
            "fmi3GetBoolean",
            instance,
            vr,
            nvr,
            values,
            nValues,
            VarType::Boolean,
            to_bool,
        )
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    let (vr, nvr) = (valueReferences, nValueReferences);
    let from_bool = |b: fmi3Boolean| if b != fmi3False { 1.0 } else { 0.0 };
    unsafe {
        set(
            "fmi3SetBoolean",
            instance,
            vr,
            nvr,
            values,
            nValues,
            VarType::Boolean,
            from_bool,
        )
    }
}

/// Getters and setters of the types this FMU has no variables of: OK for no value reference,
/// else fmi3Error naming the first one (the value pointer is not touched).
macro_rules! no_variables_of {
    ($($name:ident($values:ty) => $type_name:literal;)*) => {$(
        /// # Safety
        /// The FMI 3.0 standard's contract for this function.
        #[no_mangle]
        pub unsafe extern "C" fn $name(
            instance: fmi3Instance,
            valueReferences: *const fmi3ValueReference,
            nValueReferences: usize,
            _values: $values,
            _nValues: usize,
        ) -> fmi3Status {
            let call = if stringify!($name).starts_with("fmi3Get") {
                Call::Get(stringify!($name))
            } else {
                Call::Set(stringify!($name))
            };
            unsafe {
                guard(instance, call, |s| {
                    s.no_variables_of($type_name, slice(valueReferences, nValueReferences, "valueReferences")?)
                })
            }
        }
    )*};
}

no_variables_of! {
    fmi3GetFloat32(*mut fmi3Float32) => "Float32";
    fmi3GetInt8(*mut fmi3Int8) => "Int8";
    fmi3GetUInt8(*mut fmi3UInt8) => "UInt8";
    fmi3GetInt16(*mut fmi3Int16) => "Int16";
    fmi3GetUInt16(*mut fmi3UInt16) => "UInt16";
    fmi3GetUInt32(*mut fmi3UInt32) => "UInt32";
    fmi3GetInt64(*mut fmi3Int64) => "Int64";
    fmi3GetUInt64(*mut fmi3UInt64) => "UInt64";
    fmi3GetString(*mut fmi3String) => "String";
    fmi3SetFloat32(*const fmi3Float32) => "Float32";
    fmi3SetInt8(*const fmi3Int8) => "Int8";
    fmi3SetUInt8(*const fmi3UInt8) => "UInt8";
    fmi3SetInt16(*const fmi3Int16) => "Int16";
    fmi3SetUInt16(*const fmi3UInt16) => "UInt16";
    fmi3SetUInt32(*const fmi3UInt32) => "UInt32";
    fmi3SetInt64(*const fmi3Int64) => "Int64";
    fmi3SetUInt64(*const fmi3UInt64) => "UInt64";
    fmi3SetString(*const fmi3String) => "String";
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetBinary(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _valueSizes: *mut usize,
    _values: *mut fmi3Binary,
    _nValues: usize,
) -> fmi3Status {
    let (vr, nvr) = (valueReferences, nValueReferences);
    unsafe {
        guard(instance, Call::Get("fmi3GetBinary"), |s| {
            s.no_variables_of("Binary", slice(vr, nvr, "valueReferences")?)
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetBinary(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _valueSizes: *const usize,
    _values: *const fmi3Binary,
    _nValues: usize,
) -> fmi3Status {
    let (vr, nvr) = (valueReferences, nValueReferences);
    unsafe {
        guard(instance, Call::Set("fmi3SetBinary"), |s| {
            s.no_variables_of("Binary", slice(vr, nvr, "valueReferences")?)
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetClock(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *mut fmi3Clock,
) -> fmi3Status {
    let (vr, nvr) = (valueReferences, nValueReferences);
    unsafe {
        guard(instance, Call::Get("fmi3GetClock"), |s| {
            s.no_variables_of("Clock", slice(vr, nvr, "valueReferences")?)
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetClock(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *const fmi3Clock,
) -> fmi3Status {
    let (vr, nvr) = (valueReferences, nValueReferences);
    unsafe {
        guard(instance, Call::Set("fmi3SetClock"), |s| {
            s.no_variables_of("Clock", slice(vr, nvr, "valueReferences")?)
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    unsafe {
        guard(instance, Call::GetFMUState, |s| {
            fmu_state::store(FMUState, s.get_fmu_state())
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
) -> fmi3Status {
    unsafe {
        guard(instance, Call::SetFMUState, |s| {
            s.set_fmu_state(fmu_state::borrow(FMUState)?)
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3FreeFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    unsafe { guard(instance, Call::FreeFMUState, |_| fmu_state::free(FMUState)) }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    unsafe {
        guard(instance, Call::SerializedFMUStateSize, |s| {
            let bytes = s.serialize_fmu_state(fmu_state::borrow(FMUState)?);
            put(size, bytes.len(), "size")
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    serializedState: *mut fmi3Byte,
    size: usize,
) -> fmi3Status {
    unsafe {
        guard(instance, Call::SerializeFMUState, |s| {
            let bytes = s.serialize_fmu_state(fmu_state::borrow(FMUState)?);
            fmu_state::copy_out(&bytes, slice_mut(serializedState, size, "serializedState")?)
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    instance: fmi3Instance,
    serializedState: *const fmi3Byte,
    size: usize,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    unsafe {
        guard(instance, Call::DeserializeFMUState, |s| {
            let bytes = slice(serializedState, size, "serializedState")?;
            fmu_state::store(FMUState, s.deserialize_fmu_state(bytes)?)
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
    instance: fmi3Instance,
    unknowns: *const fmi3ValueReference,
    nUnknowns: usize,
    knowns: *const fmi3ValueReference,
    nKnowns: usize,
    seed: *const fmi3Float64,
    nSeed: usize,
    sensitivity: *mut fmi3Float64,
    nSensitivity: usize,
) -> fmi3Status {
    unsafe {
        guard(instance, Call::GetDirectionalDerivative, |s| {
            // copied first: an importer may pass overlapping arrays (seed = sensitivity)
            let u = slice(unknowns, nUnknowns, "unknowns")?.to_vec();
            let k = slice(knowns, nKnowns, "knowns")?.to_vec();
            let seed = slice(seed, nSeed, "seed")?.to_vec();
            let d = s.get_directional_derivative(&u, &k, &seed, nSensitivity)?;
            slice_mut(sensitivity, nSensitivity, "sensitivity")?.copy_from_slice(&d);
            Ok(())
        })
    }
}

/// # Safety
/// The FMI 3.0 standard's contract for this function.
#[no_mangle]
pub unsafe extern "C" fn fmi3DoStep(
    instance: fmi3Instance,
    currentCommunicationPoint: fmi3Float64,
    communicationStepSize: fmi3Float64,
    _noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    eventHandlingNeeded: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
    earlyReturn: *mut fmi3Boolean,
    lastSuccessfulTime: *mut fmi3Float64,
) -> fmi3Status {
    let (t, h) = (currentCommunicationPoint, communicationStepSize);
    unsafe {
        guard(instance, Call::DoStep, |s| {
            // every output checked before the step: a refused call changes nothing
            for (p, what) in [
                (eventHandlingNeeded, "eventHandlingNeeded"),
                (terminateSimulation, "terminateSimulation"),
                (earlyReturn, "earlyReturn"),
            ] {
                slice_mut(p, 1, what)?;
            }
            slice_mut(lastSuccessfulTime, 1, "lastSuccessfulTime")?;
            let outcome = s.do_step(t, h);
            let report = match &outcome {
                Ok(report) => *report,
                Err(_) => s.after_failure(),
            };
            let terminate = if report.terminate {
                fmi3True
            } else {
                fmi3False
            };
            put(eventHandlingNeeded, fmi3False, "eventHandlingNeeded")?;
            put(terminateSimulation, terminate, "terminateSimulation")?;
            put(earlyReturn, fmi3False, "earlyReturn")?;
            put(
                lastSuccessfulTime,
                report.last_successful_time,
                "lastSuccessfulTime",
            )?;
            outcome.map(|_| ())
        })
    }
}

/// Functions of the standard this FMU does not provide: each returns fmi3Error (in any state,
/// changing nothing) with a message that says why.
macro_rules! unsupported {
    ($($name:ident($($arg:ident: $ty:ty),*) => $why:literal;)*) => {$(
        /// # Safety
        /// The FMI 3.0 standard's contract for this function.
        #[no_mangle]
        pub unsafe extern "C" fn $name(instance: fmi3Instance, $($arg: $ty),*) -> fmi3Status {
            $(let _ = $arg;)*
            unsafe {
                guard(instance, Call::Unsupported(stringify!($name)), |_| {
                    Err(Fault::refused($why))
                })
            }
        }
    )*};
}

unsupported! {
    fmi3EnterEventMode() => "this FMU has no event mode (hasEventMode = false)";
    fmi3EnterStepMode() => "this FMU has no event mode (hasEventMode = false): it is in Step \
        Mode from fmi3ExitInitializationMode on";
    fmi3EnterConfigurationMode() => "this FMU has no structural parameters";
    fmi3ExitConfigurationMode() => "this FMU has no structural parameters";
    fmi3GetNumberOfVariableDependencies(_vr: fmi3ValueReference, _n: *mut usize) =>
        "dependencies are not provided at run time (providesPerElementDependencies = false): \
         they are in the ModelStructure of modelDescription.xml";
    fmi3GetVariableDependencies(_dependent: fmi3ValueReference, _elements: *mut usize,
        _independents: *mut fmi3ValueReference, _independent_elements: *mut usize,
        _kinds: *mut fmi3DependencyKind, _n: usize) =>
        "dependencies are not provided at run time (providesPerElementDependencies = false): \
         they are in the ModelStructure of modelDescription.xml";
    fmi3GetAdjointDerivative(_unknowns: *const fmi3ValueReference, _n_unknowns: usize,
        _knowns: *const fmi3ValueReference, _n_knowns: usize, _seed: *const fmi3Float64,
        _n_seed: usize, _sensitivity: *mut fmi3Float64, _n_sensitivity: usize) =>
        "adjoint derivatives are not provided (providesAdjointDerivatives = false); \
         fmi3GetDirectionalDerivative is";
    fmi3GetIntervalDecimal(_vr: *const fmi3ValueReference, _n: usize, _intervals: *mut fmi3Float64,
        _qualifiers: *mut fmi3IntervalQualifier) => "this FMU has no clocks";
    fmi3GetIntervalFraction(_vr: *const fmi3ValueReference, _n: usize, _counters: *mut fmi3UInt64,
        _resolutions: *mut fmi3UInt64, _qualifiers: *mut fmi3IntervalQualifier) =>
        "this FMU has no clocks";
    fmi3GetShiftDecimal(_vr: *const fmi3ValueReference, _n: usize, _shifts: *mut fmi3Float64) =>
        "this FMU has no clocks";
    fmi3GetShiftFraction(_vr: *const fmi3ValueReference, _n: usize, _counters: *mut fmi3UInt64,
        _resolutions: *mut fmi3UInt64) => "this FMU has no clocks";
    fmi3SetIntervalDecimal(_vr: *const fmi3ValueReference, _n: usize,
        _intervals: *const fmi3Float64) => "this FMU has no clocks";
    fmi3SetIntervalFraction(_vr: *const fmi3ValueReference, _n: usize,
        _counters: *const fmi3UInt64, _resolutions: *const fmi3UInt64) => "this FMU has no clocks";
    fmi3SetShiftDecimal(_vr: *const fmi3ValueReference, _n: usize, _shifts: *const fmi3Float64) =>
        "this FMU has no clocks";
    fmi3SetShiftFraction(_vr: *const fmi3ValueReference, _n: usize, _counters: *const fmi3UInt64,
        _resolutions: *const fmi3UInt64) => "this FMU has no clocks";
    fmi3EvaluateDiscreteStates() => "this FMU has no event mode and no discrete states";
    fmi3UpdateDiscreteStates(_needs_update: *mut fmi3Boolean, _terminate: *mut fmi3Boolean,
        _nominals_changed: *mut fmi3Boolean, _values_changed: *mut fmi3Boolean,
        _next_defined: *mut fmi3Boolean, _next: *mut fmi3Float64) =>
        "this FMU has no event mode and no discrete states";
    fmi3EnterContinuousTimeMode() => "this FMU supports co-simulation only";
    fmi3CompletedIntegratorStep(_no_set: fmi3Boolean, _enter_event_mode: *mut fmi3Boolean,
        _terminate: *mut fmi3Boolean) => "this FMU supports co-simulation only";
    fmi3SetTime(_time: fmi3Float64) => "this FMU supports co-simulation only";
    fmi3SetContinuousStates(_x: *const fmi3Float64, _n: usize) =>
        "this FMU supports co-simulation only";
    fmi3GetContinuousStateDerivatives(_dx: *mut fmi3Float64, _n: usize) =>
        "this FMU supports co-simulation only";
    fmi3GetEventIndicators(_z: *mut fmi3Float64, _n: usize) =>
        "this FMU supports co-simulation only";
    fmi3GetContinuousStates(_x: *mut fmi3Float64, _n: usize) =>
        "this FMU supports co-simulation only";
    fmi3GetNominalsOfContinuousStates(_nominals: *mut fmi3Float64, _n: usize) =>
        "this FMU supports co-simulation only";
    fmi3GetNumberOfEventIndicators(_n: *mut usize) => "this FMU supports co-simulation only";
    fmi3GetNumberOfContinuousStates(_n: *mut usize) => "this FMU supports co-simulation only";
    fmi3GetOutputDerivatives(_vr: *const fmi3ValueReference, _n_vr: usize,
        _orders: *const fmi3Int32, _values: *mut fmi3Float64, _n_values: usize) =>
        "output derivatives are not provided (maxOutputDerivativeOrder = 0)";
    fmi3ActivateModelPartition(_clock: fmi3ValueReference, _time: fmi3Float64) =>
        "this FMU supports co-simulation only";
}
