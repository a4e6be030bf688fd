//! The assembled multibody system: bodies stacked in q, joints stacked in g.
//!
//! Residual of the equations of motion (what the integrator drives to zero):
//! r(q, q', q'', λ) = Σ_bodies r_body + G(q)ᵀ λ,   and   g(q) = 0.

use super::frame::{self, Frame};
use super::weld::Weld;
use crate::beam::planar_beam::PlanarBeam;
use crate::error::EngineError;
use crate::scene::{JointKind, Scene};
use nalgebra::{DMatrix, DVector, Vector2};

/// Energies of the system (J).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Energy {
    pub kinetic: f64,
    pub strain: f64,
    pub potential: f64,
}

impl Energy {
    pub fn total(&self) -> f64 {
        self.kinetic + self.strain + self.potential
    }
}

#[derive(Debug, Clone)]
pub struct System {
    pub bodies: Vec<PlanarBeam>,
    /// Index of each body's first coordinate in q.
    pub offsets: Vec<usize>,
    pub welds: Vec<Weld>,
    pub gravity: Vector2<f64>,
    n: usize,
}

impl System {
    /// Assembles the system of a validated scene.
    pub fn from_scene(scene: &Scene) -> System {
        let bodies: Vec<PlanarBeam> = scene.beams.iter().map(PlanarBeam::from_spec).collect();
        let mut offsets = Vec::with_capacity(bodies.len());
        let mut n = 0;
        for b in &bodies {
            offsets.push(n);
            n += b.ndof();
        }
        let frame_of = |name: &str| -> Frame {
            if name == "world" {
                return Frame::World {
                    position: Vector2::zeros(),
                    angle: 0.0,
                };
            }
            let (beam, flange) = name.rsplit_once('.').unwrap_or((name, "a"));
            let body = bodies.iter().position(|b| b.name == beam).unwrap_or(0);
            let map = if flange == "b" {
                bodies[body].flange_b.clone()
            } else {
                bodies[body].flange_a.clone()
            };
            Frame::OnBody { body, map }
        };
        let welds = scene
            .joints
            .iter()
            .map(|j| match j.kind {
                JointKind::Weld => Weld {
                    name: j.name.clone(),
                    frames: [frame_of(&j.frames[0]), frame_of(&j.frames[1])],
                },
            })
            .collect();
        System {
            offsets,
            welds,
            gravity: Vector2::new(scene.world.gravity[0], scene.world.gravity[1]),
            n,
            bodies,
        }
    }

    /// Number of coordinates.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of constraint equations.
    pub fn m(&self) -> usize {
        self.welds.len() * Weld::EQUATIONS
    }

    /// Coordinates of body `i`.
    pub fn body_coords(&self, i: usize, q: &DVector<f64>) -> DVector<f64> {
        q.rows(self.offsets[i], self.bodies[i].ndof()).into_owned()
    }

    /// Initial coordinates from the scene: placed frames and the initial deformed shapes.
    pub fn initial_coordinates(&self, scene: &Scene) -> Result<DVector<f64>, EngineError> {
        let mut q = DVector::zeros(self.n);
        for (i, (b, spec)) in self.bodies.iter().zip(&scene.beams).enumerate() {
            let o = self.offsets[i];
            q[o] = spec.position[0];
            q[o + 1] = spec.position[1];
            q[o + 2] = spec.angle;
            if spec.initial.tip_displacement != 0.0 {
                let shape = b
                    .static_tip_shape(spec.initial.tip_displacement)
                    .ok_or_else(|| EngineError::InitialState {
                        message: format!(
                            "beam '{}': no static tip shape (is the tip held by the frame?)",
                            b.name
                        ),
                    })?;
                q.rows_mut(o + 3, b.nflex()).copy_from(&shape);
            }
        }
        Ok(q)
    }

    fn frame_pose(&self, f: &Frame, q: &DVector<f64>) -> (Vector2<f64>, f64) {
        match f {
            Frame::World { position, angle } => (*position, *angle),
            Frame::OnBody { body, map } => {
                self.bodies[*body].point(map, &self.body_coords(*body, q))
            }
        }
    }

    /// Constraint residual g(q).
    pub fn constraints(&self, q: &DVector<f64>, g: &mut DVector<f64>) {
        for (k, w) in self.welds.iter().enumerate() {
            let (p0, a0) = self.frame_pose(&w.frames[0], q);
            let (p1, a1) = self.frame_pose(&w.frames[1], q);
            g[3 * k] = p0[0] - p1[0];
            g[3 * k + 1] = p0[1] - p1[1];
            g[3 * k + 2] = a0 - a1;
        }
    }

    /// Constraint Jacobian G = ∂g/∂q (m × n), overwritten.
    pub fn constraint_jacobian(&self, q: &DVector<f64>, g: &mut DMatrix<f64>) {
        g.fill(0.0);
        for (k, w) in self.welds.iter().enumerate() {
            for (f, sign) in w.frames.iter().zip([1.0, -1.0]) {
                if let Frame::OnBody { body, map } = f {
                    let b = &self.bodies[*body];
                    let z = self.body_coords(*body, q);
                    frame::add_jacobian(
                        b,
                        map,
                        &z,
                        sign,
                        g.view_mut((3 * k, self.offsets[*body]), (3, b.ndof())),
                    );
                }
            }
        }
    }

    /// Acceleration bias: d²g/dt² = G q'' + bias.
    pub fn accel_bias(&self, q: &DVector<f64>, v: &DVector<f64>, out: &mut DVector<f64>) {
        out.fill(0.0);
        for (k, w) in self.welds.iter().enumerate() {
            for (f, sign) in w.frames.iter().zip([1.0, -1.0]) {
                if let Frame::OnBody { body, map } = f {
                    let b = &self.bodies[*body];
                    let bias = frame::accel_bias(
                        b,
                        map,
                        &self.body_coords(*body, q),
                        &self.body_coords(*body, v),
                    );
                    out[3 * k] += sign * bias[0];
                    out[3 * k + 1] += sign * bias[1];
                }
            }
        }
    }

    /// Mass matrix M(q), overwritten.
    pub fn mass_matrix(&self, q: &DVector<f64>, m: &mut DMatrix<f64>) {
        m.fill(0.0);
        for (i, b) in self.bodies.iter().enumerate() {
            let o = self.offsets[i];
            b.mass_matrix(
                &self.body_coords(i, q),
                m.view_mut((o, o), (b.ndof(), b.ndof())),
            );
        }
    }

    /// Residual r(q, q', q'') without the reactions, overwritten.
    pub fn body_residual(
        &self,
        q: &DVector<f64>,
        v: &DVector<f64>,
        a: &DVector<f64>,
        r: &mut DVector<f64>,
    ) {
        r.fill(0.0);
        for (i, b) in self.bodies.iter().enumerate() {
            let o = self.offsets[i];
            let n = b.ndof();
            b.residual(
                &self.body_coords(i, q),
                &self.body_coords(i, v),
                &self.body_coords(i, a),
                self.gravity,
                &mut r.as_mut_slice()[o..o + n],
            );
        }
    }

    /// Tangents K_t = ∂(r + Gᵀλ)/∂q and C_t = ∂r/∂q', overwritten.
    pub fn tangents(
        &self,
        q: &DVector<f64>,
        v: &DVector<f64>,
        a: &DVector<f64>,
        lambda: &DVector<f64>,
        kt: &mut DMatrix<f64>,
        ct: &mut DMatrix<f64>,
    ) {
        kt.fill(0.0);
        ct.fill(0.0);
        for (i, b) in self.bodies.iter().enumerate() {
            let o = self.offsets[i];
            let n = b.ndof();
            b.tangents(
                &self.body_coords(i, q),
                &self.body_coords(i, v),
                &self.body_coords(i, a),
                self.gravity,
                kt.view_mut((o, o), (n, n)),
                ct.view_mut((o, o), (n, n)),
            );
        }
        for (k, w) in self.welds.iter().enumerate() {
            let lp = Vector2::new(lambda[3 * k], lambda[3 * k + 1]);
            for (f, sign) in w.frames.iter().zip([1.0, -1.0]) {
                if let Frame::OnBody { body, map } = f {
                    let b = &self.bodies[*body];
                    let o = self.offsets[*body];
                    frame::add_reaction_tangent(
                        b,
                        map,
                        &self.body_coords(*body, q),
                        lp * sign,
                        kt.view_mut((o, o), (b.ndof(), b.ndof())),
                    );
                }
            }
        }
    }

    /// Kinetic, strain and gravity energy.
    pub fn energy(&self, q: &DVector<f64>, v: &DVector<f64>) -> Energy {
        let mut e = Energy::default();
        for (i, b) in self.bodies.iter().enumerate() {
            let z = self.body_coords(i, q);
            e.kinetic += b.kinetic_energy(&z, &self.body_coords(i, v));
            e.strain += b.strain_energy(&z);
            e.potential += b.gravity_energy(&z, self.gravity);
        }
        e
    }

    /// Names of the joints whose equations are in the given constraint rows.
    pub fn joints_of_rows(&self, rows: &[usize]) -> Vec<String> {
        let mut names: Vec<String> = rows
            .iter()
            .map(|r| self.welds[r / Weld::EQUATIONS].name.clone())
            .collect();
        names.dedup();
        names
    }
}
