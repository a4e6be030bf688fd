//! Frames that joints and loads attach to: the world, or a material point of a body (a beam
//! flange, a rigid body's named frame). [`FrameState`] carries what joints need: the world
//! position p and angle φ, their rates, Jacobians over the body's coordinates and the
//! acceleration bias (p'' = J_p z'' + bias).

use super::body::Body;
use crate::beam::planar_beam::{rot, PointMap, FLEX, THETA};
use nalgebra::{DMatrix, DMatrixViewMut, DVector, Vector2};

/// Where a frame sits.
#[derive(Debug, Clone)]
pub enum Frame {
    /// Fixed in the world.
    World { position: Vector2<f64>, angle: f64 },
    /// A material point of body `body` (index into the system's bodies).
    OnBody { body: usize, map: PointMap },
}

/// Kinematics of a frame at (q, q').
#[derive(Debug, Clone)]
pub struct FrameState {
    pub body: Option<usize>,
    pub p: Vector2<f64>,
    pub phi: f64,
    pub pd: Vector2<f64>,
    pub phid: f64,
    /// ∂p/∂z (2 × ndof of the body).
    pub jp: DMatrix<f64>,
    /// ∂φ/∂z.
    pub jphi: DVector<f64>,
    pub bias_p: Vector2<f64>,
}

impl FrameState {
    pub fn world(position: Vector2<f64>, angle: f64) -> FrameState {
        FrameState {
            body: None,
            p: position,
            phi: angle,
            pd: Vector2::zeros(),
            phid: 0.0,
            jp: DMatrix::zeros(2, 0),
            jphi: DVector::zeros(0),
            bias_p: Vector2::zeros(),
        }
    }

    /// The frame `map` on body `index` with coordinates z and rates zd.
    pub fn on_body(
        index: usize,
        body: &Body,
        map: &PointMap,
        z: &DVector<f64>,
        zd: &DVector<f64>,
    ) -> FrameState {
        let n = body.ndof();
        let nf = body.nflex();
        let (ar, ath) = rot(z[THETA]);
        let s = body.local_point(map, z);
        let sd = &map.sp * zd.rows(FLEX, nf);
        let td = zd[THETA];
        let mut jp = DMatrix::zeros(2, n);
        let mut jphi = DVector::zeros(n);
        let aths = ath * s;
        let asp = ar * &map.sp;
        for i in 0..2 {
            jp[(i, i)] = 1.0;
            jp[(i, THETA)] = aths[i];
            for k in 0..nf {
                jp[(i, FLEX + k)] = asp[(i, k)];
            }
        }
        jphi[THETA] = 1.0;
        for k in 0..nf {
            jphi[FLEX + k] = map.sphi[k];
        }
        let (p, phi) = body.point(map, z);
        let pd = &jp * zd;
        FrameState {
            body: Some(index),
            p,
            phi,
            pd: Vector2::new(pd[0], pd[1]),
            phid: jphi.dot(zd),
            bias_p: -(ar * s) * (td * td) + ath * sd * (2.0 * td),
            jp,
            jphi,
        }
    }
}

/// Adds ∂(J_pᵀ F)/∂z for a world force F held constant, into `k` (ndof × ndof):
/// the tangent of a reaction or load applied at the frame.
pub fn add_force_tangent(
    body: &Body,
    map: &PointMap,
    z: &DVector<f64>,
    force: Vector2<f64>,
    mut k: DMatrixViewMut<f64>,
) {
    let nf = body.nflex();
    let (ar, ath) = rot(z[THETA]);
    let s = body.local_point(map, z);
    k[(THETA, THETA)] += -force.dot(&(ar * s));
    let cross = (ath * &map.sp).tr_mul(&force);
    for j in 0..nf {
        k[(THETA, FLEX + j)] += cross[j];
        k[(FLEX + j, THETA)] += cross[j];
    }
}
