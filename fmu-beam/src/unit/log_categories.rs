//! The log categories of the unit, the same for FMI 2.0 and 3.0 (each standard's layer
//! writes them into its modelDescription.xml and logs through its own callback), and which of
//! them a master switched on.

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

/// Which debug categories are on: one bit per entry of [`LOG_CATEGORIES`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Categories {
    enabled: u32,
}

impl Categories {
    /// All categories on (`loggingOn` at instantiation) or none.
    pub fn new(logging_on: bool) -> Categories {
        Categories {
            enabled: if logging_on { ALL } else { 0 },
        }
    }

    /// `logEvents` is on.
    pub fn events(self) -> bool {
        self.enabled & LOG_EVENTS != 0
    }

    /// `logInformation` is on.
    pub fn information(self) -> bool {
        self.enabled & LOG_INFORMATION != 0
    }

    /// SetDebugLogging: no categories means all of them; `logAll` stands for all of them.
    /// Nothing changes when a name is unknown.
    pub fn set(&mut self, on: bool, categories: &[String]) -> Result<(), String> {
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn categories() {
        let mut l = Categories::new(false);
        l.set(true, &["logEvents".into()]).unwrap();
        assert_eq!(l.enabled, LOG_EVENTS);
        l.set(true, &["logAll".into()]).unwrap();
        assert_eq!(l.enabled, ALL);
        l.set(false, &["logEvents".into()]).unwrap();
        assert_eq!(l.enabled, ALL & !LOG_EVENTS);
        assert!(l.set(true, &["logNonsense".into()]).is_err());
        assert_eq!(l.enabled, ALL & !LOG_EVENTS);
        l.set(false, &[]).unwrap();
        assert_eq!(l.enabled, 0);
        l.set(true, &["logInformation".into()]).unwrap();
        assert_eq!(l.enabled, LOG_INFORMATION);
    }
}
