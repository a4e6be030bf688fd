//! One FMU instance: the engine, the call-sequence state and the master's logger. Every method
//! is safe; the exports reach them through the guard, which has already checked that the call
//! is legal in the current state.
//!
//! Which failures move the instance to `Error` ([`Instance::fail`]): only those of the model
//! (it cannot be assembled, its initial state cannot be found, a state could not be restored,
//! a panic). A refused call (illegal in this state, a bad argument, an unknown value reference,
//! a value the scene's rules refuse) returns fmi2Error and leaves a running instance as it was:
//! the engine guarantees that a refused request changed nothing, so there is nothing to
//! protect the master from.
//!
//! A step that fails returns fmi2Discard with the state put back to the step's start, which
//! fmi2LastSuccessfulTime reports (FMI 2.0 §4.2.3). Where a smaller step may succeed (Newton,
//! a singular matrix, a non-finite iterate, the work budget), the instance stays in
//! `StepComplete`: the master retries fmi2DoStep from that time with a smaller step, or rolls
//! back with fmi2SetFMUstate. Where no step can (the validity monitor: the model is out of its
//! range), or where the master repeats the very step that failed (the engine is deterministic,
//! so it fails the same way: a master such as fmpy's `simulate_fmu` would loop forever), the
//! instance moves to `StepFailed`, fmi2GetBooleanStatus(fmi2Terminated) answers true and the
//! log says why; fmi2Terminate, fmi2SetFMUstate and fmi2Reset are what is left.

use super::fmu_state::FmuState;
use super::guard::Fault;
use super::logger::Logger;
use super::resources;
use super::state_machine::ModelState;
use super::types::{
    self as t, fmi2Boolean, fmi2False, fmi2Status, fmi2StatusKind, fmi2True, fmi2Type,
};
use crate::error::EngineError;
use crate::unit::engine::Engine;
use crate::unit::retry::Retry;
use crate::unit::variables::VarType;

pub struct Instance {
    pub(super) logger: Logger,
    pub(super) state: ModelState,
    engine: Engine,
    /// Why the unit cannot continue (fmi2Terminated = true), set with `StepFailed`.
    ended: Option<String>,
    /// Whether a failed step may be retried.
    retry: Retry,
    /// The tolerance the master passed to fmi2SetupExperiment (toleranceDefined), if any.
    master_tolerance: Option<f64>,
}

impl Instance {
    /// fmi2Instantiate: checks the type and the GUID, reads the scene from the resources.
    pub fn instantiate(
        fmu_type: fmi2Type,
        guid: &str,
        resource_location: &str,
        logger: Logger,
    ) -> Result<Instance, Fault> {
        match fmu_type {
            t::fmi2CoSimulation => {}
            t::fmi2ModelExchange => {
                return Err(Fault::refused(
                    "fmuType = fmi2ModelExchange: this FMU supports co-simulation only",
                ))
            }
            other => {
                return Err(Fault::refused(format!(
                    "fmuType = {other} is neither fmi2ModelExchange (0) nor fmi2CoSimulation (1)"
                )))
            }
        }
        let dir = resources::directory(resource_location).map_err(Fault::refused)?;
        let expected = resources::guid(&dir).map_err(Fault::refused)?;
        if guid.trim() != expected {
            return Err(Fault::refused(format!(
                "fmuGUID '{guid}' is not the GUID '{expected}' of this FMU (in {}): the \
                 modelDescription.xml and the resources do not belong together",
                dir.join("guid.txt").display()
            )));
        }
        let scene = resources::scene(&dir).map_err(Fault::refused)?;
        logger.event(&format!(
            "instantiated scene '{}' from {}",
            scene.name,
            dir.display()
        ));
        Ok(Instance {
            logger,
            state: ModelState::Instantiated,
            engine: Engine::new(scene),
            ended: None,
            retry: Retry::default(),
            master_tolerance: None,
        })
    }

    /// Maps an engine error to a fault and moves the call-sequence state as the failure says.
    fn fail(&mut self, e: EngineError) -> Fault {
        let refused = e.is_refusal();
        if let EngineError::BadStep { message } = e {
            // The engine's text starts with "doStep: "; the guard names the function already.
            return Fault::refused(message);
        }
        if refused {
            return Fault::refused(e.to_string());
        }
        if e.is_discard() && self.state == ModelState::StepComplete {
            self.state = ModelState::StepFailed;
            self.ended = Some(e.to_string());
            return Fault::from(e);
        }
        self.state = ModelState::Error;
        Fault::refused(format!("{e}; the instance is now in state Error"))
    }

    fn transition(&mut self, to: ModelState) {
        if self.state != to {
            self.logger.event(&format!(
                "state {:?} -> {to:?} at t = {}",
                self.state,
                self.engine.time()
            ));
            self.state = to;
        }
    }

    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Result<(), Fault> {
        self.logger
            .set_debug_logging(on, categories)
            .map_err(Fault::refused)
    }

    /// The value reference of `solver.tolerance` and the scene's value of it.
    fn scene_tolerance(&self) -> Option<(u32, f64)> {
        let v = self.engine.variables().by_name("solver.tolerance")?;
        Some((v.vr, v.start?))
    }

    /// fmi2SetupExperiment: a defined tolerance goes to `solver.tolerance`, as the standard asks
    /// (the master's tolerance is the one to use), with a warning when it is looser than the
    /// scene's; the log says which tolerance the unit runs at and where it came from. The start
    /// and a defined stop time are checked first (`Engine::check_experiment`), so that a refusal
    /// changes nothing.
    pub fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> Result<(), Fault> {
        self.engine
            .check_experiment(start_time, stop_time)
            .map_err(|e| self.fail(e))?;
        let scene = self.scene_tolerance();
        if let (Some(tolerance), Some((vr, _))) = (tolerance, scene) {
            self.engine
                .set_real(vr, tolerance)
                .map_err(|e| self.fail(e))?;
        }
        self.engine
            .set_experiment(start_time, stop_time)
            .map_err(|e| self.fail(e))?;
        self.master_tolerance = tolerance;
        if let Some((_, scene)) = scene {
            match tolerance {
                Some(m) if m > scene => self.logger.status(
                    fmi2Status::fmi2Warning,
                    &format!(
                        "fmi2SetupExperiment: the unit runs at the master's tolerance {m:e} \
                         (toleranceDefined), looser than the scene's solver.tolerance {scene:e}: \
                         results may differ from the scene's by more than its tolerance; pass \
                         the DefaultExperiment's tolerance {scene:e}, or toleranceDefined = \
                         false, to run at the scene's"
                    ),
                ),
                Some(m) => self.logger.event(&format!(
                    "tolerance {m:e} from the master (fmi2SetupExperiment, toleranceDefined); \
                     the scene's solver.tolerance is {scene:e}"
                )),
                None => self.logger.event(&format!(
                    "tolerance {scene:e} from the scene (solver.tolerance): the master \
                     defined none"
                )),
            }
        }
        Ok(())
    }

    /// Where the tolerance the unit runs at came from, for the log at initialization.
    fn tolerance_report(&mut self) -> Option<String> {
        let (vr, scene) = self.scene_tolerance()?;
        let now = self.engine.get_real(vr).ok()?;
        let source = if self.master_tolerance == Some(now) {
            "the master's fmi2SetupExperiment (toleranceDefined)"
        } else if now == scene {
            "the scene (solver.tolerance)"
        } else {
            "the parameter solver.tolerance, set by the master"
        };
        Some(format!(
            "runs at tolerance {now:e}, from {source}; the scene's is {scene:e}"
        ))
    }

    pub fn enter_initialization_mode(&mut self) -> Result<(), Fault> {
        self.transition(ModelState::InitializationMode);
        Ok(())
    }

    pub fn exit_initialization_mode(&mut self) -> Result<(), Fault> {
        let result = self.engine.exit_initialization();
        // what building the model found (assembly, effects): said at initialization
        for message in self.engine.take_messages() {
            self.logger.status(fmi2Status::fmi2Warning, &message);
        }
        for note in self.engine.take_notes() {
            self.logger.info(&note);
        }
        result.map_err(|e| self.fail(e))?;
        if let Some(report) = self.tolerance_report() {
            self.logger.event(&report);
        }
        self.transition(ModelState::StepComplete);
        Ok(())
    }

    pub fn terminate(&mut self) -> Result<(), Fault> {
        self.transition(ModelState::Terminated);
        Ok(())
    }

    /// fmi2Reset: as right after fmi2Instantiate (the debug-logging settings stay).
    pub fn reset(&mut self) -> Result<(), Fault> {
        self.engine.reset();
        self.ended = None;
        self.retry.clear();
        self.master_tolerance = None;
        self.transition(ModelState::Instantiated);
        Ok(())
    }

    pub fn get_real(&mut self, vr: &[u32], value: &mut [f64]) -> Result<(), Fault> {
        for (&r, v) in vr.iter().zip(value) {
            *v = self.engine.get_real(r).map_err(|e| self.fail(e))?;
        }
        Ok(())
    }

    pub fn get_integer(&mut self, vr: &[u32], value: &mut [i32]) -> Result<(), Fault> {
        for (&r, v) in vr.iter().zip(value) {
            *v = self.engine.get_integer(r).map_err(|e| self.fail(e))?;
        }
        Ok(())
    }

    pub fn get_boolean(&mut self, vr: &[u32], value: &mut [fmi2Boolean]) -> Result<(), Fault> {
        for (&r, v) in vr.iter().zip(value) {
            let b = self.engine.get_boolean(r).map_err(|e| self.fail(e))?;
            *v = if b { fmi2True } else { fmi2False };
        }
        Ok(())
    }

    pub fn set_real(&mut self, vr: &[u32], value: &[f64]) -> Result<(), Fault> {
        self.engine.set_reals(vr, value).map_err(|e| self.fail(e))
    }

    pub fn set_integer(&mut self, vr: &[u32], value: &[i32]) -> Result<(), Fault> {
        let value: Vec<f64> = value.iter().map(|&v| v as f64).collect();
        self.engine
            .set_many(vr, VarType::Integer, &value)
            .map_err(|e| self.fail(e))
    }

    pub fn set_boolean(&mut self, vr: &[u32], value: &[fmi2Boolean]) -> Result<(), Fault> {
        let value: Vec<f64> = value
            .iter()
            .map(|&v| if v != fmi2False { 1.0 } else { 0.0 })
            .collect();
        self.engine
            .set_many(vr, VarType::Boolean, &value)
            .map_err(|e| self.fail(e))
    }

    /// fmi2GetString / fmi2SetString: this FMU has no String variables.
    pub fn string_access(&mut self, vr: &[u32]) -> Result<(), Fault> {
        match vr.first() {
            None => Ok(()),
            Some(r) => Err(Fault::refused(format!(
                "unknown value reference {r} for a variable of type String (this FMU has none)"
            ))),
        }
    }

    pub fn do_step(&mut self, t: f64, h: f64) -> Result<(), Fault> {
        if self.state == ModelState::StepFailed {
            let why = self.ended.as_deref().unwrap_or("a step failed");
            return Err(Fault::refused(format!(
                "the unit has ended the simulation at t = {} (fmi2Terminated = true): {why}; \
                 call fmi2Terminate, or go back with fmi2SetFMUstate or fmi2Reset",
                self.engine.time()
            )));
        }
        let result = self.engine.do_step(t, h);
        for message in self.engine.take_messages() {
            self.logger.status(fmi2Status::fmi2Warning, &message);
        }
        for note in self.engine.take_notes() {
            self.logger.info(&note);
        }
        match result {
            Ok(()) => {
                self.retry.clear();
                Ok(())
            }
            Err(e) if e.is_discard() && self.state == ModelState::StepComplete => {
                Err(self.discard(e, t, h))
            }
            Err(e) => Err(self.fail(e)),
        }
    }

    /// A step that failed with a Discard: the state is back at `t`. A retry from there with a
    /// smaller step may succeed, unless the model is out of its range or the master repeated
    /// the step that failed; then the unit ends the simulation (fmi2Terminated = true).
    fn discard(&mut self, e: EngineError, t: f64, h: f64) -> Fault {
        let good = self.engine.time();
        let why = self.retry.judge(&e, t, h);
        let message = match why {
            Some(why) => {
                self.ended = Some(format!("{e}; {why}"));
                self.state = ModelState::StepFailed;
                format!(
                    "{e}; {why}: the unit ends the simulation at its last good time t = {good} s \
                     (fmi2LastSuccessfulTime; fmi2Terminated = true)"
                )
            }
            None => {
                format!(
                    "{e}; the state is back at the last good time t = {good} s \
                     (fmi2LastSuccessfulTime): retry fmi2DoStep from there with a smaller step"
                )
            }
        };
        Fault {
            status: fmi2Status::fmi2Discard,
            message,
        }
    }

    pub fn cancel_step(&mut self) -> Result<(), Fault> {
        Err(Fault::refused(
            "no step is in progress: fmi2DoStep runs synchronously (canRunAsynchronuously = false)",
        ))
    }

    pub fn get_fmu_state(&self) -> FmuState {
        FmuState::new(self.state, self.engine.snapshot())
    }

    pub fn set_fmu_state(&mut self, s: &FmuState) -> Result<(), Fault> {
        if let Err(e) = self.engine.restore(s.snapshot()) {
            return Err(Fault::refused(format!(
                "{e}; the instance is left as it was"
            )));
        }
        self.transition(s.model_state());
        self.ended = None;
        self.retry.clear();
        self.logger
            .event(&format!("FMU state restored at t = {}", self.engine.time()));
        Ok(())
    }

    pub fn serialize_fmu_state(&self, s: &FmuState) -> Vec<u8> {
        s.serialize(&self.engine)
    }

    pub fn deserialize_fmu_state(&self, bytes: &[u8]) -> Result<FmuState, Fault> {
        FmuState::deserialize(&self.engine, bytes)
    }

    pub fn get_status(&self, kind: fmi2StatusKind) -> Result<fmi2Status, Fault> {
        Err(Fault::refused(match kind {
            t::fmi2DoStepStatus => {
                "fmi2DoStepStatus: there is no asynchronous step (fmi2DoStep never \
                                 returns fmi2Pending)"
                    .to_string()
            }
            other => format!("status kind {other} has no fmi2Status value"),
        }))
    }

    /// fmi2LastSuccessfulTime: the time of the last good state (also after a failed step).
    pub fn get_real_status(&self, kind: fmi2StatusKind) -> Result<f64, Fault> {
        match kind {
            t::fmi2LastSuccessfulTime => Ok(self.engine.time()),
            other => Err(Fault::refused(format!(
                "status kind {other} has no Real value"
            ))),
        }
    }

    pub fn get_integer_status(&self, kind: fmi2StatusKind) -> Result<i32, Fault> {
        Err(Fault::refused(format!(
            "status kind {kind} has no Integer value"
        )))
    }

    /// fmi2Terminated: true once a step has failed in a way no retry overcomes (see the
    /// module's comment); the log said why.
    pub fn get_boolean_status(&self, kind: fmi2StatusKind) -> Result<fmi2Boolean, Fault> {
        match kind {
            t::fmi2Terminated if self.ended.is_some() => Ok(fmi2True),
            t::fmi2Terminated => Ok(fmi2False),
            other => Err(Fault::refused(format!(
                "status kind {other} has no Boolean value"
            ))),
        }
    }

    pub fn get_string_status(&self, kind: fmi2StatusKind) -> Result<(), Fault> {
        Err(Fault::refused(match kind {
            t::fmi2PendingStatus => "fmi2PendingStatus: there is no asynchronous step".to_string(),
            other => format!("status kind {other} has no String value"),
        }))
    }

    /// fmi2GetDirectionalDerivative: dv_unknown = (∂ outputs / ∂ inputs) dv_known, exact, at
    /// the current communication point ([`crate::unit::interface`]).
    pub fn get_directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
    ) -> Result<Vec<f64>, Fault> {
        self.engine
            .directional_derivative(unknowns, knowns, dv_known)
            .map_err(|e| self.fail(e))
    }

    pub fn get_real_output_derivatives(&mut self) -> Result<(), Fault> {
        Err(Fault::refused(
            "output derivatives are not provided (maxOutputDerivativeOrder = 0)",
        ))
    }

    /// fmi2SetRealInputDerivatives: the inputs are extrapolated over the next step with the
    /// derivatives of order 1 and 2 (canInterpolateInputs = true).
    pub fn set_real_input_derivatives(
        &mut self,
        vr: &[u32],
        order: &[i32],
        value: &[f64],
    ) -> Result<(), Fault> {
        self.engine
            .set_input_derivatives(vr, order, value)
            .map_err(|e| self.fail(e))
    }
}
