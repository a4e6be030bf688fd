//! The run's times as FMI 2.0 has them (§4.2.1 fmi2SetupExperiment, §4.2.2 fmi2DoStep; issue
//! 45): a start time double precision can step from, a stop time no step ends past, and a
//! communication step that moves the time. Refusals are fmi2Error with the reason and change
//! nothing: never an fmi2OK without motion.

use super::Engine;
use crate::error::EngineError;
use crate::scene::Short;

/// The time resolution at t (s): f64::EPSILON × max(|t|, 1 s), between one and two units in the
/// last place of t (the spacing of doubles near t) for |t| ≥ 1 s, and 2.2e-16 s below. The
/// engine's other time comparisons are relative to max(|t|, 1 s) too (the stepper's smallest
/// step, the check of the communication point); a step below this is one they cannot tell
/// from no step.
pub fn resolution(t: f64) -> f64 {
    f64::EPSILON * t.abs().max(1.0)
}

/// A step that ends past the stop time by at most this fraction of its size still ends on it:
/// a master that adds up its steps lands a few units in the last place off (0.1 added ten
/// times from 0 ends at 0.9999999999999999; nine times 0.1 and then 0.1 at 1.0000000000000002).
const STOP_SLACK: f64 = 1e-6;

impl Engine {
    /// Checks fmi2SetupExperiment's times before any is set: a finite start time at which
    /// the solver's largest internal step (`solver.max_step`) is above the time resolution
    /// (at 1e15 s a double moves by 0.125 s: no step of the solver, no drive law's motion, no
    /// input's extrapolation could be told apart), and, when defined, a stop time that is
    /// finite and not before the start. A stop time equal to the start time is an experiment of
    /// the initial state alone (FMI 2.0 §4.2.1 asks stopTime ≥ startTime): accepted, and every
    /// doStep of it refused.
    pub fn check_experiment(&self, start: f64, stop: Option<f64>) -> Result<(), EngineError> {
        let refuse = |message: String| Err(EngineError::Experiment { message });
        if !start.is_finite() {
            return refuse(format!(
                "startTime = {} is not a finite number",
                Short(start)
            ));
        }
        let max_step = self.scene_with(&self.values).solver.max_step;
        let res = resolution(start);
        if res > max_step {
            return refuse(format!(
                "startTime = {} s: double precision resolves times there to {} s, more than \
                 the solver's largest step solver.max_step = {} s, so no step of the solver \
                 could be told from the next; start nearer 0 (below {} s for this max_step)",
                Short(start),
                Short(res),
                Short(max_step),
                Short(max_step / f64::EPSILON)
            ));
        }
        match stop {
            Some(stop) if !stop.is_finite() => refuse(format!(
                "stopTime = {} (stopTimeDefined) is not a finite number",
                Short(stop)
            )),
            Some(stop) if stop < start => refuse(format!(
                "stopTime = {} s (stopTimeDefined) is before startTime = {} s",
                Short(stop),
                Short(start)
            )),
            _ => Ok(()),
        }
    }

    /// fmi2SetupExperiment's times, checked by [`Engine::check_experiment`]; a refused pair
    /// changes nothing.
    pub fn set_experiment(&mut self, start: f64, stop: Option<f64>) -> Result<(), EngineError> {
        self.check_experiment(start, stop)?;
        if self.start_time != start {
            self.start_time = start;
            self.model = None;
        }
        self.stop_time = stop;
        Ok(())
    }

    /// The start time of the run, the stop time left as it is.
    pub fn set_start_time(&mut self, t0: f64) -> Result<(), EngineError> {
        self.set_experiment(t0, self.stop_time.filter(|&s| s >= t0))
    }

    /// The end of a communication step of size `h` from the master's point `t`, the instance
    /// being at `now`: refused (fmi2Error) when `h` is not positive and finite, below the time
    /// resolution at `now` (`now + h` would be `now`, or a step of another size), when `t` is
    /// not the instance's time, and when the end is past a defined stop time.
    pub(super) fn step_end(&self, t: f64, h: f64, now: f64) -> Result<f64, EngineError> {
        let refuse = |message: String| Err(EngineError::BadStep { message });
        if !(h.is_finite() && h > 0.0) {
            return refuse(format!(
                "communicationStepSize = {} must be positive and finite",
                Short(h)
            ));
        }
        if !t.is_finite() || (t - now).abs() > 1e-9 * now.abs().max(1.0) {
            return refuse(format!(
                "currentCommunicationPoint = {} differs from the instance time {}",
                Short(t),
                Short(now)
            ));
        }
        let res = resolution(now);
        let end = now + h;
        if h < res || end <= now {
            return refuse(format!(
                "communicationStepSize = {} s is below the time resolution {} s at t = {} s: \
                 double precision cannot advance the time by it (t + h is t, or a step of \
                 another size); the unit did not step",
                Short(h),
                Short(res),
                Short(now)
            ));
        }
        if let Some(stop) = self.stop_time {
            if end - stop > STOP_SLACK * h {
                return refuse(format!(
                    "the step from t = {} s of {} s ends at {} s, past the stopTime {} s set by \
                     fmi2SetupExperiment (stopTimeDefined): FMI 2.0 does not let a master step \
                     past it; the unit did not step",
                    Short(now),
                    Short(h),
                    Short(end),
                    Short(stop)
                ));
            }
        }
        Ok(end)
    }
}
