//! Frames that joints attach to: the world, or a material point of a body (a beam flange).
//! A frame gives its world position p and angle φ, their Jacobians over the body's
//! coordinates, the acceleration bias and the second-derivative terms of joint reactions.

use crate::beam::planar_beam::{rot, PlanarBeam, PointMap, FLEX, THETA};
use nalgebra::{DMatrixViewMut, DVector, Vector2};

/// Where a frame sits.
#[derive(Debug, Clone)]
pub enum Frame {
    /// Fixed in the world.
    World { position: Vector2<f64>, angle: f64 },
    /// A material point of body `body` (index into the system's bodies).
    OnBody { body: usize, map: PointMap },
}

/// Adds `sign` × the Jacobian of [p; φ] (3 rows) over z into `g` (3 × ndof).
pub fn add_jacobian(
    beam: &PlanarBeam,
    map: &PointMap,
    z: &DVector<f64>,
    sign: f64,
    mut g: DMatrixViewMut<f64>,
) {
    let nf = beam.nflex();
    let (ar, ath) = rot(z[THETA]);
    let s = beam.local_point(map, z);
    let aths = ath * s;
    let asp = ar * &map.sp;
    for i in 0..2 {
        g[(i, i)] += sign;
        g[(i, THETA)] += sign * aths[i];
        for k in 0..nf {
            g[(i, FLEX + k)] += sign * asp[(i, k)];
        }
    }
    g[(2, THETA)] += sign;
    for k in 0..nf {
        g[(2, FLEX + k)] += sign * map.sphi[k];
    }
}

/// Acceleration bias of [p; φ]: p̈ = G z̈ + bias (the φ bias is zero, φ is linear in z).
pub fn accel_bias(
    beam: &PlanarBeam,
    map: &PointMap,
    z: &DVector<f64>,
    zd: &DVector<f64>,
) -> Vector2<f64> {
    let nf = beam.nflex();
    let (ar, ath) = rot(z[THETA]);
    let s = beam.local_point(map, z);
    let sd = &map.sp * zd.rows(FLEX, nf);
    let td = zd[THETA];
    -(ar * s) * (td * td) + ath * sd * (2.0 * td)
}

/// Adds ∂(Gᵀλ)/∂z for the position rows with multiplier `lambda_p` (2) into `k` (ndof × ndof).
pub fn add_reaction_tangent(
    beam: &PlanarBeam,
    map: &PointMap,
    z: &DVector<f64>,
    lambda_p: Vector2<f64>,
    mut k: DMatrixViewMut<f64>,
) {
    let nf = beam.nflex();
    let (ar, ath) = rot(z[THETA]);
    let s = beam.local_point(map, z);
    k[(THETA, THETA)] += -lambda_p.dot(&(ar * s));
    let cross = (ath * &map.sp).tr_mul(&lambda_p);
    for j in 0..nf {
        k[(THETA, FLEX + j)] += cross[j];
        k[(FLEX + j, THETA)] += cross[j];
    }
}
