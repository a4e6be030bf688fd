//! Frames in 3D: fixed in the world, or attached to a material point of a body (a point map
//! of a beam, or a named frame of a rigid body), with a constant rotation offset.

use super::body::{frame_of, FRAME};
use super::quaternion::{left_jacobian, rotation_derivatives};
use crate::mechanics::beam::spatial_beam::{skew, SpatialPointMap};
use nalgebra::{DMatrix, DVectorView, Matrix3, Rotation3, Vector3};

/// A frame that joints and loads act on: its pose is fixed, or follows a point of a body.
#[derive(Debug, Clone)]
pub enum Frame3 {
    /// Fixed in the world.
    World {
        /// Position in the world (m).
        position: Vector3<f64>,
        /// Rotation (frame → world).
        rotation: Matrix3<f64>,
    },
    /// Attached to a material point of a body.
    OnBody {
        /// Index of the body in the system's bodies.
        body: usize,
        /// The material point: its position in the body frame and, for a beam, its
        /// displacement and section rotation per deformation coordinate.
        map: SpatialPointMap,
        /// Rotation of the frame relative to the material section (frame → section).
        rotation: Matrix3<f64>,
        /// Coordinates of the body (indices in z) on which the frame's pose depends.
        active: Vec<usize>,
    },
}

/// World position and rotation of the material point `map` of a body with coordinates z:
/// x = R + A (s0 + S_p q_f), A exp(φ̃) with φ = S_φ q_f.
pub fn map_pose(map: &SpatialPointMap, z: DVectorView<f64>) -> (Vector3<f64>, Matrix3<f64>) {
    let (r, _, a) = frame_of(&z);
    let f = z.rows(FRAME, map.sp.ncols());
    let s = map.s0 + mul(&map.sp, &f);
    let phi = mul(&map.sphi, &f);
    (r + a * s, a * Rotation3::from_scaled_axis(phi).into_inner())
}

impl Frame3 {
    /// A frame on body `body` at `map`, rotated by `rotation`.
    pub fn on_body(body: usize, map: SpatialPointMap, rotation: Matrix3<f64>) -> Frame3 {
        let nf = map.sp.ncols();
        let active = (0..FRAME)
            .chain((0..nf).filter_map(|k| {
                let used = map.sp.column(k).amax() > 0.0 || map.sphi.column(k).amax() > 0.0;
                used.then_some(FRAME + k)
            }))
            .collect();
        Frame3::OnBody {
            body,
            map,
            rotation,
            active,
        }
    }

    /// The body the frame moves with.
    pub fn body(&self) -> Option<usize> {
        match self {
            Frame3::World { .. } => None,
            Frame3::OnBody { body, .. } => Some(*body),
        }
    }

    /// Coordinates of the body on which the pose depends (empty for the world).
    pub fn active(&self) -> &[usize] {
        match self {
            Frame3::World { .. } => &[],
            Frame3::OnBody { active, .. } => active,
        }
    }

    /// World position and rotation (frame → world) from the body's coordinates z (ignored for
    /// a world frame): x = R + A (s0 + S_p q_f), A_f = A exp(φ̃) C with φ = S_φ q_f.
    pub fn pose(&self, z: Option<DVectorView<f64>>) -> (Vector3<f64>, Matrix3<f64>) {
        match (self, z) {
            (Frame3::World { position, rotation }, _) => (*position, *rotation),
            (Frame3::OnBody { map, rotation, .. }, Some(z)) => {
                let (r, a) = map_pose(map, z);
                (r, a * rotation)
            }
            (Frame3::OnBody { .. }, None) => panic!("a body frame needs its body's coordinates"),
        }
    }

    /// The pose and, in `out`, its derivatives (∂x, ∂A_f) over the [`Frame3::active`]
    /// coordinates in that order: ∂x/∂R = I, ∂x/∂p_k = ∂A/∂p_k s, ∂x/∂q_f = A S_p;
    /// ∂A_f/∂p_k = ∂A/∂p_k E C, ∂A_f/∂q_f = A (J_l(φ) S_φ)~ E C with E = exp(φ̃).
    pub fn pose_derivatives(
        &self,
        z: Option<DVectorView<f64>>,
        out: &mut Vec<(Vector3<f64>, Matrix3<f64>)>,
    ) -> (Vector3<f64>, Matrix3<f64>) {
        out.clear();
        let (
            Frame3::OnBody {
                map,
                rotation,
                active,
                ..
            },
            Some(z),
        ) = (self, z)
        else {
            return self.pose(z);
        };
        let (r, p, a) = frame_of(&z);
        let f = z.rows(FRAME, map.sp.ncols());
        let s = map.s0 + mul(&map.sp, &f);
        let phi = mul(&map.sphi, &f);
        let ec = Rotation3::from_scaled_axis(phi).into_inner() * rotation;
        for i in 0..3 {
            out.push((Vector3::ith(i, 1.0), Matrix3::zeros()));
        }
        for da in rotation_derivatives(&p) {
            out.push((da * s, da * ec));
        }
        let jl = left_jacobian(&phi);
        for &k in &active[FRAME..] {
            let c = k - FRAME;
            let sp = Vector3::new(map.sp[(0, c)], map.sp[(1, c)], map.sp[(2, c)]);
            let sphi = Vector3::new(map.sphi[(0, c)], map.sphi[(1, c)], map.sphi[(2, c)]);
            out.push((a * sp, a * skew(&(jl * sphi)) * ec));
        }
        (r + a * s, a * ec)
    }
}

fn mul(m: &DMatrix<f64>, x: &DVectorView<f64>) -> Vector3<f64> {
    let mut y = Vector3::zeros();
    for k in 0..x.len() {
        if x[k] != 0.0 {
            for i in 0..3 {
                y[i] += m[(i, k)] * x[k];
            }
        }
    }
    y
}
