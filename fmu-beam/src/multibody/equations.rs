//! What the integrator needs from a mechanical system: M(q) q'' + G(q)ᵀλ = Q(q, q', t),
//! g(q, t) = 0, with tangents for Newton. The planar [`super::System`] and the spatial
//! [`crate::multibody3d::System3`] implement it, so one generalized-α serves both.

use crate::error::EngineError;
use crate::scene::Scene;
use nalgebra::{DMatrix, DVector};

/// How a coordinate's local error is weighed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoordinateKind {
    /// A length: weighed against the system's length scale.
    Length,
    /// An angle (or a quaternion component): weighed against 1.
    Angle,
    /// A coordinate of a massless body: fixed by the joints, out of the error norm.
    Algebraic,
}

impl CoordinateKind {
    /// The kind of a body's coordinate: algebraic for a massless body, else angle or length.
    pub fn of(massless: bool, angle: bool) -> CoordinateKind {
        if massless {
            CoordinateKind::Algebraic
        } else if angle {
            CoordinateKind::Angle
        } else {
            CoordinateKind::Length
        }
    }
}

/// The equations of motion of a constrained mechanical system in index-3 form.
pub trait Equations {
    /// Number of coordinates.
    fn n(&self) -> usize;
    /// Number of constraint equations.
    fn m(&self) -> usize;
    /// The largest body length (m): the scale of position errors.
    fn length_scale(&self) -> f64;
    /// The error weight class of each coordinate (n entries).
    fn coordinate_kinds(&self) -> Vec<CoordinateKind>;
    /// Indices in q of the bodies' frame coordinates (moved to assemble, never deformed).
    fn frame_coordinates(&self) -> Vec<usize>;
    /// Coordinates before assembly (from the scene, or the system's own placement).
    fn initial_coordinates(&self, scene: &Scene) -> Result<DVector<f64>, EngineError>;
    /// Mass matrix M(q), overwritten.
    fn mass_matrix(&self, q: &DVector<f64>, m: &mut DMatrix<f64>);
    /// r(q, q', q'', t) without the reactions Gᵀλ, overwritten.
    fn body_residual(
        &self,
        q: &DVector<f64>,
        v: &DVector<f64>,
        a: &DVector<f64>,
        t: f64,
        r: &mut DVector<f64>,
    );
    /// K_t = ∂(r + Gᵀλ)/∂q and C_t = ∂r/∂q', overwritten (approximations only slow Newton).
    #[allow(clippy::too_many_arguments)]
    fn tangents(
        &self,
        q: &DVector<f64>,
        v: &DVector<f64>,
        a: &DVector<f64>,
        lambda: &DVector<f64>,
        t: f64,
        kt: &mut DMatrix<f64>,
        ct: &mut DMatrix<f64>,
    );
    /// Constraint residual g(q, t).
    fn constraints(&self, q: &DVector<f64>, t: f64, g: &mut DVector<f64>);
    /// Constraint Jacobian G = ∂g/∂q (m × n), overwritten.
    fn constraint_jacobian(&self, q: &DVector<f64>, t: f64, g: &mut DMatrix<f64>);
    /// g and G (overwritten) together.
    fn constraints_and_jacobian(
        &self,
        q: &DVector<f64>,
        t: f64,
        g: &mut DVector<f64>,
        gm: &mut DMatrix<f64>,
    ) {
        self.constraints(q, t, g);
        self.constraint_jacobian(q, t, gm);
    }
    /// Acceleration bias: d²g/dt² = G q'' + bias.
    fn accel_bias(&self, q: &DVector<f64>, v: &DVector<f64>, t: f64, out: &mut DVector<f64>);
    /// Times where a drive law jumps, for the integrator to land on.
    fn breakpoints(&self) -> Vec<f64>;
    /// Names of the joints whose equations are in the given constraint rows.
    fn joints_of_rows(&self, rows: &[usize]) -> Vec<String>;
    /// Power of drives and loads (W).
    fn power(&self, q: &DVector<f64>, v: &DVector<f64>, lambda: &DVector<f64>, t: f64) -> f64;
}
