//! What a study is asked (`Options`, checked before any run) and why it cannot run
//! (`AccuracyError`, with the option and the rule it breaks).

use thiserror::Error;

/// Why a study cannot run.
#[derive(Debug, Error)]
pub enum AccuracyError {
    #[error(
        "--output {name}: the scene's unit has no real variable of that name (it has: {})",
        .available.join(", ")
    )]
    UnknownOutput {
        name: String,
        available: Vec<String>,
    },
    #[error("--output: give at least one output to study (e.g. --output beam.tip.deflection)")]
    NoOutput,
    #[error("--{name} {value}: {rule}")]
    BadOption {
        name: &'static str,
        value: String,
        rule: &'static str,
    },
    #[error("--reference {path}: {message}")]
    Reference { path: String, message: String },
    #[error("the study was interrupted")]
    Interrupted,
    #[error(
        "the study's wall-clock safety stop ({seconds:e} s) fired before any run of its time \
         ladder ended: raise --max-seconds"
    )]
    Stopped { seconds: f64 },
    #[error(
        "no run of the time ladder succeeded (coarsest step {step:e} s; first failure: {first}); \
         try a smaller --step"
    )]
    NothingRan { step: f64, first: String },
}

/// The most runs run at once.
pub const MAX_JOBS: usize = 256;

/// What the user asks of a study.
#[derive(Debug, Clone)]
pub struct Options {
    pub outputs: Vec<String>,
    /// The largest error accepted (the study's norm, relative to each output's peak).
    pub target: f64,
    /// [default: the scene's experiment]
    pub stop: Option<f64>,
    /// The grid the outputs are compared on [default: the experiment's step_size].
    pub comm: Option<f64>,
    /// The time ladder's coarsest step [default: the larger of the communication step and the
    /// scene's max_step].
    pub step: Option<f64>,
    /// Newton's tolerance at the coarsest step [default: the smaller of the scene's tolerance
    /// and target / 10].
    pub newton: Option<f64>,
    /// Steps in the time ladder.
    pub levels: usize,
    /// Meshes in the mesh ladder (the scene's, then each doubled).
    pub mesh_levels: usize,
    /// The study's own budget: runs, and counted work ([`super::cost`]: about a CPU second a
    /// unit where its weights were fitted); both studies where it is re-centred.
    pub max_runs: usize,
    pub max_work: f64,
    /// A safety stop in wall seconds: where it fires the study ends INCOMPLETE (said in its
    /// report; its choice is then that of the runs before the stop).
    pub max_seconds: f64,
    /// Runs run at once [default: every core]; the choice and every figure but the seconds
    /// are those of one at a time.
    pub jobs: Option<usize>,
    /// A reference CSV and its column for each output: each run's true error is reported.
    pub reference: Option<(std::path::PathBuf, Vec<String>)>,
    /// The reference's values instead of a file: per output, on the study's grid ([`super::grid`]).
    pub reference_values: Option<Vec<Vec<f64>>>,
    /// Draw a progress bar on standard error (when it is a terminal).
    pub progress: bool,
    /// Run the study again at another mesh where that may be cheaper (`study`'s `recentred`).
    pub recentre: bool,
}

/// The counted budget's default: C2's tip deflection at 1e-3 spends about 200 (both studies).
pub const DEFAULT_MAX_WORK: f64 = 600.0;

/// The wall-clock safety stop's default (s).
pub const DEFAULT_MAX_SECONDS: f64 = 3600.0;

impl Options {
    /// The runs run at once: `jobs`, else every core.
    pub fn jobs(&self) -> usize {
        self.jobs.unwrap_or_else(|| {
            std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
        })
    }

    /// The defaults, for `outputs` and `target`.
    pub fn new(outputs: Vec<String>, target: f64) -> Options {
        Options {
            outputs,
            target,
            stop: None,
            comm: None,
            step: None,
            newton: None,
            levels: 5,
            mesh_levels: 3,
            max_runs: 60,
            max_work: DEFAULT_MAX_WORK,
            max_seconds: DEFAULT_MAX_SECONDS,
            jobs: None,
            reference: None,
            reference_values: None,
            progress: false,
            recentre: true,
        }
    }

    /// Refuses options no study can run with (before anything runs).
    pub fn check(&self) -> Result<(), AccuracyError> {
        let bad = |name, value: String, rule| Err(AccuracyError::BadOption { name, value, rule });
        if self.outputs.is_empty() {
            return Err(AccuracyError::NoOutput);
        }
        if !(self.target > 0.0 && self.target < 1.0) {
            return bad(
                "target",
                self.target.to_string(),
                "the error target must be above 0 and below 1 (relative to each output's peak)",
            );
        }
        for (name, v) in [
            ("stop", self.stop),
            ("comm", self.comm),
            ("step", self.step),
            ("newton", self.newton),
        ] {
            if let Some(v) = v {
                if !(v.is_finite() && v > 0.0) {
                    return bad(name, v.to_string(), "must be a positive number");
                }
            }
        }
        if let Some((p, cols)) = &self.reference {
            if cols.len() != self.outputs.len() {
                return Err(AccuracyError::Reference {
                    path: p.display().to_string(),
                    message: format!(
                        "give one --column per --output ({} outputs, {} columns)",
                        self.outputs.len(),
                        cols.len()
                    ),
                });
            }
        }
        if !(2..=12).contains(&self.levels) {
            return bad(
                "levels",
                self.levels.to_string(),
                "the time ladder needs 2 to 12 steps (3 or more to observe its order)",
            );
        }
        if !(1..=6).contains(&self.mesh_levels) {
            return bad(
                "mesh-levels",
                self.mesh_levels.to_string(),
                "1 (the scene's mesh only) to 6 meshes",
            );
        }
        if self.max_runs < 2 {
            return bad("max-runs", self.max_runs.to_string(), "at least 2 runs");
        }
        if self.max_work.is_nan() || self.max_work <= 0.0 {
            return bad(
                "max-work",
                self.max_work.to_string(),
                "must be a positive amount of counted work",
            );
        }
        if self.jobs == Some(0) || self.jobs.is_some_and(|j| j > MAX_JOBS) {
            return bad(
                "jobs",
                self.jobs.unwrap_or(0).to_string(),
                "1 (one run at a time) to 256 runs at once",
            );
        }
        if self.max_seconds.is_nan() || self.max_seconds <= 0.0 {
            return bad(
                "max-seconds",
                self.max_seconds.to_string(),
                "must be a positive number of seconds",
            );
        }
        Ok(())
    }
}
