//! The tests that need the crate's internals (element matrices and their coordinates, the
//! spatial system assembled by hand, the iteration matrix's sparse path), moved in from
//! `tests/` when the public API was narrowed; the tests of the public API stay in `tests/`.
//! Above every layer: a test may import any of them.

#[path = "../../tests/common/mod.rs"]
mod common;

mod beam_damping;
mod bordered_iteration_matrix;
mod input_inertia;
mod planar_beam_element;
mod planar_spatial_agreement;
mod sparse_iteration_matrix;
mod spatial_beam_element;
mod spatial_jacobians;
mod spatial_stiffening;
mod spatial_system;
