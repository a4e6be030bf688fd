//! The FMI 2.0 co-simulation C ABI: the only unsafe code of the crate.
//!
//! [`exports`] holds the `extern "C"` functions, each a line or two that hands over to a safe
//! [`instance::Instance`] method through [`guard::guard`]. The call-sequence state machine is in
//! [`state_machine`], FMU states (rollback) in [`fmu_state`], the master's logger in [`logger`],
//! the resources directory in [`resources`], the C types in [`types`].

#![allow(unsafe_code)]
#![deny(unsafe_op_in_unsafe_fn)]

pub(crate) mod exports;
pub(crate) mod fmu_state;
pub(crate) mod guard;
pub(crate) mod instance;
pub(crate) mod logger;
pub(crate) mod resources;
pub(crate) mod state_machine;
pub mod types;

#[cfg(test)]
mod abi_tests;
