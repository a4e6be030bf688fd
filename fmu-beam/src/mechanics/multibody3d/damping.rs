//! The α part of the spatial beams' Rayleigh damping, beam by beam ([`BeamDamping`]): relative
//! to the beam's reference frame (its root: the root section's rotation for a tangent frame;
//! for a pinned one, the chord from root to tip and the root's twist about it), over all its
//! substructures, in the coordinates z = [R, p, q_f] of each body.

use super::body::{frame_of, Body3};
use super::frame::Frame3;
use super::quaternion::g_body;
use super::system::System3;
use crate::mechanics::beam::spatial_beam::{skew, SpatialPointMap};
use crate::mechanics::beam::FloatingFrame;
use crate::mechanics::multibody::beam_damping::{BeamDamping, DampedBody};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

impl System3 {
    /// The α damping of beam `g` at q, `None` when it has none (α = 0, damping off, or a
    /// rigid bar).
    pub fn beam_damping(&self, g: usize, q: &DVector<f64>) -> Option<BeamDamping> {
        self.beam_damping_with(g, q, |i| self.bodies[i].mass_matrix(self.body_coords(i, q)))
    }

    /// Whether beam `g` has α damping.
    pub fn damps(&self, g: usize) -> bool {
        let group = &self.beams[g];
        let (first, last) = (group.bodies.start, group.bodies.end - 1);
        matches!(
            (&self.bodies[first], &self.bodies[last]),
            (Body3::Beam(beam), Body3::Beam(_)) if beam.rayleigh_alpha != 0.0
        )
    }

    /// [`System3::beam_damping`] with each body's mass matrix over ż at q from `mass` (body
    /// index to matrix: the residual has them at hand).
    pub fn beam_damping_with(
        &self,
        g: usize,
        q: &DVector<f64>,
        mut mass: impl FnMut(usize) -> DMatrix<f64>,
    ) -> Option<BeamDamping> {
        if !self.damps(g) {
            return None;
        }
        let group = &self.beams[g];
        let (first, last) = (group.bodies.start, group.bodies.end - 1);
        let (Body3::Beam(beam), Body3::Beam(last_beam)) = (&self.bodies[first], &self.bodies[last])
        else {
            return None;
        };
        let ja = self.map_jacobian(first, &beam.flange_a, q);
        let origin = ja.0;
        let bodies: Vec<DampedBody> = group
            .bodies
            .clone()
            .map(|i| {
                let z = self.body_coords(i, q);
                let n = self.bodies[i].ncoords();
                let (r, p, a) = frame_of(&z);
                let mut rigid = DMatrix::zeros(n, 6);
                rigid
                    .view_mut((0, 0), (3, 3))
                    .copy_from(&Matrix3::identity());
                rigid
                    .view_mut((0, 3), (3, 3))
                    .copy_from(&(-skew(&(r - origin))));
                // ṗ = ½ Gᵀ Aᵀ ω turns the frame at the world angular velocity ω
                rigid
                    .view_mut((3, 3), (4, 3))
                    .copy_from(&(g_body(&p).transpose() * a.transpose() * 0.5));
                DampedBody {
                    body: i,
                    offset: self.offsets[i],
                    mass: mass(i),
                    rigid,
                    reference: None,
                }
            })
            .collect();
        let mut s_first = ja.1.clone();
        let s_last = if beam.frame == FloatingFrame::Pinned {
            // ω = (ω_a·ĉ) ĉ + c × ċ / |c|², c the chord from root to tip
            let jb = self.map_jacobian(last, &last_beam.flange_b, q);
            let c = jb.0 - origin;
            let c2 = c.norm_squared();
            let along = c * c.transpose() / c2;
            let cross = skew(&c) / c2;
            let rot_a = ja.1.rows(3, 3) * 1.0;
            let pos_a = ja.1.rows(0, 3) * 1.0;
            s_first
                .rows_mut(3, 3)
                .copy_from(&(along * rot_a - cross * pos_a));
            let mut s_last = DMatrix::zeros(6, jb.1.ncols());
            s_last.rows_mut(3, 3).copy_from(&(cross * jb.1.rows(0, 3)));
            Some(s_last)
        } else {
            None
        };
        Some(BeamDamping::with_reference(
            beam.rayleigh_alpha,
            bodies,
            s_first,
            s_last,
        ))
    }

    /// Position of the material point `map` of body `body` and the Jacobian (6 × n_body) of
    /// its velocity and world angular velocity over the body's coordinates.
    fn map_jacobian(
        &self,
        body: usize,
        map: &SpatialPointMap,
        q: &DVector<f64>,
    ) -> (Vector3<f64>, DMatrix<f64>) {
        let frame = Frame3::on_body(body, map.clone(), Matrix3::identity());
        let mut d = Vec::new();
        let (x, a) = frame.pose_derivatives(Some(self.body_coords(body, q)), &mut d);
        let mut j = DMatrix::zeros(6, self.bodies[body].ncoords());
        for (&k, (dx, da)) in frame.active().iter().zip(&d) {
            let w = da * a.transpose();
            let dth = Vector3::new(
                w[(2, 1)] - w[(1, 2)],
                w[(0, 2)] - w[(2, 0)],
                w[(1, 0)] - w[(0, 1)],
            ) * 0.5;
            j.view_mut((0, k), (3, 1)).copy_from(dx);
            j.view_mut((3, k), (3, 1)).copy_from(&dth);
        }
        (x, j)
    }

    /// The power (W, ≥ 0) the beams' α damping takes out at (q, q').
    pub fn damping_dissipation(&self, q: &DVector<f64>, v: &DVector<f64>) -> f64 {
        (0..self.beams.len())
            .filter_map(|g| self.beam_damping(g, q))
            .map(|d| d.dissipation(v))
            .sum()
    }
}
