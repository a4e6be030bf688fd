//! Frames that joints and loads attach to: the world, or a material point of a body (a beam
//! flange, a rigid body's named frame). [`FrameState`] carries what joints need: the world
//! position p and angle φ, their rates, the acceleration bias (p'' = J_p z'' + bias) and what
//! the Jacobians J_p = ∂p/∂z, J_φ = ∂φ/∂z over the body's coordinates are made of, without
//! building them: joints and loads only need J_pᵀ w + J_φ c for a world vector w and a scalar c.

use super::body::Body;
use crate::mechanics::beam::band::BlockMut;
use crate::mechanics::beam::planar_beam::{PointMap, FLEX, THETA};
use nalgebra::{DVectorView, Matrix2, Vector2};

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
pub struct FrameState<'a> {
    pub body: Option<usize>,
    pub p: Vector2<f64>,
    pub phi: f64,
    pub pd: Vector2<f64>,
    pub phid: f64,
    pub bias_p: Vector2<f64>,
    /// A(θ) of the body frame.
    ar: Matrix2<f64>,
    /// A_θ s = ∂p/∂θ.
    aths: Vector2<f64>,
    map: Option<&'a PointMap>,
}

impl<'a> FrameState<'a> {
    pub fn world(position: Vector2<f64>, angle: f64) -> FrameState<'a> {
        FrameState {
            body: None,
            p: position,
            phi: angle,
            pd: Vector2::zeros(),
            phid: 0.0,
            bias_p: Vector2::zeros(),
            ar: Matrix2::identity(),
            aths: Vector2::zeros(),
            map: None,
        }
    }

    /// The frame `map` on body `index` with coordinates z and rates zd (at rest without).
    pub fn on_body(
        index: usize,
        body: &Body,
        map: &'a PointMap,
        z: DVectorView<f64>,
        zd: Option<DVectorView<f64>>,
    ) -> FrameState<'a> {
        let nf = body.nflex();
        let (ar, ath) = body.turn().rot(z[THETA]);
        let s = body.local_point(map, z);
        let aths = ath * s;
        let (p, phi) = body.placed(map, z, &ar, s);
        let mut fs = FrameState {
            body: Some(index),
            p,
            phi,
            pd: Vector2::zeros(),
            phid: 0.0,
            bias_p: Vector2::zeros(),
            ar,
            aths,
            map: Some(map),
        };
        if let Some(zd) = zd {
            let fd = zd.rows(FLEX, nf);
            let sd = map.displacement(&fd);
            let td = zd[THETA];
            fs.pd = Vector2::new(zd[0], zd[1]) + aths * td + ar * sd;
            fs.phid = td + map.sphi.dot(&fd);
            fs.bias_p = -(ar * s) * (td * td) + ath * sd * (2.0 * td);
        }
        fs
    }

    /// Visits (k, (J_pᵀ w + J_φ c)_k) for the body coordinates k: the generalized force of a
    /// world force w and torque c at the frame, or a constraint row's Jacobian. Nothing for a
    /// world frame.
    pub fn for_each_jacobian(&self, w: Vector2<f64>, c: f64, mut visit: impl FnMut(usize, f64)) {
        let Some(map) = self.map else { return };
        visit(0, w[0]);
        visit(1, w[1]);
        visit(THETA, w.dot(&self.aths) + c);
        let local = self.ar.tr_mul(&w);
        for k in 0..map.sp.ncols() {
            // a coordinate that does not move the frame (most of a flange's body)
            if map.sp[(0, k)] == 0.0 && map.sp[(1, k)] == 0.0 && map.sphi[k] == 0.0 {
                continue;
            }
            visit(
                FLEX + k,
                local[0] * map.sp[(0, k)] + local[1] * map.sp[(1, k)] + c * map.sphi[k],
            );
        }
    }

    /// (J_pᵀ w + J_φ c) · zd: the rate of the row with that Jacobian.
    pub fn jacobian_dot(&self, w: Vector2<f64>, c: f64, zd: DVectorView<f64>) -> f64 {
        let mut sum = 0.0;
        self.for_each_jacobian(w, c, |k, x| sum += x * zd[k]);
        sum
    }
}

/// Adds ∂(J_pᵀ F)/∂z for a world force F held constant, into `k` (ndof × ndof):
/// the tangent of a reaction or load applied at the frame.
pub fn add_force_tangent<B: BlockMut>(
    body: &Body,
    map: &PointMap,
    z: DVectorView<f64>,
    force: Vector2<f64>,
    k: &mut B,
) {
    let nf = body.nflex();
    let (ar, ath) = body.turn().rot(z[THETA]);
    let s = body.local_point(map, z);
    k[(THETA, THETA)] += -force.dot(&(ar * s));
    let local = ath.tr_mul(&force);
    for j in 0..nf {
        let cross = map.sp[(0, j)] * local[0] + map.sp[(1, j)] * local[1];
        k[(THETA, FLEX + j)] += cross;
        k[(FLEX + j, THETA)] += cross;
    }
}
