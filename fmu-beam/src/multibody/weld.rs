//! The weld joint: two frames keep the same position and angle (3 equations).
//! Flange a of a beam welded to the world is the clamp of case C1.

use super::frame::Frame;

/// A rigid connection between two frames; g = [p₀ - p₁; φ₀ - φ₁] = 0.
#[derive(Debug, Clone)]
pub struct Weld {
    pub name: String,
    pub frames: [Frame; 2],
}

impl Weld {
    /// Number of constraint equations.
    pub const EQUATIONS: usize = 3;
}
