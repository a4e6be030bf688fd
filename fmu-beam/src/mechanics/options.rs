//! What a built system computes: the resolved effects (the policy that resolves them from a
//! scene, `effects = "auto"` among them, is the unit's: `unit::effects`).

use super::beam::planar_beam::BeamOptions;

/// The resolved effects: what the system computes.
#[derive(Debug, Clone, PartialEq)]
pub struct Effects {
    /// The world's gravity field acts (off: `world.gravity` is ignored, its terms are not
    /// evaluated).
    pub gravity: bool,
    /// One entry per scene beam, in scene order.
    pub beams: Vec<BeamEffects>,
}

/// The resolved effects of one scene beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamEffects {
    /// A rigid bar (no deformation coordinates).
    pub rigid: bool,
    /// The terms of the flexible beam (ignored when rigid).
    pub options: BeamOptions,
}
