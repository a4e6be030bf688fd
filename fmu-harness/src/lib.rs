//! fmu-harness: turns a scene file into an FMI 2.0 (or 3.0) co-simulation FMU, reports a scene's
//! linearized natural frequencies, and runs FMI 2.0 and 3.0 co-simulation FMUs (any, not only
//! ours) through [`slave::Slave`] over the raw bindings [`fmi2_binding`] and [`fmi3_binding`]
//! (with what they share, [`binding`]: the crate's only unsafe code).
//!
//! Data flow of `package`: [`fmu_beam::Scene`] → [`fmu_beam::VariableTable`] →
//! [`model_description::render`] (the template in `modelDescription-templates/`) →
//! [`guid::guid`] → [`archive::write_fmu`] (deterministic zip, written atomically).

pub mod accuracy;
pub mod animate;
pub mod archive;
#[allow(unsafe_code)]
pub mod binding;
pub mod chart;
pub mod cli;
pub mod cosim;
pub mod engine_library;
pub mod error;
#[allow(unsafe_code)]
pub mod fmi2_binding;
#[allow(unsafe_code)]
pub mod fmi3_binding;
pub mod guid;
pub mod input_file;
pub mod log_categories;
pub mod log_format;
pub mod model_description;
pub mod modes;
pub mod output_file;
pub mod package;
pub mod platform;
pub mod reference;
pub mod schema;
pub mod scratch;
pub mod simulate;
pub mod slave;
pub mod template;

pub use error::HarnessError;
