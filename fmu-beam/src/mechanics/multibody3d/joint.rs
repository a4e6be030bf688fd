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
use crate::mechanics::multibody::joint::{Drive, DriveKind, JointKind};
use crate::mechanics::multibody::law::InputValue;
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

#[derive(Debug, Clone)]
pub struct Joint3 {
    pub name: String,
    pub kind: JointKind,
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
    pub fn rows_count(kind: JointKind, drive: Option<&Drive>) -> usize {
        let motion = drive.is_some_and(|d| d.kind == DriveKind::Motion) as usize;
        match kind {
            JointKind::Weld => 6,
            JointKind::Revolute | JointKind::Prismatic => 5 + motion,
            JointKind::Spherical => 3,
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
            JointKind::Revolute => {
                let e = a1.column(0);
                e.dot(&a0.column(1)).atan2(e.dot(&a0.column(0)))
            }
            JointKind::Prismatic => (x1 - x0).dot(&a0.column(0)),
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
            JointKind::Weld => {
                d.iter().for_each(|&v| push(v));
                rotation_error(a0, a1).iter().for_each(|&v| push(v));
            }
            JointKind::Revolute => {
                d.iter().for_each(|&v| push(v));
                let z1 = a1.column(2);
                push(z1.dot(&a0.column(0)));
                push(z1.dot(&a0.column(1)));
            }
            JointKind::Prismatic => {
                rotation_error(a0, a1).iter().for_each(|&v| push(v));
                push(d.dot(&a0.column(1)));
                push(d.dot(&a0.column(2)));
            }
            JointKind::Spherical => d.iter().for_each(|&v| push(v)),
        }
        if let Some(dr) = self.drive.as_ref().filter(|d| d.kind == DriveKind::Motion) {
            let (s, _, _) = dr.law.eval(t, inputs);
            let c = self.coordinate(f0, f1);
            push(match self.kind {
                JointKind::Revolute => wrap(c - s),
                _ => c - s,
            });
        }
    }

    /// Second time derivative of the rows along a motion of the two frames, at a fixed drive
    /// law, from the poses, their rates r = (ẋ, Ȧ) and accelerations a = (ẍ, Ä). Every row is
    /// a product of two pose factors (or the angle atan2(s, c) of two), so the rule is
    /// (u·w)¨ = ü·w + 2 u̇·ẇ + u·ẅ. With zero rates it is the rows' derivative along the pose
    /// variations a0, a1: a column of the constraint Jacobian.
    #[allow(clippy::too_many_arguments)]
    pub fn rows_acceleration(
        &self,
        f0: &Pose,
        f1: &Pose,
        r0: &Pose,
        r1: &Pose,
        a0: &Pose,
        a1: &Pose,
        out: &mut [f64],
    ) {
        let dd = a1.0 - a0.0;
        let mut k = 0;
        let mut push = |v: f64| {
            out[k] = v;
            k += 1;
        };
        // ½ vee(Ẅ − Ẅᵀ) of W = A0ᵀ A1
        let rotation_rows = |push: &mut dyn FnMut(f64)| {
            let w = a0.1.tr_mul(&f1.1) + r0.1.tr_mul(&r1.1) * 2.0 + f0.1.tr_mul(&a1.1);
            push(0.5 * (w[(2, 1)] - w[(1, 2)]));
            push(0.5 * (w[(0, 2)] - w[(2, 0)]));
            push(0.5 * (w[(1, 0)] - w[(0, 1)]));
        };
        match self.kind {
            JointKind::Weld => {
                dd.iter().for_each(|&v| push(v));
                rotation_rows(&mut push);
            }
            JointKind::Revolute => {
                dd.iter().for_each(|&v| push(v));
                for c in 0..2 {
                    push(col_product(f1, r1, a1, 2, f0, r0, a0, c));
                }
            }
            JointKind::Prismatic => {
                rotation_rows(&mut push);
                for c in 1..3 {
                    push(gap_product(f0, f1, r0, r1, a0, a1, c));
                }
            }
            JointKind::Spherical => dd.iter().for_each(|&v| push(v)),
        }
        if self
            .drive
            .as_ref()
            .is_some_and(|d| d.kind == DriveKind::Motion)
        {
            push(self.coordinate_acceleration(f0, f1, r0, r1, a0, a1));
        }
    }

    /// Second time derivative of [`Joint3::coordinate`] (see [`Joint3::rows_acceleration`]);
    /// with zero rates, its derivative along a0, a1. For the angle θ = atan2(s, c):
    /// θ̈ = (c s̈ − s c̈)/ρ − 2 (c ṡ − s ċ)(s ṡ + c ċ)/ρ², ρ = s² + c².
    #[allow(clippy::too_many_arguments)]
    pub fn coordinate_acceleration(
        &self,
        f0: &Pose,
        f1: &Pose,
        r0: &Pose,
        r1: &Pose,
        a0: &Pose,
        a1: &Pose,
    ) -> f64 {
        match self.kind {
            JointKind::Revolute => {
                let e = |m: &Matrix3<f64>| m.column(0).into_owned();
                let (x, xd, xdd) = (e(&f1.1), e(&r1.1), e(&a1.1));
                let c3 = |m: &Matrix3<f64>, i| m.column(i).into_owned();
                let prod = |i: usize| {
                    let (u, ud, udd) = (c3(&f0.1, i), c3(&r0.1, i), c3(&a0.1, i));
                    (
                        x.dot(&u),
                        xd.dot(&u) + x.dot(&ud),
                        xdd.dot(&u) + 2.0 * xd.dot(&ud) + x.dot(&udd),
                    )
                };
                let (s, sd, sdd) = prod(1);
                let (c, cd, cdd) = prod(0);
                let rho = s * s + c * c;
                (c * sdd - s * cdd) / rho
                    - 2.0 * (c * sd - s * cd) * (s * sd + c * cd) / (rho * rho)
            }
            JointKind::Prismatic => gap_product(f0, f1, r0, r1, a0, a1, 0),
            _ => 0.0,
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

/// (u·w)¨ for u column `cu` of frame u's rotation, w column `cw` of frame w's.
#[allow(clippy::too_many_arguments)]
fn col_product(
    fu: &Pose,
    ru: &Pose,
    au: &Pose,
    cu: usize,
    fw: &Pose,
    rw: &Pose,
    aw: &Pose,
    cw: usize,
) -> f64 {
    let (u, ud, udd) = (fu.1.column(cu), ru.1.column(cu), au.1.column(cu));
    let (w, wd, wdd) = (fw.1.column(cw), rw.1.column(cw), aw.1.column(cw));
    udd.dot(&w) + 2.0 * ud.dot(&wd) + u.dot(&wdd)
}

/// (d·c)¨ for d = x1 − x0 and c column `col` of frame 0's rotation.
fn gap_product(
    f0: &Pose,
    f1: &Pose,
    r0: &Pose,
    r1: &Pose,
    a0: &Pose,
    a1: &Pose,
    col: usize,
) -> f64 {
    let (d, dd, ddd) = (f1.0 - f0.0, r1.0 - r0.0, a1.0 - a0.0);
    let (c, cd, cdd) = (f0.1.column(col), r0.1.column(col), a0.1.column(col));
    ddd.dot(&c) + 2.0 * dd.dot(&cd) + d.dot(&cdd)
}
