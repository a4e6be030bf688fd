//! What the integrator needs from a mechanical system: M(q) q'' + G(q)ᵀλ = Q(q, q', t),
//! g(q, t) = 0, with tangents for Newton. The planar [`super::System`] and the spatial
//! [`crate::mechanics::multibody3d::System3`] implement it, so one generalized-α serves both. The
//! matrices come by body blocks and constraint rows ([`super::sparsity`]), so that the
//! integrator's work stays linear in the number of bodies; dense forms are derived from them.

use super::sparsity::{BlockDiagonal, JacobianRows};
use crate::error::EngineError;
use nalgebra::{DMatrix, DVector};
use std::ops::Range;

/// A point of the equations: coordinates q, rates q', accelerations q'', multipliers λ and
/// time t, where the integrator evaluates the tangents and the iteration matrix.
#[derive(Debug, Clone, Copy)]
pub struct Point<'a> {
    /// Coordinates q.
    pub q: &'a DVector<f64>,
    /// Rates q'.
    pub v: &'a DVector<f64>,
    /// Accelerations q''.
    pub a: &'a DVector<f64>,
    /// Lagrange multipliers λ.
    pub lambda: &'a DVector<f64>,
    /// Time (s).
    pub t: f64,
}

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

/// Where a planar system's unknowns turn when every body turns by one angle δ about the plane's
/// normal: the equations are invariant to turning the whole system (up to the tangents of loads
/// and prismatic axes fixed in the world), so the iteration matrix at the turned state is
/// R(δ) S R(δ)ᵀ, with R turning each (x, y) pair below by δ. Newton keeps a factorized S over
/// steps in which a spinning or swinging system turns.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Turning {
    /// Indices in q of the bodies' world angles.
    pub angles: Vec<usize>,
    /// First index of each (x, y) pair of world-vector components among the n + m unknowns of
    /// a Newton correction: the bodies' positions, and the joint rows that hold p₁ - p₀.
    pub pairs: Vec<usize>,
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
    /// Coordinates before assembly: the system's placement at t = 0 (with its initial shapes).
    fn initial_coordinates(&self) -> Result<DVector<f64>, EngineError>;
    /// Coordinates of each body in q, consecutive and covering 0..n: M, K_t and C_t have
    /// entries only in these diagonal blocks.
    fn body_ranges(&self) -> Vec<Range<usize>>;
    /// For each constraint row, the bodies (indices into [`Equations::body_ranges`]) whose
    /// coordinates it depends on; `None` for a frame fixed in the world.
    fn row_bodies(&self) -> Vec<[Option<usize>; 2]>;
    /// Mass matrix M(q) by body blocks, overwritten.
    fn mass_blocks(&self, q: &DVector<f64>, m: &mut BlockDiagonal);
    /// r(q, q', q'', t) without the reactions Gᵀλ, overwritten.
    fn body_residual(
        &self,
        q: &DVector<f64>,
        v: &DVector<f64>,
        a: &DVector<f64>,
        t: f64,
        r: &mut DVector<f64>,
    );
    /// K_t = ∂(r + Gᵀλ)/∂q and C_t = ∂r/∂q' by body blocks, overwritten (approximations only
    /// slow Newton; coupling terms between bodies are left out).
    fn tangent_blocks(&self, at: &Point, kt: &mut BlockDiagonal, ct: &mut BlockDiagonal);
    /// Constraint residual g(q, t).
    fn constraints(&self, q: &DVector<f64>, t: f64, g: &mut DVector<f64>);
    /// Constraint Jacobian G = ∂g/∂q by rows, overwritten.
    fn jacobian_rows(&self, q: &DVector<f64>, t: f64, gm: &mut JacobianRows);
    /// g and G by rows (overwritten) together.
    fn constraints_and_rows(
        &self,
        q: &DVector<f64>,
        t: f64,
        g: &mut DVector<f64>,
        gm: &mut JacobianRows,
    ) {
        self.constraints(q, t, g);
        self.jacobian_rows(q, t, gm);
    }
    /// Zero blocks of the system's block-diagonal matrices (M, K_t, C_t).
    fn block_diagonal(&self) -> BlockDiagonal {
        BlockDiagonal::zeros(&self.body_ranges())
    }
    /// The constraint Jacobian's storage, with the system's pattern.
    fn jacobian_pattern(&self) -> JacobianRows {
        JacobianRows::new(self.n(), &self.body_ranges(), &self.row_bodies())
    }
    /// Mass matrix M(q), dense (n × n), overwritten.
    fn mass_matrix(&self, q: &DVector<f64>, m: &mut DMatrix<f64>) {
        let mut b = self.block_diagonal();
        self.mass_blocks(q, &mut b);
        b.to_dense(m);
    }
    /// K_t and C_t, dense (n × n), overwritten.
    fn tangents(&self, at: &Point, kt: &mut DMatrix<f64>, ct: &mut DMatrix<f64>) {
        let (mut kb, mut cb) = (self.block_diagonal(), self.block_diagonal());
        self.tangent_blocks(at, &mut kb, &mut cb);
        kb.to_dense(kt);
        cb.to_dense(ct);
    }
    /// Constraint Jacobian G = ∂g/∂q, dense (m × n), overwritten.
    fn constraint_jacobian(&self, q: &DVector<f64>, t: f64, gm: &mut DMatrix<f64>) {
        let mut rows = self.jacobian_pattern();
        self.jacobian_rows(q, t, &mut rows);
        rows.to_dense(gm);
    }
    /// Acceleration bias: d²g/dt² = G q'' + bias.
    fn accel_bias(&self, q: &DVector<f64>, v: &DVector<f64>, t: f64, out: &mut DVector<f64>);
    /// Times where a drive law jumps, for the integrator to land on.
    fn breakpoints(&self) -> Vec<f64>;
    /// Names of the joints whose equations are in the given constraint rows.
    fn joints_of_rows(&self, rows: &[usize]) -> Vec<String>;
    /// Power of drives and loads (W).
    fn power(&self, q: &DVector<f64>, v: &DVector<f64>, lambda: &DVector<f64>, t: f64) -> f64;
    /// How the unknowns turn with the whole system (`Turning`); None where no such
    /// symmetry is used.
    fn turning(&self) -> Option<Turning> {
        None
    }
    /// Whether the dense iteration matrix condenses out the coordinates that a constraint row
    /// fixes alone before its LU (`integrator/condensed.rs`): the planar system does; the
    /// spatial one not yet. Its fixed-step runs of 80 000 steps pile up Newton's remainders,
    /// and with the condensation's rounding the master's communication step moved C6's rigid
    /// twin by 2.5e-8 rad at 1.25e-5 s (3.2e-9 without), past
    /// `fixed_steps_converge_as_they_shrink`'s 1e-8.
    fn condenses(&self) -> bool {
        false
    }
}
