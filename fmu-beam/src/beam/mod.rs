//! Beam sections and finite elements (planar paper §3).

pub mod planar_beam;
pub mod planar_element;
pub mod section;
