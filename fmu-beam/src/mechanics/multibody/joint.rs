//! Joints as algebraic constraints with Lagrange multipliers, and their drives.
//! Each joint contributes rows g_k(q, t) = 0 with Jacobians on the two frames' bodies.

use super::frame::FrameState;
use super::law::{InputValue, TimeLaw};
use super::{prismatic, revolute, weld};
use nalgebra::Vector2;

/// The kinds of joint, planar and spatial (their rows: the planar ones in [`super::weld`],
/// [`super::revolute`] and [`super::prismatic`]; the spatial ones in `multibody3d::joint`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// No relative motion (3 rows in the plane, 6 in space).
    Weld,
    /// Rotation about frame 0's z axis (2 rows in the plane, 5 in space).
    Revolute,
    /// Translation along frame 0's x axis (2 rows in the plane, 5 in space).
    Prismatic,
    /// Rotation about a common point (3 rows in space; in the plane it acts as revolute).
    Spherical,
}

/// What a drive prescribes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DriveKind {
    /// The joint coordinate follows the law (one more constraint row).
    Motion,
    /// A torque or force given by the law acts across the joint (a generalized force).
    Effort,
}

/// One constraint equation between frames 0 and 1. Its Jacobian on the body of frame i is
/// J_pᵀ w_i + J_φ c_i (see [`FrameState::for_each_jacobian`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct Row {
    pub g: f64,
    pub w0: Vector2<f64>,
    pub c0: f64,
    pub w1: Vector2<f64>,
    pub c1: f64,
    /// g'' = J q'' + bias.
    pub bias: f64,
    /// World direction of the reaction on frame 1 (frame 0 gets the opposite), for the
    /// tangent of Gᵀλ; None for angle rows.
    pub force_dir: Option<Vector2<f64>>,
}

impl Row {
    /// g = d·(p₁ - p₀) for a fixed world direction d.
    pub fn along(f0: &FrameState, f1: &FrameState, d: Vector2<f64>) -> Row {
        Row {
            g: d.dot(&(f1.p - f0.p)),
            w0: -d,
            c0: 0.0,
            w1: d,
            c1: 0.0,
            bias: d.dot(&(f1.bias_p - f0.bias_p)),
            force_dir: Some(d),
        }
    }

    /// g = n·(p₁ - p₀) (normal = true) or e·(p₁ - p₀) for the axes of frame 0.
    pub fn along_rotating(f0: &FrameState, f1: &FrameState, axis_angle: f64, normal: bool) -> Row {
        let (e, n) = prismatic::axes(f0, axis_angle);
        // d/dφ₀ of n is -e, of e is n
        let (dir, ddir) = if normal { (n, -e) } else { (e, n) };
        let d = f1.p - f0.p;
        let dd = f1.pd - f0.pd;
        let w = f0.phid;
        Row {
            g: dir.dot(&d),
            w0: -dir,
            c0: ddir.dot(&d),
            w1: dir,
            c1: 0.0,
            bias: dir.dot(&(f1.bias_p - f0.bias_p)) + 2.0 * w * ddir.dot(&dd) - w * w * dir.dot(&d),
            force_dir: Some(dir),
        }
    }

    /// g = φ₁ - φ₀ - offset.
    pub fn angle(f0: &FrameState, f1: &FrameState, offset: f64) -> Row {
        Row {
            g: f1.phi - f0.phi - offset,
            w0: Vector2::zeros(),
            c0: -1.0,
            w1: Vector2::zeros(),
            c1: 1.0,
            bias: 0.0,
            force_dir: None,
        }
    }
}

/// The rows of one joint (at most 3), without allocation.
#[derive(Debug, Clone, Copy, Default)]
pub struct Rows {
    rows: [Row; 3],
    len: usize,
}

impl Rows {
    pub fn push(&mut self, r: Row) {
        self.rows[self.len] = r;
        self.len += 1;
    }
}

impl std::ops::Deref for Rows {
    type Target = [Row];
    fn deref(&self) -> &[Row] {
        &self.rows[..self.len]
    }
}

/// A joint's drive: its coordinate follows the law (motion) or a torque or force given by the
/// law acts across it (effort).
#[derive(Debug, Clone)]
pub struct Drive {
    /// Motion (a constraint row on the joint coordinate) or effort (a generalized force).
    pub kind: DriveKind,
    /// The joint coordinate (rad or m) or the effort (N·m or N) as a function of time.
    pub law: TimeLaw,
}

#[derive(Debug, Clone)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    /// Indices into the system's frames.
    pub frames: [usize; 2],
    pub axis_angle: f64,
    /// Relative angle φ₁ - φ₀ kept by weld and prismatic joints (from the initial scene).
    pub angle_offset: f64,
    pub drive: Option<Drive>,
    /// First constraint row of this joint.
    pub row: usize,
}

impl Joint {
    /// Number of constraint rows.
    pub fn rows_count(kind: JointKind, drive: Option<&Drive>) -> usize {
        let motion = drive.is_some_and(|d| d.kind == DriveKind::Motion) as usize;
        match kind {
            JointKind::Weld => 3,
            // in the plane a spherical joint acts as a revolute one
            JointKind::Revolute | JointKind::Spherical | JointKind::Prismatic => 2 + motion,
        }
    }

    /// The joint coordinate row: φ₁ - φ₀ (revolute) or e·(p₁ - p₀) (prismatic), unshifted.
    pub fn coordinate(&self, f0: &FrameState, f1: &FrameState) -> Row {
        match self.kind {
            JointKind::Prismatic => Row::along_rotating(f0, f1, self.axis_angle, false),
            _ => Row::angle(f0, f1, 0.0),
        }
    }

    /// All rows at time t.
    pub fn rows(&self, f0: &FrameState, f1: &FrameState, t: f64, inputs: &[InputValue]) -> Rows {
        let mut rows = match self.kind {
            JointKind::Weld => weld::rows(f0, f1, self.angle_offset),
            JointKind::Revolute | JointKind::Spherical => revolute::rows(f0, f1),
            JointKind::Prismatic => prismatic::rows(f0, f1, self.axis_angle, self.angle_offset),
        };
        if let Some(d) = self.drive.as_ref().filter(|d| d.kind == DriveKind::Motion) {
            let (s, _, sdd) = d.law.eval(t, inputs);
            let mut r = self.coordinate(f0, f1);
            r.g -= s;
            r.bias -= sdd;
            rows.push(r);
        }
        rows
    }

    /// Effort (torque or force) of an effort drive at time t.
    pub fn effort(&self, t: f64, inputs: &[InputValue]) -> Option<f64> {
        self.drive
            .as_ref()
            .filter(|d| d.kind == DriveKind::Effort)
            .map(|d| d.law.eval(t, inputs).0)
    }
}
