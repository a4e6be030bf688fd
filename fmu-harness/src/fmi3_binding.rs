//! The raw FMI 3.0 co-simulation binding: the function pointer types of `fmi3FunctionTypes.h`
//! that the master uses, loaded with `libloading` from
//! `binaries/<platform tuple>/<modelIdentifier>.<so|dll>`, and an [`Instance`] whose methods
//! call them one to one (slices instead of pointer + length, status as [`Status`]). The C types
//! of `fmi3PlatformTypes.h` are the unit's, shared: [`fmu_beam::fmi3_types`]. What this binding
//! shares with FMI 2.0's ([`crate::fmi2_binding`]) is [`crate::binding`]'s.
//!
//! Unsafe code, as FMI 2.0's binding, with the same guarantees to the safe code above it: an
//! [`Instance`] owns its instance pointer and its log sink, which outlives every call and is
//! freed after `fmi3FreeInstance`; the library stays loaded while an instance lives; the counts
//! passed to C are the slice lengths; an [`FmuState`] is only ever handed back to the instance
//! that made it.

#![allow(non_camel_case_types, non_snake_case, non_upper_case_globals)]

use crate::binding::{push_message, required, symbol, take_messages, StateFunctions};
pub use crate::binding::{FmuState, LoadError, LogMessage, LogSink, RawStatus, Refusal, Status};
pub use fmu_beam::fmi3_types::{
    fmi3Boolean, fmi3FMUState, fmi3False, fmi3Float64, fmi3Instance, fmi3InstanceEnvironment,
    fmi3Int32, fmi3LogMessageCallback, fmi3String, fmi3True, fmi3ValueReference,
};
use std::ffi::CStr;
use std::os::raw::{c_int, c_void};
use std::path::Path;
use std::sync::{Arc, Mutex};

pub type fmi3InstantiateCoSimulationTYPE = unsafe extern "C" fn(
    fmi3String,
    fmi3String,
    fmi3String,
    fmi3Boolean,
    fmi3Boolean,
    fmi3Boolean,
    fmi3Boolean,
    *const fmi3ValueReference,
    usize,
    fmi3InstanceEnvironment,
    Option<fmi3LogMessageCallback>,
    *const c_void,
) -> fmi3Instance;
pub type fmi3FreeInstanceTYPE = unsafe extern "C" fn(fmi3Instance);
pub type fmi3EnterInitializationModeTYPE = unsafe extern "C" fn(
    fmi3Instance,
    fmi3Boolean,
    fmi3Float64,
    fmi3Float64,
    fmi3Boolean,
    fmi3Float64,
) -> RawStatus;
pub type fmi3InstanceTYPE = unsafe extern "C" fn(fmi3Instance) -> RawStatus;
pub type fmi3GetTYPE<T> = unsafe extern "C" fn(
    fmi3Instance,
    *const fmi3ValueReference,
    usize,
    *mut T,
    usize,
) -> RawStatus;
pub type fmi3SetTYPE<T> = unsafe extern "C" fn(
    fmi3Instance,
    *const fmi3ValueReference,
    usize,
    *const T,
    usize,
) -> RawStatus;
pub type fmi3DoStepTYPE = unsafe extern "C" fn(
    fmi3Instance,
    fmi3Float64,
    fmi3Float64,
    fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Float64,
) -> RawStatus;
pub type fmi3GetDirectionalDerivativeTYPE = unsafe extern "C" fn(
    fmi3Instance,
    *const fmi3ValueReference,
    usize,
    *const fmi3ValueReference,
    usize,
    *const fmi3Float64,
    usize,
    *mut fmi3Float64,
    usize,
) -> RawStatus;

/// The master's logger: appends to the instance's [`LogSink`] (the instance environment). FMI
/// 3.0's message is plain text, kept as it is.
unsafe extern "C" fn log_message(
    env: fmi3InstanceEnvironment,
    status: c_int,
    category: fmi3String,
    message: fmi3String,
) {
    // SAFETY: env is the instance's LogSink, kept alive until after fmi3FreeInstance; the FMU
    // passes NUL-terminated strings valid for the call.
    unsafe { push_message(env, Status::from_c3(status), category, message, false) }
}

/// The fmi3 functions of one loaded library. Optional ones are `None` when not exported.
pub struct Api {
    instantiate: fmi3InstantiateCoSimulationTYPE,
    free_instance: fmi3FreeInstanceTYPE,
    enter_initialization_mode: fmi3EnterInitializationModeTYPE,
    exit_initialization_mode: fmi3InstanceTYPE,
    terminate: fmi3InstanceTYPE,
    reset: fmi3InstanceTYPE,
    get_float64: fmi3GetTYPE<fmi3Float64>,
    get_int32: fmi3GetTYPE<fmi3Int32>,
    get_boolean: fmi3GetTYPE<fmi3Boolean>,
    set_float64: fmi3SetTYPE<fmi3Float64>,
    set_int32: fmi3SetTYPE<fmi3Int32>,
    set_boolean: fmi3SetTYPE<fmi3Boolean>,
    do_step: fmi3DoStepTYPE,
    /// Get, set and free FMU state (each optional).
    states: StateFunctions,
    get_directional_derivative: Option<fmi3GetDirectionalDerivativeTYPE>,
    // Last: the function pointers above are only valid while the library is loaded.
    _library: libloading::Library,
}

impl Api {
    /// Loads the shared library of an extracted FMU and resolves its fmi3 functions (see
    /// [`crate::binding::open`]).
    pub fn load(path: &Path) -> Result<Arc<Api>, LoadError> {
        let library = crate::binding::open(path)?;
        macro_rules! optional {
            ($name:literal) => {
                // SAFETY: the field's type is the C type the FMI 3.0 standard gives the symbol;
                // the pointer is kept with the library.
                unsafe { symbol(&library, $name) }
            };
        }
        macro_rules! required {
            ($name:literal) => {
                // SAFETY: as for `optional!`.
                unsafe { required(&library, path, $name) }?
            };
        }
        Ok(Arc::new(Api {
            instantiate: required!("fmi3InstantiateCoSimulation"),
            free_instance: required!("fmi3FreeInstance"),
            enter_initialization_mode: required!("fmi3EnterInitializationMode"),
            exit_initialization_mode: required!("fmi3ExitInitializationMode"),
            terminate: required!("fmi3Terminate"),
            reset: required!("fmi3Reset"),
            get_float64: required!("fmi3GetFloat64"),
            get_int32: required!("fmi3GetInt32"),
            get_boolean: required!("fmi3GetBoolean"),
            set_float64: required!("fmi3SetFloat64"),
            set_int32: required!("fmi3SetInt32"),
            set_boolean: required!("fmi3SetBoolean"),
            do_step: required!("fmi3DoStep"),
            // SAFETY: the FMI 3.0 standard's FMU-state functions.
            states: unsafe {
                StateFunctions::load(
                    &library,
                    ["fmi3GetFMUState", "fmi3SetFMUState", "fmi3FreeFMUState"],
                )
            },
            get_directional_derivative: optional!("fmi3GetDirectionalDerivative"),
            _library: library,
        }))
    }
}

/// What `fmi3DoStep` returns besides its status.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepOutcome {
    pub event_handling_needed: bool,
    pub terminate_simulation: bool,
    pub early_return: bool,
    pub last_successful_time: f64,
}

/// One co-simulation instance: the instance pointer and what C holds pointers to.
pub struct Instance {
    instance: fmi3Instance,
    // Boxed: C keeps its address until fmi3FreeInstance.
    log: Box<LogSink>,
    api: Arc<Api>,
}

impl Instance {
    /// `fmi3InstantiateCoSimulation(name, token, resourcePath, visible, loggingOn,
    /// eventModeUsed = false, earlyReturnAllowed = false, no required intermediate variables,
    /// env, logMessage, no intermediate update)`; `Err` with what the logger got when it returns
    /// NULL.
    pub fn instantiate(
        api: &Arc<Api>,
        name: &CStr,
        token: &CStr,
        resource_path: &CStr,
        visible: bool,
        logging_on: bool,
    ) -> Result<Instance, Vec<LogMessage>> {
        let log: Box<LogSink> = Box::new(Mutex::new(Vec::new()));
        let env = &*log as *const LogSink as *mut c_void;
        // SAFETY: valid C strings; the log sink boxed and kept with the instance.
        let instance = unsafe {
            (api.instantiate)(
                name.as_ptr(),
                token.as_ptr(),
                resource_path.as_ptr(),
                visible as fmi3Boolean,
                logging_on as fmi3Boolean,
                fmi3False,
                fmi3False,
                std::ptr::null(),
                0,
                env,
                Some(log_message),
                std::ptr::null(),
            )
        };
        if instance.is_null() {
            return Err(take_messages(&log));
        }
        Ok(Instance {
            instance,
            log,
            api: Arc::clone(api),
        })
    }

    /// The messages logged since the last call of this function.
    pub fn take_messages(&self) -> Vec<LogMessage> {
        take_messages(&self.log)
    }

    pub fn enter_initialization_mode(
        &mut self,
        tolerance: Option<f64>,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> Status {
        // SAFETY: a live instance.
        Status::from_c3(unsafe {
            (self.api.enter_initialization_mode)(
                self.instance,
                tolerance.is_some() as fmi3Boolean,
                tolerance.unwrap_or(0.0),
                start_time,
                stop_time.is_some() as fmi3Boolean,
                stop_time.unwrap_or(0.0),
            )
        })
    }

    pub fn exit_initialization_mode(&mut self) -> Status {
        // SAFETY: a live instance.
        Status::from_c3(unsafe { (self.api.exit_initialization_mode)(self.instance) })
    }

    pub fn terminate(&mut self) -> Status {
        // SAFETY: a live instance.
        Status::from_c3(unsafe { (self.api.terminate)(self.instance) })
    }

    pub fn reset(&mut self) -> Status {
        // SAFETY: a live instance.
        Status::from_c3(unsafe { (self.api.reset)(self.instance) })
    }

    /// `fmi3DoStep`: the status and the step's outputs (read only where the status is not
    /// Error or Fatal; NaN and false before).
    pub fn do_step(&mut self, t: f64, h: f64, no_set_prior: bool) -> (Status, StepOutcome) {
        let (mut event, mut terminate, mut early) = (fmi3False, fmi3False, fmi3False);
        let mut last = f64::NAN;
        // SAFETY: a live instance; each output points to a local of its type.
        let s = Status::from_c3(unsafe {
            (self.api.do_step)(
                self.instance,
                t,
                h,
                no_set_prior as fmi3Boolean,
                &mut event,
                &mut terminate,
                &mut early,
                &mut last,
            )
        });
        let outcome = StepOutcome {
            event_handling_needed: event != fmi3False,
            terminate_simulation: terminate != fmi3False,
            early_return: early != fmi3False,
            last_successful_time: last,
        };
        (s, outcome)
    }

    /// `fmi3GetFloat64(vr, values)`: `values` holds every value of the variables (an array's
    /// elements in order).
    pub fn get_float64(&mut self, vr: &[fmi3ValueReference], values: &mut [f64]) -> Status {
        // SAFETY: a live instance; each array holds the count passed with it.
        Status::from_c3(unsafe { get(self.api.get_float64, self.instance, vr, values) })
    }

    pub fn get_int32(&mut self, vr: &[fmi3ValueReference], values: &mut [i32]) -> Status {
        // SAFETY: as for get_float64.
        Status::from_c3(unsafe { get(self.api.get_int32, self.instance, vr, values) })
    }

    /// `fmi3GetBoolean`, values as the C `bool` (one byte).
    pub fn get_boolean(&mut self, vr: &[fmi3ValueReference], values: &mut [u8]) -> Status {
        // SAFETY: as for get_float64.
        Status::from_c3(unsafe { get(self.api.get_boolean, self.instance, vr, values) })
    }

    pub fn set_float64(&mut self, vr: &[fmi3ValueReference], values: &[f64]) -> Status {
        // SAFETY: as for get_float64.
        Status::from_c3(unsafe { set(self.api.set_float64, self.instance, vr, values) })
    }

    pub fn set_int32(&mut self, vr: &[fmi3ValueReference], values: &[i32]) -> Status {
        // SAFETY: as for get_float64.
        Status::from_c3(unsafe { set(self.api.set_int32, self.instance, vr, values) })
    }

    /// `fmi3SetBoolean`, values as the C `bool`: 0 or 1.
    pub fn set_boolean(&mut self, vr: &[fmi3ValueReference], values: &[u8]) -> Status {
        // SAFETY: as for get_float64.
        Status::from_c3(unsafe { set(self.api.set_boolean, self.instance, vr, values) })
    }

    /// `fmi3GetDirectionalDerivative(unknowns, knowns, seed, sensitivity)`: `seed` holds a value
    /// per element of the knowns, `sensitivity` one per element of the unknowns.
    pub fn get_directional_derivative(
        &mut self,
        unknowns: &[fmi3ValueReference],
        knowns: &[fmi3ValueReference],
        seed: &[f64],
        sensitivity: &mut [f64],
    ) -> Result<Status, Refusal> {
        let f = self
            .api
            .get_directional_derivative
            .ok_or(Refusal::NotExported("fmi3GetDirectionalDerivative"))?;
        // SAFETY: a live instance; each array holds the count passed with it.
        Ok(Status::from_c3(unsafe {
            f(
                self.instance,
                unknowns.as_ptr(),
                unknowns.len(),
                knowns.as_ptr(),
                knowns.len(),
                seed.as_ptr(),
                seed.len(),
                sensitivity.as_mut_ptr(),
                sensitivity.len(),
            )
        }))
    }

    /// `fmi3GetFMUState`: fills an empty `state` or overwrites one of this instance.
    pub fn get_fmu_state(&mut self, state: &mut FmuState) -> Result<Status, Refusal> {
        // SAFETY: a live instance of the library.
        unsafe { self.api.states.get(self.instance, state) }.map(Status::from_c3)
    }

    pub fn set_fmu_state(&mut self, state: &FmuState) -> Result<Status, Refusal> {
        // SAFETY: a live instance of the library.
        unsafe { self.api.states.set(self.instance, state) }.map(Status::from_c3)
    }

    /// `fmi3FreeFMUState`; the state is empty afterwards if the FMU set it to NULL.
    pub fn free_fmu_state(&mut self, state: &mut FmuState) -> Result<Status, Refusal> {
        // SAFETY: a live instance of the library.
        let s = unsafe { self.api.states.free(self.instance, state) }?;
        Ok(s.map_or(Status::Ok, Status::from_c3))
    }
}

/// An `fmi3Get<Type>` call: every value reference of `vr`, `values` the values of all of them.
///
/// # Safety
/// `instance` is live and `f` is its library's function.
unsafe fn get<T>(
    f: fmi3GetTYPE<T>,
    instance: fmi3Instance,
    vr: &[fmi3ValueReference],
    values: &mut [T],
) -> RawStatus {
    // SAFETY: the caller's contract; each array holds the count passed with it.
    unsafe {
        f(
            instance,
            vr.as_ptr(),
            vr.len(),
            values.as_mut_ptr(),
            values.len(),
        )
    }
}

/// An `fmi3Set<Type>` call, as [`get`].
///
/// # Safety
/// As for [`get`].
unsafe fn set<T>(
    f: fmi3SetTYPE<T>,
    instance: fmi3Instance,
    vr: &[fmi3ValueReference],
    values: &[T],
) -> RawStatus {
    // SAFETY: the caller's contract; each array holds the count passed with it.
    unsafe {
        f(
            instance,
            vr.as_ptr(),
            vr.len(),
            values.as_ptr(),
            values.len(),
        )
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: a live instance, freed once; the log sink outlives the call.
        unsafe { (self.api.free_instance)(self.instance) }
    }
}
