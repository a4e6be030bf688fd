//! The package's exceptions and the one guard every call goes through: an error of fmu_beam or
//! fmu_harness becomes [`SceneError`] (a refused scene: the field and the rule as attributes)
//! or [`Error`] (anything else), and a panic becomes [`Error`] instead of crossing into Python.

use fmu_harness::HarnessError;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

pyo3::create_exception!(
    fmu_beam,
    Error,
    PyException,
    "An error of fmu_beam: an engine library or a file that cannot be read or written, a \
     scene whose unit cannot be built, an FMU that cannot be run."
);

pyo3::create_exception!(
    fmu_beam,
    SceneError,
    Error,
    "A scene refused by the packager's validation. Its message is the packager's; its \
     attributes: `origin` (the file, or '<dict>'), `field` (the field's path such as \
     'beam \"arm\".length', or None when the text could not be read at all), `value` (as written), \
     `rule` (what the value breaks, or the parser's message) and `code` (the rule's code in the \
     scene reference, or None)."
);

pyo3::create_exception!(
    fmu_beam,
    SimulationError,
    Error,
    "A run that the unit could not continue: a step it refused (fmi2Discard) or a failure. \
     Attributes: `time` (the last good time, s), `reason` (the unit's message), `ended` (True \
     where no smaller step can pass: the model left its range), and, from Scene.simulate, \
     `rows` (a DataFrame of every communication point up to `time`)."
);

/// The parts of a refusal, as [`SceneError`]'s attributes.
#[derive(Debug, Default)]
pub struct Refusal {
    pub message: String,
    pub origin: String,
    pub field: Option<String>,
    pub value: Option<String>,
    pub rule: Option<String>,
    pub code: Option<&'static str>,
}

impl Refusal {
    /// The refusal of fmu_beam's validation, field for field.
    pub fn of(e: &fmu_beam::SceneError) -> Refusal {
        use fmu_beam::SceneError as E;
        let message = e.to_string();
        match e {
            E::Io { origin, message: m } | E::Parse { origin, message: m } => Refusal {
                message,
                origin: origin.clone(),
                rule: Some(m.clone()),
                ..Refusal::default()
            },
            E::File {
                origin,
                field,
                file,
                rule,
            } => Refusal {
                message,
                origin: origin.clone(),
                field: Some(field.clone()),
                value: Some(file.clone()),
                rule: Some(rule.clone()),
                code: None,
            },
            E::Invalid {
                origin,
                field,
                value,
                rule,
                code,
            } => Refusal {
                message,
                origin: origin.clone(),
                field: Some(field.clone()),
                value: Some(value.clone()),
                rule: Some(rule.clone()),
                code: Some(code),
            },
        }
    }

    /// As a Python exception.
    pub fn into_err(self, py: Python<'_>) -> PyErr {
        let err = SceneError::new_err(self.message);
        let value = err.value(py);
        let set = |name: &str, v: Option<String>| value.setattr(name, v);
        let attrs = set("origin", Some(self.origin))
            .and_then(|_| set("field", self.field))
            .and_then(|_| set("value", self.value))
            .and_then(|_| set("rule", self.rule))
            .and_then(|_| set("code", self.code.map(String::from)));
        match attrs {
            Ok(()) => err,
            Err(e) => e,
        }
    }
}

/// A harness error as a Python exception: a refused scene (also one refused by the engine)
/// as [`SceneError`], the rest as [`Error`].
pub fn harness_err(py: Python<'_>, e: HarnessError) -> PyErr {
    match &e {
        HarnessError::Scene(s) => Refusal::of(s).into_err(py),
        HarnessError::Engine {
            source: fmu_beam::EngineError::Scene(s),
            ..
        } => Refusal::of(s).into_err(py),
        _ => Error::new_err(e.to_string()),
    }
}

/// Runs `f`, turning a panic into [`Error`] (the default hook has printed where it happened).
pub fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(result) => result,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic".into());
            Err(Error::new_err(format!(
                "internal error of fmu_beam (please report it): {what}"
            )))
        }
    }
}
