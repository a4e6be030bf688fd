//! Layer 2, the mechanics: beam sections and finite elements (planar and spatial), the planar
//! and spatial multibody systems with their joints, and the [`Equations`] the integrator solves.
//! Imports only the errors; the systems, joints and laws have their own types, and the scene
//! format is read in one place, `from_scene/` (the one door, checked by `tests/layers.rs`).
//!
//! Public here: what assembles a system without a scene file (the benchmarks build C5's beam
//! this way); the element internals stay private to the crate.

pub(crate) mod any_system;
pub(crate) mod beam;
pub(crate) mod from_scene;
pub(crate) mod multibody;
pub(crate) mod multibody3d;
pub(crate) mod options;

pub use any_system::Mechanics;
pub use beam::planar_beam::{BeamOptions, PlanarBeam};
pub use beam::section::Section;
pub use beam::spatial_beam::{InertiaModel, SpatialBeam, SpatialBeamProps};
pub use beam::spatial_element::{
    mass as spatial_element_mass, stiffness as spatial_element_stiffness,
};
pub use beam::spatial_section::SpatialSection;
pub use beam::FloatingFrame;
pub use from_scene::matrix_file_beam;
pub use multibody::joint::{Drive, DriveKind, JointKind};
pub use multibody::law::{Law, TimeLaw};
pub use multibody::{Equations, Point, System};
pub use multibody3d::{Body3, Frame3, Load3, RigidBody3, System3};
pub use options::{BeamEffects, Effects};
