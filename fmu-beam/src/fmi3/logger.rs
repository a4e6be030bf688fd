//! Messages to the importer through its `logMessage` callback (FMI 3.0 §2.3.1), with its
//! `instanceEnvironment` passed back. The categories, and which of them are on, are the
//! unit's own ([`crate::unit::log_categories`]), as in FMI 2.0: messages of a failed call are
//! always sent; `logEvents` and `logInformation` only when switched on.

use super::types::{fmi3InstanceEnvironment, fmi3LogMessageCallback, fmi3Status};
use crate::unit::log_categories::Categories;
use std::ffi::{CStr, CString};
use std::os::raw::c_int;

/// Where messages of one instance go, and which debug categories are on.
#[derive(Clone)]
pub struct Logger {
    callback: Option<fmi3LogMessageCallback>,
    env: fmi3InstanceEnvironment,
    categories: Categories,
}

impl Logger {
    /// `callback` may be NULL: then nothing is logged.
    pub fn new(
        callback: Option<fmi3LogMessageCallback>,
        env: fmi3InstanceEnvironment,
        logging_on: bool,
    ) -> Logger {
        Logger {
            callback,
            env,
            categories: Categories::new(logging_on),
        }
    }

    /// A debug message of category `logEvents`, sent only when that category is on.
    pub fn event(&self, message: &str) {
        if self.categories.events() {
            self.send(fmi3Status::fmi3OK, c"logEvents", message);
        }
    }

    /// Information (category `logInformation`, status fmi3OK), sent only when that category is on.
    pub fn info(&self, message: &str) {
        if self.categories.information() {
            self.send(fmi3Status::fmi3OK, c"logInformation", message);
        }
    }

    /// The message of a call that returns `status`; sent whatever the debug settings.
    pub fn status(&self, status: fmi3Status, message: &str) {
        let category = match status {
            fmi3Status::fmi3OK => c"logEvents",
            fmi3Status::fmi3Warning => c"logStatusWarning",
            fmi3Status::fmi3Discard => c"logStatusDiscard",
            fmi3Status::fmi3Error => c"logStatusError",
            fmi3Status::fmi3Fatal => c"logStatusFatal",
        };
        self.send(status, category, message);
    }

    /// fmi3SetDebugLogging ([`Categories::set`]).
    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Result<(), String> {
        self.categories.set(on, categories)
    }

    fn send(&self, status: fmi3Status, category: &CStr, message: &str) {
        let Some(callback) = self.callback else {
            return;
        };
        let text = CString::new(message.replace('\0', "")).unwrap_or_default();
        // SAFETY: the importer gave this callback for exactly this use; both strings are valid,
        // NUL-terminated and outlive the call.
        unsafe { callback(self.env, status as c_int, category.as_ptr(), text.as_ptr()) };
    }
}
