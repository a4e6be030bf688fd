//! fmu-beam: a flexible-multibody core (floating-frame Euler–Bernoulli beams, joints,
//! generalized-α) and its FMI 2.0 co-simulation ABI.
//!
//! Data flow: [`scene::Scene`] (TOML) → [`multibody::System`] → [`integrator::Stepper`] →
//! [`engine::Engine`] (one FMU instance, safe) → `fmi2` (the C ABI, the only unsafe code).

pub mod axial_load;
pub mod beam;
pub mod effects;
pub mod engine;
pub mod error;
pub mod fmi2;
pub mod integrator;
pub mod interface;
pub mod mechanics;
pub mod modes;
pub mod multibody;
pub mod multibody3d;
pub mod scene;
pub mod shape;
pub mod variables;

pub use engine::Engine;
pub use error::EngineError;
pub use scene::Scene;
