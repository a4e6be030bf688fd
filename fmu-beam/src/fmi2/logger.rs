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
use crate::unit::log_categories::Categories;
use std::ffi::{CStr, CString};
use std::os::raw::c_int;

/// Where messages of one instance go, and which debug categories are on.
#[derive(Clone)]
pub struct Logger {
    callback: Option<fmi2CallbackLogger>,
    env: fmi2ComponentEnvironment,
    instance_name: CString,
    categories: Categories,
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
            categories: Categories::new(logging_on),
        }
    }

    /// A debug message of category `logEvents`, sent only when that category is on.
    pub fn event(&self, message: &str) {
        if self.categories.events() {
            self.send(fmi2Status::fmi2OK, c"logEvents", message);
        }
    }

    /// Information (category `logInformation`, status fmi2OK), sent only when that category is on.
    pub fn info(&self, message: &str) {
        if self.categories.information() {
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

    /// fmi2SetDebugLogging ([`Categories::set`]).
    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Result<(), String> {
        self.categories.set(on, categories)
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
}
