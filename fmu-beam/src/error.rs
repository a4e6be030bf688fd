//! Errors of the engine, carrying the numbers that explain them. The FMI layer maps each to a
//! status in one place ([`EngineError::is_discard`]).

use crate::scene::{SceneError, Short};
use thiserror::Error;

/// Why the engine refused a call or a step; [`EngineError::is_discard`] tells a step the master
/// may retry (fmi2Discard) from an error of use or input (fmi2Error).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum EngineError {
    /// Boxed: a refusal carries four texts, and every step's `Result` would carry their size.
    #[error(transparent)]
    Scene(Box<SceneError>),
    /// The initial state cannot be built: redundant constraints, or a mass matrix singular on
    /// the motions the joints leave free.
    #[error("initial state: {message}")]
    InitialState {
        /// What is wrong, with the joints or the time concerned.
        message: String,
    },
    /// The modes cannot be computed as asked: an unknown or unlockable joint, no hub to spin,
    /// a spinning state that is not steady, or no steady state found.
    #[error("modes: {message}")]
    Modes {
        /// What is wrong, naming the joint or the figure concerned.
        message: String,
    },
    #[error(
        "the mechanism cannot be assembled at t = {t} s: constraint residual {residual:.3e} \
         of joint(s) {joints} stays above {tolerance:.1e} after {iterations} iterations"
    )]
    /// No placement of the bodies closes the joints: the Gauss–Newton assembly on the frame
    /// coordinates did not bring g(q) to zero.
    Assembly {
        /// Time of the assembly (s).
        t: f64,
        /// Largest |gᵢ(q)| left, in its row's unit (m for a position; rad, or 1 for a
        /// quaternion's norm, for an orientation).
        residual: f64,
        /// The joints of the rows still above the tolerance, comma-separated.
        joints: String,
        /// The residual asked for: 10⁻¹² × max(the system's length scale, 1 m).
        tolerance: f64,
        /// Gauss–Newton iterations done.
        iterations: usize,
    },
    #[error(
        "Newton iteration did not converge at t = {t} s with step {h:.3e} s: {iterations} \
         iterations, last correction {correction:.3e} (1 = tolerance)"
    )]
    /// Newton's iteration failed at every step size down to the smallest.
    NewtonNotConverged {
        /// Time at the start of the failed step (s).
        t: f64,
        /// Size of the last step tried (s).
        h: f64,
        /// Newton iterations of that step.
        iterations: usize,
        /// Weighted norm of its last correction, in units of the tolerance (1 = tolerance).
        correction: f64,
    },
    #[error("the iteration matrix is singular at t = {t} s (step {h:.3e} s)")]
    /// The iteration matrix is singular: in a step, at every size down to the smallest; or at
    /// a jump of a law, where the jump of the accelerations is solved for.
    SingularMatrix {
        /// Time at the start of the failed step, or of the jump (s).
        t: f64,
        /// Size of the last step tried, or of the step that met the jump (s).
        h: f64,
    },
    #[error("the state became non-finite (NaN or infinite) at t = {t} s")]
    /// Newton's iterate became NaN or infinite, down to the smallest step.
    NonFinite {
        /// Time at the start of the failed step (s).
        t: f64,
    },
    #[error(
        "the step size fell to {h:.3e} s at t = {t} s, below the minimum {h_min:.3e} s: \
         the solution is not resolvable at tolerance {tolerance:.1e}"
    )]
    /// The step size fell below the smallest the stepper takes (or a step rounded away).
    StepTooSmall {
        /// Time at the start of the refused step (s).
        t: f64,
        /// The step size refused, or the one that was to be tried next (s).
        h: f64,
        /// The smallest step: 10⁻¹² × max(|end time|, 1 s) (s).
        h_min: f64,
        /// The solver's relative tolerance (1), `solver.tolerance`.
        tolerance: f64,
    },
    #[error(
        "doStep: the work budget of one communication step is spent: {work} work units (Newton \
         iterations times unknowns, factorizations times the matrix's stored entries; solver.step_budget = \
         {budget}, a few seconds of work, documented in docs/robustness.md) in {attempts} \
         internal steps between t = {} s and t = {} s, without reaching t = {} s; the last good \
         state is kept (a shorter communication step, or a scene whose forces and solver \
         settings make sense, goes on)",
        Short(*.t_start),
        Short(*.t),
        Short(*.t_end)
    )]
    /// One communication step took more work than the work budget allows.
    WorkBudget {
        /// Where the communication step started (s).
        t_start: f64,
        /// Where the integrator was when the budget ran out (s).
        t: f64,
        /// Where the communication step was to end (s).
        t_end: f64,
        /// Internal steps tried (accepted and refused).
        attempts: u64,
        /// The work done, in `integrator::work_units`.
        work: u64,
        /// The budget: `solver.step_budget`.
        budget: u64,
    },
    #[error(
        "beam '{beam}': deflection {deflection:.3e} m of a floating frame exceeds the frame's \
         length {length} m at t = {t} s: the solution has run away"
    )]
    /// A floating frame's transverse deflection exceeds its length: the linear model has run
    /// away.
    Runaway {
        /// Name of the floating frame: the beam's, or that of one of its substructures.
        beam: String,
        /// Time at which the deflection was seen (s).
        t: f64,
        /// The frame's largest transverse deflection (m).
        deflection: f64,
        /// The frame's length (m).
        length: f64,
    },
    #[error(
        "beam '{beam}': its tip is {chord:.4} m from its root at t = {t} s, more than 1 % beyond \
         its length {length} m: the linear frames have stretched, the model is out of its range"
    )]
    /// A beam's chord (root to tip) is more than 1 % longer than the beam.
    Stretched {
        /// Name of the beam in the scene.
        beam: String,
        /// Time at which the chord was measured (s).
        t: f64,
        /// Distance from the beam's root to its tip (m).
        chord: f64,
        /// The beam's length (m).
        length: f64,
    },
    #[error("{cause}. {diagnosis}")]
    /// A failed step with what the unit found of its cause (`unit::engine::diagnosis`): an
    /// input on a small effective inertia at the communication step in use, a frame spun near
    /// its first bending frequency, a runaway deflection, or none of them.
    Diagnosed {
        /// The failure as the integrator or the validity monitor reported it.
        cause: Box<EngineError>,
        /// The causes checked that hold, with their figures and what to change.
        diagnosis: String,
    },
    #[error("unknown value reference {vr} for a variable of type {ty}")]
    /// No variable of this type has this value reference.
    UnknownValueReference {
        /// The FMI value reference asked for.
        vr: u32,
        /// The type of the get or set call: "Real", "Integer" or "Boolean".
        ty: &'static str,
    },
    #[error("variable '{name}' cannot be set now: {reason}")]
    /// The variable exists but may not be set now (not a parameter or input, or a fixed
    /// parameter after initialization).
    NotSettable {
        /// The variable's name in the model description.
        name: String,
        /// Why it cannot be set.
        reason: String,
    },
    #[error("variable '{name}': value {} is not a finite number", Short(*.value))]
    /// A value set was NaN or infinite.
    NonFiniteValue {
        /// The variable's name in the model description.
        name: String,
        /// The value refused, in the variable's unit.
        value: f64,
    },
    #[error("variable '{name}': value {} is not allowed: {rule}", Short(*.value))]
    /// A finite value that the scene's rules refuse (or an input derivative order other
    /// than 1 or 2).
    InvalidValue {
        /// The variable's name in the model description.
        name: String,
        /// The value refused, in the variable's unit (the order, for an input derivative).
        value: f64,
        /// The rule it breaks, as the scene's validation states it.
        rule: String,
    },
    #[error(
        "{what}: the unit needs about {mebibytes} MiB of memory and the process cannot have it \
         (reserving it failed: a limit on the address space, strict commit accounting, or too \
         little memory); make the scene smaller (fewer elements or substructures) or raise the limit"
    )]
    /// The memory the scene's unit will hold could not be reserved before building it
    /// (`unit::memory`): refused instead of aborting the process later.
    OutOfMemory {
        /// The call that needed it.
        what: &'static str,
        /// What was asked for, with headroom (MiB).
        mebibytes: u64,
    },
    #[error("doStep: {message}")]
    /// A doStep call the instance cannot take: not initialized, a step size not positive and
    /// finite, or a communication point other than the instance's time.
    BadStep {
        /// Which, with the numbers.
        message: String,
    },
    #[error("fmi2SetupExperiment: {message}")]
    /// Times fmi2SetupExperiment cannot take: a start time that is not finite or at which the
    /// solver's steps are below the time resolution, a stop time not finite or before it.
    Experiment {
        /// Which, with the numbers.
        message: String,
    },
    #[error("FMU state: {message}")]
    /// A serialized FMU state that cannot be read back (truncated, inconsistent, non-finite).
    BadState {
        /// What is wrong with the bytes.
        message: String,
    },
    #[error(
        "{role} value reference {vr}{}: {reason}",
        .name.as_ref().map(|n| format!(" ('{n}')")).unwrap_or_default()
    )]
    /// A directional-derivative request names a reference that is not a Real output (an
    /// unknown) or a Real input (a known).
    DirectionalDerivative {
        /// The value reference refused.
        vr: u32,
        /// Its role in the request: "unknown" or "known".
        role: &'static str,
        /// The variable's name, when a variable has this reference.
        name: Option<String>,
        /// Why it is refused.
        reason: String,
    },
    #[error(
        "the accelerations at t = {t} s are not determined by the inputs: [[M, G^T], [G, 0]] is \
         singular (a body without mass or inertia that the joints do not hold)"
    )]
    /// [[M, Gᵀ], [G, 0]] is singular: the inputs do not determine the accelerations, so the
    /// outputs' feedthrough (consistent accelerations, directional derivatives) is undefined.
    FeedthroughSingular {
        /// Time of the state at which the matrix was factorized (s).
        t: f64,
    },
}

impl EngineError {
    /// True for failures of a step that the master may retry with a smaller one
    /// (fmi2Discard); all others are errors of use or of input (fmi2Error).
    pub fn is_discard(&self) -> bool {
        if let EngineError::Diagnosed { cause, .. } = self {
            return cause.is_discard();
        }
        matches!(
            self,
            EngineError::NewtonNotConverged { .. }
                | EngineError::SingularMatrix { .. }
                | EngineError::NonFinite { .. }
                | EngineError::StepTooSmall { .. }
                | EngineError::WorkBudget { .. }
                | EngineError::Runaway { .. }
                | EngineError::Stretched { .. }
        )
    }
}

impl EngineError {
    /// True for the failures after which no step from the last good state can succeed: the
    /// validity monitor found the model out of its range (a frame that ran away, a beam
    /// stretched). A smaller step only reaches the same end sooner, so the unit asks the master
    /// to end the simulation (fmi2Terminated) instead of inviting a retry.
    pub fn ends_run(&self) -> bool {
        matches!(
            self.cause(),
            EngineError::Runaway { .. } | EngineError::Stretched { .. }
        )
    }
}

impl EngineError {
    /// True for a refused request (an unknown value reference, a value or a call the unit does
    /// not take): the FMI layers return an error status and leave the instance as it was.
    pub fn is_refusal(&self) -> bool {
        matches!(
            self,
            EngineError::UnknownValueReference { .. }
                | EngineError::NotSettable { .. }
                | EngineError::NonFiniteValue { .. }
                | EngineError::InvalidValue { .. }
                | EngineError::BadStep { .. }
                | EngineError::BadState { .. }
                | EngineError::Experiment { .. }
                | EngineError::DirectionalDerivative { .. }
                | EngineError::FeedthroughSingular { .. }
        )
    }
}

impl EngineError {
    /// The failure itself, without the diagnosis a failed step carries.
    pub fn cause(&self) -> &EngineError {
        match self {
            EngineError::Diagnosed { cause, .. } => cause,
            e => e,
        }
    }
}

impl EngineError {
    /// The same error of the system or the integrator with its times counted from absolute
    /// time 0 rather than from the run's start `origin` (their time 0,
    /// `Mechanics::set_time_origin`); the engine's own errors (the validity monitor's) are in
    /// absolute time already.
    pub fn at_origin(self, origin: f64) -> EngineError {
        use EngineError as E;
        if origin == 0.0 {
            return self;
        }
        match self {
            E::Assembly {
                t,
                residual,
                joints,
                tolerance,
                iterations,
            } => E::Assembly {
                t: origin + t,
                residual,
                joints,
                tolerance,
                iterations,
            },
            E::NewtonNotConverged {
                t,
                h,
                iterations,
                correction,
            } => E::NewtonNotConverged {
                t: origin + t,
                h,
                iterations,
                correction,
            },
            E::SingularMatrix { t, h } => E::SingularMatrix { t: origin + t, h },
            E::NonFinite { t } => E::NonFinite { t: origin + t },
            E::StepTooSmall {
                t,
                h,
                h_min,
                tolerance,
            } => E::StepTooSmall {
                t: origin + t,
                h,
                h_min,
                tolerance,
            },
            E::WorkBudget {
                t_start,
                t,
                t_end,
                attempts,
                work,
                budget,
            } => E::WorkBudget {
                t_start: origin + t_start,
                t: origin + t,
                t_end: origin + t_end,
                attempts,
                work,
                budget,
            },
            E::FeedthroughSingular { t } => E::FeedthroughSingular { t: origin + t },
            E::Diagnosed { cause, diagnosis } => E::Diagnosed {
                cause: Box::new(cause.at_origin(origin)),
                diagnosis,
            },
            e => e,
        }
    }
}

impl From<SceneError> for EngineError {
    fn from(e: SceneError) -> Self {
        EngineError::Scene(Box::new(e))
    }
}
