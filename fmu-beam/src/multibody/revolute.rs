//! The revolute joint: two frames share their position (2 equations); their relative angle
//! φ₁ - φ₀ is the joint angle.

use super::frame::FrameState;
use super::joint::Row;
use nalgebra::Vector2;

/// g = p₁ - p₀.
pub fn rows(f0: &FrameState, f1: &FrameState) -> Vec<Row> {
    [Vector2::x(), Vector2::y()]
        .into_iter()
        .map(|d| Row::along(f0, f1, d))
        .collect()
}
