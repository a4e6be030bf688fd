//! Generalized-α for index-3 constrained mechanical systems, with Newton iterations on the
//! position correction, scaling of the iteration matrix, and local error control.
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
use super::newton::{Contraction, Verdict, KAPPA, STALE, STALE_TURNED};
use super::{Settings, Stats};
use crate::error::EngineError;
use crate::mechanics::multibody::{CoordinateKind, Equations, JacobianRows, Turning};
use nalgebra::DVector;

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
        self.q.clone_from(&o.q);
        self.v.clone_from(&o.v);
        self.acc.clone_from(&o.acc);
        self.qdd.clone_from(&o.qdd);
        self.lambda.clone_from(&o.lambda);
        self.work = o.work;
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

/// A step-size factor rounded down to a multiple of 1/64. The factor is a power of the error
/// estimate, and libm's `pow` may round the last bit differently on another platform: rounded,
/// the step sizes (and with them every decision that follows) are the same bit for bit unless
/// the factor lies within a last bit of a multiple.
fn quantized(factor: f64) -> f64 {
    let q = (factor * 64.0).floor() / 64.0;
    if q > 0.0 {
        q
    } else {
        factor
    }
}

/// The factor on the step size after an accepted step whose controller proposes `grow`.
fn step_factor(grow: f64) -> f64 {
    let grow = grow.clamp(0.2, MAX_GROWTH);
    if (1.0..=KEEP_STEP).contains(&grow) {
        1.0
    } else {
        grow
    }
}

/// Where the factorized iteration matrix was evaluated. The factors are not stored: a restored
/// state factorizes the matrix again at this point, so that it continues bit for bit.
#[derive(Debug, Clone, PartialEq)]
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
#[derive(Debug, Clone, PartialEq, Default)]
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

/// The step-size controller's memory.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Controller {
    /// Error norms of the last accepted steps (at most [`RECENT`], the newest last); a rejected
    /// step clears them.
    pub recent: Vec<f64>,
    /// A cap on the step size after Newton's iteration diverged with a fresh matrix, and the
    /// accepted steps it still holds for.
    pub cap: Option<(f64, u32)>,
}

impl Controller {
    /// The step after an accepted one of size `h` and error norm `err`.
    fn accepted(&mut self, h: f64, err: f64) -> f64 {
        if self.recent.len() == RECENT {
            self.recent.remove(0);
        }
        self.recent.push(err);
        let worst = self.recent.iter().copied().fold(0.0, f64::max);
        let grow = if worst > 0.0 {
            0.9 * worst.powf(-1.0 / 3.0)
        } else {
            MAX_GROWTH
        };
        let mut next = h * quantized(step_factor(grow));
        if let Some((cap, left)) = self.cap {
            next = next.min(cap);
            self.cap = (left > 1).then_some((cap, left - 1));
        }
        next
    }

    /// The step after a rejected one of size `h` and error norm `err`.
    fn rejected(&mut self, h: f64, err: f64) -> f64 {
        self.recent.clear();
        h * quantized((0.9 * err.powf(-1.0 / 3.0)).clamp(0.2, 1.0))
    }

    /// Newton's iteration diverged with a fresh matrix at step `h`.
    fn newton_failed(&mut self, h: f64) {
        self.recent.clear();
        self.cap = Some((NEWTON_CAP * h, NEWTON_CAP_STEPS));
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

    /// Appends the end (t1, q1) of an accepted step from (t0, q0) to the history of positions,
    /// which starts again at t0 where it does not end there.
    fn remember(&mut self, t0: f64, q0: &DVector<f64>, t1: f64, q1: &DVector<f64>) {
        let history = &mut self.memory.history;
        if history.last().map(|p| p.0) != Some(t0) {
            history.clear();
            history.push((t0, q0.clone()));
        }
        if history.len() == HISTORY {
            // the oldest point's vector is reused: no allocation per step
            let (_, mut q) = history.remove(0);
            q.copy_from(q1);
            history.push((t1, q));
        } else {
            history.push((t1, q1.clone()));
        }
    }

    /// The local error of a step from `st` to (t1, q1) per coordinate, |β − 1/6| h³ q''', with
    /// q''' from the third divided difference of the positions at the last [`HISTORY`] points
    /// and the step's end. Where the history does not reach back that far (the first two steps
    /// after the start or a restart), the state at the step's start enters as a repeated node
    /// with its velocity (and, at the restart point itself, its acceleration): a cubic through
    /// the positions and derivatives since the restart, none from before it.
    ///
    /// Why positions, not the algorithmic accelerations' change (β − 1/6) h² Δa of Géradin and
    /// Cardona: both estimate the same h³ q''' where the motion is resolved, but a mode of
    /// frequency ω and amplitude A that the step does not resolve (ωh ≫ 1) weighs ω²h²A in
    /// Δa, and at most 8A in a third difference. A load's jump rings every mode of a mesh, each
    /// with an amplitude about its share of the static deflection, 1/ω²: in Δa the mesh's
    /// highest modes lead, and an error-controlled run resolved them at their own time scale.
    /// With positions a mode is resolved only where its amplitude matters at the tolerance,
    /// and ρ∞ damps the rest, as at fixed steps (C3's elastic crank after its torque's cut-off).
    /// The velocity and the acceleration at a restart stay bounded by the positions' scale on
    /// such a mode (h q' and h² q'' of order A: the jump is met through the iteration matrix,
    /// [`initial::meet_jump`]), so the first steps after it are estimated on the same footing.
    fn position_error(
        &self,
        st: &GaState,
        t1: f64,
        q1: &DVector<f64>,
        c: &Coefficients,
    ) -> DVector<f64> {
        let history = self.memory.history.as_slice();
        // the points before the step's start, where the history ends there
        let earlier = match history.split_last() {
            Some((last, rest)) if last.0 == st.t && rest.iter().all(|p| p.1.len() == q1.len()) => {
                rest
            }
            _ => &[],
        };
        let h = t1 - st.t;
        let factor = (c.beta - 1.0 / 6.0).abs() * 6.0 * h * h * h;
        let tc = st.t;
        DVector::from_fn(q1.len(), |k, _| {
            let (qc, q) = (st.q[k], q1[k]);
            factor
                * match earlier {
                    [(ta, a), (tb, b)] => third_difference([*ta, *tb, tc, t1], [a[k], b[k], qc, q]),
                    [(tb, b)] => {
                        third_difference_with_velocity([*tb, tc, t1], [b[k], qc, q], st.v[k])
                    }
                    _ => third_difference_with_acceleration([tc, t1], [qc, q], st.v[k], st.qdd[k]),
                }
        })
    }

    /// Weighted RMS norm of a position-like vector against the tolerance.
    fn norm<'a>(&self, dq: impl Iterator<Item = &'a f64>, q: &DVector<f64>) -> f64 {
        let tol = self.settings.tolerance;
        let n = q.len().max(1) as f64;
        let s: f64 = dq
            .zip(q.iter())
            .zip(self.scale.iter())
            .map(|((d, x), sc)| {
                let w = tol * (x.abs() + sc);
                (d / w) * (d / w)
            })
            .sum();
        (s / n).sqrt()
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
        while !reached(st.t) {
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
                if target == bp {
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
                            if h < set.max_step * (1.0 - SPLIT) {
                                stats.split += 1;
                                let why = if divided_until.is_some() {
                                    SplitReason::Newton
                                } else if target == bp {
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
                        if last && target == bp {
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

    /// Builds and factorizes the scaled iteration matrix at a point.
    #[allow(clippy::too_many_arguments)]
    fn factorize<S: Equations + ?Sized>(
        &mut self,
        sys: &S,
        q: &DVector<f64>,
        v: &DVector<f64>,
        qdd: &DVector<f64>,
        lambda: &DVector<f64>,
        t: f64,
        h: f64,
        c: &Coefficients,
    ) -> bool {
        self.matrix
            .factorize(sys, q, v, qdd, lambda, t, c.scaling(h))
    }

    /// Solves for the Newton correction at iterate `q` in `rhs`. Where the bodies have turned
    /// since the matrix was factorized, by angles δ_b, the matrix is used as if turned by the
    /// middle of their range ([`Turning`]): a matrix of a spinning or swinging system stays a
    /// good one over many steps, and no body's mismatch exceeds what it was unturned.
    fn solve_turned(&mut self, q: &DVector<f64>) -> bool {
        let (Some(delta), Some(turning)) = (self.turned(q), &self.turning) else {
            return self.matrix.solve_mut(&mut self.rhs);
        };
        turn_pairs(&mut self.rhs, &turning.pairs, -delta);
        let solved = self.matrix.solve_mut(&mut self.rhs);
        turn_pairs(&mut self.rhs, &turning.pairs, delta);
        solved
    }

    /// The angle δ by which the matrix is used as turned at iterate `q` (the middle of the
    /// range of the bodies' turns since it was factorized), where it is not zero.
    fn turned(&self, q: &DVector<f64>) -> Option<f64> {
        let (Some(turning), Some(p)) = (&self.turning, &self.memory.point) else {
            return None;
        };
        let (lo, hi) = turning
            .angles
            .iter()
            .map(|&k| q[k] - p.q[k])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| {
                (lo.min(d), hi.max(d))
            });
        // no bodies: ∞ - ∞, not finite
        let delta = 0.5 * (lo + hi);
        (delta != 0.0 && delta.is_finite()).then_some(delta)
    }

    /// The norm of the step's local error: that of the positions' estimate
    /// ([`Stepper::position_error`]), and where it refuses the step under ρ∞ < 1, that of the
    /// estimate filtered by the scheme's damping ([`Stepper::filtered`]) if smaller.
    fn error_norm(&mut self, st: &GaState, t1: f64, q1: &DVector<f64>, c: &Coefficients) -> f64 {
        let e = self.position_error(st, t1, q1, c);
        let raw = self.norm(e.iter(), q1);
        if raw <= 1.0 || self.settings.rho_inf >= 1.0 {
            return raw;
        }
        self.filtered(e, q1)
            .map_or(raw, |f| raw.min(self.norm(f.iter(), q1)))
    }

    /// The position error `e` of a step ending at `q1`, filtered [`FILTER_PASSES`] times by
    /// the step's iteration matrix ([`IterationMatrix::filter`], turned as the Newton
    /// corrections are). With S = c_m M + d K_t + c_c C_t (d = βh², c_m = (1 − α_m)/(1 − α_f))
    /// each pass keeps the motion the step resolves (ωh ≪ 1) and multiplies a mode of
    /// frequency ω by 1/(1 + β'(ωh)²), β' = β(1 − α_f)/(1 − α_m) (0.27 at ρ∞ = 0.7): the
    /// modes generalized-α with ρ∞ < 1 damps instead of following. Their raw estimate stays
    /// up to 8|β − 1/6| × their amplitude however long the step (the third difference of an
    /// oscillation), so a step that lets ρ∞ damp a mode its jump struck, as a fixed step
    /// does, was refused for it while the mode lasted, and steps shrank until they resolved
    /// it: C3's elastic crank at tolerance 1e-5 took 1 368 steps, 1 200 of them after the
    /// torque's cut-off, to end 4.1e-4 off where the fixed 4e-3 s step (400) ends 1.9e-4 off.
    /// Filtered twice, such a mode's estimate falls as (ωh)⁻⁴: 183 steps, 6.9e-4 (issue 12,
    /// item 5; docs/accuracy.md). None when the matrix cannot solve.
    fn filtered(&mut self, mut e: DVector<f64>, q1: &DVector<f64>) -> Option<DVector<f64>> {
        let delta = self.turned(q1);
        if let (Some(d), Some(t)) = (delta, &self.turning) {
            turn_pairs(&mut e, &t.pairs, -d);
        }
        for _ in 0..FILTER_PASSES {
            if !self.matrix.filter(&mut e, &mut self.rhs) {
                return None;
            }
        }
        if let (Some(d), Some(t)) = (delta, &self.turning) {
            turn_pairs(&mut e, &t.pairs, d);
        }
        Some(e)
    }

    /// Whether the iteration matrix is factorized sparse.
    pub fn is_sparse(&self) -> bool {
        self.matrix.is_sparse()
    }

    /// One step of size h from `st`; returns the new state and the local error norm.
    fn attempt<S: Equations + ?Sized>(
        &mut self,
        sys: &S,
        st: &GaState,
        stats: &mut Stats,
        h: f64,
        t_new: f64,
    ) -> Result<(GaState, f64), Failure> {
        let c = Coefficients::new(self.settings.rho_inf);
        let (n, m) = (sys.n(), sys.m());
        let d = c.beta * h * h;
        let beta_p = (1.0 - c.alpha_m) / (d * (1.0 - c.alpha_f));
        let gamma_p = c.gamma / (c.beta * h);
        if self
            .memory
            .point
            .as_ref()
            .is_some_and(|p| (h - p.h).abs() > SAME_STEP * h)
        {
            self.forget();
        }
        // a restored state: the same factors, at the same point
        if !self.matrix.is_factored() {
            if let Some(p) = self.memory.point.take() {
                if !self.factorize(sys, &p.q, &p.v, &p.qdd, &p.lambda, p.t, p.h, &c) {
                    self.forget();
                    return Err(Failure::Singular);
                }
                self.memory.point = Some(p);
            }
        }
        // predictor: q''_{n+1} = q''_n
        let mut qdd = st.qdd.clone();
        let acc_new = (&st.qdd * c.alpha_f - &st.acc * c.alpha_m + &qdd * (1.0 - c.alpha_f))
            / (1.0 - c.alpha_m);
        let mut v = &st.v + &st.acc * (h * (1.0 - c.gamma)) + &acc_new * (h * c.gamma);
        let mut q = &st.q + &st.v * h + &st.acc * (h * h * (0.5 - c.beta)) + &acc_new * d;
        let mut lambda = st.lambda.clone();
        let mut fresh = false;
        let mut prev = f64::INFINITY;
        let mut norm = f64::INFINITY;
        let mut iterations = 0;
        // corrections since the matrix was factorized, and refactorizations within this step
        let (mut k, mut refreshed) = (0, 0);
        let tol = self.settings.tolerance;
        let floor_of = |noise: f64| ROUNDING.max(NOISE_BAND * noise * f64::EPSILON) / tol;
        let mut floor = floor_of(self.memory.noise);
        // Newton's error bound: κ of the tolerance, and at most the tolerance's share of the
        // step's own increment, so that it cannot pile up over many small steps (summed over a
        // run it stays below tol × the path the coordinates travel)
        let increment = self.norm((&q - &st.q).iter(), &q);
        let kappa = KAPPA.min(INCREMENT_SHARE * self.settings.tolerance * increment);
        for it in 0..MAX_NEWTON {
            if !self.matrix.is_factored() {
                if !self.factorize(sys, &q, &v, &qdd, &lambda, t_new, h, &c) {
                    self.forget();
                    return Err(Failure::Singular);
                }
                stats.jacobians += 1;
                // a new matrix: its point, and a rate not yet measured (the grid, the
                // controller and the noise level are the run's, not the matrix's)
                self.memory.point = Some(MatrixPoint {
                    q: q.clone(),
                    v: v.clone(),
                    qdd: qdd.clone(),
                    lambda: lambda.clone(),
                    t: t_new,
                    h,
                });
                self.memory.contraction.fresh();
                fresh = true;
                k = 0;
                prev = f64::INFINITY;
            }
            sys.body_residual(&q, &v, &qdd, t_new, &mut self.r);
            sys.constraints_and_rows(&q, t_new, &mut self.g, &mut self.gm);
            self.gm.add_transpose_times(&lambda, &mut self.r);
            for i in 0..n {
                self.rhs[i] = -d * self.r[i];
            }
            for k in 0..m {
                self.rhs[n + k] = -self.g[k];
            }
            if !self.solve_turned(&q) {
                self.forget();
                return Err(Failure::Singular);
            }
            stats.newton_iterations += 1;
            iterations += 1;
            let dq = self.rhs.rows(0, n);
            q += dq;
            v.axpy(gamma_p, &dq, 1.0);
            qdd.axpy(beta_p, &dq, 1.0);
            for k in 0..m {
                lambda[k] += self.rhs[n + k] / d;
            }
            if !dq.iter().all(|x| x.is_finite()) || !q.iter().all(|x| x.is_finite()) {
                self.forget();
                return Err(Failure::NonFinite);
            }
            norm = self.norm(dq.iter(), &q);
            let ratio = norm / prev;
            let size = norm * tol / f64::EPSILON;
            if fresh
                && k >= 1
                && size <= NOISE_CEILING
                && (ratio > NOISE_STAGNANT || (ratio > NOISE_RATIO && size <= NOISE_SMALL))
            {
                self.memory.noise = size;
                floor = floor_of(self.memory.noise);
            }
            let verdict = self.memory.contraction.judge(
                k,
                norm,
                prev,
                floor,
                MAX_NEWTON - 1 - it,
                kappa,
                fresh,
            );
            k += 1;
            match verdict {
                Verdict::Converged => {
                    let mut acc = (&st.qdd * c.alpha_f - &st.acc * c.alpha_m
                        + &qdd * (1.0 - c.alpha_f))
                        / (1.0 - c.alpha_m);
                    // coordinates of massless bodies are algebraic: their accelerations enter
                    // no equation, and the scheme's recurrence would let them grow without bound
                    for &k in &self.algebraic {
                        acc[k] = 0.0;
                        qdd[k] = 0.0;
                    }
                    let err = if self.settings.adaptive {
                        self.error_norm(st, t_new, &q, &c)
                    } else {
                        0.0
                    };
                    let stale = if self.turning.is_some() {
                        STALE_TURNED
                    } else {
                        STALE
                    };
                    if self.memory.contraction.slow(stale) {
                        self.forget(); // slow: a new matrix for the next step
                    }
                    return Ok((
                        GaState {
                            t: st.t,
                            h: st.h,
                            q,
                            v,
                            acc,
                            qdd,
                            lambda,
                            work: st.work,
                        },
                        err,
                    ));
                }
                Verdict::Continue => {
                    prev = norm;
                    // a matrix that contracts slowly (it was evaluated at a predictor far from
                    // the solution, or steps ago) is evaluated again at the current iterate,
                    // close to the solution: Newton's own quadratic convergence
                    if self.memory.contraction.stalls() && k > 2 && refreshed < MAX_REFRESH {
                        self.matrix.forget();
                        refreshed += 1;
                    }
                }
                Verdict::Diverging => break,
            }
        }
        self.forget();
        Err(Failure::Newton {
            iterations,
            correction: norm,
            fresh,
        })
    }
}

/// The third divided difference q[t0, t1, t2, t3] of four values at increasing times: q'''/6
/// somewhere in [t0, t3] for a smooth q.
fn third_difference(t: [f64; 4], q: [f64; 4]) -> f64 {
    let first = |i: usize, j: usize, a: f64, b: f64| (b - a) / (t[j] - t[i]);
    let (s01, s12, s23) = (
        first(0, 1, q[0], q[1]),
        first(1, 2, q[1], q[2]),
        first(2, 3, q[2], q[3]),
    );
    let (s012, s123) = (first(0, 2, s01, s12), first(1, 3, s12, s23));
    first(0, 3, s012, s123)
}

/// The third divided difference q[t0, t1, t1, t2] of values at three increasing times and the
/// velocity at the middle one.
fn third_difference_with_velocity(t: [f64; 3], q: [f64; 3], v1: f64) -> f64 {
    let s01 = (q[1] - q[0]) / (t[1] - t[0]);
    let s12 = (q[2] - q[1]) / (t[2] - t[1]);
    let (s011, s112) = ((v1 - s01) / (t[1] - t[0]), (s12 - v1) / (t[2] - t[1]));
    (s112 - s011) / (t[2] - t[0])
}

/// The third divided difference q[t0, t0, t0, t1] of values at two times and the velocity and
/// acceleration at the first.
fn third_difference_with_acceleration(t: [f64; 2], q: [f64; 2], v0: f64, a0: f64) -> f64 {
    let h = t[1] - t[0];
    let s001 = ((q[1] - q[0]) / h - v0) / h;
    (s001 - 0.5 * a0) / h
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

/// An explicit Taylor step of a length far below the step size (a remainder before a point to
/// land on): q += h v + h²/2 q'', v += h q''; accelerations and multipliers kept.
fn taylor(st: &mut GaState, h: f64) {
    st.q.axpy(h, &st.v, 1.0);
    st.q.axpy(0.5 * h * h, &st.qdd, 1.0);
    st.v.axpy(h, &st.qdd, 1.0);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One low error among higher ones (an oscillation's estimate at a lucky phase) does not
    /// grow the step; the step grows once the higher ones have left the window.
    #[test]
    fn the_step_grows_on_the_largest_recent_error() {
        let mut c = Controller::default();
        assert_eq!(c.accepted(1.0, 1e-6), MAX_GROWTH);
        let after_high = c.accepted(1.0, 0.9);
        assert!(after_high < 1.0, "{after_high}");
        for _ in 1..RECENT {
            assert_eq!(c.accepted(1.0, 1e-3), after_high);
        }
        assert_eq!(c.accepted(1.0, 1e-3), 9.0f64.min(MAX_GROWTH));
        // a rejection forgets the errors before it
        assert!(c.rejected(1.0, 8.0) < 0.5);
        assert!(c.recent.is_empty());
        assert_eq!(c.accepted(1.0, 1e-6), MAX_GROWTH);
    }

    /// The position-level estimate is exact for a cubic at any step sizes, and bounded by the
    /// amplitude of a mode the steps do not resolve, where the change of the algorithmic
    /// acceleration grows as ω²h².
    #[test]
    fn the_third_difference_finds_a_cubic_and_stays_bounded_on_an_unresolved_mode() {
        let diff = |f: &dyn Fn(f64) -> f64, t: [f64; 4]| third_difference(t, t.map(f));
        // q''' = 9 of a cubic, from unequal steps
        let cubic = |t: f64| 2.0 - t + 0.5 * t * t + 1.5 * t * t * t;
        assert!((6.0 * diff(&cubic, [0.1, 0.13, 0.2, 0.45]) - 9.0).abs() < 1e-11);
        // a mode of amplitude 1 at ωh = 50 over equal steps h: h³ q''' estimated as the third
        // difference of four values within ±1, at most 8, where the acceleration changes by
        // up to 2 ω²h² = 5000
        let (omega, h) = (5e4, 1e-3);
        let t = [0.3, 0.3 + h, 0.3 + 2.0 * h, 0.3 + 3.0 * h];
        let estimate = 6.0 * h * h * h * diff(&|t: f64| (omega * t).cos(), t);
        assert!(estimate.abs() <= 8.0 + 1e-9, "{estimate}");
    }

    /// The first two steps after a restart take the restart point's derivatives as repeated
    /// nodes: both find a cubic's q''' from unequal steps.
    #[test]
    fn the_third_difference_with_derivatives_finds_a_cubic() {
        let q = |t: f64| 2.0 - t + 0.5 * t * t + 1.5 * t * t * t;
        let (v, a) = (|t: f64| -1.0 + t + 4.5 * t * t, |t: f64| 1.0 + 9.0 * t);
        let with_v =
            third_difference_with_velocity([0.1, 0.13, 0.2], [q(0.1), q(0.13), q(0.2)], v(0.13));
        assert!((6.0 * with_v - 9.0).abs() < 1e-10, "{with_v}");
        let with_a =
            third_difference_with_acceleration([0.13, 0.2], [q(0.13), q(0.2)], v(0.13), a(0.13));
        assert!((6.0 * with_a - 9.0).abs() < 1e-10, "{with_a}");
    }

    /// After Newton's iteration diverged at h, the steps stay below 0.9 h for
    /// `NEWTON_CAP_STEPS` accepted steps, and are free after.
    #[test]
    fn a_newton_failure_caps_the_step_for_a_while() {
        let mut c = Controller::default();
        c.newton_failed(1.0);
        let mut h = 0.25;
        for _ in 0..NEWTON_CAP_STEPS {
            h = c.accepted(h, 1e-6);
            assert!(h <= NEWTON_CAP, "{h}");
        }
        assert_eq!(c.cap, None);
        assert!(c.accepted(h, 1e-6) > 1.0);
    }
}
