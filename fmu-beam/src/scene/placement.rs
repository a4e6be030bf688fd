//! Where a scene puts its frames at t = 0, and how far apart each joint's two frames are there
//! (issue 32): a joint whose frames do not meet is refused unless it says `assemble = true`
//! ([`super::rules::JOINT_GAP`]); then the unit moves the parts together and logs it.
//!
//! The world frame is the origin with the world axes. A beam's flange a is at its `position`,
//! its flange b at `position + R [L, δ, 0]` (R the beam's rotation at t = 0, δ its initial tip
//! displacement: the static tip shape moves the tip across the axis only); a body's frame at
//! `position + Rz(angle) p`. A weld, revolute or spherical joint holds the two positions
//! together; a prismatic joint only across its sliding axis. The relative orientation the
//! frames have at t = 0 is the one a weld or prismatic joint holds, so it has no mismatch.

use super::paths::Part;
use super::rules as r;
use super::validate::{Checker, SceneError};
use super::{JointKind, JointSpec, Scene};

/// The gap a joint's frames may have at t = 0, relative to the scene's longest beam: 1e-6,
/// the integrator's default relative tolerance on the same length scale, so that closing such
/// a gap moves nothing by more than the default error control already allows; six
/// significant digits of a position (0.866025 for cos 30°) stay below it.
pub const GAP_TOLERANCE: f64 = 1e-6;

/// How far apart one joint's frames are at t = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct JointGap {
    /// The joint's index in the scene.
    pub joint: usize,
    /// World positions of its two frames at t = 0 (m).
    pub at: [[f64; 3]; 2],
    /// The distance the joint closes (m): between the positions, or across the sliding axis
    /// of a prismatic joint.
    pub gap: f64,
}

type Matrix = [[f64; 3]; 3];

/// Rotation about z by `a` (rows).
fn about_z(a: f64) -> Matrix {
    let (s, c) = a.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

fn apply(r: &Matrix, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(v: [f64; 3]) -> f64 {
    dot(v, v).sqrt()
}

/// `v` scaled to unit length (a zero vector stays zero).
fn unit(v: [f64; 3]) -> [f64; 3] {
    super::planar::unit(v).unwrap_or([0.0; 3])
}

impl Scene {
    /// The length that [`GAP_TOLERANCE`] is relative to: the longest beam (every scene has one).
    pub fn gap_scale(&self) -> f64 {
        self.beams.iter().map(|b| b.length).fold(0.0, f64::max)
    }

    /// The gap a joint's frames may have at t = 0 (m).
    pub fn gap_allowed(&self) -> f64 {
        GAP_TOLERANCE * self.gap_scale()
    }

    /// Rotation (columns: local axes in world components) of a beam or body at t = 0: a beam's
    /// local x along `axis` (default: `angle` in the x–y plane), local z along `normal` (default
    /// world z); a body's frame is the world's turned by `angle` about z.
    fn owner_rotation(&self, owner: &str) -> Option<Matrix> {
        if let Some(b) = self.beam(owner) {
            let x = unit(b.axis.unwrap_or([b.angle.cos(), b.angle.sin(), 0.0]));
            let z = unit(b.normal.unwrap_or([0.0, 0.0, 1.0]));
            let y = cross(z, x);
            return Some([0, 1, 2].map(|i| [x[i], y[i], z[i]]));
        }
        let body = self.bodies.iter().find(|b| b.name == owner)?;
        Some(about_z(body.angle))
    }

    /// World position at t = 0 of a frame the scene names (`world`, `<beam>.a`, `<beam>.b`,
    /// `<body>.<frame>`), and its rotation; None for a frame the scene does not have.
    pub fn frame_at(&self, name: &str) -> Option<([f64; 3], Matrix)> {
        if name == "world" {
            return Some(([0.0; 3], about_z(0.0)));
        }
        let (owner, part) = name.split_once('.')?;
        let r = self.owner_rotation(owner)?;
        let add = |p: [f64; 3], s: [f64; 3]| [0, 1, 2].map(|i| p[i] + s[i]);
        if let Some(b) = self.beam(owner) {
            return match part {
                "a" => Some((b.position, r)),
                "b" => {
                    let d = b.initial.tip_displacement;
                    // the static tip shape's slope at the tip, 3 δ / (2 L), turns flange b
                    let slope = about_z(1.5 * d / b.length);
                    let turned = [0, 1, 2]
                        .map(|i| [0, 1, 2].map(|j| (0..3).map(|k| r[i][k] * slope[k][j]).sum()));
                    Some((add(b.position, apply(&r, [b.length, d, 0.0])), turned))
                }
                _ => None,
            };
        }
        let body = self.bodies.iter().find(|b| b.name == owner)?;
        let p = match part {
            "origin" => [0.0; 3],
            "com" => body.com,
            f => body.frames.get(f)?.0,
        };
        Some((add(body.position, apply(&r, p)), r))
    }

    /// How far apart the frames of joint `j` are at t = 0; None when a frame is unknown.
    pub fn joint_gap(&self, index: usize, j: &JointSpec) -> Option<JointGap> {
        let (p0, r0) = self.frame_at(&j.frames[0])?;
        let (p1, _) = self.frame_at(&j.frames[1])?;
        let d = [0, 1, 2].map(|i| p1[i] - p0[i]);
        let gap = match j.kind {
            JointKind::Prismatic => {
                let (s, c) = j.axis_angle.sin_cos();
                let e = unit(j.axis.unwrap_or_else(|| apply(&r0, [c, s, 0.0])));
                let along = dot(d, e);
                norm([0, 1, 2].map(|i| d[i] - along * e[i]))
            }
            JointKind::Weld | JointKind::Revolute | JointKind::Spherical => norm(d),
        };
        Some(JointGap {
            joint: index,
            at: [p0, p1],
            gap,
        })
    }

    /// Every joint's frames meet at t = 0 ([`super::placement`]), unless it asks to be
    /// assembled.
    pub(super) fn validate_placement(&self, ck: &Checker) -> Result<(), SceneError> {
        for g in self.joint_gaps() {
            let j = &self.joints[g.joint];
            if j.assemble {
                continue;
            }
            let across = if j.kind == JointKind::Prismatic {
                " across the sliding axis"
            } else {
                ""
            };
            return Err(ck.fail_with(
                &r::JOINT_GAP,
                &format!("{}.frames", self.path_of(Part::Joint, g.joint)),
                format!("{:?}", j.frames),
                &format!(
                    ": at t = 0 {:?} is at {} m and {:?} at {} m, {} m apart{across} \
                     ({} m allowed)",
                    j.frames[0],
                    show(g.at[0]),
                    j.frames[1],
                    show(g.at[1]),
                    show_length(g.gap),
                    show_length(self.gap_allowed()),
                ),
            ));
        }
        Ok(())
    }

    /// The joints whose frames are further apart at t = 0 than [`Scene::gap_allowed`].
    pub fn joint_gaps(&self) -> Vec<JointGap> {
        let allowed = self.gap_allowed();
        self.joints
            .iter()
            .enumerate()
            .filter_map(|(i, j)| self.joint_gap(i, j))
            .filter(|g| g.gap > allowed)
            .collect()
    }
}

/// A length for a message: six decimals without trailing zeros (0.3, 0.1), or three
/// significant digits in exponent form below 1e-3 (2.5e-5).
pub(crate) fn show_length(x: f64) -> String {
    if x != 0.0 && x.abs() < 1e-3 {
        let e = format!("{x:.2e}");
        return match e.split_once('e') {
            Some((m, p)) if m.contains('.') => {
                format!("{}e{p}", m.trim_end_matches('0').trim_end_matches('.'))
            }
            _ => e,
        };
    }
    let s = format!("{x:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// A position for a message: `[0.3, 0, 0]` ([`show_length`] of each).
pub(crate) fn show(p: [f64; 3]) -> String {
    format!(
        "[{}, {}, {}]",
        show_length(p[0]),
        show_length(p[1]),
        show_length(p[2])
    )
}
