//! The revolute joint: two frames share their position (2 equations); their relative angle
//! φ₁ - φ₀ is the joint angle.

use super::frame::FrameState;
use super::joint::{Row, Rows};
use nalgebra::Vector2;

/// g = p₁ - p₀.
pub fn rows(f0: &FrameState, f1: &FrameState) -> Rows {
    let mut rows = Rows::default();
    rows.push(Row::along(f0, f1, Vector2::x()));
    rows.push(Row::along(f0, f1, Vector2::y()));
    rows
}
