//! What the raw bindings of both FMI versions share ([`crate::fmi2_binding`],
//! [`crate::fmi3_binding`]): the status as returned ([`Status`]), the log sink a logger callback
//! appends to ([`LogSink`], [`push_message`]), an FMU state tagged with its instance
//! ([`FmuState`]: the owner checks of get, set and free, written once), the symbol look-up of a
//! loaded library ([`symbol`]) and why a library is refused ([`LoadError`]).
//!
//! Unsafe code, like the two bindings: the C strings a logger receives, the symbols of a library.

use std::ffi::CStr;
use std::os::raw::{c_char, c_int, c_void};
use std::sync::Mutex;

/// A status as the master receives it: a plain `c_int`, never a Rust enum (a Rust enum must
/// never hold a value outside its variants, and a foreign FMU may return any integer);
/// [`Status::from_c`] reads it. FMI 2.0 and 3.0 number their statuses alike (0 OK ... 4 Fatal).
pub type RawStatus = c_int;

/// A status as returned; a value outside the standard's range is kept as `Unknown`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    Ok,
    Warning,
    Discard,
    Error,
    Fatal,
    /// fmi2Pending (FMI 2.0 only: asynchronous steps).
    Pending,
    Unknown(c_int),
}

impl Status {
    /// An FMI 2.0 status.
    pub fn from_c(s: RawStatus) -> Self {
        match s {
            0 => Status::Ok,
            1 => Status::Warning,
            2 => Status::Discard,
            3 => Status::Error,
            4 => Status::Fatal,
            5 => Status::Pending,
            other => Status::Unknown(other),
        }
    }

    /// An FMI 3.0 status: as 2.0's, without Pending.
    pub fn from_c3(s: RawStatus) -> Self {
        match Status::from_c(s) {
            Status::Pending => Status::Unknown(s),
            other => other,
        }
    }

    /// OK or Warning: the call did what was asked.
    pub fn is_success(self) -> bool {
        matches!(self, Status::Ok | Status::Warning)
    }

    /// The status's name without its version prefix (`Discard`).
    fn suffix(self) -> &'static str {
        match self {
            Status::Ok => "OK",
            Status::Warning => "Warning",
            Status::Discard => "Discard",
            Status::Error => "Error",
            Status::Fatal => "Fatal",
            Status::Pending => "Pending",
            Status::Unknown(_) => "",
        }
    }

    /// The status as the standard of `function` names it: `fmi3Discard` for an `fmi3…`
    /// function, `fmi2Discard` otherwise.
    pub fn named_for(self, function: &str) -> String {
        match self {
            Status::Unknown(v) => format!("unknown status {v}"),
            s => {
                let prefix = if function.starts_with("fmi3") {
                    "fmi3"
                } else {
                    "fmi2"
                };
                format!("{prefix}{}", s.suffix())
            }
        }
    }
}

/// FMI 2.0's names (`fmi2Discard`); [`Status::named_for`] names a 3.0 function's.
impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.named_for("fmi2"))
    }
}

/// One call of the FMU's logger.
#[derive(Debug, Clone, PartialEq)]
pub struct LogMessage {
    pub status: Status,
    pub category: String,
    pub message: String,
}

/// Where the logger callback of one instance puts its messages.
pub type LogSink = Mutex<Vec<LogMessage>>;

/// Appends one logger call to the [`LogSink`] at `env` (nothing when `env` is NULL).
/// `printf`: the message is a printf format (FMI 2.0: `%%` is printed `%`, see
/// [`crate::log_format::printf`]); FMI 3.0's is plain text. Never unwinds: whatever could panic
/// runs inside `catch_unwind`.
///
/// # Safety
/// `env` is NULL or a live [`LogSink`]; `category` and `message` are NULL or NUL-terminated
/// strings valid for the call.
pub(crate) unsafe fn push_message(
    env: *mut c_void,
    status: Status,
    category: *const c_char,
    message: *const c_char,
    printf: bool,
) {
    let text = |p: *const c_char| {
        if p.is_null() {
            String::new()
        } else {
            // SAFETY: the caller's contract: a NUL-terminated string valid for the call.
            unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
        }
    };
    if env.is_null() {
        return;
    }
    // SAFETY: the caller's contract: env is a live LogSink.
    let sink = unsafe { &*(env as *const LogSink) };
    let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let message = text(message);
        let entry = LogMessage {
            status,
            category: text(category),
            message: if printf {
                crate::log_format::printf(&message)
            } else {
                message
            },
        };
        if let Ok(mut v) = sink.lock() {
            v.push(entry);
        }
    }));
}

/// The messages in `sink`, which is left empty.
pub(crate) fn take_messages(sink: &LogSink) -> Vec<LogMessage> {
    std::mem::take(&mut *sink.lock().unwrap_or_else(|e| e.into_inner()))
}

/// A library that cannot be loaded, or lacks a function the master needs.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    #[error("cannot load {path}: {source}")]
    Open {
        path: String,
        source: libloading::Error,
    },
    #[error("{path} does not export {symbol}")]
    Missing { path: String, symbol: &'static str },
}

/// Loads the shared library at `path`.
///
/// Loading runs the library's initializers; an FMU's binary is trusted code of the master's
/// choosing, as in every FMI importer.
pub(crate) fn open(path: &std::path::Path) -> Result<libloading::Library, LoadError> {
    // SAFETY: see above: loading an FMU's library is running its code.
    unsafe { libloading::Library::new(path) }.map_err(|source| LoadError::Open {
        path: path.display().to_string(),
        source,
    })
}

/// The function `name` of `library`, if it exports it.
///
/// # Safety
/// `T` is the C type the FMI standard gives the function `name`; the pointer is used only while
/// `library` is loaded.
pub(crate) unsafe fn symbol<T: Copy>(library: &libloading::Library, name: &str) -> Option<T> {
    let mut c_name = name.as_bytes().to_vec();
    c_name.push(0);
    // SAFETY: the caller's contract.
    unsafe { library.get::<T>(&c_name) }.ok().map(|s| *s)
}

/// The function `name` of `library`, or [`LoadError::Missing`].
///
/// # Safety
/// As for [`symbol`].
pub(crate) unsafe fn required<T: Copy>(
    library: &libloading::Library,
    path: &std::path::Path,
    name: &'static str,
) -> Result<T, LoadError> {
    // SAFETY: the caller's contract.
    unsafe { symbol(library, name) }.ok_or_else(|| LoadError::Missing {
        path: path.display().to_string(),
        symbol: name,
    })
}

/// A function the library does not export, or a state of another instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    NotExported(&'static str),
    ForeignState,
}

/// An FMU state made by an instance's `get_fmu_state`; tagged with its instance so that it is
/// never handed to another one (of either version).
#[derive(Debug)]
pub struct FmuState {
    pointer: *mut c_void,
    owner: *mut c_void,
}

impl FmuState {
    /// No state yet: the FMU's GetFMUState allocates a new one.
    pub fn empty() -> Self {
        FmuState {
            pointer: std::ptr::null_mut(),
            owner: std::ptr::null_mut(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.pointer.is_null()
    }

    /// GetFMUState of `instance` into this state: `call` gets the state's address, which holds
    /// NULL or a state of `instance`; refused for a state of another instance.
    pub(crate) fn get(
        &mut self,
        instance: *mut c_void,
        call: impl FnOnce(*mut *mut c_void) -> RawStatus,
    ) -> Result<RawStatus, Refusal> {
        if !self.is_empty() && self.owner != instance {
            return Err(Refusal::ForeignState);
        }
        let s = call(&mut self.pointer);
        if !self.pointer.is_null() {
            self.owner = instance;
        }
        Ok(s)
    }

    /// SetFMUState of `instance`: `call` gets the state, one of `instance`'s; refused for an
    /// empty state or one of another instance.
    pub(crate) fn set(
        &self,
        instance: *mut c_void,
        call: impl FnOnce(*mut c_void) -> RawStatus,
    ) -> Result<RawStatus, Refusal> {
        if self.is_empty() || self.owner != instance {
            return Err(Refusal::ForeignState);
        }
        Ok(call(self.pointer))
    }

    /// FreeFMUState of `instance`: `None` for an empty state (nothing to free); the state is
    /// empty afterwards if the FMU set it to NULL.
    pub(crate) fn free(
        &mut self,
        instance: *mut c_void,
        call: impl FnOnce(*mut *mut c_void) -> RawStatus,
    ) -> Result<Option<RawStatus>, Refusal> {
        if self.is_empty() {
            return Ok(None);
        }
        if self.owner != instance {
            return Err(Refusal::ForeignState);
        }
        let s = call(&mut self.pointer);
        if self.pointer.is_null() {
            self.owner = std::ptr::null_mut();
        }
        Ok(Some(s))
    }
}

/// `fmi2GetFMUstate` / `fmi3GetFMUState` and the free functions: the same C type in both.
pub type GetStateFn = unsafe extern "C" fn(*mut c_void, *mut *mut c_void) -> RawStatus;
/// `fmi2SetFMUstate` / `fmi3SetFMUState`.
pub type SetStateFn = unsafe extern "C" fn(*mut c_void, *mut c_void) -> RawStatus;

/// The FMU-state functions of a library (get, set, free: each `None` when not exported), with
/// their names for [`Refusal::NotExported`]; one implementation for both versions.
pub(crate) struct StateFunctions {
    get: Option<GetStateFn>,
    set: Option<SetStateFn>,
    free: Option<GetStateFn>,
    names: [&'static str; 3],
}

impl StateFunctions {
    /// The functions `names` (get, set, free) of `library`.
    ///
    /// # Safety
    /// The names are the FMU-state functions of an FMI standard, whose C types are
    /// [`GetStateFn`] and [`SetStateFn`]; the pointers are used only while `library` is loaded.
    pub(crate) unsafe fn load(library: &libloading::Library, names: [&'static str; 3]) -> Self {
        // SAFETY: the caller's contract.
        unsafe {
            StateFunctions {
                get: symbol(library, names[0]),
                set: symbol(library, names[1]),
                free: symbol(library, names[2]),
                names,
            }
        }
    }

    /// GetFMUState of `instance` into `state` (empty, or one of `instance`'s).
    ///
    /// # Safety
    /// `instance` is live, of the library these functions come from.
    pub(crate) unsafe fn get(
        &self,
        instance: *mut c_void,
        state: &mut FmuState,
    ) -> Result<RawStatus, Refusal> {
        let f = self.get.ok_or(Refusal::NotExported(self.names[0]))?;
        // SAFETY: the caller's contract; the pointer holds NULL or a state of `instance`.
        state.get(instance, |p| unsafe { f(instance, p) })
    }

    /// SetFMUState of `instance` to `state`, one of its own.
    ///
    /// # Safety
    /// As for [`StateFunctions::get`].
    pub(crate) unsafe fn set(
        &self,
        instance: *mut c_void,
        state: &FmuState,
    ) -> Result<RawStatus, Refusal> {
        let f = self.set.ok_or(Refusal::NotExported(self.names[1]))?;
        // SAFETY: the caller's contract; a state of `instance`.
        state.set(instance, |p| unsafe { f(instance, p) })
    }

    /// FreeFMUState: `None` for an empty state; the state is empty afterwards if the FMU set it
    /// to NULL.
    ///
    /// # Safety
    /// As for [`StateFunctions::get`].
    pub(crate) unsafe fn free(
        &self,
        instance: *mut c_void,
        state: &mut FmuState,
    ) -> Result<Option<RawStatus>, Refusal> {
        let f = self.free.ok_or(Refusal::NotExported(self.names[2]))?;
        // SAFETY: the caller's contract; a state of `instance`.
        state.free(instance, |p| unsafe { f(instance, p) })
    }
}

/// The array lengths of a get or set, checked: a caller's bug otherwise (it panics, naming
/// `function`).
pub(crate) fn same_length(function: &str, a: usize, b: usize) {
    assert_eq!(a, b, "{function}: the arrays differ in length");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statuses_are_named_in_the_version_of_the_function() {
        assert_eq!(Status::from_c(2).named_for("fmi3DoStep"), "fmi3Discard");
        assert_eq!(Status::from_c(2).to_string(), "fmi2Discard");
        assert_eq!(Status::from_c3(5), Status::Unknown(5));
        assert_eq!(Status::from_c(5), Status::Pending);
        assert_eq!(
            Status::from_c3(9).named_for("fmi3DoStep"),
            "unknown status 9"
        );
    }

    #[test]
    fn a_state_of_one_instance_is_refused_to_another() {
        let (mut x, mut y, mut z) = (0u8, 0u8, 0u8);
        let a = &mut x as *mut u8 as *mut c_void;
        let b = &mut y as *mut u8 as *mut c_void;
        let made = &mut z as *mut u8 as *mut c_void;
        let mut state = FmuState::empty();
        assert_eq!(state.set(a, |_| 0), Err(Refusal::ForeignState));
        assert_eq!(state.free(a, |_| 0), Ok(None));
        let got = state.get(a, |p| {
            // SAFETY: p is the state's own field.
            unsafe { *p = made };
            0
        });
        assert_eq!(got, Ok(0));
        assert_eq!(state.set(b, |_| 0), Err(Refusal::ForeignState));
        assert_eq!(state.get(b, |_| 0), Err(Refusal::ForeignState));
        assert_eq!(state.set(a, |p| (p == made) as RawStatus), Ok(1));
        let freed = state.free(a, |p| {
            // SAFETY: p is the state's own field.
            unsafe { *p = std::ptr::null_mut() };
            0
        });
        assert_eq!(freed, Ok(Some(0)));
        assert!(state.is_empty());
    }
}
