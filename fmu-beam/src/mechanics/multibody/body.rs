//! A body of the system: a flexible beam (one floating frame) or a rigid body. Both share the
//! floating-frame kinematics r = R + A(θ) (s0 + S_p q_f); a rigid body has no q_f.

use super::rigid_body::RigidBody;
use crate::mechanics::beam::planar_beam::{PlanarBeam, PointMap, TermCounts, FLEX, THETA};
use crate::mechanics::beam::sines::RecentTurn;
use nalgebra::{DMatrixViewMut, DVectorView, Matrix2, Vector2};

#[derive(Debug, Clone)]
pub enum Body {
    Beam(Box<PlanarBeam>),
    Rigid(RigidBody),
}

impl Body {
    pub fn name(&self) -> &str {
        match self {
            Body::Beam(b) => &b.name,
            Body::Rigid(r) => &r.name,
        }
    }

    pub fn ndof(&self) -> usize {
        FLEX + self.nflex()
    }

    pub fn nflex(&self) -> usize {
        match self {
            Body::Beam(b) => b.nflex(),
            Body::Rigid(_) => 0,
        }
    }

    /// Characteristic length (m) for error weights.
    pub fn length_scale(&self) -> f64 {
        match self {
            Body::Beam(b) => b.length,
            Body::Rigid(r) => r
                .frames
                .iter()
                .map(|(_, p)| p.norm())
                .fold(r.com.norm(), f64::max),
        }
    }

    /// Its last angle's sine and cosine.
    pub fn turn(&self) -> &RecentTurn {
        match self {
            Body::Beam(b) => &b.turn,
            Body::Rigid(r) => &r.turn,
        }
    }

    /// How often this body evaluated each optional term.
    pub fn counts(&self) -> &TermCounts {
        match self {
            Body::Beam(b) => &b.counts,
            Body::Rigid(r) => &r.counts,
        }
    }

    /// A rigid body without mass and inertia (its coordinates are fixed by joints).
    pub fn is_massless(&self) -> bool {
        matches!(self, Body::Rigid(r) if r.mass == 0.0 && r.inertia == 0.0)
    }

    /// True for coordinates that are angles (θ, nodal slopes); false for lengths and modal
    /// amplitudes.
    pub fn is_angle(&self, k: usize) -> bool {
        match self {
            Body::Beam(b) => k == THETA || (k >= FLEX && b.is_slope(k - FLEX)),
            Body::Rigid(_) => k == THETA,
        }
    }

    pub fn mass_matrix(&self, z: DVectorView<f64>, m: DMatrixViewMut<f64>) {
        match self {
            Body::Beam(b) => b.mass_matrix(z, m),
            Body::Rigid(r) => r.mass_matrix(z, m),
        }
    }

    pub fn residual(
        &self,
        z: DVectorView<f64>,
        zd: DVectorView<f64>,
        zdd: DVectorView<f64>,
        g: Option<Vector2<f64>>,
        out: &mut [f64],
    ) {
        match self {
            Body::Beam(b) => b.residual(z, zd, zdd, g, out),
            Body::Rigid(r) => r.residual(z, zd, zdd, g, out),
        }
    }

    pub fn tangents(
        &self,
        z: DVectorView<f64>,
        zd: DVectorView<f64>,
        zdd: DVectorView<f64>,
        g: Option<Vector2<f64>>,
        kt: DMatrixViewMut<f64>,
        ct: DMatrixViewMut<f64>,
    ) {
        match self {
            Body::Beam(b) => b.tangents(z, zd, zdd, g, kt, ct),
            Body::Rigid(r) => r.tangents(z, zd, zdd, g, kt, ct),
        }
    }

    pub fn kinetic_energy(&self, z: DVectorView<f64>, zd: DVectorView<f64>) -> f64 {
        match self {
            Body::Beam(b) => b.kinetic_energy(z, zd),
            Body::Rigid(r) => r.kinetic_energy(z, zd),
        }
    }

    pub fn strain_energy(&self, z: DVectorView<f64>) -> f64 {
        match self {
            Body::Beam(b) => b.strain_energy(z),
            Body::Rigid(_) => 0.0,
        }
    }

    pub fn gravity_energy(&self, z: DVectorView<f64>, g: Option<Vector2<f64>>) -> f64 {
        match self {
            Body::Beam(b) => b.gravity_energy(z, g),
            Body::Rigid(r) => r.gravity_energy(z, g),
        }
    }

    /// Position of a material point in the body frame, s = s0 + S_p q_f.
    pub fn local_point(&self, map: &PointMap, z: DVectorView<f64>) -> Vector2<f64> {
        map.s0 + map.displacement(&z.rows(FLEX, self.nflex()))
    }

    /// World position and angle of a material point.
    pub fn point(&self, map: &PointMap, z: DVectorView<f64>) -> (Vector2<f64>, f64) {
        let (ar, _) = self.turn().rot(z[THETA]);
        self.placed(map, z, &ar, self.local_point(map, z))
    }

    /// [`Body::point`] with the body's rotation `ar` and the point's body-frame position `s`
    /// already at hand.
    pub fn placed(
        &self,
        map: &PointMap,
        z: DVectorView<f64>,
        ar: &Matrix2<f64>,
        s: Vector2<f64>,
    ) -> (Vector2<f64>, f64) {
        let f = z.rows(FLEX, self.nflex());
        (
            Vector2::new(z[0], z[1]) + ar * s,
            z[THETA] + map.sphi.dot(&f),
        )
    }
}
