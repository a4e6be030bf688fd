//! The raw FMI 2.0 co-simulation binding: the function pointer types of `fmi2FunctionTypes.h`
//! that the master uses, loaded with `libloading` from `binaries/linux64/<modelIdentifier>.so`,
//! and an [`Instance`] whose methods call them one to one (slices instead of pointer + length,
//! status as [`Status`]). The C types of `fmi2TypesPlatform.h` are the unit's, shared:
//! [`fmu_beam::fmi2_types`]; the master differs from the unit only where it receives: a status
//! as a plain `c_int` ([`RawStatus`]) and a logger without the variadic tail.
//!
//! The one module of fmu-harness with unsafe code. What it guarantees to the safe code above it:
//! an [`Instance`] owns its component, its callback struct and its log sink, which outlive every
//! call and are freed after `fmi2FreeInstance`; the library stays loaded while an instance lives;
//! array lengths passed to C are the slice lengths; an [`FmuState`] is only ever handed back to
//! the instance that made it.
//!
//! What both versions' bindings share (the status, the log sink, the FMU state's owner checks,
//! the symbol look-up) is [`crate::binding`]'s; FMI 3.0's binding is [`crate::fmi3_binding`].

#![allow(non_camel_case_types, non_snake_case, non_upper_case_globals)]

pub use fmu_beam::fmi2_types::{
    fmi2Boolean, fmi2CallbackAllocateMemory, fmi2CallbackFreeMemory, fmi2CoSimulation,
    fmi2Component, fmi2ComponentEnvironment, fmi2FMUstate, fmi2False, fmi2Integer, fmi2Real,
    fmi2StatusKind, fmi2StepFinished, fmi2String, fmi2True, fmi2Type, fmi2ValueReference,
};
pub use fmu_beam::fmi2_types::{fmi2LastSuccessfulTime, fmi2Terminated};
use std::ffi::CStr;
use std::os::raw::c_void;
use std::path::Path;
use std::sync::{Arc, Mutex};

use crate::binding::{push_message, required, same_length, symbol, take_messages, StateFunctions};
/// `fmi2Status` as the master receives it (not the unit's `fmi2Status` enum of
/// [`fmu_beam::fmi2_types`]), and what both bindings share.
pub use crate::binding::{FmuState, LoadError, LogMessage, LogSink, RawStatus, Refusal, Status};

/// `fmi2CallbackLogger` without its variadic tail. C declares it `(env, name, status, category,
/// message, ...)`; a stable Rust `extern "C" fn` cannot be variadic, so the master's logger takes
/// the fixed arguments only and formats `message` without them ([`crate::log_format::printf`]):
/// `%%` becomes `%`, as every importer prints it; a directive that would read an argument (a
/// foreign FMU's `%d`, `%s`, ...) is kept as it is written. Hence the master's own logger type
/// and callback struct, of the same layout as [`fmu_beam::fmi2_types::fmi2CallbackFunctions`]
/// (checked below).
pub type fmi2CallbackLogger =
    unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, RawStatus, fmi2String, fmi2String);

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct fmi2CallbackFunctions {
    pub logger: Option<fmi2CallbackLogger>,
    pub allocateMemory: Option<fmi2CallbackAllocateMemory>,
    pub freeMemory: Option<fmi2CallbackFreeMemory>,
    pub stepFinished: Option<fmi2StepFinished>,
    pub componentEnvironment: fmi2ComponentEnvironment,
}

// The callback struct the FMU reads has the layout of the one it declares.
const _: () = {
    use fmu_beam::fmi2_types::fmi2CallbackFunctions as Declared;
    use std::mem::{align_of, offset_of, size_of};
    type Ours = fmi2CallbackFunctions;
    assert!(size_of::<Ours>() == size_of::<Declared>());
    assert!(align_of::<Ours>() == align_of::<Declared>());
    assert!(offset_of!(Ours, logger) == offset_of!(Declared, logger));
    assert!(offset_of!(Ours, allocateMemory) == offset_of!(Declared, allocateMemory));
    assert!(offset_of!(Ours, freeMemory) == offset_of!(Declared, freeMemory));
    assert!(offset_of!(Ours, stepFinished) == offset_of!(Declared, stepFinished));
    assert!(offset_of!(Ours, componentEnvironment) == offset_of!(Declared, componentEnvironment));
};

pub type fmi2InstantiateTYPE = unsafe extern "C" fn(
    fmi2String,
    fmi2Type,
    fmi2String,
    fmi2String,
    *const fmi2CallbackFunctions,
    fmi2Boolean,
    fmi2Boolean,
) -> fmi2Component;
pub type fmi2FreeInstanceTYPE = unsafe extern "C" fn(fmi2Component);
pub type fmi2SetupExperimentTYPE = unsafe extern "C" fn(
    fmi2Component,
    fmi2Boolean,
    fmi2Real,
    fmi2Real,
    fmi2Boolean,
    fmi2Real,
) -> RawStatus;
pub type fmi2EnterInitializationModeTYPE = unsafe extern "C" fn(fmi2Component) -> RawStatus;
pub type fmi2ExitInitializationModeTYPE = unsafe extern "C" fn(fmi2Component) -> RawStatus;
pub type fmi2TerminateTYPE = unsafe extern "C" fn(fmi2Component) -> RawStatus;
pub type fmi2ResetTYPE = unsafe extern "C" fn(fmi2Component) -> RawStatus;
pub type fmi2GetRealTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *mut fmi2Real,
) -> RawStatus;
pub type fmi2GetIntegerTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *mut fmi2Integer,
) -> RawStatus;
pub type fmi2GetBooleanTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *mut fmi2Boolean,
) -> RawStatus;
pub type fmi2SetRealTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Real,
) -> RawStatus;
pub type fmi2SetIntegerTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Integer,
) -> RawStatus;
pub type fmi2SetBooleanTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Boolean,
) -> RawStatus;
pub type fmi2SetRealInputDerivativesTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Integer,
    *const fmi2Real,
) -> RawStatus;
pub type fmi2GetDirectionalDerivativeTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2ValueReference,
    usize,
    *const fmi2Real,
    *mut fmi2Real,
) -> RawStatus;
pub type fmi2DoStepTYPE =
    unsafe extern "C" fn(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean) -> RawStatus;
pub type fmi2GetRealStatusTYPE =
    unsafe extern "C" fn(fmi2Component, fmi2StatusKind, *mut fmi2Real) -> RawStatus;
pub type fmi2GetBooleanStatusTYPE =
    unsafe extern "C" fn(fmi2Component, fmi2StatusKind, *mut fmi2Boolean) -> RawStatus;

extern "C" {
    fn calloc(nobj: usize, size: usize) -> *mut c_void;
    fn free(obj: *mut c_void);
}

/// The master's logger: appends to the instance's [`LogSink`] (the component environment),
/// the message formatted as printf prints it without arguments.
unsafe extern "C" fn log_message(
    env: fmi2ComponentEnvironment,
    _instance_name: fmi2String,
    status: RawStatus,
    category: fmi2String,
    message: fmi2String,
) {
    // SAFETY: env is the instance's LogSink, kept alive until after fmi2FreeInstance; the FMU
    // passes NUL-terminated strings valid for the call.
    unsafe { push_message(env, Status::from_c(status), category, message, true) }
}

unsafe extern "C" fn allocate_memory(nobj: usize, size: usize) -> *mut c_void {
    // SAFETY: libc's calloc, any arguments allowed.
    unsafe { calloc(nobj, size) }
}

unsafe extern "C" fn free_memory(obj: *mut c_void) {
    // SAFETY: obj came from allocate_memory (or is NULL), as the standard requires.
    unsafe { free(obj) }
}

/// The fmi2 functions of one loaded library. Optional ones are `None` when not exported.
pub struct Api {
    instantiate: fmi2InstantiateTYPE,
    free_instance: fmi2FreeInstanceTYPE,
    setup_experiment: fmi2SetupExperimentTYPE,
    enter_initialization_mode: fmi2EnterInitializationModeTYPE,
    exit_initialization_mode: fmi2ExitInitializationModeTYPE,
    terminate: fmi2TerminateTYPE,
    reset: fmi2ResetTYPE,
    get_real: fmi2GetRealTYPE,
    get_integer: fmi2GetIntegerTYPE,
    get_boolean: fmi2GetBooleanTYPE,
    set_real: fmi2SetRealTYPE,
    set_integer: fmi2SetIntegerTYPE,
    set_boolean: fmi2SetBooleanTYPE,
    do_step: fmi2DoStepTYPE,
    /// Get, set and free FMU state (each optional).
    states: StateFunctions,
    set_real_input_derivatives: Option<fmi2SetRealInputDerivativesTYPE>,
    get_directional_derivative: Option<fmi2GetDirectionalDerivativeTYPE>,
    get_real_status: Option<fmi2GetRealStatusTYPE>,
    get_boolean_status: Option<fmi2GetBooleanStatusTYPE>,
    // Last: the function pointers above are only valid while the library is loaded.
    _library: libloading::Library,
}

impl Api {
    /// Loads the shared library of an extracted FMU and resolves its fmi2 functions.
    ///
    /// Loading runs the library's initializers; an FMU's binary is trusted code of the master's
    /// choosing, as in every FMI importer.
    pub fn load(path: &Path) -> Result<Arc<Api>, LoadError> {
        let library = crate::binding::open(path)?;
        macro_rules! optional {
            ($name:literal, $ty:ty) => {
                // SAFETY: the symbol has the C type the FMI standard gives it; the pointer is
                // kept with the library.
                unsafe { symbol::<$ty>(&library, $name) }
            };
        }
        macro_rules! required {
            ($name:literal, $ty:ty) => {
                // SAFETY: as for `optional!`.
                unsafe { required::<$ty>(&library, path, $name) }?
            };
        }
        Ok(Arc::new(Api {
            instantiate: required!("fmi2Instantiate", fmi2InstantiateTYPE),
            free_instance: required!("fmi2FreeInstance", fmi2FreeInstanceTYPE),
            setup_experiment: required!("fmi2SetupExperiment", fmi2SetupExperimentTYPE),
            enter_initialization_mode: required!(
                "fmi2EnterInitializationMode",
                fmi2EnterInitializationModeTYPE
            ),
            exit_initialization_mode: required!(
                "fmi2ExitInitializationMode",
                fmi2ExitInitializationModeTYPE
            ),
            terminate: required!("fmi2Terminate", fmi2TerminateTYPE),
            reset: required!("fmi2Reset", fmi2ResetTYPE),
            get_real: required!("fmi2GetReal", fmi2GetRealTYPE),
            get_integer: required!("fmi2GetInteger", fmi2GetIntegerTYPE),
            get_boolean: required!("fmi2GetBoolean", fmi2GetBooleanTYPE),
            set_real: required!("fmi2SetReal", fmi2SetRealTYPE),
            set_integer: required!("fmi2SetInteger", fmi2SetIntegerTYPE),
            set_boolean: required!("fmi2SetBoolean", fmi2SetBooleanTYPE),
            do_step: required!("fmi2DoStep", fmi2DoStepTYPE),
            // SAFETY: the FMI 2.0 standard's FMU-state functions.
            states: unsafe {
                StateFunctions::load(
                    &library,
                    ["fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate"],
                )
            },
            set_real_input_derivatives: optional!(
                "fmi2SetRealInputDerivatives",
                fmi2SetRealInputDerivativesTYPE
            ),
            get_directional_derivative: optional!(
                "fmi2GetDirectionalDerivative",
                fmi2GetDirectionalDerivativeTYPE
            ),
            get_real_status: optional!("fmi2GetRealStatus", fmi2GetRealStatusTYPE),
            get_boolean_status: optional!("fmi2GetBooleanStatus", fmi2GetBooleanStatusTYPE),
            _library: library,
        }))
    }
}

/// One co-simulation instance: the component and what C holds pointers to.
pub struct Instance {
    component: fmi2Component,
    // Boxed: C keeps their addresses until fmi2FreeInstance.
    _callbacks: Box<fmi2CallbackFunctions>,
    log: Box<LogSink>,
    api: Arc<Api>,
}

impl Instance {
    /// `fmi2Instantiate(name, fmi2CoSimulation, guid, resources, callbacks, visible, loggingOn)`;
    /// `Err` with what the logger got when it returns NULL.
    pub fn instantiate(
        api: &Arc<Api>,
        name: &CStr,
        guid: &CStr,
        resource_location: &CStr,
        visible: bool,
        logging_on: bool,
    ) -> Result<Instance, Vec<LogMessage>> {
        let log: Box<LogSink> = Box::new(Mutex::new(Vec::new()));
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: Some(log_message),
            allocateMemory: Some(allocate_memory),
            freeMemory: Some(free_memory),
            stepFinished: None,
            componentEnvironment: &*log as *const LogSink as *mut c_void,
        });
        // SAFETY: valid C strings; callbacks and log boxed and kept with the instance.
        let component = unsafe {
            (api.instantiate)(
                name.as_ptr(),
                fmi2CoSimulation,
                guid.as_ptr(),
                resource_location.as_ptr(),
                &*callbacks,
                visible as fmi2Boolean,
                logging_on as fmi2Boolean,
            )
        };
        if component.is_null() {
            return Err(take_messages(&log));
        }
        Ok(Instance {
            component,
            _callbacks: callbacks,
            log,
            api: Arc::clone(api),
        })
    }

    /// The messages logged since the last call of this function.
    pub fn take_messages(&self) -> Vec<LogMessage> {
        take_messages(&self.log)
    }

    pub fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> Status {
        // SAFETY: a live component.
        Status::from_c(unsafe {
            (self.api.setup_experiment)(
                self.component,
                tolerance.is_some() as fmi2Boolean,
                tolerance.unwrap_or(0.0),
                start_time,
                stop_time.is_some() as fmi2Boolean,
                stop_time.unwrap_or(0.0),
            )
        })
    }

    pub fn enter_initialization_mode(&mut self) -> Status {
        // SAFETY: a live component.
        Status::from_c(unsafe { (self.api.enter_initialization_mode)(self.component) })
    }

    pub fn exit_initialization_mode(&mut self) -> Status {
        // SAFETY: a live component.
        Status::from_c(unsafe { (self.api.exit_initialization_mode)(self.component) })
    }

    pub fn terminate(&mut self) -> Status {
        // SAFETY: a live component.
        Status::from_c(unsafe { (self.api.terminate)(self.component) })
    }

    pub fn reset(&mut self) -> Status {
        // SAFETY: a live component.
        Status::from_c(unsafe { (self.api.reset)(self.component) })
    }

    pub fn do_step(&mut self, t: f64, h: f64, no_set_fmu_state_prior: bool) -> Status {
        // SAFETY: a live component.
        Status::from_c(unsafe {
            (self.api.do_step)(self.component, t, h, no_set_fmu_state_prior as fmi2Boolean)
        })
    }

    /// `fmi2GetRealStatus(kind)`: the status and the value.
    pub fn get_real_status(&mut self, kind: fmi2StatusKind) -> Result<(Status, f64), Refusal> {
        let f = self
            .api
            .get_real_status
            .ok_or(Refusal::NotExported("fmi2GetRealStatus"))?;
        let mut value = f64::NAN;
        // SAFETY: a live component and a valid pointer for the call.
        let s = Status::from_c(unsafe { f(self.component, kind, &mut value) });
        Ok((s, value))
    }

    /// `fmi2GetBooleanStatus(kind)`: the status and the value.
    pub fn get_boolean_status(&mut self, kind: fmi2StatusKind) -> Result<(Status, bool), Refusal> {
        let f = self
            .api
            .get_boolean_status
            .ok_or(Refusal::NotExported("fmi2GetBooleanStatus"))?;
        let mut value: fmi2Boolean = fmi2False;
        // SAFETY: a live component and a valid pointer for the call.
        let s = Status::from_c(unsafe { f(self.component, kind, &mut value) });
        Ok((s, value != fmi2False))
    }

    /// `fmi2GetReal`; panics if the slices differ in length (a bug of the caller).
    pub fn get_real(&mut self, vr: &[fmi2ValueReference], values: &mut [f64]) -> Status {
        same_length("fmi2GetReal", vr.len(), values.len());
        // SAFETY: both arrays hold vr.len() elements.
        Status::from_c(unsafe {
            (self.api.get_real)(self.component, vr.as_ptr(), vr.len(), values.as_mut_ptr())
        })
    }

    pub fn get_integer(&mut self, vr: &[fmi2ValueReference], values: &mut [i32]) -> Status {
        same_length("fmi2GetInteger", vr.len(), values.len());
        // SAFETY: both arrays hold vr.len() elements.
        Status::from_c(unsafe {
            (self.api.get_integer)(self.component, vr.as_ptr(), vr.len(), values.as_mut_ptr())
        })
    }

    /// `fmi2GetBoolean`, values as the C `fmi2Boolean` (int).
    pub fn get_boolean(&mut self, vr: &[fmi2ValueReference], values: &mut [i32]) -> Status {
        same_length("fmi2GetBoolean", vr.len(), values.len());
        // SAFETY: both arrays hold vr.len() elements.
        Status::from_c(unsafe {
            (self.api.get_boolean)(self.component, vr.as_ptr(), vr.len(), values.as_mut_ptr())
        })
    }

    pub fn set_real(&mut self, vr: &[fmi2ValueReference], values: &[f64]) -> Status {
        same_length("fmi2SetReal", vr.len(), values.len());
        // SAFETY: both arrays hold vr.len() elements.
        Status::from_c(unsafe {
            (self.api.set_real)(self.component, vr.as_ptr(), vr.len(), values.as_ptr())
        })
    }

    pub fn set_integer(&mut self, vr: &[fmi2ValueReference], values: &[i32]) -> Status {
        same_length("fmi2SetInteger", vr.len(), values.len());
        // SAFETY: both arrays hold vr.len() elements.
        Status::from_c(unsafe {
            (self.api.set_integer)(self.component, vr.as_ptr(), vr.len(), values.as_ptr())
        })
    }

    /// `fmi2SetBoolean`, values as the C `fmi2Boolean` (int).
    pub fn set_boolean(&mut self, vr: &[fmi2ValueReference], values: &[i32]) -> Status {
        same_length("fmi2SetBoolean", vr.len(), values.len());
        // SAFETY: both arrays hold vr.len() elements.
        Status::from_c(unsafe {
            (self.api.set_boolean)(self.component, vr.as_ptr(), vr.len(), values.as_ptr())
        })
    }

    pub fn set_real_input_derivatives(
        &mut self,
        vr: &[fmi2ValueReference],
        order: &[i32],
        values: &[f64],
    ) -> Result<Status, Refusal> {
        assert!(
            vr.len() == order.len() && vr.len() == values.len(),
            "fmi2SetRealInputDerivatives: lengths differ"
        );
        let f = self
            .api
            .set_real_input_derivatives
            .ok_or(Refusal::NotExported("fmi2SetRealInputDerivatives"))?;
        // SAFETY: the three arrays hold vr.len() elements.
        Ok(Status::from_c(unsafe {
            f(
                self.component,
                vr.as_ptr(),
                vr.len(),
                order.as_ptr(),
                values.as_ptr(),
            )
        }))
    }

    /// `fmi2GetDirectionalDerivative(vUnknown_ref, vKnown_ref, dvKnown, dvUnknown)`; panics if
    /// the slices differ in length (a bug of the caller).
    pub fn get_directional_derivative(
        &mut self,
        unknowns: &[fmi2ValueReference],
        knowns: &[fmi2ValueReference],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Result<Status, Refusal> {
        assert!(
            knowns.len() == dv_known.len() && unknowns.len() == dv_unknown.len(),
            "fmi2GetDirectionalDerivative: lengths differ"
        );
        let f = self
            .api
            .get_directional_derivative
            .ok_or(Refusal::NotExported("fmi2GetDirectionalDerivative"))?;
        // SAFETY: each array holds the number of elements passed with it.
        Ok(Status::from_c(unsafe {
            f(
                self.component,
                unknowns.as_ptr(),
                unknowns.len(),
                knowns.as_ptr(),
                knowns.len(),
                dv_known.as_ptr(),
                dv_unknown.as_mut_ptr(),
            )
        }))
    }

    /// `fmi2GetFMUstate`: fills an empty `state` or overwrites one of this instance.
    pub fn get_fmu_state(&mut self, state: &mut FmuState) -> Result<Status, Refusal> {
        // SAFETY: a live instance of the library.
        unsafe { self.api.states.get(self.component, state) }.map(Status::from_c)
    }

    pub fn set_fmu_state(&mut self, state: &FmuState) -> Result<Status, Refusal> {
        // SAFETY: a live instance of the library.
        unsafe { self.api.states.set(self.component, state) }.map(Status::from_c)
    }

    /// `fmi2FreeFMUstate`; the state is empty afterwards if the FMU set it to NULL.
    pub fn free_fmu_state(&mut self, state: &mut FmuState) -> Result<Status, Refusal> {
        // SAFETY: a live instance of the library.
        let s = unsafe { self.api.states.free(self.component, state) }?;
        Ok(s.map_or(Status::Ok, Status::from_c))
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: a live component, freed once; callbacks and log outlive the call.
        unsafe { (self.api.free_instance)(self.component) }
    }
}
