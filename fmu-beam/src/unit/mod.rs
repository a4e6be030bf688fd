//! Layer 4, the unit: one FMU instance, safe. The [`engine::Engine`] (a scene's system, its
//! stepper and its variables), the variable table, the interface (inputs, outputs, their
//! derivatives), shape outputs, natural frequencies and the effects policy (which may run the
//! integrator). Imports every layer below; `fmi2` above it is the only caller.

pub mod axial_load;
pub mod effects;
pub mod engine;
pub mod interface;
pub mod modes;
pub mod shape;
pub mod variables;
