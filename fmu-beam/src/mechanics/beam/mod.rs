//! Beam sections and finite elements (planar paper §3).

pub(crate) mod planar_beam;
pub(crate) mod planar_element;
pub(crate) mod section;
pub(crate) mod spatial_beam;
pub(crate) mod spatial_element;
pub(crate) mod spatial_section;
