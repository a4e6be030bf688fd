//! One FMI 3.0 co-simulation instance: the same [`Engine`] as the 2.0 unit's, its call-sequence
//! state and the importer's logger. Every method is safe; the exports reach them through the
//! guard, which has already checked that the call is legal in the current state.
//!
//! The rules are the 2.0 unit's (`fmi2/instance.rs`): a refused call (illegal here, a bad
//! argument, an unknown value reference, a value the scene refuses, a wrong number of values)
//! returns fmi3Error and changes nothing; a failure of the model moves to `Error`. A step that
//! fails returns fmi3Discard with the state back at the step's start (lastSuccessfulTime).
//! Where a smaller step may succeed the instance stays in `StepMode` (terminateSimulation =
//! false); where none can (the model is out of its range), or the importer repeats the very
//! step that failed, it moves to `StepDiscarded` with terminateSimulation = true.
//!
//! Values are moved by FMI 3.0 variable ([`Layout3`]): a shape array moves its elements in
//! order, so `nValues` counts elements, not value references.

use super::super::fmi2::fmu_state::FmuState;
use super::super::fmi2::guard::Fault;
use super::super::fmi2::resources;
use super::super::fmi2::state_machine::ModelState;
use super::logger::Logger;
use super::state_machine::State;
use super::types::fmi3Status;
use crate::error::EngineError;
use crate::unit::engine::Engine;
use crate::unit::retry::Retry;
use crate::unit::variables::{Declared, Layout3, VarType};

pub struct Instance {
    pub(super) logger: Logger,
    pub(super) state: State,
    engine: Engine,
    layout: Layout3,
    /// Why the unit cannot continue (terminateSimulation = true), set with `StepDiscarded`.
    ended: Option<String>,
    /// Whether a failed step may be retried.
    retry: Retry,
}

/// What fmi3DoStep reports besides its status.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    pub terminate: bool,
    pub last_successful_time: f64,
}

impl Instance {
    /// fmi3InstantiateCoSimulation: checks the instantiation token against the resources' and
    /// reads the scene. Event mode and intermediate variables are refused (the model
    /// description declares neither); an allowed early return is fine (the unit never returns
    /// early).
    pub fn instantiate(
        token: &str,
        resource_path: &str,
        event_mode_used: bool,
        intermediate: usize,
        logger: Logger,
    ) -> Result<Instance, Fault> {
        if event_mode_used {
            return Err(Fault::refused(
                "eventModeUsed = true: this FMU has no event mode (hasEventMode = false)",
            ));
        }
        if intermediate > 0 {
            return Err(Fault::refused(format!(
                "{intermediate} required intermediate variables: this FMU provides no \
                 intermediate update (providesIntermediateUpdate = false)"
            )));
        }
        let dir = resources::directory(resource_path).map_err(Fault::refused)?;
        let expected = resources::guid(&dir).map_err(Fault::refused)?;
        if token.trim() != expected {
            return Err(Fault::refused(format!(
                "instantiationToken '{token}' is not the token '{expected}' of this FMU (in {}): \
                 the modelDescription.xml and the resources do not belong together",
                dir.join("guid.txt").display()
            )));
        }
        let scene = resources::scene(&dir).map_err(Fault::refused)?;
        logger.event(&format!(
            "instantiated scene '{}' from {}",
            scene.name,
            dir.display()
        ));
        let engine = Engine::new(scene);
        let layout = Layout3::of(engine.variables());
        Ok(Instance {
            logger,
            state: State::Instantiated,
            engine,
            layout,
            ended: None,
            retry: Retry::default(),
        })
    }

    /// Maps an engine error to a fault and moves the call-sequence state as the failure says.
    fn fail(&mut self, e: EngineError) -> Fault {
        if e.is_refusal() {
            return match e {
                EngineError::BadStep { message } => Fault::refused(message),
                e => Fault::refused(e.to_string()),
            };
        }
        self.state = State::Error;
        Fault::refused(format!("{e}; the instance is now in state Error"))
    }

    fn transition(&mut self, to: State) {
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

    /// fmi3EnterInitializationMode: the experiment (checked first, so a refusal changes
    /// nothing), a defined tolerance into `solver.tolerance` (warned about when looser than
    /// the scene's, as in FMI 2.0's fmi2SetupExperiment), then initialization mode.
    pub fn enter_initialization_mode(
        &mut self,
        tolerance: Option<f64>,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> Result<(), Fault> {
        self.engine
            .check_experiment(start_time, stop_time)
            .map_err(|e| self.fail(e))?;
        let scene = self
            .engine
            .variables()
            .by_name("solver.tolerance")
            .and_then(|v| Some((v.vr, v.start?)));
        if let (Some(m), Some((vr, scene))) = (tolerance, scene) {
            self.engine.set_real(vr, m).map_err(|e| self.fail(e))?;
            if m > scene {
                self.logger.status(
                    fmi3Status::fmi3Warning,
                    &format!(
                        "fmi3EnterInitializationMode: the unit runs at the importer's tolerance \
                         {m:e}, looser than the scene's solver.tolerance {scene:e}: pass the \
                         DefaultExperiment's tolerance, or toleranceDefined = false, to run at \
                         the scene's"
                    ),
                );
            }
        }
        self.engine
            .set_experiment(start_time, stop_time)
            .map_err(|e| self.fail(e))?;
        self.transition(State::InitializationMode);
        Ok(())
    }

    pub fn exit_initialization_mode(&mut self) -> Result<(), Fault> {
        let result = self.engine.exit_initialization();
        self.pass_messages();
        result.map_err(|e| self.fail(e))?;
        self.transition(State::StepMode);
        Ok(())
    }

    /// The engine's warnings and notes, to the log.
    fn pass_messages(&mut self) {
        for message in self.engine.take_messages() {
            self.logger.status(fmi3Status::fmi3Warning, &message);
        }
        for note in self.engine.take_notes() {
            self.logger.info(&note);
        }
    }

    pub fn terminate(&mut self) -> Result<(), Fault> {
        self.transition(State::Terminated);
        Ok(())
    }

    /// fmi3Reset: as right after instantiation (the debug-logging settings stay).
    pub fn reset(&mut self) -> Result<(), Fault> {
        self.engine.reset();
        self.ended = None;
        self.retry.clear();
        self.transition(State::Instantiated);
        Ok(())
    }

    /// The variables behind `vrs` if all are of type `ty` and their values number `n`.
    fn resolve(&self, vrs: &[u32], ty: VarType, n: usize) -> Result<Vec<Declared>, Fault> {
        let declared = self.layout.resolve(vrs).map_err(|vr| {
            Fault::refused(format!(
                "unknown value reference {vr} (no FMI 3.0 variable)"
            ))
        })?;
        for (&vr, d) in vrs.iter().zip(&declared) {
            let actual = match d {
                Declared::Time => VarType::Real,
                d => self.engine.variables().variables[d.elements().start as usize].ty,
            };
            if actual != ty {
                return Err(Fault::refused(format!(
                    "value reference {vr} is a variable of type {}, not {}",
                    type_name(actual),
                    type_name(ty)
                )));
            }
        }
        let total: usize = declared.iter().map(|d| d.values()).sum();
        if total != n {
            return Err(Fault::refused(format!(
                "nValues = {n}, but the {} value references hold {total} values",
                vrs.len()
            )));
        }
        Ok(declared)
    }

    /// fmi3GetFloat64 / Int32 / Boolean: every value of the variables, in order, as f64 (the
    /// export converts); nothing is written unless every value could be read.
    pub fn get(&mut self, vrs: &[u32], ty: VarType, n: usize) -> Result<Vec<f64>, Fault> {
        let declared = self.resolve(vrs, ty, n)?;
        let mut out = Vec::with_capacity(n);
        for d in declared {
            if d == Declared::Time {
                out.push(self.engine.time());
                continue;
            }
            for vr in d.elements() {
                let value = match ty {
                    VarType::Real => self.engine.get_real(vr),
                    VarType::Integer => self.engine.get_integer(vr).map(f64::from),
                    VarType::Boolean => self.engine.get_boolean(vr).map(|b| f64::from(u8::from(b))),
                };
                out.push(value.map_err(|e| self.fail(e))?);
            }
        }
        Ok(out)
    }

    /// fmi3SetFloat64 / Int32 / Boolean: all or nothing (`Engine::set_many`).
    pub fn set(&mut self, vrs: &[u32], ty: VarType, values: &[f64]) -> Result<(), Fault> {
        let declared = self.resolve(vrs, ty, values.len())?;
        if declared.contains(&Declared::Time) {
            return Err(Fault::refused(
                "time is the independent variable: it is not set, it advances with fmi3DoStep",
            ));
        }
        let elements: Vec<u32> = declared.iter().flat_map(|d| d.elements()).collect();
        self.engine
            .set_many(&elements, ty, values)
            .map_err(|e| self.fail(e))
    }

    /// A getter or setter of a type this FMU has no variable of: fine for no value reference.
    pub fn no_variables_of(&self, type_name: &str, vrs: &[u32]) -> Result<(), Fault> {
        match vrs.first() {
            None => Ok(()),
            Some(vr) => Err(Fault::refused(format!(
                "unknown value reference {vr} for a variable of type {type_name} (this FMU has \
                 none)"
            ))),
        }
    }

    /// fmi3DoStep: never returns early and never asks for event handling.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<StepReport, Fault> {
        if self.state == State::StepDiscarded {
            let why = self.ended.as_deref().unwrap_or("a step failed");
            return Err(Fault::refused(format!(
                "the unit has ended the simulation at t = {} (terminateSimulation = true): \
                 {why}; call fmi3Terminate, or go back with fmi3SetFMUState or fmi3Reset",
                self.engine.time()
            )));
        }
        let result = self.engine.do_step(t, h);
        self.pass_messages();
        match result {
            Ok(()) => {
                self.retry.clear();
                Ok(StepReport {
                    terminate: false,
                    last_successful_time: self.engine.time(),
                })
            }
            Err(e) if e.is_discard() => Err(self.discard(e, t, h)),
            Err(e) => Err(self.fail(e)),
        }
    }

    /// A step that failed with a Discard: the state is back at `t`.
    fn discard(&mut self, e: EngineError, t: f64, h: f64) -> Fault {
        let good = self.engine.time();
        let why = self.retry.judge(&e, t, h);
        let message = match why {
            Some(why) => {
                self.ended = Some(format!("{e}; {why}"));
                self.transition(State::StepDiscarded);
                format!(
                    "{e}; {why}: the unit ends the simulation at its last good time t = {good} s \
                     (lastSuccessfulTime; terminateSimulation = true)"
                )
            }
            None => {
                format!(
                    "{e}; the state is back at the last good time t = {good} s \
                     (lastSuccessfulTime): retry fmi3DoStep from there with a smaller step"
                )
            }
        };
        Fault {
            status: crate::fmi2_types::fmi2Status::fmi2Discard,
            message,
        }
    }

    /// What fmi3DoStep's output arguments say after a failed step.
    pub fn after_failure(&self) -> StepReport {
        StepReport {
            terminate: self.state != State::StepMode,
            last_successful_time: self.engine.time(),
        }
    }

    pub fn get_fmu_state(&self) -> FmuState {
        let phase = match self.state {
            State::Instantiated => ModelState::Instantiated,
            State::InitializationMode => ModelState::InitializationMode,
            _ => ModelState::StepComplete,
        };
        FmuState::new(phase, self.engine.snapshot())
    }

    pub fn set_fmu_state(&mut self, s: &FmuState) -> Result<(), Fault> {
        if let Err(e) = self.engine.restore(s.snapshot()) {
            return Err(Fault::refused(format!(
                "{e}; the instance is left as it was"
            )));
        }
        self.transition(match s.model_state() {
            ModelState::Instantiated => State::Instantiated,
            ModelState::InitializationMode => State::InitializationMode,
            _ => State::StepMode,
        });
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

    /// fmi3GetDirectionalDerivative: sensitivity = (∂ unknowns / ∂ knowns) seed, exact, at the
    /// current communication point, the 2.0 unit's over the arrays' elements; `nSeed` and
    /// `nSensitivity` count elements.
    pub fn get_directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        n_sensitivity: usize,
    ) -> Result<Vec<f64>, Fault> {
        let u = self.resolve(unknowns, VarType::Real, n_sensitivity)?;
        let k = self.resolve(knowns, VarType::Real, seed.len())?;
        if u.contains(&Declared::Time) || k.contains(&Declared::Time) {
            return Err(Fault::refused(
                "time has no directional derivative here: name outputs and inputs",
            ));
        }
        let u: Vec<u32> = u.iter().flat_map(|d| d.elements()).collect();
        let k: Vec<u32> = k.iter().flat_map(|d| d.elements()).collect();
        self.engine
            .directional_derivative(&u, &k, seed)
            .map_err(|e| self.fail(e))
    }
}

/// The FMI 3.0 name of a variable type.
fn type_name(ty: VarType) -> &'static str {
    match ty {
        VarType::Real => "Float64",
        VarType::Integer => "Int32",
        VarType::Boolean => "Boolean",
    }
}
