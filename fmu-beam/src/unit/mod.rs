//! Layer 4, the unit: one FMU instance, safe. The [`engine::Engine`] (a scene's system, its
//! stepper and its variables), the variable table, the interface (inputs, outputs, their
//! derivatives), shape outputs, natural frequencies and the effects policy (which may run the
//! integrator). Imports every layer below; `fmi2` and `fmi3` above it are its callers.

pub(crate) mod axial_load;
pub(crate) mod effects;
pub(crate) mod engine;
pub(crate) mod input_inertia;
pub(crate) mod interface;
pub(crate) mod log_categories;
pub(crate) mod memory;
pub(crate) mod modes;
pub(crate) mod retry;
pub(crate) mod shape;
pub(crate) mod variables;
