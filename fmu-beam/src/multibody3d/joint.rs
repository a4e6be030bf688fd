//! Joints in 3D as constraint rows on the poses (x0, A0), (x1, A1) of two frames. Axes are
//! those of frame 0: a revolute joint turns about its z axis, a prismatic joint slides along
//! its x axis (a frame's rotation offset points them anywhere).
//! - weld (6 rows): x1 − x0 = 0, ½ vee(R − Rᵀ) = 0 with R = A0ᵀ A1;
//! - revolute (5): x1 − x0 = 0, z1·x0 = z1·y0 = 0; coordinate θ = atan2(x1·y0, x1·x0);
//! - prismatic (5): the weld's three rotation rows, d·y0 = d·z0 = 0 with d = x1 − x0;
//!   coordinate s = d·x0;
//! - spherical (3): x1 − x0 = 0;
//! - a motion drive adds the row θ − θ(t) (wrapped to (−π, π], smooth where it vanishes) or
//!   s − s(t); an effort drive is a generalized force along the coordinate.

use super::quaternion::rotation_error;
use crate::multibody::joint::Drive;
use crate::multibody::law::InputValue;
use crate::scene::DriveKind;
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind3 {
    Weld,
    Revolute,
    Prismatic,
    Spherical,
}

#[derive(Debug, Clone)]
pub struct Joint3 {
    pub name: String,
    pub kind: JointKind3,
    /// Indices into the system's frames.
    pub frames: [usize; 2],
    pub drive: Option<Drive>,
    /// First constraint row of this joint.
    pub row: usize,
}

/// Pose of a frame: world position and rotation (frame → world).
pub type Pose = (Vector3<f64>, Matrix3<f64>);

/// x wrapped to (−π, π].
pub fn wrap(x: f64) -> f64 {
    let y = (x + PI).rem_euclid(2.0 * PI) - PI;
    if y == -PI {
        PI
    } else {
        y
    }
}

impl Joint3 {
    /// Number of constraint rows.
    pub fn rows_count(kind: JointKind3, drive: Option<&Drive>) -> usize {
        let motion = drive.is_some_and(|d| d.kind == DriveKind::Motion) as usize;
        match kind {
            JointKind3::Weld => 6,
            JointKind3::Revolute | JointKind3::Prismatic => 5 + motion,
            JointKind3::Spherical => 3,
        }
    }

    /// Number of rows of this joint.
    pub fn len(&self) -> usize {
        Joint3::rows_count(self.kind, self.drive.as_ref())
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The joint coordinate: angle (revolute, wrapped) or slide (prismatic); 0 otherwise.
    pub fn coordinate(&self, f0: &Pose, f1: &Pose) -> f64 {
        let (x0, a0) = f0;
        let (x1, a1) = f1;
        match self.kind {
            JointKind3::Revolute => {
                let e = a1.column(0);
                e.dot(&a0.column(1)).atan2(e.dot(&a0.column(0)))
            }
            JointKind3::Prismatic => (x1 - x0).dot(&a0.column(0)),
            _ => 0.0,
        }
    }

    /// The rows g at time t, written to `out` (length [`Joint3::len`]).
    pub fn rows(&self, f0: &Pose, f1: &Pose, t: f64, inputs: &[InputValue], out: &mut [f64]) {
        let (x0, a0) = f0;
        let (x1, a1) = f1;
        let d = x1 - x0;
        let mut k = 0;
        let mut push = |v: f64| {
            out[k] = v;
            k += 1;
        };
        match self.kind {
            JointKind3::Weld => {
                d.iter().for_each(|&v| push(v));
                rotation_error(a0, a1).iter().for_each(|&v| push(v));
            }
            JointKind3::Revolute => {
                d.iter().for_each(|&v| push(v));
                let z1 = a1.column(2);
                push(z1.dot(&a0.column(0)));
                push(z1.dot(&a0.column(1)));
            }
            JointKind3::Prismatic => {
                rotation_error(a0, a1).iter().for_each(|&v| push(v));
                push(d.dot(&a0.column(1)));
                push(d.dot(&a0.column(2)));
            }
            JointKind3::Spherical => d.iter().for_each(|&v| push(v)),
        }
        if let Some(dr) = self.drive.as_ref().filter(|d| d.kind == DriveKind::Motion) {
            let (s, _, _) = dr.law.eval(t, inputs);
            let c = self.coordinate(f0, f1);
            push(match self.kind {
                JointKind3::Revolute => wrap(c - s),
                _ => c - s,
            });
        }
    }

    /// Second time derivative of the drive law (the time part of the motion row's bias).
    pub fn drive_acceleration(&self, t: f64, inputs: &[InputValue]) -> Option<f64> {
        self.drive
            .as_ref()
            .filter(|d| d.kind == DriveKind::Motion)
            .map(|d| d.law.eval(t, inputs).2)
    }

    /// Effort (torque or force) of an effort drive at time t.
    pub fn effort(&self, t: f64, inputs: &[InputValue]) -> Option<f64> {
        self.drive
            .as_ref()
            .filter(|d| d.kind == DriveKind::Effort)
            .map(|d| d.law.eval(t, inputs).0)
    }
}
