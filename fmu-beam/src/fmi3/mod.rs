//! The FMI 3.0 co-simulation C ABI (issue 47), beside FMI 2.0's over the same unit layer: with
//! `fmi2/`, the only unsafe code of the crate.
//!
//! [`exports`] holds every `extern "C"` function of the standard, each a line or two that hands
//! over to a safe [`instance::Instance`] method through [`guard::guard`]. The state machine is
//! in [`state_machine`], the importer's logger in [`logger`], the C types in [`types`]. What
//! does not depend on the standard's version is the 2.0 layer's and shared, not copied: the
//! guard's core (`fmi2::guard::guard_with`, the pointer conversions, `Fault`), the resources
//! directory, and the FMU states (`fmi2::fmu_state`; so a serialized state of one scene loads
//! into either unit of it). The FMI 3.0 variables, shape arrays included, are the unit's
//! [`crate::unit::variables::Layout3`].

#![allow(unsafe_code)]
#![deny(unsafe_op_in_unsafe_fn)]

pub(crate) mod exports;
pub(crate) mod guard;
pub(crate) mod instance;
pub(crate) mod logger;
pub(crate) mod state_machine;
pub mod types;

#[cfg(test)]
mod abi_tests;
