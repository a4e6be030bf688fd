//! Layer 3, time integration of M(q) q'' + G(q)ᵀλ = Q(q, q', t), g(q) = 0: generalized-α
//! ([`Stepper`]) with Newton iterations on a factorized iteration matrix, error control, dense
//! output, consistent (re)starts and the byte codec of its state. Imports the mechanics' [`Equations`](crate::mechanics::Equations)
//! and the layers below.

pub(crate) mod bordered_band;
pub(crate) mod codec;
pub(crate) mod condensed;
pub(crate) mod dense_output;
pub(crate) mod generalized_alpha;
pub(crate) mod given_start;
pub(crate) mod initial;
pub(crate) mod iteration_matrix;
pub(crate) mod newton;

pub use generalized_alpha::{iteration_scaling, GaState, Stepper};
pub(crate) use generalized_alpha::{within, Controller, MatrixPoint, Memory, SplitReason};
pub use given_start::{given_start, CoordinateStart};
pub use initial::{initial_state, initial_state_from};
pub(crate) use iteration_matrix::Scaling;
pub use iteration_matrix::{IterationMatrix, LinearSolver};

use crate::error::EngineError;
use crate::mechanics::multibody::Point;
use crate::scene::Scene;
pub(crate) use codec::{write_vec, Reader};

/// Solver settings (all tunable between communication steps).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Local error control (true) or a fixed internal step of `max_step` (false).
    pub adaptive: bool,
    /// Relative tolerance (1) of the error control and of Newton's iteration, on each
    /// coordinate against tol × (|q| + the system's length; 1 rad for angles).
    pub tolerance: f64,
    /// Largest internal step (s); the fixed step when not `adaptive`.
    pub max_step: f64,
    /// Spectral radius at infinity ρ∞ of generalized-α (1): 1 = no numerical damping.
    pub rho_inf: f64,
    /// The work budget of one communication step ([`Stepper::advance`]), in work units
    /// ([`work_units`]); past it the step ends in [`EngineError::WorkBudget`] (a Discard).
    pub step_budget: u64,
}

/// The default work budget of a communication step, in [`work_units`]: 3e7 units are 1–4.5 s
/// on the shipped scenes (30–150 ns a unit; doStep(0, 1e6) of each on one core of the
/// development machine beside another build, 2026-12-06: `worst_do_step_of_every_shipped_scene`
/// in `fmu-beam/tests/issue_45_work_budget.rs`). A communication step that needs more (a doStep
/// of 1e6 s took 287 s on rollup_3d and 66 s on spin_up_omega10 when the budget counted 1e6
/// internal steps, whatever each cost) ends in a Discard within seconds instead;
/// `solver.step_budget` sets it. No doStep of a shipped scene's DefaultExperiment comes near it
/// (the largest, rollup_3d's, takes 4.9e5 units).
pub const DEFAULT_STEP_BUDGET: u64 = crate::scene::DEFAULT_STEP_BUDGET;

/// Work units per Newton iteration beyond one per unknown: the iteration's fixed cost (the
/// step's bookkeeping, the error estimate), about 30 unknowns' worth on the shipped scenes
/// (a scene of 5 unknowns spends 5.8 µs an iteration, one of 35 spends 9 µs).
const ITERATION_OVERHEAD: u64 = 32;

/// The work of `iterations` Newton iterations and `factorizations` iteration matrices (each
/// evaluated and factorized) for a system of `unknowns` (n + m) whose iteration matrix costs
/// `per_factorization` units ([`IterationMatrix::factorization_units`]: unknowns² / 4 when
/// dense): iterations × (unknowns + [`ITERATION_OVERHEAD`]) + factorizations ×
/// per_factorization. A residual and a solve cost about one unit per unknown; evaluating the
/// tangents and factorizing a dense matrix a quarter unit per unknown² (30–55 ns per unknown²
/// measured, the roll-up's 3D tangents included). Counted as dense whatever the matrix, a
/// factorization of the 64-substructure roll-up (1 280 unknowns, 32 292 entries stored) read
/// 13 times its sparse count: one doStep of 0.01 s of its DefaultExperiment counted 5.0e6, a
/// sixth of the default budget.
pub fn work_units(
    iterations: u64,
    factorizations: u64,
    unknowns: u64,
    per_factorization: u64,
) -> u64 {
    iterations
        .saturating_mul(unknowns + ITERATION_OVERHEAD)
        .saturating_add(factorizations.saturating_mul(per_factorization))
}

impl Settings {
    /// The settings of the scene's `solver` entry.
    pub fn from_scene(scene: &Scene) -> Settings {
        Settings {
            adaptive: scene.solver.adaptive,
            tolerance: scene.solver.tolerance,
            max_step: scene.solver.max_step,
            rho_inf: scene.solver.rho_inf,
            step_budget: scene.solver.step_budget,
        }
    }
}

/// Work counters since initialization.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Stats {
    /// Internal steps accepted.
    pub steps: u64,
    /// Newton corrections solved for, over accepted and refused steps.
    pub newton_iterations: u64,
    /// Iteration matrices evaluated and factorized.
    pub jacobians: u64,
    /// Steps refused and retried smaller: an error estimate above the tolerance, a singular
    /// matrix, a non-finite iterate, or Newton not converging with a fresh matrix.
    pub rejected: u64,
    /// Fixed steps cut short (to land, or after a failed Newton iteration).
    pub split: u64,
}

impl Stats {
    pub(crate) fn write(&self, w: &mut Vec<u8>) {
        for x in [
            self.steps,
            self.newton_iterations,
            self.jacobians,
            self.rejected,
            self.split,
        ] {
            w.extend_from_slice(&x.to_le_bytes());
        }
    }

    pub(crate) fn read(r: &mut Reader) -> Result<Stats, EngineError> {
        Ok(Stats {
            steps: r.u64()?,
            newton_iterations: r.u64()?,
            jacobians: r.u64()?,
            rejected: r.u64()?,
            split: r.u64()?,
        })
    }
}

impl GaState {
    /// The state as a point of the equations: (q, q', q'', λ) at its time.
    pub fn point(&self) -> Point<'_> {
        Point {
            q: &self.q,
            v: &self.v,
            a: &self.qdd,
            lambda: &self.lambda,
            t: self.t,
        }
    }

    pub(crate) fn write(&self, w: &mut Vec<u8>) {
        w.extend_from_slice(&self.t.to_le_bytes());
        w.extend_from_slice(&self.h.to_le_bytes());
        w.extend_from_slice(&self.work.to_le_bytes());
        for v in [&self.q, &self.v, &self.acc, &self.qdd, &self.lambda] {
            write_vec(w, v.as_slice());
        }
    }

    pub(crate) fn read(r: &mut Reader) -> Result<GaState, EngineError> {
        let t = r.f64()?;
        let h = r.f64()?;
        let work = r.f64()?;
        let mut vs = Vec::with_capacity(5);
        for _ in 0..5 {
            vs.push(nalgebra::DVector::from_vec(r.vec()?));
        }
        let n = vs[0].len();
        if vs[1..4].iter().any(|v| v.len() != n) {
            return Err(EngineError::BadState {
                message: "state vectors of different lengths".into(),
            });
        }
        if !t.is_finite()
            || !h.is_finite()
            || !work.is_finite()
            || vs.iter().any(|v| v.iter().any(|x| !x.is_finite()))
        {
            return Err(EngineError::BadState {
                message: "non-finite numbers in the state".into(),
            });
        }
        let lambda = vs.pop().unwrap_or_default();
        let qdd = vs.pop().unwrap_or_default();
        let acc = vs.pop().unwrap_or_default();
        let v = vs.pop().unwrap_or_default();
        let q = vs.pop().unwrap_or_default();
        Ok(GaState {
            t,
            h,
            q,
            v,
            acc,
            qdd,
            lambda,
            work,
        })
    }
}

impl Memory {
    pub(crate) fn write(&self, w: &mut Vec<u8>) {
        match &self.point {
            None => w.push(0),
            Some(p) => {
                w.push(1);
                w.extend_from_slice(&p.t.to_le_bytes());
                w.extend_from_slice(&p.h.to_le_bytes());
                for v in [&p.q, &p.v, &p.qdd, &p.lambda] {
                    write_vec(w, v.as_slice());
                }
            }
        }
        match self.contraction.theta {
            None => w.push(0),
            Some(theta) => {
                w.push(1);
                w.extend_from_slice(&theta.to_le_bytes());
            }
        }
        w.extend_from_slice(&self.contraction.since.to_le_bytes());
        match self.grid {
            None => w.push(0),
            Some((anchor, k)) => {
                w.push(1);
                w.extend_from_slice(&anchor.to_le_bytes());
                w.extend_from_slice(&k.to_le_bytes());
            }
        }
        let c = &self.controller;
        w.push(c.recent.len() as u8);
        for e in &c.recent {
            w.extend_from_slice(&e.to_le_bytes());
        }
        match c.cap {
            None => w.push(0),
            Some((cap, left)) => {
                w.push(1);
                w.extend_from_slice(&cap.to_le_bytes());
                w.extend_from_slice(&left.to_le_bytes());
            }
        }
        w.extend_from_slice(&self.noise.to_le_bytes());
        w.push(self.history.len() as u8);
        for (t, q) in &self.history {
            w.extend_from_slice(&t.to_le_bytes());
            write_vec(w, q.as_slice());
        }
    }

    pub(crate) fn read(r: &mut Reader) -> Result<Memory, EngineError> {
        let bad = |m: &str| EngineError::BadState {
            message: format!("integrator memory: {m}"),
        };
        let flag = |r: &mut Reader| match r.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(bad("corrupt flag")),
        };
        let point = if flag(r)? {
            let (t, h) = (r.f64()?, r.f64()?);
            let mut vs = Vec::with_capacity(4);
            for _ in 0..4 {
                vs.push(nalgebra::DVector::from_vec(r.vec()?));
            }
            let n = vs[0].len();
            if vs[1].len() != n || vs[2].len() != n {
                return Err(bad("vectors of different lengths"));
            }
            if !(t.is_finite() && h.is_finite() && h > 0.0)
                || vs.iter().any(|v| v.iter().any(|x| !x.is_finite()))
            {
                return Err(bad("non-finite or non-positive numbers"));
            }
            let lambda = vs.pop().unwrap_or_default();
            let qdd = vs.pop().unwrap_or_default();
            let v = vs.pop().unwrap_or_default();
            let q = vs.pop().unwrap_or_default();
            Some(MatrixPoint {
                q,
                v,
                qdd,
                lambda,
                t,
                h,
            })
        } else {
            None
        };
        let theta = if flag(r)? {
            let theta = r.f64()?;
            if !(0.0..1.0).contains(&theta) {
                return Err(bad("contraction rate outside [0, 1)"));
            }
            Some(theta)
        } else {
            None
        };
        let since = r.u32()?;
        let grid = if flag(r)? {
            let anchor = r.f64()?;
            if !anchor.is_finite() {
                return Err(bad("non-finite grid anchor"));
            }
            Some((anchor, r.u64()?))
        } else {
            None
        };
        let count = r.u8()? as usize;
        if count > generalized_alpha::RECENT {
            return Err(bad("too many remembered step errors"));
        }
        let mut recent = Vec::with_capacity(count);
        for _ in 0..count {
            let e = r.f64()?;
            if !(e.is_finite() && e >= 0.0) {
                return Err(bad("step error not a finite non-negative number"));
            }
            recent.push(e);
        }
        let cap = if flag(r)? {
            let cap = r.f64()?;
            if !(cap.is_finite() && cap > 0.0) {
                return Err(bad("step cap not a finite positive number"));
            }
            Some((cap, r.u32()?))
        } else {
            None
        };
        let noise = r.f64()?;
        if !(noise.is_finite() && noise >= 0.0) {
            return Err(bad("noise level not a finite non-negative number"));
        }
        let count = r.u8()? as usize;
        if count > generalized_alpha::HISTORY {
            return Err(bad("too many remembered points"));
        }
        let mut history: Vec<(f64, nalgebra::DVector<f64>)> = Vec::with_capacity(count);
        for _ in 0..count {
            let t = r.f64()?;
            let q = nalgebra::DVector::from_vec(r.vec()?);
            let ordered = history
                .last()
                .is_none_or(|(t0, q0)| *t0 < t && q0.len() == q.len());
            if !(t.is_finite() && ordered && q.iter().all(|x| x.is_finite())) {
                return Err(bad(
                    "remembered points not finite, in order and of one length",
                ));
            }
            history.push((t, q));
        }
        Ok(Memory {
            point,
            contraction: newton::Contraction::measured(theta, since),
            grid,
            controller: Controller { recent, cap },
            noise,
            history,
        })
    }
}
