//! Layer 2, the mechanics: beam sections and finite elements (planar and spatial), the planar
//! and spatial multibody systems with their joints, and the [`Equations`] the integrator solves.
//! Imports only the scene format and the errors below it.

pub mod any_system;
pub mod beam;
pub mod multibody;
pub mod multibody3d;
pub mod options;

pub use any_system::Mechanics;
pub use multibody::Equations;
pub use options::{BeamEffects, Effects};
