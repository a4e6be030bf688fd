//! A planar rigid body: coordinates z = [x, y, φ] of its reference frame, centre of mass at
//! c̄ in that frame. A body of zero mass is allowed when joints fix all its coordinates
//! (the massless slider of case C3): its block of the mass matrix is zero.

use crate::mechanics::beam::planar_beam::{PointMap, TermCounts};
use crate::mechanics::beam::sines::RecentTurn;
use nalgebra::{DMatrix, DMatrixViewMut, DVector, DVectorView, Vector2};

#[derive(Debug, Clone)]
pub struct RigidBody {
    pub name: String,
    pub mass: f64,
    /// Centre of mass in the body frame (m).
    pub com: Vector2<f64>,
    /// Moment of inertia about the centre of mass (kg m^2).
    pub inertia: f64,
    /// Named frames: position in the body frame.
    pub frames: Vec<(String, Vector2<f64>)>,
    /// Evaluations of the optional terms (gravity only, for a rigid body).
    pub counts: TermCounts,
    /// Its last angle's sine and cosine ([`RecentTurn`]).
    pub turn: RecentTurn,
}

impl RigidBody {
    pub const NDOF: usize = 3;

    /// The frame `name` as a material point map (no deformation coordinates).
    pub fn frame_map(&self, name: &str) -> Option<PointMap> {
        let s0 = if name == "origin" {
            Vector2::zeros()
        } else if name == "com" {
            self.com
        } else {
            self.frames.iter().find(|(n, _)| n == name)?.1
        };
        Some(PointMap {
            s0,
            sp: DMatrix::zeros(2, 0),
            sphi: DVector::zeros(0),
        })
    }

    /// M(z) = [[m I, m A_φ c̄], [·, J_c + m |c̄|²]].
    pub fn mass_matrix(&self, z: DVectorView<f64>, mut m: DMatrixViewMut<f64>) {
        let (_, ath) = self.turn.rot(z[2]);
        let mc = ath * self.com * self.mass;
        m.fill(0.0);
        m[(0, 0)] = self.mass;
        m[(1, 1)] = self.mass;
        for i in 0..2 {
            m[(i, 2)] = mc[i];
            m[(2, i)] = mc[i];
        }
        m[(2, 2)] = self.inertia + self.mass * self.com.norm_squared();
    }

    /// r = M z̈ + h - Q_g, with h_R = -φ̇² A c̄ m.
    pub fn residual(
        &self,
        z: DVectorView<f64>,
        zd: DVectorView<f64>,
        zdd: DVectorView<f64>,
        gravity: Option<Vector2<f64>>,
        r: &mut [f64],
    ) {
        let (ar, ath) = self.turn.rot(z[2]);
        let (pd, pdd) = (zd[2], zdd[2]);
        let c = self.com * self.mass;
        let mut rr = Vector2::new(zdd[0], zdd[1]) * self.mass + ath * c * pdd - ar * c * (pd * pd);
        let mut accel = Vector2::new(zdd[0], zdd[1]);
        if let Some(g) = gravity {
            TermCounts::bump(&self.counts.gravity);
            rr -= g * self.mass;
            accel -= g;
        }
        r[0] += rr[0];
        r[1] += rr[1];
        r[2] += (ath * c).dot(&accel) + (self.inertia + self.mass * self.com.norm_squared()) * pdd;
    }

    /// K_t = ∂r/∂z and C_t = ∂r/∂ż, added.
    pub fn tangents(
        &self,
        z: DVectorView<f64>,
        zd: DVectorView<f64>,
        zdd: DVectorView<f64>,
        gravity: Option<Vector2<f64>>,
        mut kt: DMatrixViewMut<f64>,
        mut ct: DMatrixViewMut<f64>,
    ) {
        let (ar, ath) = self.turn.rot(z[2]);
        let (pd, pdd) = (zd[2], zdd[2]);
        let mut accel = Vector2::new(zdd[0], zdd[1]);
        if let Some(g) = gravity {
            TermCounts::bump(&self.counts.gravity);
            accel -= g;
        }
        let c = self.com * self.mass;
        let d_r_phi = -ar * c * pdd - ath * c * (pd * pd);
        let d_r_phid = -ar * c * (2.0 * pd);
        for i in 0..2 {
            kt[(i, 2)] += d_r_phi[i];
            ct[(i, 2)] += d_r_phid[i];
        }
        kt[(2, 2)] += -(ar * c).dot(&accel);
    }

    pub fn kinetic_energy(&self, z: DVectorView<f64>, zd: DVectorView<f64>) -> f64 {
        let mut m = DMatrix::zeros(3, 3);
        self.mass_matrix(z, m.view_mut((0, 0), (3, 3)));
        0.5 * zd.dot(&(&m * zd))
    }

    pub fn gravity_energy(&self, z: DVectorView<f64>, g: Option<Vector2<f64>>) -> f64 {
        let Some(g) = g else { return 0.0 };
        let (ar, _) = self.turn.rot(z[2]);
        -g.dot(&((Vector2::new(z[0], z[1]) + ar * self.com) * self.mass))
    }
}
