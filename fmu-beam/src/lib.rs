//! fmu-beam: a flexible-multibody core (floating-frame Euler–Bernoulli beams, joints,
//! generalized-α) and its FMI 2.0 co-simulation ABI.
//!
//! Five layers, each importing only from those below it (`tests/layers.rs` checks it):
//! 1. [`scene`]: the file format (parsing, validation, the rule table); [`error`] beside it;
//! 2. [`mechanics`]: beam sections and elements, planar and spatial systems, joints, equations;
//! 3. [`integrator`]: generalized-α, Newton, the iteration matrix, the state codec;
//! 4. [`unit`]: one FMU instance, safe ([`Engine`]), its variables, interface, effects policy;
//! 5. `fmi2`: the C ABI, the only unsafe code.

pub mod error;
pub mod fmi2;
pub mod integrator;
pub mod mechanics;
pub mod scene;
pub mod unit;

pub use error::EngineError;
/// The FMI 2.0 C types, one definition for the unit (`fmi2`) and fmu-harness's master binding.
pub use fmi2::types as fmi2_types;
pub use scene::Scene;
pub use unit::engine::Engine;
