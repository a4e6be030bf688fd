//! Joints as algebraic constraints with Lagrange multipliers, and their drives.
//! Each joint contributes rows g_k(q, t) = 0 with Jacobians on the two frames' bodies.

use super::frame::FrameState;
use super::law::{InputValue, TimeLaw};
use super::{prismatic, revolute, weld};
use crate::scene::{DriveKind, JointKind};
use nalgebra::{DVector, Vector2};

/// One constraint equation between frames 0 and 1.
#[derive(Debug, Clone)]
pub struct Row {
    pub g: f64,
    /// ∂g/∂z on the bodies of frame 0 and frame 1.
    pub j0: DVector<f64>,
    pub j1: DVector<f64>,
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
            j0: -f0.jp.tr_mul(&d),
            j1: f1.jp.tr_mul(&d),
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
        let mut j0 = -f0.jp.tr_mul(&dir);
        j0 += &f0.jphi * ddir.dot(&d);
        Row {
            g: dir.dot(&d),
            j0,
            j1: f1.jp.tr_mul(&dir),
            bias: dir.dot(&(f1.bias_p - f0.bias_p)) + 2.0 * w * ddir.dot(&dd) - w * w * dir.dot(&d),
            force_dir: Some(dir),
        }
    }

    /// g = φ₁ - φ₀ - offset.
    pub fn angle(f0: &FrameState, f1: &FrameState, offset: f64) -> Row {
        Row {
            g: f1.phi - f0.phi - offset,
            j0: -&f0.jphi,
            j1: f1.jphi.clone(),
            bias: 0.0,
            force_dir: None,
        }
    }
}

#[derive(Debug, Clone)]
pub struct Drive {
    pub kind: DriveKind,
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
            JointKind::Revolute | JointKind::Prismatic => 2 + motion,
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
    pub fn rows(
        &self,
        f0: &FrameState,
        f1: &FrameState,
        t: f64,
        inputs: &[InputValue],
    ) -> Vec<Row> {
        let mut rows = match self.kind {
            JointKind::Weld => weld::rows(f0, f1, self.angle_offset),
            JointKind::Revolute => revolute::rows(f0, f1),
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
