//! Errors of the engine, carrying the numbers that explain them. The FMI layer maps each to a
//! status in one place ([`EngineError::is_discard`]).

use crate::scene::SceneError;
use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum EngineError {
    /// Boxed: a refusal carries four texts, and every step's `Result` would carry their size.
    #[error(transparent)]
    Scene(Box<SceneError>),
    #[error("initial state: {message}")]
    InitialState { message: String },
    #[error(
        "the mechanism cannot be assembled at t = {t} s: constraint residual {residual:.3e} \
         of joint(s) {joints} stays above {tolerance:.1e} after {iterations} iterations"
    )]
    Assembly {
        t: f64,
        residual: f64,
        joints: String,
        tolerance: f64,
        iterations: usize,
    },
    #[error(
        "Newton iteration did not converge at t = {t} s with step {h:.3e} s: {iterations} \
         iterations, last correction {correction:.3e} (1 = tolerance)"
    )]
    NewtonNotConverged {
        t: f64,
        h: f64,
        iterations: usize,
        correction: f64,
    },
    #[error("the iteration matrix is singular at t = {t} s (step {h:.3e} s)")]
    SingularMatrix { t: f64, h: f64 },
    #[error("the state became non-finite (NaN or infinite) at t = {t} s")]
    NonFinite { t: f64 },
    #[error(
        "the step size fell to {h:.3e} s at t = {t} s, below the minimum {h_min:.3e} s: \
         the solution is not resolvable at tolerance {tolerance:.1e}"
    )]
    StepTooSmall {
        t: f64,
        h: f64,
        h_min: f64,
        tolerance: f64,
    },
    #[error(
        "beam '{beam}': deflection {deflection:.3e} m of a floating frame exceeds the frame's \
         length {length} m at t = {t} s: the solution has run away (a linear frame spun near or \
         above its first bending frequency softens without bound); use (more) substructures or \
         geometric_stiffening"
    )]
    Runaway {
        beam: String,
        t: f64,
        deflection: f64,
        length: f64,
    },
    #[error(
        "beam '{beam}': its tip is {chord:.4} m from its root at t = {t} s, more than 1 % beyond \
         its length {length} m: the linear frames have stretched, the model is out of its range \
         (more substructures, or geometric_stiffening for a spinning beam)"
    )]
    Stretched {
        beam: String,
        t: f64,
        chord: f64,
        length: f64,
    },
    #[error("unknown value reference {vr} for a variable of type {ty}")]
    UnknownValueReference { vr: u32, ty: &'static str },
    #[error("variable '{name}' cannot be set now: {reason}")]
    NotSettable { name: String, reason: String },
    #[error("variable '{name}': value {value} is not a finite number")]
    NonFiniteValue { name: String, value: f64 },
    #[error("variable '{name}': value {value} is not allowed: {rule}")]
    InvalidValue {
        name: String,
        value: f64,
        rule: String,
    },
    #[error("doStep: {message}")]
    BadStep { message: String },
    #[error("FMU state: {message}")]
    BadState { message: String },
    #[error(
        "{role} value reference {vr}{}: {reason}",
        .name.as_ref().map(|n| format!(" ('{n}')")).unwrap_or_default()
    )]
    DirectionalDerivative {
        vr: u32,
        role: &'static str,
        name: Option<String>,
        reason: String,
    },
    #[error(
        "the accelerations at t = {t} s are not determined by the inputs: [[M, G^T], [G, 0]] is \
         singular (a body without mass or inertia that the joints do not hold)"
    )]
    FeedthroughSingular { t: f64 },
}

impl EngineError {
    /// True for failures of a step that the master may retry with a smaller one
    /// (fmi2Discard); all others are errors of use or of input (fmi2Error).
    pub fn is_discard(&self) -> bool {
        matches!(
            self,
            EngineError::NewtonNotConverged { .. }
                | EngineError::SingularMatrix { .. }
                | EngineError::NonFinite { .. }
                | EngineError::StepTooSmall { .. }
                | EngineError::Runaway { .. }
                | EngineError::Stretched { .. }
        )
    }
}

impl From<SceneError> for EngineError {
    fn from(e: SceneError) -> Self {
        EngineError::Scene(Box::new(e))
    }
}
