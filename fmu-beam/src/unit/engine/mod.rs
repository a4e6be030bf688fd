//! The safe engine behind one FMU instance: a scene, its parameter values, the assembled
//! system and the integrator state. The FMI layer (`fmi2/`) owns the call-sequence state
//! machine and hands every request over to these methods.
//!
//! The types are here; their work is split by what it does: [`model`] (a built model: landing
//! on communication points, meeting input jumps, advancing), [`state`] (FMU state snapshot,
//! restore and the byte form), [`outputs`] (an output's value from the state), [`parameters`]
//! (a parameter value into the scene) and [`validity`] (the small-deformation monitor).

mod assembly;
mod diagnosis;
mod model;
mod outputs;
mod parameters;
mod setting;
mod start;
mod state;
mod times;
mod tunable_loads;
mod validity;

use outputs::output;
use parameters::apply;

use crate::error::EngineError;
use crate::integrator::{self, GaState, Memory, Settings, SplitReason, Stats, Stepper};
use crate::mechanics::multibody::law::InputValue;
use crate::mechanics::Mechanics;
use crate::scene::Scene;
use crate::unit::effects::Effects;
use crate::unit::variables::{Binding, Causality, OutputKind, VarType, Variability, VariableTable};

/// A built model: the system for the current parameter values and its integration state.
#[derive(Debug, Clone)]
struct Model {
    system: Mechanics,
    /// The absolute time of the system's time 0: the run's start time. The system, the
    /// integrator and every `GaState` count time from it (`Mechanics::set_time_origin`), so
    /// that a run started at 1e11 s takes the steps of one started at 0.
    origin: f64,
    /// The absolute time of the current communication point, as the master counts it (the
    /// sum of its steps): `state.t` is this less `origin`.
    time: f64,
    /// The state at the current communication point.
    state: GaState,
    /// The integrator's own state, at the end of its last step; a unit steps across
    /// communication points (one with inputs while they go on as extrapolated), so it may lie
    /// past `state`.
    front: GaState,
    /// The state at the start of the integrator's last step, when that step ends past the
    /// communication point: `state` is interpolated between it and `front`.
    back: Option<GaState>,
    /// Whether the next steps land on the communication point: a unit whose inputs changed at
    /// the last one, where the master may change them again (`Engine::sync_inputs`).
    lands: bool,
    stats: Stats,
    stepper: Stepper,
    /// Input values and derivatives (3 per input) at the current point as the last step ended
    /// them (`interface::inputs_ended`): when the inputs set for the next step jump from them,
    /// the scheme restarts from accelerations consistent with the new inputs.
    applied_inputs: Vec<f64>,
    /// The tunable load components the last step had (one per `Engine::load_parts`).
    applied_loads: Vec<f64>,
    /// System joint index of each scene joint, system body index of each scene body.
    joint_index: Vec<usize>,
    body_index: Vec<usize>,
    /// The material points of the shape outputs (evaluated only when read).
    shape: crate::unit::shape::ShapeMaps,
    /// What the last `do_step` saved, kept for its storage: the next one saves into it.
    spare: Option<ModelState>,
}

/// The integration state of a built model, as get/set FMU state copy it (and `do_step` saves
/// it, into the storage of the last one: `Model::spare`).
#[derive(Debug, Clone, PartialEq)]
struct ModelState {
    time: f64,
    state: GaState,
    front: GaState,
    back: Option<GaState>,
    stats: Stats,
    applied_inputs: Vec<f64>,
    applied_loads: Vec<f64>,
    memory: Memory,
}

/// Everything that changes while an instance runs; get/set FMU state copy exactly this.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// The scene's fingerprint: a snapshot is restored only into an instance of the same model.
    identity: u64,
    initialized: bool,
    start_time: f64,
    values: Vec<f64>,
    input_ders: Vec<[f64; 2]>,
    model: Option<ModelState>,
}

/// One FMU instance, safe: a scene with its variable table, the values set on it, and the
/// model built from them at initialization (system, stepper, state). The FMI layer calls it.
#[derive(Debug, Clone)]
pub struct Engine {
    scene: Scene,
    /// The effects resolved from the scene as packaged; parameter values set later change
    /// the model's numbers, not which terms it computes (nor its variables).
    effects: Effects,
    table: VariableTable,
    /// Current value of every parameter and input, indexed by value reference (outputs unused).
    values: Vec<f64>,
    /// First and second time derivatives of the inputs (fmi2SetRealInputDerivatives).
    input_ders: Vec<[f64; 2]>,
    /// Beams already warned about leaving the small-deformation range.
    warned: Vec<bool>,
    /// Reasons for cutting a fixed step already logged.
    split_reported: Vec<SplitReason>,
    /// Warnings for the master's log (something to act on: results may be off), taken by the
    /// FMI layer and logged with fmi2Warning.
    messages: Vec<String>,
    /// Information for the master's log (what the unit did or found on its own that asks
    /// nothing of the user: a fixed step cut to land on a jump), logged with fmi2OK.
    notes: Vec<String>,
    /// Whether what assembly moved was logged already (a restored state builds again).
    assembly_reported: bool,
    /// The effective inertia of each force or torque input, measured when the model was first
    /// built (`unit::input_inertia`); `None` before.
    inertias: Option<Vec<crate::unit::input_inertia::InputInertia>>,
    /// The inputs and their joints' speeds at the last two doStep starts (`diagnosis`).
    probes: [Option<diagnosis::InputProbe>; 2],
    /// Each beam's chord at the last communication points, for the spin a diagnosis reads.
    chords: std::collections::VecDeque<(f64, Vec<nalgebra::Vector3<f64>>)>,
    initialized: bool,
    start_time: f64,
    /// fmi2SetupExperiment's stopTime when stopTimeDefined: no step may end past it.
    stop_time: Option<f64>,
    model: Option<Model>,
    /// Accelerations consistent with the inputs set now, and their derivatives.
    feedthrough: crate::unit::interface::Feedthrough,
    /// The scene's fingerprint: FMU states carry it, and only states of this model are restored.
    /// Computed at the first get or serialize of a state (the scene's canonical text is most of
    /// an instantiation's work otherwise: 0.33 of its 0.9 M instructions for C1).
    identity: std::sync::OnceLock<u64>,
    /// The tunable load components, in the order of `Model::applied_loads`.
    load_parts: Vec<tunable_loads::LoadPart>,
}

impl Engine {
    /// The instance of a validated scene, its parameters at their start values, not yet
    /// initialized (the model is built at exit of initialization mode).
    pub fn new(scene: Scene) -> Engine {
        let effects = crate::unit::effects::resolve(&scene).effects;
        let table = VariableTable::build_with(&scene, &effects);
        let values: Vec<f64> = table
            .variables
            .iter()
            .map(|v| v.start.unwrap_or(0.0))
            .collect();
        let load_parts = tunable_loads::load_parts(&table, &scene);
        Engine {
            load_parts,
            input_ders: vec![[0.0; 2]; values.len()],
            warned: vec![false; scene.beams.len()],
            split_reported: Vec::new(),
            messages: Vec::new(),
            notes: Vec::new(),
            assembly_reported: false,
            inertias: None,
            probes: [None, None],
            chords: Default::default(),
            scene,
            effects,
            table,
            values,
            initialized: false,
            start_time: 0.0,
            stop_time: None,
            model: None,
            feedthrough: Default::default(),
            identity: std::sync::OnceLock::new(),
        }
    }

    /// The scene as packaged (parameter values set since are not written into it).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The variable table: value references, names, causalities, bindings.
    pub fn variables(&self) -> &VariableTable {
        &self.table
    }

    /// Simulated time of the last accepted communication point.
    pub fn time(&self) -> f64 {
        self.model.as_ref().map_or(self.start_time, |m| m.time)
    }

    /// Back to the state right after instantiation: parameters at their start values.
    pub fn reset(&mut self) {
        *self = Engine::new(self.scene.clone());
    }

    /// fmi2SetReal of one variable: a parameter (refused after initialization when fixed), an
    /// input, or an input's derivative; a non-finite value is refused and changes nothing.
    pub fn set_real(&mut self, vr: u32, value: f64) -> Result<(), EngineError> {
        self.set(vr, VarType::Real, value)
    }

    /// fmi2SetInteger of one variable (as [`Engine::set_real`]).
    pub fn set_integer(&mut self, vr: u32, value: i32) -> Result<(), EngineError> {
        self.set(vr, VarType::Integer, value as f64)
    }

    /// fmi2SetBoolean of one variable (as [`Engine::set_real`]).
    pub fn set_boolean(&mut self, vr: u32, value: bool) -> Result<(), EngineError> {
        self.set(vr, VarType::Boolean, if value { 1.0 } else { 0.0 })
    }

    /// fmi2GetReal of one variable: a parameter or input as set, an output at the current
    /// communication point (building the model first where needed).
    pub fn get_real(&mut self, vr: u32) -> Result<f64, EngineError> {
        self.get(vr, VarType::Real)
    }

    /// fmi2GetInteger of one variable (the solver's counters).
    pub fn get_integer(&mut self, vr: u32) -> Result<i32, EngineError> {
        Ok(self.get(vr, VarType::Integer)? as i32)
    }

    /// fmi2GetBoolean of one variable.
    pub fn get_boolean(&mut self, vr: u32) -> Result<bool, EngineError> {
        Ok(self.get(vr, VarType::Boolean)? != 0.0)
    }

    /// Log messages (warnings) collected since the last call.
    pub fn take_messages(&mut self) -> Vec<String> {
        std::mem::take(&mut self.messages)
    }

    /// Information collected since the last call: what the unit changed or found on its own
    /// that asks nothing of the user (a split step, an input's effective inertia).
    pub fn take_notes(&mut self) -> Vec<String> {
        std::mem::take(&mut self.notes)
    }

    /// Copies the input values and derivatives into the system, held from time t0. An input
    /// that changed is a jump of the applied forces or motions at t0. The scheme restarts there
    /// from the mass matrix's consistent accelerations with the inputs the last step ended with
    /// (what a master that couples units at the acceleration level saw through the unit's
    /// outputs and directional derivatives), and meets the jump from them through the iteration
    /// matrix of the step to come, as a drive law's jump (`Stepper::meet_jump`).
    ///
    /// Where the inputs go on exactly as the last step extrapolated them (a held input, or
    /// one the master leaves alone), the unit steps past the end of this communication step as
    /// a unit without inputs does, so that its run does not depend on how the master cuts time;
    /// where any of them changed, it lands there, the master being likely to change them again.
    /// An input that changes while the integrator is past this point has its last step redone
    /// with the inputs as they were, to land here.
    fn sync_inputs(&mut self, t0: f64, h: f64) -> Result<(), EngineError> {
        let loads = self.wanted_loads();
        let Some(m) = &mut self.model else {
            return Ok(());
        };
        for (i, var) in self.table.variables.iter().enumerate() {
            if let Binding::Input(slot) = var.binding {
                let [der1, der2] = self.input_ders[i];
                m.system.inputs_mut()[slot] = InputValue {
                    value: self.values[i],
                    der1,
                    der2,
                    t0,
                };
            }
        }
        let applied = flat_inputs(&m.system);
        let changed = crate::unit::interface::inputs_changed(&m.applied_inputs, &applied);
        m.lands = !applied.is_empty() && changed;
        // a jump is a change of some parts, or of a tunable load
        let loads_changed = m.loads_changed(&loads);
        let jump = loads_changed
            || (changed
                && crate::unit::interface::inputs_jump(&m.applied_inputs, &applied, &m.system));
        // the loads the last step had, until the jump is met (set_real wrote the new ones in)
        if loads_changed {
            tunable_loads::write_loads(&mut m.system, &self.load_parts, &m.applied_loads);
        }
        if jump || (changed && m.is_past(t0)) {
            // the inputs as the last step ended them (set_real wrote the new ones in already)
            let ended = if m.applied_inputs.len() == 3 * m.system.inputs().len() {
                m.applied_inputs
                    .chunks(3)
                    .map(|e| InputValue {
                        value: e[0],
                        der1: e[1],
                        der2: e[2],
                        t0,
                    })
                    .collect()
            } else {
                m.system.inputs().to_vec()
            };
            let parts = &self.load_parts;
            m.meet_inputs(t0, h, jump, ended, |sys| {
                tunable_loads::write_loads(sys, parts, &loads)
            })?;
        }
        if loads_changed {
            // met above (a change of the loads is a jump)
            m.applied_loads = loads;
        }
        m.applied_inputs = applied;
        Ok(())
    }

    /// The index (value reference) of the variable of input slot `slot`.
    fn input_var(&self, slot: usize) -> usize {
        self.table
            .variables
            .iter()
            .position(|v| v.binding == Binding::Input(slot))
            .expect("every input slot has its variable")
    }

    fn lookup(&self, vr: u32, ty: VarType) -> Result<usize, EngineError> {
        match self.table.get(vr) {
            Some(v) if v.ty == ty => Ok(vr as usize),
            _ => Err(EngineError::UnknownValueReference {
                vr,
                ty: ty.as_str(),
            }),
        }
    }

    fn get(&mut self, vr: u32, ty: VarType) -> Result<f64, EngineError> {
        let i = self.lookup(vr, ty)?;
        match self.table.variables[i].binding {
            Binding::Parameter(_) | Binding::Input(_) => Ok(self.values[i]),
            Binding::InputDerivative { slot, order } => {
                Ok(self.input_ders[self.input_var(slot)][order as usize - 1])
            }
            Binding::Output(OutputKind::DriveReaction(j)) => {
                self.built()?;
                let m = self.model.as_mut().expect("built above");
                let (sys, st) = (&mut m.system, &m.state);
                (self.feedthrough)
                    .drive_reaction(sys, st, m.joint_index[j])
                    .map_err(|e| e.at_origin(m.origin))
            }
            Binding::Output(OutputKind::LoadFrame(load, what)) => {
                self.built()?;
                let m = self.model.as_mut().expect("built above");
                let (sys, st) = (&mut m.system, &m.state);
                (self.feedthrough)
                    .frame_output(sys, st, &self.scene, load, what)
                    .map_err(|e| e.at_origin(m.origin))
            }
            Binding::Output(kind) => {
                let m = self.built()?;
                Ok(output(m, kind))
            }
        }
    }

    /// fmi2GetDirectionalDerivative: Σ_j ∂y_i/∂u_j dv_j for outputs y_i and inputs u_j, exact, at
    /// the current communication point (`unit::interface`).
    pub fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv: &[f64],
    ) -> Result<Vec<f64>, EngineError> {
        crate::unit::interface::check_references(&self.table, unknowns, knowns)?;
        self.built()?;
        let m = self.model.as_mut().expect("built above");
        let (sys, st) = (&mut m.system, &m.state);
        self.feedthrough
            .directional_derivative(
                sys,
                st,
                &self.scene,
                &self.table,
                &m.joint_index,
                unknowns,
                knowns,
                dv,
            )
            .map_err(|e| e.at_origin(m.origin))
    }

    /// The scene with the given parameter values applied.
    fn scene_with(&self, values: &[f64]) -> Scene {
        let mut s = self.scene.clone();
        for (var, &v) in self.table.variables.iter().zip(values) {
            if let Binding::Parameter(t) = var.binding {
                apply(&mut s, t, v);
            }
        }
        s
    }

    /// With `effects = "auto"`, the effects were chosen for the packaged parameter values; if
    /// the values set now would make `auto` choose others (a faster spin that needs geometric
    /// stiffening, say), the unit still computes the packaged ones: say so.
    fn warn_if_auto_would_differ(&mut self, scene: &Scene) {
        if scene.effects != crate::scene::EffectsSpec::Mode("auto".into()) {
            return;
        }
        let now = crate::unit::effects::resolve(scene);
        if now.effects == self.effects {
            return;
        }
        let packaged = crate::unit::effects::resolve(&self.scene);
        let changed: Vec<String> = now
            .decisions
            .iter()
            .filter(|d| {
                !packaged.decisions.iter().any(|p| {
                    p.effect == d.effect && p.subject == d.subject && p.setting == d.setting
                })
            })
            .map(|d| {
                format!(
                    "{} ({}) would be {}: {}",
                    d.effect, d.subject, d.setting, d.why
                )
            })
            .collect();
        self.messages.push(format!(
            "effects = \"auto\" was resolved for the packaged parameter values; with the values \
             set now it would choose otherwise, and the unit keeps the packaged effects. \
             Re-package the scene with these values to let auto decide again. {}",
            changed.join("; ")
        ));
    }

    /// The model for the current parameters, built on first need.
    fn built(&mut self) -> Result<&mut Model, EngineError> {
        if self.model.is_none() {
            let scene = self.scene_with(&self.values);
            scene.validate("parameters")?;
            self.warn_if_auto_would_differ(&scene);
            crate::unit::memory::ensure_available(&scene, "initialization")?;
            let origin = self.start_time;
            let mut system = Mechanics::build(&scene, &self.effects);
            system.set_time_origin(origin);
            let settings = Settings::from_scene(&scene);
            for (i, var) in self.table.variables.iter().enumerate() {
                if let Binding::Input(slot) = var.binding {
                    let [der1, der2] = self.input_ders[i];
                    system.inputs_mut()[slot] = InputValue {
                        value: self.values[i],
                        der1,
                        der2,
                        t0: 0.0,
                    };
                }
            }
            // the system's time 0 is the start time
            let state = match start::given(&scene, &self.effects, &system, origin) {
                Ok(Some((q, v))) => integrator::initial_state_from(&system, 0.0, &settings, q, v),
                Ok(None) => integrator::initial_state(&system, 0.0, &settings),
                Err(e) => Err(e),
            }
            .map_err(|e| e.at_origin(origin))?;
            if !self.assembly_reported {
                use crate::mechanics::multibody::Equations;
                let placed = system.initial_coordinates()?;
                self.messages
                    .extend(assembly::report(&scene, &system, &placed, &state.q));
                self.assembly_reported = true;
            }
            if self.inertias.is_none() {
                let inertias =
                    crate::unit::input_inertia::input_inertias(&system, &state, &self.table);
                let h = scene.experiment.step_size;
                self.notes.extend(diagnosis::inertia_notes(&inertias, h));
                self.inertias = Some(inertias);
            }
            // what was recorded past the state restored is not this run's
            self.chords.retain(|(t, _)| *t <= origin);
            for p in &mut self.probes {
                if p.as_ref().is_some_and(|p| p.t > origin) {
                    *p = None;
                }
            }
            let (joint_index, body_index) = match &system {
                Mechanics::Planar(sys) => (
                    scene
                        .joints
                        .iter()
                        .map(|j| sys.joint_index(&j.name).expect("scene joint in system"))
                        .collect(),
                    scene
                        .bodies
                        .iter()
                        .map(|b| {
                            sys.bodies
                                .iter()
                                .position(|x| x.name() == b.name)
                                .expect("scene body in system")
                        })
                        .collect(),
                ),
                Mechanics::Spatial(_, index) => (index.joints.clone(), index.bodies.clone()),
            };
            let shape = crate::unit::shape::ShapeMaps::build(&scene, &self.effects, &system);
            self.model = Some(Model {
                origin,
                time: origin,
                shape,
                applied_inputs: flat_inputs(&system),
                applied_loads: self.wanted_loads(),
                stepper: Stepper::new(&system, settings),
                lands: !system.inputs().is_empty(),
                system,
                front: state.clone(),
                back: None,
                state,
                stats: Stats::default(),
                joint_index,
                body_index,
                spare: None,
            });
        }
        Ok(self.model.as_mut().expect("model built above"))
    }

    /// fmi2ExitInitializationMode: builds the model and fixes the fixed parameters.
    pub fn exit_initialization(&mut self) -> Result<(), EngineError> {
        self.built()?;
        self.initialized = true;
        Ok(())
    }

    /// fmi2DoStep: integrates from `t` to `t + h`. On failure the last good state stays.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<(), EngineError> {
        if !self.initialized {
            return Err(EngineError::BadStep {
                message: "the instance is not initialized".into(),
            });
        }
        let now = self.time();
        let end = self.step_end(t, h, now)?;
        // what the master saw at `now`: a failed step gives it back, also where the inputs'
        // change had the integrator land on `now` from past it first
        let m = self.built()?;
        let saved = m.save_reusing();
        // the step in the system's time (from the run's start): exact where the start time and
        // the end are within a factor of 2 (Sterbenz), and never shorter than the time moves
        let (tau_now, tau_end) = (m.state.t, end - m.origin);
        if tau_end <= tau_now {
            return Err(EngineError::BadStep {
                message: format!(
                    "communicationStepSize = {} s does not move the time counted from the start                      time {} s (at {} s): double precision cannot advance it; the unit did not step",
                    crate::scene::Short(h),
                    crate::scene::Short(m.origin),
                    crate::scene::Short(tau_now)
                ),
            });
        }
        self.probe_inputs();
        let mut result = self.sync_inputs(tau_now, h);
        let m = self.model.as_mut().expect("built above");
        if result.is_ok() {
            result = m.advance(tau_end);
            m.time = end;
        }
        let origin = m.origin;
        result = result.map_err(|e| e.at_origin(origin));
        if result.is_ok() {
            result = self.monitor_validity();
        }
        if result.is_ok() {
            self.report_split(saved.stats.split);
        }
        let m = self.model.as_mut().expect("built above");
        match result {
            Err(e) => {
                m.put_back(saved);
                Err(self.diagnose(e, now, h))
            }
            Ok(()) => {
                m.applied_inputs = crate::unit::interface::inputs_ended(&m.system, m.state.t);
                m.spare = Some(saved);
                Ok(())
            }
        }
    }

    /// Logs the first fixed step of each kind that was cut short (`solver.split_steps` counts
    /// them all), given the count before the communication step.
    fn report_split(&mut self, before: u64) {
        let m = self.model.as_ref().expect("model built");
        let Some((t, h, why)) = m.stepper.last_split else {
            return;
        };
        let t = m.origin + t;
        if m.stats.split == before || self.split_reported.contains(&why) {
            return;
        }
        self.split_reported.push(why);
        self.notes.push(format!(
            "fixed step of {:.6e} s cut to {h:.6e} s at t = {t} s {}; solver.split_steps counts \
             every such step (this message is given once per reason)",
            m.stepper.settings.max_step,
            why.describe()
        ));
    }
}

/// Values and derivatives of the system's inputs, 3 per input.
fn flat_inputs(sys: &Mechanics) -> Vec<f64> {
    sys.inputs()
        .iter()
        .flat_map(|u| [u.value, u.der1, u.der2])
        .collect()
}
