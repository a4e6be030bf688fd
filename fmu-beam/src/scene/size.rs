//! What a scene sizes, estimated from the scene alone, before anything is built: the unknowns of
//! its equations, the memory its unit will hold, the number of its FMU variables. Each is an
//! upper bound (a test checks the variables against the table the unit builds), so that a
//! scene within the limits ([`super::rules`]) builds and runs within them.

use super::{JointKind, Scene};

/// A law's table offers its rows' times and values as FMU parameters up to this many rows; a
/// longer one (a measured profile) offers none, so that it does not flood the unit with
/// variables.
pub const TABLE_PARAMETER_ROWS: usize = 16;

/// Bytes of one number (f64).
const F64: u64 = 8;

/// The sizes of a scene's unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Size {
    /// Coordinates n of the equations (frames, quaternions, deformation).
    pub coordinates: u64,
    /// Constraint rows m (joints, welds between substructures, drives, quaternion norms).
    pub constraints: u64,
    /// Bytes of the matrices the unit holds: the iteration matrix of n + m unknowns and its
    /// factors (dense, the worst case), the constraint Jacobian, and each frame's deformation
    /// matrices (mass, stiffness, damping and the inertia integrals).
    pub memory: u64,
    /// FMU variables (parameters, inputs, outputs), at most.
    pub variables: u64,
}

impl Size {
    /// Unknowns of the iteration matrix, n + m.
    pub fn unknowns(&self) -> u64 {
        self.coordinates + self.constraints
    }
}

impl Scene {
    /// The sizes of this scene's unit (counts saturate: a scene of absurd sizes gives huge
    /// numbers, not an overflow).
    pub fn size(&self) -> Size {
        let three = self.is_3d();
        // per frame: rigid coordinates, deformation coordinates per element, and the dense
        // matrices of its deformation coordinates that the beam and the assembly hold (mass,
        // stiffness, damping, inertia integrals, their blocks in the assembled matrices): 8
        // planar, measured (C1 at 250 and 500 elements: 56 and 202 MB of peak resident memory
        // of `fmu-harness simulate`, against 45 and 180 MB estimated); 14 in 3D, the planar
        // count with the six inertia integrals of the 3D element
        let (rigid, per_element, matrices, weld) = if three {
            (7u64, 6u64, 14u64, 6u64)
        } else {
            (3, 3, 8, 3)
        };
        let (mut n, mut m, mut frame_bytes, mut shape) = (0u64, 0u64, 0u64, 0u64);
        for b in &self.beams {
            let (per_frame, frames) = Scene::beam_layout(b);
            let (per_frame, frames) = (per_frame as u64, frames as u64);
            let flex = if b.rigid {
                0
            } else {
                match b.modes {
                    Some(k) => (k as u64).min(per_element.saturating_mul(per_frame)),
                    None => per_element.saturating_mul(per_frame),
                }
            };
            n = n.saturating_add(frames.saturating_mul(rigid + flex));
            m = m.saturating_add(frames.saturating_sub(1).saturating_mul(weld));
            if three {
                m = m.saturating_add(frames); // a quaternion's norm per frame
            }
            let nf = per_element.saturating_mul(per_frame);
            frame_bytes = frame_bytes.saturating_add(
                frames
                    .saturating_mul(matrices)
                    .saturating_mul(nf.saturating_mul(nf))
                    .saturating_mul(F64),
            );
            let wants_shape = b.outputs.is_empty() || b.outputs.iter().any(|o| o == "shape");
            let points = match b.shape_points {
                Some(p) => p as u64,
                None => per_frame.saturating_mul(frames).saturating_add(1),
            };
            if wants_shape {
                // x, y, z of each point and the axis
                shape = shape.saturating_add(3u64.saturating_mul(points).saturating_add(3));
            }
        }
        let bodies = self.bodies.len() as u64;
        n = n.saturating_add(bodies.saturating_mul(rigid));
        if three {
            m = m.saturating_add(bodies);
        }
        for j in &self.joints {
            let rows = match (three, j.kind) {
                (_, JointKind::Weld) => weld,
                (true, JointKind::Spherical) => 3,
                (true, _) => 5,
                (false, _) => 2,
            };
            m = m.saturating_add(rows + u64::from(j.drive.is_some()));
        }
        let unknowns = n.saturating_add(m);
        let memory = unknowns
            .saturating_mul(unknowns)
            .saturating_mul(2 * F64)
            .saturating_add(m.saturating_mul(n).saturating_mul(F64))
            .saturating_add(frame_bytes);
        // parameters and outputs of each part, generously: a beam's section, material, damping
        // and its outputs; a body's mass, inertia, centre of mass, position, rotation and angle;
        // a joint's drive parameters, inputs and outputs; a load's force, torque and scale law,
        // or its inputs and the accelerations of its frame; two per row of a law's table
        let table_rows: u64 = self
            .joints
            .iter()
            .filter_map(|j| j.drive.as_ref().map(|d| &d.law))
            .chain(self.loads.iter().filter_map(|l| l.scale.as_ref()))
            .filter_map(|law| law.table.as_ref())
            .map(|t| t.len())
            .filter(|&rows| rows <= TABLE_PARAMETER_ROWS)
            .map(|rows| rows as u64)
            .fold(0u64, u64::saturating_add);
        let variables = 64u64
            .saturating_add((self.beams.len() as u64).saturating_mul(40))
            .saturating_add(shape)
            .saturating_add(bodies.saturating_mul(24))
            .saturating_add((self.joints.len() as u64).saturating_mul(24))
            .saturating_add((self.loads.len() as u64).saturating_mul(24))
            .saturating_add(table_rows.saturating_mul(2));
        Size {
            coordinates: n,
            constraints: m,
            memory,
            variables,
        }
    }
}
