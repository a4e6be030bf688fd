//! A spatial rigid body: mass, centre of mass and inertia tensor in its frame, named frames.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// A rigid body of the spatial system, its properties in its own frame.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBody3 {
    /// Name of the scene body, or of the beam it is the rigid equivalent of.
    pub name: String,
    /// Mass (kg); zero makes the body's coordinates algebraic.
    pub mass: f64,
    /// Centre of mass in the body frame (m).
    pub com: Vector3<f64>,
    /// Inertia tensor about the centre of mass, body axes (kg m²).
    pub inertia: Matrix3<f64>,
    /// Named frames: position in the body frame and rotation (frame → body).
    pub frames: Vec<(String, Vector3<f64>, Matrix3<f64>)>,
}

impl RigidBody3 {
    /// The rigid equivalent of a beam: its mass, centre of mass and inertia about the centre
    /// of mass in the undeformed configuration, with the named frames `frames`.
    pub fn of_beam(
        beam: &crate::mechanics::beam::spatial_beam::SpatialBeam,
        frames: Vec<(String, Vector3<f64>, Matrix3<f64>)>,
    ) -> RigidBody3 {
        let u = &beam.undeformed;
        let m = beam.mass;
        let c = u.c0 / m;
        RigidBody3 {
            name: beam.name.clone(),
            mass: m,
            com: c,
            inertia: u.i0 - (Matrix3::identity() * c.dot(&c) - c * c.transpose()) * m,
            frames,
        }
    }

    /// Static moment m c and inertia about the body origin J_o = J_c + m (cᵀc I − c cᵀ).
    fn origin_inertia(&self) -> (Vector3<f64>, Matrix3<f64>) {
        let c = self.com;
        let jo = self.inertia + (Matrix3::identity() * c.dot(&c) - c * c.transpose()) * self.mass;
        (c * self.mass, jo)
    }

    /// Mass matrix over v = [Ṙ, ω] (6 × 6).
    pub fn mass_matrix(&self, a: &Matrix3<f64>) -> DMatrix<f64> {
        let (mc, jo) = self.origin_inertia();
        let mrw = -a * crate::mechanics::beam::spatial_beam::skew(&mc);
        let mut m = DMatrix::zeros(6, 6);
        m.view_mut((0, 0), (3, 3))
            .copy_from(&(Matrix3::identity() * self.mass));
        m.view_mut((0, 3), (3, 3)).copy_from(&mrw);
        m.view_mut((3, 0), (3, 3)).copy_from(&mrw.transpose());
        m.view_mut((3, 3), (3, 3)).copy_from(&jo);
        m
    }

    /// Residual M v̇ + h(ω) − Q_g over v = [Ṙ, ω].
    pub fn residual(
        &self,
        a: &Matrix3<f64>,
        v: &DVector<f64>,
        vd: &DVector<f64>,
        g: &Vector3<f64>,
    ) -> DVector<f64> {
        let (mc, jo) = self.origin_inertia();
        let w = Vector3::new(v[3], v[4], v[5]);
        let mut r = self.mass_matrix(a) * vd;
        let hr = a * w.cross(&w.cross(&mc)) - g * self.mass;
        let hw = w.cross(&(jo * w)) - mc.cross(&(a.transpose() * g));
        for i in 0..3 {
            r[i] += hr[i];
            r[3 + i] += hw[i];
        }
        r
    }

    /// Potential energy of gravity −g·(m R + A m c) (J).
    pub fn gravity_energy(&self, r: &Vector3<f64>, a: &Matrix3<f64>, g: &Vector3<f64>) -> f64 {
        -g.dot(&(r * self.mass + a * self.com * self.mass))
    }

    /// The named frame, if any.
    pub fn frame(&self, name: &str) -> Option<(Vector3<f64>, Matrix3<f64>)> {
        self.frames.iter().find(|f| f.0 == name).map(|f| (f.1, f.2))
    }
}
