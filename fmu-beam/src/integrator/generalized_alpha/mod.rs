//! Generalized-α for index-3 constrained mechanical systems, with Newton iterations on the
//! position correction, scaling of the iteration matrix, and local error control.
//!
//! Here: the state, the coefficients, the [`Stepper`] and its step loop ([`Stepper::advance`]:
//! landing on communication points and law jumps, splits, retries). Over 600 lines because
//! `advance` is one method of about 200 lines: the loop reads as one. One step's Newton iterations are in `newton_step`, the error
//! estimate and the step-size controller in `error_control`.
//!
//! # References
//! - J. Chung, G. M. Hulbert (1993), A time integration algorithm for structural dynamics with
//!   improved numerical dissipation: the generalized-α method. J. Appl. Mech. 60, 371–375.
//! - M. Arnold, O. Brüls (2007), Convergence of the generalized-α scheme for constrained
//!   mechanical systems. Multibody Syst. Dyn. 18, 185–202.
//! - M. Géradin, A. Cardona (2001), Flexible Multibody Dynamics, §11 (error estimate
//!   h²(β - 1/6)(a_{n+1} - a_n)).

use super::initial::{self, Equated};
use super::iteration_matrix::{IterationMatrix, LinearSolver, Scaling};
use super::newton::{Contraction, Verdict, AFTER_REFRESH, KAPPA, STALE, STALE_TURNED};
use super::{Settings, Stats};
use crate::error::EngineError;
use crate::mechanics::multibody::{CoordinateKind, Equations, JacobianRows, Point, Turning};
use nalgebra::DVector;

mod error_control;
mod newton_step;
mod restored;

pub(crate) use restored::within;

pub use error_control::Controller;

/// The integration state at a step boundary.
#[derive(Debug, PartialEq)]
pub struct GaState {
    /// Time (s).
    pub t: f64,
    /// Proposed size of the next internal step (adaptive mode).
    pub h: f64,
    /// Generalized coordinates q: each body's frame position and orientation, then its
    /// elastic coordinates.
    pub q: DVector<f64>,
    /// Velocities q'.
    pub v: DVector<f64>,
    /// Algorithmic acceleration a of the generalized-α scheme.
    pub acc: DVector<f64>,
    /// True acceleration q''.
    pub qdd: DVector<f64>,
    /// Lagrange multipliers λ, one per constraint row: the reactions Gᵀλ in
    /// M q'' + Gᵀλ = Q.
    pub lambda: DVector<f64>,
    /// Work done by drives and loads since the start (J), trapezoidal in time.
    pub work: f64,
}

impl Clone for GaState {
    fn clone(&self) -> GaState {
        GaState {
            t: self.t,
            h: self.h,
            q: self.q.clone(),
            v: self.v.clone(),
            acc: self.acc.clone(),
            qdd: self.qdd.clone(),
            lambda: self.lambda.clone(),
            work: self.work,
        }
    }

    /// Copies into the vectors already there (no allocation per communication step).
    fn clone_from(&mut self, o: &GaState) {
        self.t = o.t;
        self.h = o.h;
        copy_vector(&mut self.q, &o.q);
        copy_vector(&mut self.v, &o.v);
        copy_vector(&mut self.acc, &o.acc);
        copy_vector(&mut self.qdd, &o.qdd);
        copy_vector(&mut self.lambda, &o.lambda);
        self.work = o.work;
    }
}

/// Copies `src` into `dst`'s storage where their lengths agree, else clones it: nalgebra's
/// `clone_from` is its derived default, a new allocation each time.
fn copy_vector(dst: &mut DVector<f64>, src: &DVector<f64>) {
    if dst.len() == src.len() {
        dst.copy_from(src);
    } else {
        *dst = src.clone();
    }
}

/// Coefficients of the scheme for a spectral radius at infinity ρ∞.
#[derive(Debug, Clone, Copy)]
struct Coefficients {
    alpha_m: f64,
    alpha_f: f64,
    gamma: f64,
    beta: f64,
}

impl Coefficients {
    fn new(rho_inf: f64) -> Coefficients {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        Coefficients {
            alpha_m,
            alpha_f,
            gamma,
            beta,
        }
    }

    /// The blocks' coefficients of the scaled iteration matrix at step h: the residual rows
    /// times d = βh², so d K_t + β' d M + γ' d C_t with β' = (1 − α_m)/(βh²(1 − α_f)) and
    /// γ' = γ/(βh).
    fn scaling(&self, h: f64) -> Scaling {
        let d = self.beta * h * h;
        let beta_p = (1.0 - self.alpha_m) / (d * (1.0 - self.alpha_f));
        let gamma_p = self.gamma / (self.beta * h);
        Scaling {
            d,
            cm: beta_p * d,
            cc: gamma_p * d,
        }
    }
}

/// The scaling of the iteration matrix for spectral radius ρ∞ and step h (what
/// [`Stepper`] factorizes; for timing the factorization alone).
pub fn iteration_scaling(rho_inf: f64, h: f64) -> Scaling {
    Coefficients::new(rho_inf).scaling(h)
}

/// How a start or a jump of the applied forces or motions is met before a step of about h
/// ([`initial::meet_jump`]): through the iteration matrix of that step where ρ∞ < 1, through
/// the mass matrix at ρ∞ = 1, where the scheme is the trapezoidal rule, which gives a mode
/// struck at any ωh no energy. The step is rounded to a power of two: only its order matters
/// here, and a master that computes its communication step as a difference of times (the last
/// bit differing from another master's) must not change the run (the split slider-crank under
/// `fmu-harness cosim` and under an fmpy script parted by 1e-8 otherwise, through the error
/// control's step sequence).
pub fn jump_scaling(rho_inf: f64, h: f64) -> Scaling {
    if rho_inf < 1.0 {
        Coefficients::new(rho_inf).scaling(2f64.powi(h.log2().round() as i32))
    } else {
        Scaling::MASS
    }
}

/// Passes of the scheme's filter over a position error that refuses a step
/// ([`Stepper::filtered`]). Measured on C3's elastic crank (`fmu-harness peer`, one timed run
/// each, issue 12 item 5: error-controlled runs against the best fixed step, median): none 2.6,
/// one pass 2.2 (tolerance 1e-5 still took 429 steps), two 0.7–0.8, three 0.9; with two, C2,
/// C3's rigid crank and C4 read within the timing's noise of none (docs/accuracy.md).
const FILTER_PASSES: usize = 2;

const MAX_NEWTON: usize = 16;
/// Refactorizations of the iteration matrix at the current iterate within one step.
const MAX_REFRESH: usize = 2;
/// Absolute part of the error weights, as a fraction of the system's length (or of 1 rad):
/// a coordinate's local error must stay below tol × (|q_i| + ERROR_SCALE × scale_i).
const ERROR_SCALE: f64 = 1.0;
/// A Newton correction of one machine epsilon of the coordinates' size is rounding, whatever
/// the system ([`Memory::noise`] raises the level where the system's own arithmetic is
/// noisier). It was 1e3 ε: at small steps every correction of a reused matrix fell below it,
/// so no step measured the matrix's rate, one matrix served a rigid pendulum for 80 000 steps of
/// 1.25e-5 s while it turned, and its unconverged remainders, all of one sign, added up: a
/// planar double pendulum at ρ∞ = 0.9 was 1.5e-6 m off at 1.25e-5 s and 2e-8 m at 1e-4 s, a
/// 3D rigid pendulum 1.2e-5 rad and 1.5e-6 rad, where the converged runs are 1e-8 and 7.5e-7
/// (issue 12).
const ROUNDING: f64 = f64::EPSILON;
/// A fresh matrix converges quadratically: a correction beyond its first that shrinks by less
/// than this factor, and is at most [`NOISE_SMALL`], is the arithmetic's noise, not the
/// matrix's rate, and sets [`Memory::noise`].
const NOISE_RATIO: f64 = 0.03;
/// Below this size (machine epsilons of the coordinates' size) a fresh matrix's slow
/// correction is noise; above it only one that does not shrink by [`NOISE_STAGNANT`] is: a
/// fresh matrix is not always quadratic (tangents by differences, a first step far from its
/// predictor) and C2's substructured pendulum's first step contracts at 0.3 near 6e3 ε.
const NOISE_SMALL: f64 = 1e2;
/// A fresh matrix's correction that shrinks by less than this is noise at any size up to
/// [`NOISE_CEILING`]: evaluated at the iterate, the matrix cannot do better there.
const NOISE_STAGNANT: f64 = 0.5;
/// The largest noise level learned (machine epsilons): 2.2e-10 of the coordinates. The 3D
/// roll-up's loads and joints have gradients by central differences, whose cancellation is
/// noise of 1e3–1e5 ε once the beam is rolled up. Taken for divergence (a ceiling of 1e2 ε),
/// it cut short 240 steps of the shipped `rollup_3d` (116 under the old floor of 1e3 ε; 8 now)
/// and 8 of `rollup_3d_z` in 3D at 5e-4 s and Newton 1e-10, which moved it 2.4e-6 m off its
/// planar twin (6.7e-8 now).
const NOISE_CEILING: f64 = 1e6;
/// The learned noise level shrinks by this factor at every accepted step (halved in 70), so
/// that a level learned at one state does not hold the floor up at others.
const NOISE_DECAY: f64 = 0.99;
/// Corrections up to this multiple of the learned noise count as rounding.
const NOISE_BAND: f64 = 3.0;
/// Accepted points before a step whose positions the error estimate differences: with the
/// step's end, four points and their third divided difference, q''' (issue 12, item 5).
pub const HISTORY: usize = 3;
/// Largest growth of the step size from one step to the next.
const MAX_GROWTH: f64 = 5.0;
/// The step grows only as far as the largest error of this many accepted steps allows (the
/// newest included). The estimate of an oscillation swings with its phase from step to step;
/// growing on one low value was rejected a step or two later, and each such cycle costs two
/// iteration matrices. Error-controlled runs over the peer sweep (every formulation,
/// tolerances 1e-4 to 1e-7), CPU time over the best fixed step at equal error, median (issue
/// 12): C2 1.15 → 0.90, C3 10.9 → 6.8, C3 rigid crank 2.6 → 1.9, C4 Ω = 10 3.2 → 2.7, C4
/// Ω = 4 1.55 → 1.34.
pub const RECENT: usize = 3;
/// After Newton's iteration diverged with a fresh matrix at step h, the steps stay below
/// `NEWTON_CAP` × h for the next [`NEWTON_CAP_STEPS`] accepted steps: without it, an
/// error-controlled run at a loose tolerance grew back into the failing size at once, and C4
/// Ω = 10 at tolerance 1e-3 failed 949 times in 3591 steps (issue 12).
const NEWTON_CAP: f64 = 0.9;
const NEWTON_CAP_STEPS: u32 = 20;
/// A proposed growth of the step size up to this factor keeps the step size, and with it the
/// factorized iteration matrix (hysteresis).
const KEEP_STEP: f64 = 1.2;
/// Step sizes within this relative difference share an iteration matrix. The scaled matrix is
/// c_m M + γh C + βh² K: its mass part does not depend on h, and where it dominates a matrix of
/// a step 10 % longer or shorter still converges fast (Newton's monitor replaces one that does
/// not). Error-controlled runs at tolerance 1e-6, against rounding-equal steps only (issue 12,
/// fastest of 3 runs): C3 8984 matrices to 6087, 0.86 × the CPU time; C4 Ω = 10 4182 to 2507,
/// 0.88 ×; C2 (5 × 2) 1537 to 1065, 0.95 ×; C4 Ω = 4 1.02 ×.
const SAME_STEP: f64 = 0.1;
/// Newton's error per step relative to the step's increment, in units of the tolerance.
const INCREMENT_SHARE: f64 = 0.001;
/// A fixed step this much shorter than `max_step` (relative) is a split step.
const SPLIT: f64 = 1e-6;
/// A step that ends this close (relative) to a point it must land on lands on it.
const LAND: f64 = 1e-6;
/// A remainder this short (relative to the step) before a landing point takes no implicit step.
const TINY: f64 = 1e-6;

/// Where the factorized iteration matrix was evaluated. The factors are not stored: a restored
/// state factorizes the matrix again at this point, so that it continues bit for bit.
#[derive(Debug, PartialEq)]
pub struct MatrixPoint {
    pub q: DVector<f64>,
    pub v: DVector<f64>,
    pub qdd: DVector<f64>,
    pub lambda: DVector<f64>,
    pub t: f64,
    pub h: f64,
}

/// What the integrator carries from one step to the next beyond the state itself (part of the
/// FMU state): the iteration matrix's point and its measured contraction.
#[derive(Debug, PartialEq, Default)]
pub struct Memory {
    pub point: Option<MatrixPoint>,
    pub contraction: Contraction,
    /// The grid of a fixed-step run: its anchor and the steps taken from it.
    pub grid: Option<(f64, u64)>,
    /// What the step-size controller of an error-controlled run remembers.
    pub controller: Controller,
    /// The rounding noise of this system's Newton corrections, in machine epsilons of the
    /// coordinates' size (weighted norm), as last seen with a fresh matrix and shrunk at each
    /// step since ([`NOISE_DECAY`]); 0 until seen. The corrections of a spinning chain of stiff
    /// substructures (C4) stop shrinking near 10 ε, where a rigid pendulum's go on to 0.1 ε: a
    /// ratio measured in that noise is not the matrix's rate (taken as one, C4 at 5e-3 s
    /// replaced its matrix 253 times instead of 51).
    pub noise: f64,
    /// The last accepted points (t, q) of an error-controlled run since its last restart, the
    /// newest (the current state) last, at most [`HISTORY`]: the local error estimate is the
    /// third divided difference of these and the step's end ([`Stepper::attempt`]).
    pub history: Vec<(f64, DVector<f64>)>,
}

impl Clone for MatrixPoint {
    fn clone(&self) -> MatrixPoint {
        MatrixPoint {
            q: self.q.clone(),
            v: self.v.clone(),
            qdd: self.qdd.clone(),
            lambda: self.lambda.clone(),
            t: self.t,
            h: self.h,
        }
    }

    /// Copies into the vectors already there.
    fn clone_from(&mut self, o: &MatrixPoint) {
        copy_vector(&mut self.q, &o.q);
        copy_vector(&mut self.v, &o.v);
        copy_vector(&mut self.qdd, &o.qdd);
        copy_vector(&mut self.lambda, &o.lambda);
        self.t = o.t;
        self.h = o.h;
    }
}

impl Clone for Memory {
    fn clone(&self) -> Memory {
        Memory {
            point: self.point.clone(),
            contraction: self.contraction,
            grid: self.grid,
            controller: self.controller.clone(),
            noise: self.noise,
            history: self.history.clone(),
        }
    }

    /// Copies into the vectors already there (a unit saves its memory at every communication
    /// step, `Engine::do_step`).
    fn clone_from(&mut self, o: &Memory) {
        // every field named: one added later is not forgotten here
        let Memory {
            point,
            contraction,
            grid,
            controller: Controller { recent, cap },
            noise,
            history,
        } = o;
        self.point.clone_from(point);
        self.contraction = *contraction;
        self.grid = *grid;
        self.controller.recent.clone_from(recent);
        self.controller.cap = *cap;
        self.noise = *noise;
        self.history.truncate(history.len());
        for (mine, theirs) in self.history.iter_mut().zip(history) {
            mine.0 = theirs.0;
            copy_vector(&mut mine.1, &theirs.1);
        }
        let kept = self.history.len();
        self.history.extend_from_slice(&history[kept..]);
    }
}

/// Why a fixed step was cut short.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplitReason {
    /// To land on the end of the communication step (a unit with inputs).
    Landing,
    /// To land on a jump of a drive law.
    Breakpoint,
    /// Newton did not converge at the full step.
    Newton,
}

impl SplitReason {
    pub fn describe(self) -> &'static str {
        match self {
            SplitReason::Landing => {
                "to land on the communication point (the unit's inputs may change there)"
            }
            SplitReason::Breakpoint => "to land on a jump of a drive law",
            SplitReason::Newton => "because Newton's iteration did not converge at the full step",
        }
    }
}

/// The integrator with its workspace. The factorized iteration matrix is reused across
/// Newton iterations, internal steps and communication steps while it converges well.
#[derive(Debug, Clone)]
pub struct Stepper {
    /// The settings in force; change them by [`Stepper::set_settings`], which drops what
    /// depends on them.
    pub settings: Settings,
    /// Error weight scale of each coordinate (length for translations, 1 for angles).
    scale: DVector<f64>,
    /// Coordinates of massless bodies.
    algebraic: Vec<usize>,
    /// The iteration matrix, factorized or not.
    matrix: IterationMatrix,
    memory: Memory,
    /// How the unknowns turn with the whole system, where the equations say.
    turning: Option<Turning>,
    /// The last fixed step cut short: time, size and why (the engine logs it).
    pub last_split: Option<(f64, f64, SplitReason)>,
    // workspace
    /// G at the current iterate (the residual's Gᵀλ).
    gm: JacobianRows,
    r: DVector<f64>,
    g: DVector<f64>,
    rhs: DVector<f64>,
}

/// Why one attempt at a step failed.
enum Failure {
    /// Newton did not converge (with this last correction norm).
    Newton {
        iterations: usize,
        correction: f64,
        fresh: bool,
    },
    Singular,
    NonFinite,
}

impl Stepper {
    /// The integrator for `sys`, its iteration matrix factorized dense or sparse by the
    /// system's size ([`LinearSolver::Auto`]).
    pub fn new<S: Equations + ?Sized>(sys: &S, settings: Settings) -> Stepper {
        Stepper::with_linear_solver(sys, settings, LinearSolver::Auto)
    }

    /// The integrator for `sys` with the iteration matrix factorized as `linear` says.
    pub fn with_linear_solver<S: Equations + ?Sized>(
        sys: &S,
        settings: Settings,
        linear: LinearSolver,
    ) -> Stepper {
        let (n, m) = (sys.n(), sys.m());
        let mut scale = DVector::zeros(n);
        for (k, kind) in sys.coordinate_kinds().into_iter().enumerate() {
            // a body without mass has algebraic coordinates, fixed by the joints: its
            // "acceleration" carries no error information and stays out of the norm
            scale[k] = match kind {
                CoordinateKind::Algebraic => f64::INFINITY,
                CoordinateKind::Angle => 1.0,
                CoordinateKind::Length => sys.length_scale(),
            };
        }
        scale *= ERROR_SCALE;
        let algebraic = (0..n).filter(|&k| scale[k].is_infinite()).collect();
        Stepper {
            settings,
            scale,
            algebraic,
            matrix: IterationMatrix::new(sys, linear),
            memory: Memory::default(),
            turning: sys.turning(),
            last_split: None,
            gm: sys.jacobian_pattern(),
            r: DVector::zeros(n),
            g: DVector::zeros(m),
            rhs: DVector::zeros(n + m),
        }
    }

    /// What the next step inherits besides the state (for the FMU state).
    pub fn memory(&self) -> &Memory {
        &self.memory
    }

    /// Puts back a saved memory: the iteration matrix is factorized again at its point when
    /// the next step needs it.
    pub fn restore_memory(&mut self, memory: Memory) {
        self.matrix.forget();
        self.memory = memory;
    }

    /// New settings (a tunable solver parameter changed): the iteration matrix is dropped.
    pub fn set_settings(&mut self, settings: Settings) {
        if settings != self.settings {
            self.settings = settings;
            self.forget_all();
        }
    }

    /// Drops the iteration matrix (and, as the settings may have changed, the fixed grid and
    /// what the step-size controller remembers).
    fn forget_all(&mut self) {
        self.forget();
        self.memory.grid = None;
        self.memory.controller = Controller::default();
    }

    /// Drops the iteration matrix.
    fn forget(&mut self) {
        self.matrix.forget();
        self.memory.point = None;
        self.memory.contraction.fresh();
    }

    /// The accelerations were made consistent again at the current point (a jump of the
    /// applied forces): the trajectory before it is no history for the error estimate.
    pub fn restarted(&mut self) {
        self.memory.history.clear();
    }

    /// Meets a jump of a drive law at the state's time, before a step of about `h`
    /// ([`initial::meet_jump`]): the accelerations change by what the jump changes (without
    /// this the error order drops to one at the jump), and the trajectory before it is no
    /// history for the error estimate.
    fn meet_jump<S: Equations + ?Sized>(
        &mut self,
        sys: &S,
        st: &mut GaState,
        h: f64,
    ) -> Result<(), EngineError> {
        let before = Equated::at(sys, st, st.t * (1.0 - 1e-13) - 1e-13);
        self.meet_jump_from(sys, st, &before, h)
    }

    /// Meets a jump at the state's time from the equations' values `before` it (an input's
    /// jump: the engine takes them with the inputs the last step ended with).
    pub fn meet_jump_from<S: Equations + ?Sized>(
        &mut self,
        sys: &S,
        st: &mut GaState,
        before: &Equated,
        h: f64,
    ) -> Result<(), EngineError> {
        let after = st.t * (1.0 + 1e-13) + 1e-13;
        let w = jump_scaling(self.settings.rho_inf, h);
        initial::meet_jump(sys, st, before, after, h, w)?;
        self.restarted();
        Ok(())
    }

    /// Integrates `st` to exactly `t_end`, in internal steps.
    pub fn step_to<S: Equations + ?Sized>(
        &mut self,
        sys: &S,
        st: &mut GaState,
        stats: &mut Stats,
        t_end: f64,
    ) -> Result<(), EngineError> {
        self.advance(sys, st, stats, t_end, true).map(|_| ())
    }

    /// Integrates `st` until it reaches `t_end`. With `land` the last step ends exactly on
    /// `t_end`; without, the steps go on as the error control (or the fixed step) has them, and
    /// the last may end past `t_end`: then the state before it is returned, for the caller to
    /// interpolate at `t_end`. Steps always land on the jumps of drive laws.
    ///
    /// Fixed steps lie on a grid, anchor + k·`max_step` (the anchor is the start, or the last
    /// point a step had to land on), so that their times do not drift with rounding. A fixed
    /// step that has to be cut short (to land, or to get Newton to converge) is counted in
    /// `Stats::split` and its reason kept in `last_split`.
    pub fn advance<S: Equations + ?Sized>(
        &mut self,
        sys: &S,
        st: &mut GaState,
        stats: &mut Stats,
        t_end: f64,
        land: bool,
    ) -> Result<Option<GaState>, EngineError> {
        let set = self.settings;
        let h_min = 1e-12 * t_end.abs().max(1.0);
        let mut h_try = self.next_step(st);
        // a fixed step whose Newton iteration failed is covered in smaller steps up to here
        let mut divided_until: Option<f64> = None;
        let breakpoints = sys.breakpoints();
        let mut back = None;
        let reached = |t: f64| {
            if land {
                t >= t_end
            } else {
                t >= t_end - TINY * set.max_step
            }
        };
        let (t_start, mut attempts) = (st.t, 0u64);
        // the work of this call, counted as it is done ([`super::work_units`])
        let unknowns = (sys.n() + sys.m()) as u64;
        let per_factorization = self.matrix.factorization_units();
        let (iterations, factorizations) = (stats.newton_iterations, stats.jacobians);
        let work = |stats: &Stats| {
            super::work_units(
                stats.newton_iterations - iterations,
                stats.jacobians - factorizations,
                unknowns,
                per_factorization,
            )
        };
        while !reached(st.t) {
            let done = work(stats);
            if done >= set.step_budget {
                return Err(EngineError::WorkBudget {
                    t_start,
                    t: st.t,
                    t_end,
                    attempts,
                    work: done,
                    budget: set.step_budget,
                });
            }
            attempts += 1;
            // the next time a step must end on: a jump of a drive law, the end of the
            // communication step when landing, the end of a divided fixed step
            // every jump ahead, however close: one a sliver ahead is met after a Taylor step
            // (below). A unit with inputs lands on the master's communication points, and a
            // master that adds up its steps lands a few ulps short of a law's jump (0.0025 s
            // added 280 times is 0.6999999999999961 s): skipped as within 1e-6 of a step, the
            // jump was never met, and the elastic crank of the split slider-crank went on as if
            // 12 % of one step's torque were left (2.6e-4 J made)
            let bp = breakpoints
                .iter()
                .copied()
                .find(|&b| b > st.t)
                .unwrap_or(f64::INFINITY);
            let mut target = bp;
            // no jump ahead (bp infinite) is never one to land on
            let at_jump = |target: f64| bp.is_finite() && target == bp;
            if land {
                target = target.min(t_end);
            }
            if let Some(d) = divided_until {
                target = target.min(d);
            }
            let remaining = target - st.t;
            let nominal = if set.adaptive {
                h_try.min(set.max_step)
            } else if divided_until.is_some() {
                h_try
            } else {
                // the next point of the grid
                let (anchor, k) = self.memory.grid.unwrap_or((st.t, 0));
                anchor + (k + 1) as f64 * set.max_step - st.t
            };
            // a leftover of rounding, or a sliver before a point to land on, is no implicit
            // step: an explicit Taylor step of that length is exact to its order
            if remaining <= TINY * nominal {
                self.slide(st, target);
                if at_jump(target) {
                    self.meet_jump(sys, st, nominal)?;
                }
                if divided_until.is_some_and(|d| d <= st.t) {
                    divided_until = None;
                    h_try = set.max_step;
                }
                continue;
            }
            let mut h = nominal;
            // the last step lands; the one before shares what is left with it when a sliver
            // would remain
            let last = h >= remaining * (1.0 - LAND);
            if last {
                h = remaining;
            } else if h > 0.5 * remaining {
                h = 0.5 * remaining;
            }
            let t_new = if last { target } else { st.t + h };
            if t_new <= st.t {
                // a step that rounds away would loop forever
                return Err(EngineError::StepTooSmall {
                    t: st.t,
                    h,
                    h_min,
                    tolerance: set.tolerance,
                });
            }
            match self.attempt(sys, st, stats, h, t_new) {
                Ok((new, err)) => {
                    if set.adaptive && err > 1.0 {
                        stats.rejected += 1;
                        h_try = self.memory.controller.rejected(h, err);
                    } else {
                        // the power at the step's start, as the limit from inside the step (a drive law
                        // that stops at t_n acts no more in (t_n, t_n+1])
                        let p0 = sys.power(&st.q, &st.v, &st.lambda, st.t + 1e-9 * h);
                        let p1 = sys.power(&new.q, &new.v, &new.lambda, t_new);
                        let old = std::mem::replace(st, new);
                        st.work = old.work + 0.5 * h * (p0 + p1);
                        st.t = t_new;
                        if set.adaptive {
                            self.remember(old.t, &old.q, st.t, &st.q);
                        }
                        back = Some(old);
                        stats.steps += 1;
                        self.memory.noise *= NOISE_DECAY;
                        if !set.adaptive {
                            // cut short, not a grid step that rounding made shorter (far from
                            // t = 0 the grid's steps differ from max_step by its rounding)
                            let cut = h < nominal || divided_until.is_some();
                            if cut && h < set.max_step * (1.0 - SPLIT) {
                                stats.split += 1;
                                let why = if divided_until.is_some() {
                                    SplitReason::Newton
                                } else if at_jump(target) {
                                    SplitReason::Breakpoint
                                } else {
                                    SplitReason::Landing
                                };
                                self.last_split = Some((st.t, h, why));
                            }
                            match self.memory.grid {
                                Some((anchor, k)) if h == nominal && divided_until.is_none() => {
                                    self.memory.grid = Some((anchor, k + 1))
                                }
                                _ => self.landed(t_new),
                            }
                        }
                        if last && at_jump(target) {
                            self.meet_jump(sys, st, h)?;
                        }
                        if last && divided_until == Some(target) {
                            divided_until = None;
                            h_try = set.max_step;
                        }
                        if set.adaptive {
                            h_try = self.memory.controller.accepted(h, err);
                            // keep the proposal when the step was cut short to land
                            if !last {
                                st.h = h_try;
                            }
                        }
                        continue;
                    }
                }
                Err(Failure::NonFinite) => {
                    stats.rejected += 1;
                    h_try = h * 0.25;
                    if h_try < h_min {
                        return Err(EngineError::NonFinite { t: st.t });
                    }
                }
                Err(Failure::Singular) => {
                    stats.rejected += 1;
                    h_try = h * 0.25;
                    if h_try < h_min {
                        return Err(EngineError::SingularMatrix { t: st.t, h });
                    }
                }
                Err(Failure::Newton {
                    iterations,
                    correction,
                    fresh,
                }) => {
                    if !fresh {
                        // retry once with a new iteration matrix at the same step
                        continue;
                    }
                    stats.rejected += 1;
                    h_try = h * 0.25;
                    if set.adaptive {
                        self.memory.controller.newton_failed(h);
                    }
                    if h_try < h_min {
                        return Err(EngineError::NewtonNotConverged {
                            t: st.t,
                            h,
                            iterations,
                            correction,
                        });
                    }
                }
            }
            if !set.adaptive && divided_until.is_none() {
                divided_until = Some(t_new);
            }
            if h_try < h_min {
                return Err(EngineError::StepTooSmall {
                    t: st.t,
                    h: h_try,
                    h_min,
                    tolerance: set.tolerance,
                });
            }
        }
        // a law's jump a sliver after the end is met now: the communication point is the jump's
        // time to within rounding, and a master that couples this unit computes the next step's
        // inputs from what the unit shows there (met at the start of the next step instead, the
        // split slider-crank at 0.5 ms left its monolithic twin by 1.9e-4 m after the cut-off)
        if let Some(b) = breakpoints
            .iter()
            .copied()
            .find(|&b| b > st.t && b <= st.t + TINY * set.max_step)
        {
            self.slide(st, b);
            self.meet_jump(sys, st, set.max_step)?;
        }
        Ok(back.filter(|_| st.t > t_end))
    }

    /// The size of the next step from `st`: the controller's proposal (at most `max_step`)
    /// under error control, else the fixed step.
    pub fn next_step(&self, st: &GaState) -> f64 {
        if self.settings.adaptive {
            st.h.min(self.settings.max_step)
        } else {
            self.settings.max_step
        }
    }

    /// Takes `st` to `t`, a sliver ahead, by an explicit Taylor step, and lands there.
    fn slide(&mut self, st: &mut GaState, t: f64) {
        taylor(st, t - st.t);
        st.t = t;
        self.landed(t);
    }

    /// A fixed-step run landed on `t` off its grid: the grid goes on from there.
    fn landed(&mut self, t: f64) {
        if !self.settings.adaptive {
            self.memory.grid = Some((t, 0));
        }
    }

    /// Whether the iteration matrix is factorized sparse.
    pub fn is_sparse(&self) -> bool {
        self.matrix.is_sparse()
    }
}

/// An explicit Taylor step of a length far below the step size (a remainder before a point to
/// land on): q += h v + h²/2 q'', v += h q''; accelerations and multipliers kept.
fn taylor(st: &mut GaState, h: f64) {
    st.q.axpy(h, &st.v, 1.0);
    st.q.axpy(0.5 * h * h, &st.qdd, 1.0);
    st.v.axpy(h, &st.qdd, 1.0);
}

/// Turns each (x, y) pair of `x` starting at the given indices by the angle δ.
fn turn_pairs(x: &mut DVector<f64>, pairs: &[usize], delta: f64) {
    let (s, c) = delta.sin_cos();
    // pairs past the end of x (the joint rows, where x holds the coordinates alone) are not in it
    let len = x.len();
    for &i in pairs.iter().filter(|&&i| i + 1 < len) {
        let (a, b) = (x[i], x[i + 1]);
        x[i] = c * a - s * b;
        x[i + 1] = s * a + c * b;
    }
}
