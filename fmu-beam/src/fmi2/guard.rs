//! The one guard every export goes through: null checks, `catch_unwind`, the call-sequence
//! check, mapping of failures to an fmi2Status and logging of their message. Nothing unwinds
//! across the C boundary, and nothing global is touched (no panic hook is installed).
//!
//! Also the conversions of the master's pointers into slices and strings, each refusing NULL
//! (unless the length is zero) with a message that names the argument.

use super::instance::Instance;
use super::logger::Logger;
use super::state_machine::{check, Call, ModelState};
use super::types::{fmi2CallbackFunctions, fmi2Component, fmi2Status, fmi2String};
use crate::error::EngineError;
use std::any::Any;
use std::ffi::CStr;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Why a call did not succeed: the status to return and the message to log.
#[derive(Debug, Clone, PartialEq)]
pub struct Fault {
    pub status: fmi2Status,
    pub message: String,
}

impl Fault {
    /// A refused call (fmi2Error) that leaves the instance as it was.
    pub fn refused(message: impl Into<String>) -> Fault {
        Fault {
            status: fmi2Status::fmi2Error,
            message: message.into(),
        }
    }
}

impl From<EngineError> for Fault {
    fn from(e: EngineError) -> Fault {
        Fault {
            status: if e.is_discard() {
                fmi2Status::fmi2Discard
            } else {
                fmi2Status::fmi2Error
            },
            message: e.to_string(),
        }
    }
}

/// An instance as the guard sees it: FMI 2.0's [`Instance`] here, FMI 3.0's in `fmi3/` (the
/// two standards' status values agree, 0 to 4, so the guard speaks in `fmi2Status`).
pub trait Guarded {
    /// The functions that take an instance.
    type Call: Copy;
    /// Refuses a call that is illegal in the instance's state (nothing changes).
    fn check(&self, call: Self::Call) -> Result<(), Fault>;
    /// The C name of a call, for messages.
    fn name(call: Self::Call) -> &'static str;
    /// Sends the message of a call that returns `status`.
    fn report(&self, status: fmi2Status, message: &str);
    /// After a panic: the instance moves to its error state; says what the master may call.
    fn panicked(&mut self) -> &'static str;
}

impl Guarded for Instance {
    type Call = Call;

    fn check(&self, call: Call) -> Result<(), Fault> {
        check(self.state, call)
    }

    fn name(call: Call) -> &'static str {
        call.name()
    }

    fn report(&self, status: fmi2Status, message: &str) {
        self.logger.status(status, message);
    }

    fn panicked(&mut self) -> &'static str {
        self.state = ModelState::Error;
        "call fmi2Reset, fmi2SetFMUstate or fmi2FreeInstance"
    }
}

/// Runs `f` on the instance behind `c` if `call` is legal in its state.
///
/// # Safety
/// `c` is NULL or a component returned by fmi2Instantiate and not yet freed, used by one
/// thread at a time (as the standard requires of the master).
pub unsafe fn guard(
    c: fmi2Component,
    call: Call,
    f: impl FnOnce(&mut Instance) -> Result<(), Fault>,
) -> fmi2Status {
    // SAFETY: the same contract.
    unsafe { guard_with(c, call, f) }
}

/// [`guard`] for an instance of type `I`.
///
/// # Safety
/// `c` is NULL or points to a live `I` made by the instantiate function of `I`'s layer, used
/// by one thread at a time.
pub unsafe fn guard_with<I: Guarded>(
    c: *mut std::os::raw::c_void,
    call: I::Call,
    f: impl FnOnce(&mut I) -> Result<(), Fault>,
) -> fmi2Status {
    if c.is_null() {
        // No instance, so no logger to tell.
        return fmi2Status::fmi2Error;
    }
    // SAFETY: see the contract above.
    let instance = unsafe { &mut *c.cast::<I>() };
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        instance.check(call)?;
        f(instance)
    }));
    match outcome {
        Ok(Ok(())) => fmi2Status::fmi2OK,
        Ok(Err(fault)) => {
            instance.report(
                fault.status,
                &format!("{}: {}", I::name(call), fault.message),
            );
            fault.status
        }
        Err(payload) => {
            let next = instance.panicked();
            let message = format!(
                "{}: internal error (Rust panic: {}); the instance is now in state Error: {next}",
                I::name(call),
                panic_text(&*payload)
            );
            instance.report(fmi2Status::fmi2Error, &message);
            fmi2Status::fmi2Error
        }
    }
}

/// fmi2Instantiate: builds the instance with `f`, or logs why not and returns NULL.
///
/// # Safety
/// `functions` is NULL or points to valid callbacks; `instance_name` is NULL or a C string.
pub unsafe fn guard_instantiate(
    functions: *const fmi2CallbackFunctions,
    instance_name: fmi2String,
    logging_on: bool,
    f: impl FnOnce(Logger) -> Result<Instance, Fault>,
) -> fmi2Component {
    // SAFETY: see the contract above.
    let (functions, name) = unsafe { (functions.as_ref(), text(instance_name, "instanceName")) };
    let logger = Logger::new(functions, name.as_deref().unwrap_or(""), logging_on);
    let outcome = catch_unwind(AssertUnwindSafe(|| name.and_then(|_| f(logger.clone()))));
    let message = match outcome {
        Ok(Ok(instance)) => return Box::into_raw(Box::new(instance)).cast(),
        Ok(Err(fault)) => format!("fmi2Instantiate: {}", fault.message),
        Err(payload) => format!(
            "fmi2Instantiate: internal error (Rust panic: {})",
            panic_text(&*payload)
        ),
    };
    logger.status(fmi2Status::fmi2Error, &message);
    std::ptr::null_mut()
}

/// fmi2FreeInstance (and fmi3FreeInstance, with `I` its instance): drops the instance (NULL is
/// ignored).
///
/// # Safety
/// As for [`guard_with`]; `c` came from `Box::into_raw` and is not used again.
pub unsafe fn guard_free<I>(c: *mut std::os::raw::c_void) {
    if c.is_null() {
        return;
    }
    // SAFETY: `c` came from `Box::into_raw` of an `I` (`guard_instantiate` or fmi3's).
    let instance = unsafe { Box::from_raw(c.cast::<I>()) };
    // A panic while dropping is swallowed: there is nobody left to tell.
    let _ = catch_unwind(AssertUnwindSafe(move || drop(instance)));
}

/// The message a panic was raised with.
pub fn panic_text(payload: &(dyn Any + Send)) -> &str {
    payload
        .downcast_ref::<&str>()
        .copied()
        .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
        .unwrap_or("(no message)")
}

/// The `n` values at `ptr`; NULL is accepted only when `n` is 0.
///
/// # Safety
/// A non-NULL `ptr` points to `n` initialized values that stay valid and unaliased for `'a`.
pub unsafe fn slice<'a, T>(ptr: *const T, n: usize, what: &str) -> Result<&'a [T], Fault> {
    if n == 0 {
        return Ok(&[]);
    }
    check_array(ptr, n, what)?;
    // SAFETY: non-NULL, aligned, length bounded; the rest is the caller's contract.
    Ok(unsafe { std::slice::from_raw_parts(ptr, n) })
}

/// The `n` places at `ptr` to write to; NULL is accepted only when `n` is 0.
///
/// # Safety
/// As for [`slice`], for writing.
pub unsafe fn slice_mut<'a, T>(ptr: *mut T, n: usize, what: &str) -> Result<&'a mut [T], Fault> {
    if n == 0 {
        return Ok(&mut []);
    }
    check_array(ptr, n, what)?;
    // SAFETY: as in `slice`.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, n) })
}

fn check_array<T>(ptr: *const T, n: usize, what: &str) -> Result<(), Fault> {
    if ptr.is_null() {
        return Err(Fault::refused(format!(
            "argument {what} is NULL while its length is {n}"
        )));
    }
    if !ptr.is_aligned() || n > isize::MAX as usize / std::mem::size_of::<T>().max(1) {
        return Err(Fault::refused(format!(
            "argument {what} is not a valid array of {n} values"
        )));
    }
    Ok(())
}

/// Writes one value to an output argument.
///
/// # Safety
/// A non-NULL `ptr` is valid for writing a `T`.
pub unsafe fn put<T>(ptr: *mut T, value: T, what: &str) -> Result<(), Fault> {
    if ptr.is_null() {
        return Err(Fault::refused(format!("argument {what} is NULL")));
    }
    if !ptr.is_aligned() {
        return Err(Fault::refused(format!("argument {what} is not aligned")));
    }
    // SAFETY: non-NULL and aligned; validity is the caller's contract.
    unsafe { ptr.write(value) };
    Ok(())
}

/// A C string argument (invalid UTF-8 replaced).
///
/// # Safety
/// A non-NULL `ptr` points to a NUL-terminated string.
pub unsafe fn text(ptr: fmi2String, what: &str) -> Result<String, Fault> {
    if ptr.is_null() {
        return Err(Fault::refused(format!("argument {what} is NULL")));
    }
    // SAFETY: see the contract above.
    Ok(unsafe { CStr::from_ptr(ptr) }
        .to_string_lossy()
        .into_owned())
}

/// An array of `n` C strings.
///
/// # Safety
/// As for [`slice`] and [`text`].
pub unsafe fn texts(ptr: *const fmi2String, n: usize, what: &str) -> Result<Vec<String>, Fault> {
    // SAFETY: see the contract above.
    let items = unsafe { slice(ptr, n, what)? };
    items
        .iter()
        .enumerate()
        // SAFETY: each item is NULL or a C string, by the contract.
        .map(|(i, &p)| unsafe { text(p, &format!("{what}[{i}]")) })
        .collect()
}
