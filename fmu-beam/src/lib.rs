//! fmu-beam: a flexible-multibody core (floating-frame Euler–Bernoulli beams, joints,
//! generalized-α) and its FMI 2.0 co-simulation ABI.
//!
//! Five layers on a floor, each importing only from those below it (`tests/layers.rs` checks
//! it):
//! 0. the elements (`mechanics/beam/`): sections and finite elements, which import nothing;
//! 1. [`scene`]: the file format (parsing, validation, the rule table); `error` above it;
//! 2. [`mechanics`]: planar and spatial systems, joints, equations, built from the scene;
//! 3. [`integrator`]: generalized-α, Newton, the iteration matrix, the state codec;
//! 4. `unit`: one FMU instance, safe ([`Engine`]), its variables, interface, effects policy;
//! 5. `fmi2`: the C ABI, the only unsafe code.
//!
//! The public API is chosen here: a scene and its unit ([`Scene`], [`Engine`], the variable
//! table, the effects it resolves), and, for those who assemble systems without a scene (the
//! benchmarks), the curated [`mechanics`] and [`integrator`] modules. Everything else is
//! private to the crate.

#![warn(missing_docs)]

mod error;
mod fmi2;
mod fmi3;
pub mod integrator;
pub mod mechanics;
pub mod scene;
#[cfg(test)]
mod tests;
mod unit;
/// The crate by its own name, for `tests/common`, which the in-crate tests share.
#[cfg(test)]
extern crate self as fmu_beam;

pub use error::EngineError;
/// The FMI 2.0 C types, one definition for the unit (`fmi2`) and fmu-harness's master binding.
pub use fmi2::types as fmi2_types;
/// The FMI 3.0 C types, one definition for the unit (`fmi3`) and fmu-harness's master binding.
pub use fmi3::types as fmi3_types;
pub use scene::{Scene, SceneError};
pub use unit::effects::{resolve as resolve_effects, Decision, Resolution, EFFECTS};
pub use unit::engine::Engine;
pub use unit::interface::explain as explain_feedthrough;
pub use unit::interface::explain_accuracy;
pub use unit::log_categories::LOG_CATEGORIES;
pub use unit::modes::{modes, natural_frequencies, Mode, ModeOptions, Modes};
pub use unit::variables::{
    Binding, Causality, Declared, Initial, Layout3, UnitDef, VarType, Variability, Variable,
    Variable3, VariableTable, UNITS,
};
