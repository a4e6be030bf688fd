//! One FMU instance: the engine, the call-sequence state and the master's logger. Every method
//! is safe; the exports reach them through the guard, which has already checked that the call
//! is legal in the current state.
//!
//! Which failures move the instance to `Error` ([`Instance::fail`]): only those of the model
//! (it cannot be assembled, its initial state cannot be found, a state could not be restored,
//! a panic). A refused call (illegal in this state, a bad argument, an unknown value reference,
//! a value the scene's rules refuse) returns fmi2Error and leaves a running instance as it was:
//! the engine guarantees that a refused request changed nothing, so there is nothing to
//! protect the master from. A step that fails returns fmi2Discard and moves to `StepFailed`,
//! with the last good state readable.

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
use crate::unit::variables::VarType;

pub struct Instance {
    pub(super) logger: Logger,
    pub(super) state: ModelState,
    engine: Engine,
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
        })
    }

    /// Maps an engine error to a fault and moves the call-sequence state as the failure says.
    fn fail(&mut self, e: EngineError) -> Fault {
        use EngineError as E;
        let refused = matches!(
            e,
            E::UnknownValueReference { .. }
                | E::NotSettable { .. }
                | E::NonFiniteValue { .. }
                | E::InvalidValue { .. }
                | E::BadStep { .. }
                | E::BadState { .. }
                | E::DirectionalDerivative { .. }
                | E::FeedthroughSingular { .. }
        );
        if let E::BadStep { message } = e {
            // The engine's text starts with "doStep: "; the guard names the function already.
            return Fault::refused(message);
        }
        if refused {
            return Fault::refused(e.to_string());
        }
        if e.is_discard() && self.state == ModelState::StepComplete {
            self.state = ModelState::StepFailed;
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

    /// fmi2SetupExperiment: the tolerance goes to `solver.tolerance` when the scene has it.
    pub fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start_time: f64,
    ) -> Result<(), Fault> {
        if let Some(tolerance) = tolerance {
            if let Some(vr) = self
                .engine
                .variables()
                .by_name("solver.tolerance")
                .map(|v| v.vr)
            {
                self.engine
                    .set_real(vr, tolerance)
                    .map_err(|e| self.fail(e))?;
            }
        }
        self.engine
            .set_start_time(start_time)
            .map_err(|e| self.fail(e))
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
        result.map_err(|e| self.fail(e))?;
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
        let result = self.engine.do_step(t, h);
        for message in self.engine.take_messages() {
            self.logger.status(fmi2Status::fmi2Warning, &message);
        }
        result.map_err(|e| self.fail(e))
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

    /// fmi2Terminated: false, this FMU never asks to end the simulation.
    pub fn get_boolean_status(&self, kind: fmi2StatusKind) -> Result<fmi2Boolean, Fault> {
        match kind {
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
