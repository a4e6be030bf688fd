//! The α part of the planar beams' Rayleigh damping, beam by beam ([`BeamDamping`]): relative
//! to the beam's reference frame (its root; the root's tangent for a tangent frame, the chord
//! from root to tip for a pinned one), over all its substructures.

use super::*;
use crate::mechanics::beam::FloatingFrame;
use crate::mechanics::multibody::beam_damping::{BeamDamping, DampedBody};
use nalgebra::DMatrix;

impl System {
    /// The α damping of beam group `g` at q, `None` when it has none (α = 0, damping off,
    /// or a rigid bar).
    pub fn beam_damping(&self, g: usize, q: &DVector<f64>) -> Option<BeamDamping> {
        let group = &self.beams[g];
        let (first, last) = (group.bodies.start, group.bodies.end - 1);
        let beam = self.beam(first)?;
        if !beam.options.damping || beam.rayleigh_alpha == 0.0 {
            return None;
        }
        let last_beam = self.beam(last)?;
        let coords = |b: usize| self.body_coords(b, q);
        let root = FrameState::on_body(
            first,
            &self.bodies[first],
            &beam.flange_a,
            coords(first),
            None,
        );
        let origin = root.p;
        // rows of the Jacobian of a frame's position (x, y) and angle over its body's coordinates
        let jacobian = |fs: &FrameState, n: usize| {
            let mut j = DMatrix::zeros(3, n);
            for (row, (w, c)) in [
                (Vector2::x(), 0.0),
                (Vector2::y(), 0.0),
                (Vector2::zeros(), 1.0),
            ]
            .into_iter()
            .enumerate()
            {
                fs.for_each_jacobian(w, c, |k, x| j[(row, k)] += x);
            }
            j
        };
        let bodies: Vec<DampedBody> = group
            .bodies
            .clone()
            .map(|i| {
                let n = self.bodies[i].ndof();
                let mut mass = DMatrix::zeros(n, n);
                self.bodies[i].mass_matrix(coords(i), mass.view_mut((0, 0), (n, n)));
                let z = coords(i);
                let mut rigid = DMatrix::zeros(n, 3);
                rigid[(0, 0)] = 1.0;
                rigid[(1, 1)] = 1.0;
                rigid[(0, 2)] = -(z[1] - origin.y);
                rigid[(1, 2)] = z[0] - origin.x;
                rigid[(THETA, 2)] = 1.0;
                DampedBody {
                    body: i,
                    offset: self.offsets[i],
                    mass,
                    rigid,
                    reference: None,
                }
            })
            .collect();
        let ja = jacobian(&root, self.bodies[first].ndof());
        let mut s_first = DMatrix::zeros(3, ja.ncols());
        s_first.rows_mut(0, 2).copy_from(&ja.rows(0, 2));
        let s_last = match beam.frame {
            // ω: the rate of the root's tangent
            FloatingFrame::Tangent => {
                s_first.row_mut(2).copy_from(&ja.row(2));
                None
            }
            // ω = c × ċ / |c|², c the chord from root to tip
            FloatingFrame::Pinned => {
                let tip = FrameState::on_body(
                    last,
                    &self.bodies[last],
                    &last_beam.flange_b,
                    coords(last),
                    None,
                );
                let c = tip.p - origin;
                let c2 = c.norm_squared();
                let jb = jacobian(&tip, self.bodies[last].ndof());
                let chord_rate = |j: &DMatrix<f64>| (j.row(1) * c.x - j.row(0) * c.y) / c2;
                let mut s_last = DMatrix::zeros(3, jb.ncols());
                s_last.row_mut(2).copy_from(&chord_rate(&jb));
                let rate_a = chord_rate(&ja);
                let mut row = s_first.row_mut(2);
                row -= rate_a;
                Some(s_last)
            }
        };
        Some(BeamDamping::with_reference(
            beam.rayleigh_alpha,
            bodies,
            s_first,
            s_last,
        ))
    }

    /// The power (W, ≥ 0) the beams' α damping takes out at (q, q').
    pub fn damping_dissipation(&self, q: &DVector<f64>, v: &DVector<f64>) -> f64 {
        (0..self.beams.len())
            .filter_map(|g| self.beam_damping(g, q))
            .map(|d| d.dissipation(v))
            .sum()
    }
}
