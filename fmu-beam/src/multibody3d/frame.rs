//! Frames in 3D: fixed in the world, or attached to a material point of a body (a point map
//! of a beam, or a named frame of a rigid body), with a constant rotation offset.

use super::body::{frame_of, FRAME};
use crate::beam::spatial_beam::SpatialPointMap;
use nalgebra::{DMatrix, DVectorView, Matrix3, Rotation3, Vector3};

#[derive(Debug, Clone)]
pub enum Frame3 {
    World {
        position: Vector3<f64>,
        rotation: Matrix3<f64>,
    },
    OnBody {
        body: usize,
        map: SpatialPointMap,
        /// Rotation of the frame relative to the material section (frame → section).
        rotation: Matrix3<f64>,
        /// Coordinates of the body (indices in z) on which the frame's pose depends.
        active: Vec<usize>,
    },
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
                let (r, _, a) = frame_of(&z);
                let f = z.rows(FRAME, map.sp.ncols());
                let s = map.s0 + mul(&map.sp, &f);
                let phi = mul(&map.sphi, &f);
                (
                    r + a * s,
                    a * Rotation3::from_scaled_axis(phi).into_inner() * rotation,
                )
            }
            (Frame3::OnBody { .. }, None) => panic!("a body frame needs its body's coordinates"),
        }
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
