//! The prismatic joint: frame 1 slides along the axis e = A(φ₀ + α) x̂ of frame 0 and keeps
//! its relative angle (2 equations); e·(p₁ - p₀) is the joint position.

use super::frame::FrameState;
use super::joint::{Row, Rows};
use nalgebra::Vector2;

/// Axis e and normal n of the slide in world components.
pub fn axes(f0: &FrameState, axis_angle: f64) -> (Vector2<f64>, Vector2<f64>) {
    let (s, c) = (f0.phi + axis_angle).sin_cos();
    (Vector2::new(c, s), Vector2::new(-s, c))
}

/// g = [n·(p₁ - p₀); φ₁ - φ₀ - offset].
pub fn rows(f0: &FrameState, f1: &FrameState, axis_angle: f64, offset: f64) -> Rows {
    let mut rows = Rows::default();
    rows.push(Row::along_rotating(f0, f1, axis_angle, true));
    rows.push(Row::angle(f0, f1, offset));
    rows
}
