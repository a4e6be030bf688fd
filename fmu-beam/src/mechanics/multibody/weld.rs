//! The weld joint: two frames keep their relative position and angle (3 equations).
//! Flange a of a beam welded to the world is the clamp of case C1; substructures of a beam are
//! welded tip to root (planar paper §3.4).

use super::frame::FrameState;
use super::joint::{Row, Rows};

/// g = [p₁ - p₀; φ₁ - φ₀ - offset].
pub fn rows(f0: &FrameState, f1: &FrameState, offset: f64) -> Rows {
    let mut rows = super::revolute::rows(f0, f1);
    rows.push(Row::angle(f0, f1, offset));
    rows
}
