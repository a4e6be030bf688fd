//! Beam sections and finite elements (planar paper §3): the element layer, the bottom of the
//! mechanics. It imports nothing from the scene format (`tests/layers.rs` checks it): a beam is
//! built from its own numbers and [`FloatingFrame`]; `mechanics/from_scene/` turns a scene's
//! entries into them.

pub(crate) mod band;
pub(crate) mod planar_beam;
pub(crate) mod planar_element;
pub(crate) mod section;
pub(crate) mod sines;
pub(crate) mod spatial_beam;
pub(crate) mod spatial_element;
pub(crate) mod spatial_section;

/// How a beam's floating frame follows it (planar paper §3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FloatingFrame {
    /// Tangent to the beam at flange a: the root's deformation (u, v and slope) is zero.
    #[default]
    Tangent,
    /// Through both ends: the root's (u, v) and the tip's v are zero.
    Pinned,
}
