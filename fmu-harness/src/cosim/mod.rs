//! `fmu-harness cosim system.toml`: several FMI 2.0 or 3.0 co-simulation units (any, not only
//! ours, of either version in one system) coupled output → input, through [`Slave`]. An FMI 3.0
//! unit has no input derivatives: its inputs are held over a step (as a 2.0 unit's without
//! canInterpolateInputs).
//!
//! One communication step from t to t + h:
//! 1. with rollback on, every unit's state is saved (fmi2GetFMUstate);
//! 2. each unit gets its inputs and steps (fmi2DoStep(t, h)): **Jacobi** from the coupling values
//!    at t; **Gauss–Seidel** in `order`, a unit getting the t + h outputs of the units that
//!    stepped before it. An input is held constant over the step (extrapolation `none`, or a unit
//!    without canInterpolateInputs: the value at t, or for Gauss–Seidel the newer value at t + h),
//!    or its value at t is set with the derivatives at t of the polynomial of order 1 (`linear`)
//!    or 2 (`quadratic`) through the last communication points (fmi2SetRealInputDerivatives); for
//!    Gauss–Seidel the polynomial also passes through the t + h value: interpolation;
//! 3. the step is refused if a unit returns fmi2Discard or a `[[rollback.check]]` bound fails:
//!    with rollback every unit is restored and the step halved (at most `max_halvings` times),
//!    without it the run ends with an error naming the unit, t, h and what it logged;
//! 4. variable step: each coupling signal at t + h is compared with its extrapolation from the
//!    communication points before t + h (order p of `extrapolation`); E = max over signals of
//!    |y − ŷ| / (abs_tolerance + tolerance·|y|). The local extrapolation error is O(h^(p+1)), so
//!    the next step is h·clamp(0.9·E^(−1/(p+1)), 0.2, 5), within [min, max]. With rollback, a
//!    step with E > 1 is restored and retried with that step (unless already at min).
//!
//! Before the first step every unit is initialized with its start values, then the coupling
//! values at the start time are read and set (one Jacobi pass).
//!
//! The files follow that order: `setup.rs` (units loaded and initialized, names resolved, the
//! start values), `attempt.rs` (point 2, and the checks of 3), `step_control.rs` (rollback and
//! step size: 3 and 4), `results.rs` (the recorded rows and the [`Summary`]); [`joint`] couples
//! units at joints, [`extrapolation`] keeps each signal's history, [`system`] reads the file.
//! [`run`] holds the loop over communication steps.

mod attempt;
pub mod extrapolation;
pub mod joint;
mod results;
mod setup;
mod step_control;
pub mod system;

pub use results::Summary;

use crate::binding::FmuState;
use crate::simulate::{Results, RowSink, MAX_COMMUNICATION_STEPS};
use crate::slave::{Slave, SlaveError};
use extrapolation::History;
use joint::Joints;
use std::path::{Path, PathBuf};
use system::{Algorithm, RollbackSpec, System, SystemError};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum CosimError {
    #[error(transparent)]
    System(#[from] SystemError),
    /// The units' FMUs would expand to more than a system may (issue 45): refused before any
    /// is extracted.
    #[error(
        "{}: its units' FMUs declare {declared} bytes up to unit `{unit}` ({}); the master \
         extracts at most {limit} bytes for one system",
        .path.display(),
        .fmu.display()
    )]
    TooManyBytes {
        path: PathBuf,
        unit: String,
        fmu: PathBuf,
        declared: u64,
        limit: u64,
    },
    #[error("unit `{unit}` ({}): {source}", .fmu.display())]
    Unit {
        unit: String,
        fmu: PathBuf,
        source: SlaveError,
    },
    #[error("{}: {what} `{name}`: {message}", .path.display())]
    Variable {
        path: PathBuf,
        what: &'static str,
        name: String,
        message: String,
    },
    #[error(
        "unit `{unit}`: rollback needs fmi2GetFMUstate/fmi2SetFMUstate, but its model \
         description has canGetAndSetFMUstate=\"false\" (remove [rollback] or this unit)"
    )]
    NoFmuState { unit: String },
    #[error("at t = {t}, h = {h}: {reason}; the step is not retried ({hint})")]
    StepRefused {
        t: f64,
        h: f64,
        reason: String,
        hint: &'static str,
    },
    #[error(
        "unit `{unit}` cannot take part in joint `{joint}`: joints need \
         providesDirectionalDerivative=\"true\" (its interface mobility) and \
         canGetAndSetFMUstate=\"true\" (the iteration restores the units)"
    )]
    JointUnit { unit: String, joint: String },
    #[error(
        "at t = {t}: the joints' mobility matrix is singular: a joint direction that no unit \
         can move (a frame fixed in both units, or the same direction joined twice)"
    )]
    JointsSingular { t: f64 },
    #[error(
        "at t = {t}: the step was refused {halvings} times, down to h = {h} \
         (rollback.max_halvings = {max}); last: {reason}"
    )]
    RollbackExhausted {
        t: f64,
        h: f64,
        halvings: u32,
        max: u32,
        reason: String,
    },
    #[error(
        "at t = {t}: {steps} communication steps taken; the master takes at most {limit:e} \
         (raise step.variable.min)"
    )]
    TooManySteps { t: f64, steps: u64, limit: f64 },
    #[error("writing the results: {0}")]
    Output(#[source] std::io::Error),
    /// A unit returned fmi2Discard and fmi2Terminated: the run ends at t (not an error of the
    /// run: [`run_into`] ends cleanly, with [`Summary::ended`]).
    #[error("unit `{unit}` ended the simulation at t = {t}: {reason}")]
    UnitEnded {
        unit: String,
        t: f64,
        reason: String,
    },
}

/// One unit: its slave and what the master knows of it.
struct Unit {
    name: String,
    fmu: PathBuf,
    slave: Slave,
    interpolates: bool,
    state: FmuState,
}

impl Unit {
    fn fail(&self, source: SlaveError) -> CosimError {
        CosimError::Unit {
            unit: self.name.clone(),
            fmu: self.fmu.clone(),
            source,
        }
    }
}

/// A resolved connection: `to` input = factor × `from` output.
struct Link {
    from_unit: usize,
    from_vr: u32,
    to_unit: usize,
    to_vr: u32,
    factor: f64,
    /// Degree of the input polynomial (0 held, 1 linear, 2 quadratic).
    order: usize,
    history: History,
    /// The value at the end of the current attempt, once its source has stepped.
    fresh: Option<f64>,
}

/// A `[[rollback.check]]` bound on a Real variable.
struct Check {
    unit: usize,
    vr: u32,
    name: String,
    min: Option<f64>,
    max: Option<f64>,
}

fn is_close(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
}

/// The master during a run: the units, how they are coupled, and the counters.
struct Master<'a> {
    system: &'a System,
    /// The system's `[rollback]`, or the one joints imply.
    rollback: Option<&'a RollbackSpec>,
    units: Vec<Unit>,
    links: Vec<Link>,
    checks: Vec<Check>,
    /// The units in the order they step (Gauss–Seidel: the system's `order`).
    order: Vec<usize>,
    joints: Option<Joints>,
    summary: Summary,
}

/// Runs the system file; returns the recorded outputs and the summary.
pub fn cosim(path: &Path) -> Result<(Results, Summary), CosimError> {
    let system = System::load(path)?;
    run(&system, path)
}

/// Runs the system file, each recorded row to `sink`; returns the summary.
pub fn cosim_into(path: &Path, sink: &mut dyn RowSink) -> Result<Summary, CosimError> {
    let system = System::load(path)?;
    run_into(&system, path, sink)
}

/// Runs a checked system; `path` locates the FMUs (relative to its directory) and names errors.
/// Returns every recorded row and the summary.
pub fn run(system: &System, path: &Path) -> Result<(Results, Summary), CosimError> {
    let mut results = Results {
        columns: Vec::new(),
        types: Vec::new(),
        rows: Vec::new(),
    };
    let summary = run_into(system, path, &mut results)?;
    Ok((results, summary))
}

/// Runs a checked system, each recorded row to `sink` as soon as it is read. Set up
/// (`setup.rs`), then communication steps (`step_control.rs`) to the stop time, the outputs
/// recorded at every grid point (fixed step) or every step (variable). A fixed step is bounded
/// to [`MAX_COMMUNICATION_STEPS`] by the system file's check; a variable step here, as it goes.
pub fn run_into(
    system: &System,
    path: &Path,
    sink: &mut dyn RowSink,
) -> Result<Summary, CosimError> {
    // joints retry refused steps with half the step even without [rollback]
    let implied = RollbackSpec::default();
    let rollback = system
        .rollback
        .as_ref()
        .or((!system.joints.is_empty()).then_some(&implied));

    let mut units = setup::load_units(system, path, rollback.is_some())?;
    let mut links = setup::links(system, path, &units)?;
    let checks = setup::checks(system, path, rollback, &units)?;
    let recorded = setup::recorded(system, path, &units)?;
    let t0 = system.start_time;
    setup::start_values(&mut units, &mut links, t0)?;
    let joints = setup::joints(system, path, &mut units, t0)?;

    let (names, types) = results::columns(&recorded);
    sink.columns(&names, &types).map_err(CosimError::Output)?;
    sink.row(&results::record(&mut units, &recorded, t0)?)
        .map_err(CosimError::Output)?;
    let mut master = Master {
        system,
        rollback,
        order: match system.algorithm {
            Algorithm::Jacobi => (0..units.len()).collect(),
            Algorithm::GaussSeidel => system.stepping_order(),
        },
        summary: Summary {
            units: units.iter().map(|u| u.name.clone()).collect(),
            connections: links.len(),
            min_step: f64::INFINITY,
            max_step: 0.0,
            ..Summary::default()
        },
        units,
        links,
        checks,
        joints,
    };

    let variable_step = system.step.variable.is_some();
    let stop = system.stop_time;
    let mut t = t0;
    let mut grid: u64 = 0; // fixed step: index of the last grid point reached
    let mut h = system.step.size;
    while !(t > stop || is_close(t, stop)) {
        if master.summary.accepted_steps as f64 >= MAX_COMMUNICATION_STEPS {
            return Err(CosimError::TooManySteps {
                t,
                steps: master.summary.accepted_steps,
                limit: MAX_COMMUNICATION_STEPS,
            });
        }
        let target = step_end(system, t, h, grid);
        let mut h_try = target - t;
        if !variable_step {
            h_try = h_try.min(h);
        }
        let step = match master.step(t, h_try, h) {
            Err(CosimError::UnitEnded { unit, t, reason }) => {
                master.summary.ended = Some(format!(
                    "unit `{unit}` ended the simulation at t = {t} s (fmi2Discard, \
                     fmi2Terminated); every row up to that time is recorded: {reason}"
                ));
                break;
            }
            other => other?,
        };
        t += step.h;
        if !variable_step && is_close(t, target) {
            t = target;
            grid += 1;
        }
        h = step.next_h;
        master.accept(t, &step)?;
        if variable_step || t == target {
            sink.row(&results::record(&mut master.units, &recorded, t)?)
                .map_err(CosimError::Output)?;
        }
    }
    let mut summary = master.terminate()?;
    summary.stop_time = t;
    Ok(summary)
}

/// The end of the step from `t`: the next grid point after the `grid`-th (fixed step) or t + h
/// (variable), never past the stop time.
fn step_end(system: &System, t: f64, h: f64, grid: u64) -> f64 {
    let stop = system.stop_time;
    let target = if system.step.variable.is_some() {
        t + h
    } else {
        system.start_time + (grid + 1) as f64 * system.step.size
    };
    if target > stop || is_close(target, stop) {
        stop
    } else {
        target
    }
}

impl Master<'_> {
    /// Frees the saved states and terminates every unit; the summary's counters, finished.
    fn terminate(mut self) -> Result<Summary, CosimError> {
        for u in self.units.iter_mut() {
            if !u.state.is_empty() {
                let r = u.slave.free_fmu_state(&mut u.state);
                r.map_err(|e| u.fail(e))?;
            }
            let r = u.slave.terminate();
            r.map_err(|e| u.fail(e))?;
        }
        let mut summary = self.summary;
        summary.joints = self.joints.map(|j| j.stats);
        if summary.accepted_steps == 0 {
            summary.min_step = 0.0;
        }
        Ok(summary)
    }
}
