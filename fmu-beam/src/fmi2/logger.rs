//! Messages to the master, through its `logger` callback, with the instance name and the
//! master's `componentEnvironment` passed back.
//!
//! Messages of a failed call (status Warning, Discard, Error, Fatal) are always sent, whatever
//! fmi2SetDebugLogging said: the standard allows it and the master filters by category.
//! Debug messages (category `logEvents`) and information (category `logInformation`, status
//! fmi2OK: what the unit did on its own that asks nothing of the user) are sent only when their
//! category is switched on (fmi2Instantiate's loggingOn, or fmi2SetDebugLogging).

use super::types::{
    fmi2CallbackFunctions, fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status,
};
use std::ffi::{CStr, CString};
use std::os::raw::c_int;

/// The log categories of this FMU, (name, description), in the order of modelDescription.xml.
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    (
        "logEvents",
        "Changes of the instance's state: initialization, termination, reset, FMU state restored",
    ),
    (
        "logInformation",
        "What the unit did or found on its own that asks nothing of the user (status fmi2OK): \
         a fixed step cut short (solver.split_steps counts them), the effective inertia of an \
         input and the gains a sampled loop on it must keep",
    ),
    (
        "logStatusWarning",
        "Messages of calls that return fmi2Warning",
    ),
    (
        "logStatusDiscard",
        "Messages of calls that return fmi2Discard: why a step was not completed",
    ),
    (
        "logStatusError",
        "Messages of calls that return fmi2Error: what was wrong with the call or the model",
    ),
    ("logStatusFatal", "Messages of calls that return fmi2Fatal"),
    ("logAll", "All of the above"),
];

const LOG_EVENTS: u32 = 1 << 0;
const LOG_INFORMATION: u32 = 1 << 1;
const ALL: u32 = (1 << LOG_CATEGORIES.len()) - 1;

/// Where messages of one instance go, and which debug categories are on.
#[derive(Clone)]
pub struct Logger {
    callback: Option<fmi2CallbackLogger>,
    env: fmi2ComponentEnvironment,
    instance_name: CString,
    /// One bit per entry of [`LOG_CATEGORIES`].
    enabled: u32,
}

impl Logger {
    /// `functions` may be absent (NULL), and so may its logger: then nothing is logged.
    pub fn new(
        functions: Option<&fmi2CallbackFunctions>,
        instance_name: &str,
        logging_on: bool,
    ) -> Logger {
        Logger {
            callback: functions.and_then(|f| f.logger),
            env: functions.map_or(std::ptr::null_mut(), |f| f.componentEnvironment),
            instance_name: c_text(instance_name, false),
            enabled: if logging_on { ALL } else { 0 },
        }
    }

    /// A debug message of category `logEvents`, sent only when that category is on.
    pub fn event(&self, message: &str) {
        if self.enabled & LOG_EVENTS != 0 {
            self.send(fmi2Status::fmi2OK, c"logEvents", message);
        }
    }

    /// Information (category `logInformation`, status fmi2OK), sent only when that category is on.
    pub fn info(&self, message: &str) {
        if self.enabled & LOG_INFORMATION != 0 {
            self.send(fmi2Status::fmi2OK, c"logInformation", message);
        }
    }

    /// The message of a call that returns `status`; sent whatever the debug settings.
    pub fn status(&self, status: fmi2Status, message: &str) {
        let category = match status {
            fmi2Status::fmi2OK | fmi2Status::fmi2Pending => c"logEvents",
            fmi2Status::fmi2Warning => c"logStatusWarning",
            fmi2Status::fmi2Discard => c"logStatusDiscard",
            fmi2Status::fmi2Error => c"logStatusError",
            fmi2Status::fmi2Fatal => c"logStatusFatal",
        };
        self.send(status, category, message);
    }

    /// fmi2SetDebugLogging: no categories means all of them; `logAll` stands for all of them.
    /// Nothing changes when a name is unknown.
    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Result<(), String> {
        let mut bits = if categories.is_empty() { ALL } else { 0 };
        for name in categories {
            bits |= match LOG_CATEGORIES.iter().position(|(n, _)| n == name) {
                Some(_) if name == "logAll" => ALL,
                Some(i) => 1 << i,
                None => {
                    let known: Vec<&str> = LOG_CATEGORIES.iter().map(|(n, _)| *n).collect();
                    return Err(format!(
                        "unknown log category '{name}'; the categories are {}",
                        known.join(", ")
                    ));
                }
            };
        }
        self.enabled = match (on, categories.is_empty()) {
            (true, _) => bits,
            (false, true) => 0,
            (false, false) => self.enabled & !bits,
        };
        Ok(())
    }

    fn send(&self, status: fmi2Status, category: &CStr, message: &str) {
        let Some(callback) = self.callback else {
            return;
        };
        let text = c_text(message, true);
        // SAFETY: the master gave this callback for exactly this use; every string is a valid,
        // NUL-terminated C string that outlives the call, and `text` has no conversion
        // specification left (every '%' doubled), so no variadic argument is read.
        unsafe {
            callback(
                self.env,
                self.instance_name.as_ptr(),
                status as c_int,
                category.as_ptr(),
                text.as_ptr(),
            )
        };
    }
}

/// A C string of `s`: NUL bytes dropped and, for a printf format, every '%' doubled.
fn c_text(s: &str, format: bool) -> CString {
    let mut t = String::with_capacity(s.len() + 8);
    for ch in s.chars() {
        match ch {
            '\0' => {}
            '%' if format => t.push_str("%%"),
            _ => t.push(ch),
        }
    }
    CString::new(t).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_is_doubled_and_nul_dropped() {
        assert_eq!(c_text("50% of %s\0!", true).as_bytes(), b"50%% of %%s!");
        assert_eq!(c_text("50%", false).as_bytes(), b"50%");
    }

    #[test]
    fn categories() {
        let mut l = Logger::new(None, "x", false);
        l.set_debug_logging(true, &["logEvents".into()]).unwrap();
        assert_eq!(l.enabled, LOG_EVENTS);
        l.set_debug_logging(true, &["logAll".into()]).unwrap();
        assert_eq!(l.enabled, ALL);
        l.set_debug_logging(false, &["logEvents".into()]).unwrap();
        assert_eq!(l.enabled, ALL & !LOG_EVENTS);
        assert!(l.set_debug_logging(true, &["logNonsense".into()]).is_err());
        assert_eq!(l.enabled, ALL & !LOG_EVENTS);
        l.set_debug_logging(false, &[]).unwrap();
        assert_eq!(l.enabled, 0);
        l.set_debug_logging(true, &["logInformation".into()])
            .unwrap();
        assert_eq!(l.enabled, LOG_INFORMATION);
    }
}
