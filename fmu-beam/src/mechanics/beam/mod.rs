//! Beam sections and finite elements (planar paper §3).

pub mod planar_beam;
pub mod planar_element;
pub mod section;
pub mod spatial_beam;
pub mod spatial_element;
pub mod spatial_section;
