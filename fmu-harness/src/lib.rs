//! fmu-harness: turns a scene file into an FMI 2.0 co-simulation FMU, and reports a scene's
//! linearized natural frequencies.
//!
//! Data flow of `package`: [`fmu_beam::Scene`] → [`fmu_beam::variables::VariableTable`] →
//! [`model_description::render`] (the template in `modelDescription-templates/`) →
//! [`guid::guid`] → [`archive::write_fmu`] (deterministic zip, written atomically).

pub mod archive;
pub mod cli;
pub mod error;
pub mod guid;
pub mod log_categories;
pub mod model_description;
pub mod modes;
pub mod package;
pub mod template;
pub mod work_precision;

pub use error::HarnessError;
