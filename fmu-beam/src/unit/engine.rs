//! The safe engine behind one FMU instance: a scene, its parameter values, the assembled
//! system and the integrator state. The FMI layer (`fmi2/`) owns the call-sequence state
//! machine and hands every request over to these methods.

use crate::error::EngineError;
use crate::integrator::{
    self, write_vec, GaState, Memory, Reader, Settings, SplitReason, Stats, Stepper,
};
use crate::mechanics::multibody::equations::Equations;
use crate::mechanics::multibody::law::InputValue;
use crate::mechanics::multibody3d::System3;
use crate::mechanics::Mechanics;
use crate::scene::Scene;
use crate::unit::effects::Effects;
use crate::unit::variables::{
    Binding, Causality, OutputKind, ParamTarget, VarType, Variability, VariableTable,
};

/// A built model: the system for the current parameter values and its integration state.
#[derive(Debug, Clone)]
struct Model {
    system: Mechanics,
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
    /// System joint index of each scene joint, system body index of each scene body.
    joint_index: Vec<usize>,
    body_index: Vec<usize>,
    /// The material points of the shape outputs (evaluated only when read).
    shape: crate::unit::shape::ShapeMaps,
}

/// The integration state of a built model, as get/set FMU state copy it.
#[derive(Debug, Clone, PartialEq)]
struct ModelState {
    state: GaState,
    front: GaState,
    back: Option<GaState>,
    stats: Stats,
    applied_inputs: Vec<f64>,
    memory: Memory,
}

/// Everything that changes while an instance runs; get/set FMU state copy exactly this.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    initialized: bool,
    start_time: f64,
    values: Vec<f64>,
    input_ders: Vec<[f64; 2]>,
    model: Option<ModelState>,
}

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
    /// Log messages (warnings) for the master, taken by the FMI layer.
    messages: Vec<String>,
    initialized: bool,
    start_time: f64,
    model: Option<Model>,
    /// Accelerations consistent with the inputs set now, and their derivatives.
    feedthrough: crate::unit::interface::Feedthrough,
}

const STATE_MAGIC: &[u8; 8] = b"FMUBEAM\0";
/// Relative stretch of a beam's chord (root to tip) beyond which the step is refused.
const STRETCH_LIMIT: f64 = 0.01;
const STATE_VERSION: u32 = 5;
/// Within this fraction of `max_step` of a communication point, the integrator's state counts
/// as on it (not past it).
const SNAP: f64 = 1e-6;

impl Engine {
    pub fn new(scene: Scene) -> Engine {
        let effects = crate::unit::effects::resolve(&scene).effects;
        let table = VariableTable::build_with(&scene, &effects);
        let values: Vec<f64> = table
            .variables
            .iter()
            .map(|v| v.start.unwrap_or(0.0))
            .collect();
        Engine {
            input_ders: vec![[0.0; 2]; values.len()],
            warned: vec![false; scene.beams.len()],
            split_reported: Vec::new(),
            messages: Vec::new(),
            scene,
            effects,
            table,
            values,
            initialized: false,
            start_time: 0.0,
            model: None,
            feedthrough: Default::default(),
        }
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    pub fn variables(&self) -> &VariableTable {
        &self.table
    }

    /// Simulated time of the last accepted communication point.
    pub fn time(&self) -> f64 {
        self.model.as_ref().map_or(self.start_time, |m| m.state.t)
    }

    /// Back to the state right after instantiation: parameters at their start values.
    pub fn reset(&mut self) {
        *self = Engine::new(self.scene.clone());
    }

    pub fn set_real(&mut self, vr: u32, value: f64) -> Result<(), EngineError> {
        self.set(vr, VarType::Real, value)
    }

    pub fn set_integer(&mut self, vr: u32, value: i32) -> Result<(), EngineError> {
        self.set(vr, VarType::Integer, value as f64)
    }

    pub fn set_boolean(&mut self, vr: u32, value: bool) -> Result<(), EngineError> {
        self.set(vr, VarType::Boolean, if value { 1.0 } else { 0.0 })
    }

    pub fn get_real(&mut self, vr: u32) -> Result<f64, EngineError> {
        self.get(vr, VarType::Real)
    }

    pub fn get_integer(&mut self, vr: u32) -> Result<i32, EngineError> {
        Ok(self.get(vr, VarType::Integer)? as i32)
    }

    pub fn get_boolean(&mut self, vr: u32) -> Result<bool, EngineError> {
        Ok(self.get(vr, VarType::Boolean)? != 0.0)
    }

    /// fmi2SetRealInputDerivatives: derivative of `order` (1 or 2) of a Real input, used to
    /// extrapolate it over the next communication step.
    pub fn set_input_derivative(
        &mut self,
        vr: u32,
        order: i32,
        value: f64,
    ) -> Result<(), EngineError> {
        let i = self.lookup(vr, VarType::Real)?;
        let var = &self.table.variables[i];
        let Binding::Input(slot) = var.binding else {
            return Err(EngineError::NotSettable {
                name: var.name.clone(),
                reason: "input derivatives are only for inputs".into(),
            });
        };
        if !(1..=2).contains(&order) {
            return Err(EngineError::InvalidValue {
                name: var.name.clone(),
                value: order as f64,
                rule: "derivative order must be 1 or 2 (MaxInputDerivativeOrder)".into(),
            });
        }
        if !value.is_finite() {
            return Err(EngineError::NonFiniteValue {
                name: var.name.clone(),
                value,
            });
        }
        self.input_ders[i][order as usize - 1] = value;
        if let Some(m) = &mut self.model {
            let u = &mut m.system.inputs_mut()[slot];
            if order == 1 {
                u.der1 = value;
            } else {
                u.der2 = value;
            }
        }
        Ok(())
    }

    /// Log messages (warnings) collected since the last call.
    pub fn take_messages(&mut self) -> Vec<String> {
        std::mem::take(&mut self.messages)
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
        // a jump is a change of some parts
        let jump =
            changed && crate::unit::interface::inputs_jump(&m.applied_inputs, &applied, &m.system);
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
            m.meet_inputs(t0, h, jump, ended)?;
        }
        m.applied_inputs = applied;
        Ok(())
    }

    /// Sets several Real variables as one fmi2SetReal call: the inputs' values first, then the
    /// inputs that are their derivatives (a value resets its derivatives), whatever the order of
    /// the references.
    pub fn set_reals(&mut self, vr: &[u32], value: &[f64]) -> Result<(), EngineError> {
        let is_derivative = |e: &Engine, r: u32| {
            matches!(
                e.table.get(r).map(|v| v.binding),
                Some(Binding::InputDerivative { .. })
            )
        };
        for pass in [false, true] {
            for (&r, &v) in vr.iter().zip(value) {
                if is_derivative(self, r) == pass {
                    self.set_real(r, v)?;
                }
            }
        }
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

    fn set(&mut self, vr: u32, ty: VarType, value: f64) -> Result<(), EngineError> {
        let i = self.lookup(vr, ty)?;
        let var = &self.table.variables[i];
        let name = var.name.clone();
        if !value.is_finite() {
            return Err(EngineError::NonFiniteValue { name, value });
        }
        if let Binding::InputDerivative { slot, order } = var.binding {
            let base = self.input_var(slot) as u32;
            return self.set_input_derivative(base, order as i32, value);
        }
        if let Binding::Input(slot) = var.binding {
            self.values[i] = value;
            self.input_ders[i] = [0.0; 2];
            let t0 = self.time();
            if let Some(m) = &mut self.model {
                m.system.inputs_mut()[slot] = InputValue {
                    value,
                    der1: 0.0,
                    der2: 0.0,
                    t0,
                };
            }
            return Ok(());
        }
        if !matches!(
            (var.causality, var.binding),
            (Causality::Parameter, Binding::Parameter(_))
        ) {
            return Err(EngineError::NotSettable {
                name,
                reason: format!("it is a {} variable", var.causality.as_str()),
            });
        }
        if self.initialized && var.variability == Variability::Fixed {
            return Err(EngineError::NotSettable {
                name,
                reason: "it is a fixed parameter and the instance is past initialization".into(),
            });
        }
        // The scene's own rules decide what a value may be.
        let mut trial = self.values.clone();
        trial[i] = value;
        let scene = self.scene_with(&trial);
        if let Err(e) = scene.validate("parameters") {
            let rule = match e {
                crate::scene::SceneError::Invalid { rule, .. } => rule,
                other => other.to_string(),
            };
            return Err(EngineError::InvalidValue { name, value, rule });
        }
        self.values[i] = value;
        match &mut self.model {
            Some(m) if self.initialized => m.stepper.set_settings(Settings::from_scene(&scene)),
            _ => self.model = None,
        }
        Ok(())
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
                (self.feedthrough).drive_reaction(sys, st, m.joint_index[j])
            }
            Binding::Output(OutputKind::LoadFrame(load, what)) => {
                self.built()?;
                let m = self.model.as_mut().expect("built above");
                let (sys, st) = (&mut m.system, &m.state);
                (self.feedthrough).frame_output(sys, st, &self.scene, load, what)
            }
            Binding::Output(kind) => {
                let m = self.built()?;
                Ok(output(m, kind))
            }
        }
    }

    /// fmi2GetDirectionalDerivative: Σ_j ∂y_i/∂u_j dv_j for outputs y_i and inputs u_j, exact, at
    /// the current communication point ([`crate::unit::interface`]).
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
        self.feedthrough.directional_derivative(
            sys,
            st,
            &self.scene,
            &self.table,
            &m.joint_index,
            unknowns,
            knowns,
            dv,
        )
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
            let mut system = Mechanics::build(&scene, &self.effects);
            let settings = Settings::from_scene(&scene);
            for (i, var) in self.table.variables.iter().enumerate() {
                if let Binding::Input(slot) = var.binding {
                    let [der1, der2] = self.input_ders[i];
                    system.inputs_mut()[slot] = InputValue {
                        value: self.values[i],
                        der1,
                        der2,
                        t0: self.start_time,
                    };
                }
            }
            let state = integrator::initial_state(&system, &scene, self.start_time, &settings)?;
            let (joint_index, body_index) = match &system {
                Mechanics::Planar(sys, _) => (
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
                shape,
                applied_inputs: flat_inputs(&system),
                stepper: Stepper::new(&system, settings),
                lands: !system.inputs().is_empty(),
                system,
                front: state.clone(),
                back: None,
                state,
                stats: Stats::default(),
                joint_index,
                body_index,
            });
        }
        Ok(self.model.as_mut().expect("model built above"))
    }

    /// fmi2SetupExperiment / fmi2EnterInitializationMode: the start time of the run.
    pub fn set_start_time(&mut self, t0: f64) -> Result<(), EngineError> {
        if !t0.is_finite() {
            return Err(EngineError::NonFiniteValue {
                name: "startTime".into(),
                value: t0,
            });
        }
        if self.start_time != t0 {
            self.start_time = t0;
            self.model = None;
        }
        Ok(())
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
        if !(h.is_finite() && h > 0.0) {
            return Err(EngineError::BadStep {
                message: format!("communicationStepSize = {h} must be positive and finite"),
            });
        }
        let now = self.time();
        if !t.is_finite() || (t - now).abs() > 1e-9 * now.abs().max(1.0) {
            return Err(EngineError::BadStep {
                message: format!(
                    "currentCommunicationPoint = {t} differs from the instance time {now}"
                ),
            });
        }
        // what the master saw at `now`: a failed step gives it back, also where the inputs'
        // change had the integrator land on `now` from past it first
        let saved = self.built()?.save();
        let mut result = self.sync_inputs(now, h);
        let m = self.model.as_mut().expect("built above");
        if result.is_ok() {
            result = m.advance(now + h);
        }
        if result.is_ok() {
            result = self.monitor_validity();
        }
        if result.is_ok() {
            self.report_split(saved.stats.split);
        }
        let m = self.model.as_mut().expect("built above");
        if result.is_err() {
            m.put_back(saved);
        } else {
            m.applied_inputs = crate::unit::interface::inputs_ended(&m.system, m.state.t);
        }
        result
    }

    /// Logs the first fixed step of each kind that was cut short (`solver.split_steps` counts
    /// them all), given the count before the communication step.
    fn report_split(&mut self, before: u64) {
        let m = self.model.as_ref().expect("model built");
        let Some((t, h, why)) = m.stepper.last_split else {
            return;
        };
        if m.stats.split == before || self.split_reported.contains(&why) {
            return;
        }
        self.split_reported.push(why);
        self.messages.push(format!(
            "fixed step of {:.6e} s cut to {h:.6e} s at t = {t} s {}; solver.split_steps counts \
             every such step (this message is given once per reason)",
            m.stepper.settings.max_step,
            why.describe()
        ));
    }

    /// The validity monitor: a floating frame assumes small deformation. Beyond 5 % of its
    /// length it warns once per beam; beyond its length the solution has run away (a linear
    /// beam spun above its first bending frequency) and the step is refused, as it is when a
    /// beam's chord (root to tip) is longer than the beam.
    fn monitor_validity(&mut self) -> Result<(), EngineError> {
        let Engine {
            model,
            warned,
            messages,
            ..
        } = self;
        let m = model.as_ref().expect("model built");
        let (q, t) = (&m.state.q, m.state.t);
        match &m.system {
            Mechanics::Planar(sys, _) => {
                for (g, grp) in sys.beams.iter().enumerate() {
                    let z0 = sys.body_coords(grp.bodies.start, q);
                    let (tip, _) = sys.beam_tip(g, q);
                    let chord = (tip - nalgebra::Vector2::new(z0[0], z0[1])).norm();
                    let frames = grp.bodies.clone().filter_map(|body| {
                        let b = sys.beam(body)?;
                        let defl = b.largest_transverse(sys.body_coords(body, q));
                        Some((b.name.as_str(), b.length, defl))
                    });
                    let beam = (grp.name.as_str(), grp.length, chord);
                    check_beam(beam, frames, t, &mut warned[g], messages)?;
                }
            }
            Mechanics::Spatial(sys, index) => {
                for (g, (grp, &(root, tip))) in sys.beams.iter().zip(&index.beam_frames).enumerate()
                {
                    let chord = (sys.frame_pose(tip, q).0 - sys.frame_pose(root, q).0).norm();
                    let frames = grp.bodies.clone().filter_map(|body| {
                        let crate::mechanics::multibody3d::Body3::Beam(b) = &sys.bodies[body]
                        else {
                            return None;
                        };
                        let z = sys.body_coords(body, q);
                        let defl = b.largest_transverse(z.rows(7, b.nflex()));
                        Some((b.name.as_str(), b.length, defl))
                    });
                    let beam = (grp.name.as_str(), grp.length, chord);
                    check_beam(beam, frames, t, &mut warned[g], messages)?;
                }
            }
        }
        Ok(())
    }

    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            initialized: self.initialized,
            start_time: self.start_time,
            values: self.values.clone(),
            input_ders: self.input_ders.clone(),
            model: self.model.as_ref().map(Model::save),
        }
    }

    pub fn restore(&mut self, s: &Snapshot) -> Result<(), EngineError> {
        self.values = s.values.clone();
        self.input_ders = s.input_ders.clone();
        self.start_time = s.start_time;
        self.model = None;
        self.initialized = false;
        if let Some(saved) = &s.model {
            let m = self.built()?;
            let (n, k) = (m.state.q.len(), m.state.lambda.len());
            let fits = |st: &GaState| st.q.len() == n && st.lambda.len() == k;
            let ahead_fits = fits(&saved.front) && saved.back.as_ref().is_none_or(fits);
            let point_fits = saved
                .memory
                .point
                .as_ref()
                .is_none_or(|p| p.q.len() == n && p.lambda.len() == k);
            if !fits(&saved.state) || !ahead_fits || !point_fits {
                return Err(EngineError::BadState {
                    message: "the state does not belong to this model".into(),
                });
            }
            if saved.applied_inputs.len() != m.applied_inputs.len() {
                return Err(EngineError::BadState {
                    message: "the state has another number of inputs".into(),
                });
            }
            m.put_back(saved.clone());
        }
        self.initialized = s.initialized;
        Ok(())
    }

    /// A fingerprint of the scene, so that a state is only restored into the same model.
    fn fingerprint(&self) -> u64 {
        // FNV-1a over the canonical scene text.
        let text = self.scene.to_toml_string();
        text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
        })
    }

    pub fn serialize(&self, s: &Snapshot) -> Vec<u8> {
        let mut w = Vec::new();
        w.extend_from_slice(STATE_MAGIC);
        w.extend_from_slice(&STATE_VERSION.to_le_bytes());
        w.extend_from_slice(&self.fingerprint().to_le_bytes());
        w.push(s.initialized as u8);
        w.extend_from_slice(&s.start_time.to_le_bytes());
        write_vec(&mut w, &s.values);
        let ders: Vec<f64> = s.input_ders.iter().flatten().copied().collect();
        write_vec(&mut w, &ders);
        match &s.model {
            None => w.push(0),
            Some(ms) => {
                w.push(1);
                ms.state.write(&mut w);
                ms.front.write(&mut w);
                match &ms.back {
                    None => w.push(0),
                    Some(b) => {
                        w.push(1);
                        b.write(&mut w);
                    }
                }
                ms.stats.write(&mut w);
                write_vec(&mut w, &ms.applied_inputs);
                ms.memory.write(&mut w);
            }
        }
        w
    }

    pub fn deserialize(&self, bytes: &[u8]) -> Result<Snapshot, EngineError> {
        let mut r = Reader::new(bytes);
        let bad = |m: &str| EngineError::BadState {
            message: m.to_string(),
        };
        if r.take(8)? != STATE_MAGIC {
            return Err(bad(
                "not a serialized state of this FMU (wrong magic bytes)",
            ));
        }
        if r.u32()? != STATE_VERSION {
            return Err(bad("serialized state of another format version"));
        }
        if r.u64()? != self.fingerprint() {
            return Err(bad("serialized state of another scene"));
        }
        let initialized = match r.u8()? {
            0 => false,
            1 => true,
            _ => return Err(bad("corrupt flag")),
        };
        let start_time = r.f64()?;
        let values = r.vec()?;
        if values.len() != self.values.len() {
            return Err(bad("wrong number of parameter values"));
        }
        let ders = r.vec()?;
        if ders.len() != 2 * self.values.len() {
            return Err(bad("wrong number of input derivatives"));
        }
        let input_ders = ders.chunks(2).map(|c| [c[0], c[1]]).collect();
        let model = match r.u8()? {
            0 => None,
            1 => {
                let state = GaState::read(&mut r)?;
                let front = GaState::read(&mut r)?;
                let back = match r.u8()? {
                    0 => None,
                    1 => Some(GaState::read(&mut r)?),
                    _ => return Err(bad("corrupt flag")),
                };
                Some(ModelState {
                    state,
                    front,
                    back,
                    stats: Stats::read(&mut r)?,
                    applied_inputs: r.vec()?,
                    memory: Memory::read(&mut r)?,
                })
            }
            _ => return Err(bad("corrupt flag")),
        };
        if r.pos() != bytes.len() {
            return Err(bad("trailing bytes after the state"));
        }
        if values.iter().chain(ders.iter()).any(|v| !v.is_finite()) || !start_time.is_finite() {
            return Err(bad("non-finite values"));
        }
        Ok(Snapshot {
            initialized,
            start_time,
            values,
            input_ders,
            model,
        })
    }
}

impl Model {
    /// Whether the integrator stepped past the communication point t0 (beyond rounding).
    fn is_past(&self, t0: f64) -> bool {
        self.front.t > t0 + SNAP * self.stepper.settings.max_step
    }

    /// At the communication point t0, with the system's inputs set for the step to come and
    /// `ended` the ones the last step ended with: lands the integrator on t0 if it stepped past
    /// it (its last step redone from the state before it, with the inputs it had), and where the
    /// inputs jump, restarts the scheme there from the consistent accelerations with `ended` and
    /// meets the jump. The front is replaced only when all of it succeeded.
    fn meet_inputs(
        &mut self,
        t0: f64,
        h: f64,
        jump: bool,
        ended: Vec<InputValue>,
    ) -> Result<(), EngineError> {
        let next = std::mem::replace(self.system.inputs_mut(), ended);
        let landed = self.land_with_ended_inputs(t0, jump);
        *self.system.inputs_mut() = next;
        let (mut st, before) = landed?;
        if let Some(before) = before {
            let step = self.stepper.next_step(&st).min(h);
            self.stepper
                .meet_jump_from(&self.system, &mut st, &before, step)?;
        }
        self.front = st;
        self.back = None;
        self.state.clone_from(&self.front);
        self.state.t = t0;
        Ok(())
    }

    /// The integrator's state on t0 with the system's inputs as the last step ended them (its
    /// last step redone from `back` where it is past t0), and where the inputs jump, with the
    /// consistent accelerations there and the equations' values before the jump.
    fn land_with_ended_inputs(
        &mut self,
        t0: f64,
        jump: bool,
    ) -> Result<(GaState, Option<integrator::initial::Equated>), EngineError> {
        let mut st = if self.is_past(t0) {
            let Some(back) = self.back.as_ref().filter(|b| b.t <= t0) else {
                return Err(EngineError::BadState {
                    message: format!(
                        "the integrator is at t = {} s past the communication point {t0} s \
                         without the state before its last step",
                        self.front.t
                    ),
                });
            };
            let mut st = back.clone();
            self.stepper
                .step_to(&self.system, &mut st, &mut self.stats, t0)?;
            st
        } else {
            self.front.clone()
        };
        if !jump {
            return Ok((st, None));
        }
        // just after t, as the jump is met (a drive law's jump at t is behind the state)
        let after = st.t * (1.0 + 1e-13) + 1e-13;
        let (qdd, lambda) = integrator::initial::consistent_accelerations(
            &self.system,
            &st.q,
            &st.v,
            after,
            integrator::Scaling::MASS,
        )?;
        st.acc = qdd.clone();
        st.qdd = qdd;
        st.lambda = lambda;
        let before = integrator::initial::Equated::at(&self.system, &st, after);
        Ok((st, Some(before)))
    }

    fn save(&self) -> ModelState {
        ModelState {
            state: self.state.clone(),
            front: self.front.clone(),
            back: self.back.clone(),
            stats: self.stats,
            applied_inputs: self.applied_inputs.clone(),
            memory: self.stepper.memory().clone(),
        }
    }

    fn put_back(&mut self, s: ModelState) {
        self.state = s.state;
        self.front = s.front;
        self.back = s.back;
        self.stats = s.stats;
        self.applied_inputs = s.applied_inputs;
        self.stepper.restore_memory(s.memory);
    }

    /// Advances the state at the communication point to `t_end`: the integrator goes on from
    /// its front until it reaches `t_end` (a unit whose inputs changed at the last point lands
    /// on it, `Engine::sync_inputs`), and the state at `t_end` is the front where it ends
    /// there, else interpolated inside the last step.
    fn advance(&mut self, t_end: f64) -> Result<(), EngineError> {
        // within this of t_end, the integrator's state counts as at t_end
        let snap = SNAP * self.stepper.settings.max_step.min(t_end - self.state.t);
        if self.front.t < t_end - snap {
            self.back = self.stepper.advance(
                &self.system,
                &mut self.front,
                &mut self.stats,
                t_end,
                self.lands,
            )?;
        }
        match &self.back {
            Some(back) if self.front.t - t_end > snap => {
                self.state.interpolate_into(back, &self.front, t_end)
            }
            _ => {
                self.state.clone_from(&self.front);
                self.state.t = t_end;
            }
        }
        Ok(())
    }
}

fn apply(s: &mut Scene, t: ParamTarget, v: f64) {
    use ParamTarget as T;
    match t {
        T::GravityX => s.world.gravity[0] = v,
        T::GravityY => s.world.gravity[1] = v,
        T::GravityZ => s.world.gravity[2] = v,
        T::BeamG(i) => s.beams[i].material.g = Some(v),
        T::BeamIy(i) => s.beams[i].section.iy = Some(v),
        T::BeamIz(i) => s.beams[i].section.iz = Some(v),
        T::BeamTorsion(i) => s.beams[i].section.torsion_constant = Some(v),
        T::SolverAdaptive => s.solver.adaptive = v != 0.0,
        T::SolverTolerance => s.solver.tolerance = v,
        T::SolverMaxStep => s.solver.max_step = v,
        T::SolverRhoInf => s.solver.rho_inf = v,
        T::BeamLength(i) => s.beams[i].length = v,
        T::BeamRho(i) => s.beams[i].material.rho = v,
        T::BeamE(i) => s.beams[i].material.e = v,
        T::BeamArea(i) => s.beams[i].section.area = Some(v),
        T::BeamSecondMoment(i) => s.beams[i].section.second_moment = Some(v),
        T::BeamRayleighAlpha(i) => s.beams[i].rayleigh.alpha = v,
        T::BeamRayleighBeta(i) => s.beams[i].rayleigh.beta = v,
        T::BeamTipDisplacement(i) => s.beams[i].initial.tip_displacement = v,
        T::DriveValue(j) => law_mut(s, j).value = Some(v),
        T::DriveOmega(j) => law_mut(s, j).omega = Some(v),
        T::DriveRampTime(j) => law_mut(s, j).ramp_time = Some(v),
        T::DriveTimeConstant(j) => law_mut(s, j).time_constant = Some(v),
        T::DriveUntil(j) => law_mut(s, j).until = Some(v),
    }
}

fn law_mut(s: &mut Scene, joint: usize) -> &mut crate::scene::LawSpec {
    &mut s.joints[joint]
        .drive
        .as_mut()
        .expect("drive parameters exist only for drives")
        .law
}

/// The validity rules of one beam (name, length, chord from root to tip) and its floating
/// frames (name, length, largest transverse deflection) at time t: a chord longer than the
/// beam is a model out of range (`Stretched`), a frame bent past its length has run away
/// (`Runaway`), past 5 % it is warned about once per beam (`warned`).
fn check_beam<'a>(
    (beam, length, chord): (&str, f64, f64),
    frames: impl Iterator<Item = (&'a str, f64, f64)>,
    t: f64,
    warned: &mut bool,
    messages: &mut Vec<String>,
) -> Result<(), EngineError> {
    // a beam does not stretch: a chord longer than the beam is a model out of range
    if !chord.is_finite() || chord > (1.0 + STRETCH_LIMIT) * length {
        return Err(EngineError::Stretched {
            beam: beam.to_string(),
            t,
            chord,
            length,
        });
    }
    // each floating frame's own deformation must stay small against its length
    for (frame, length, defl) in frames {
        if defl > length || !defl.is_finite() {
            return Err(EngineError::Runaway {
                beam: frame.to_string(),
                t,
                deflection: defl,
                length,
            });
        }
        if defl > 0.05 * length && !*warned {
            *warned = true;
            messages.push(format!(
                "beam '{beam}': deflection {defl:.3e} m of frame '{frame}' at t = {t} s is \
                 {:.1} % of the frame's length, beyond the small-deformation range of a \
                 floating frame; use (more) substructures (or geometric_stiffening for a \
                 spinning beam)",
                100.0 * defl / length
            ));
        }
    }
    Ok(())
}

/// A 3D output of a planar model (a 3D scene reduced to the plane): nothing leaves the plane.
fn planar_3d(
    sys: &crate::mechanics::multibody::System,
    q: &nalgebra::DVector<f64>,
    kind: OutputKind,
) -> f64 {
    use OutputKind as K;
    match kind {
        K::TipDeflectionY(g) => sys.beam_tip_deflection(g, q),
        _ => 0.0, // tip z, deflection along z, twist and body z
    }
}

/// An output of a spatial model.
fn spatial_output(
    m: &Model,
    sys: &System3,
    index: &crate::mechanics::multibody3d::build::SceneIndex,
    kind: OutputKind,
) -> f64 {
    use OutputKind as K;
    let st = &m.state;
    let (q, v) = (&st.q, &st.v);
    // the tip relative to the root frame: position, and rotation root → tip
    let local = |g: usize| {
        let (root, tip) = index.beam_frames[g];
        let (x0, a0) = sys.frame_pose(root, q);
        let (x1, a1) = sys.frame_pose(tip, q);
        (a0.transpose() * (x1 - x0), a0.transpose() * a1)
    };
    let tip = |g: usize| sys.frame_pose(index.beam_frames[g].1, q).0;
    let body = |b: usize| sys.offsets[m.body_index[b]];
    match kind {
        K::TipX(g) => tip(g)[0],
        K::TipY(g) => tip(g)[1],
        K::TipZ(g) => tip(g)[2],
        K::TipDeflectionY(g) | K::TipDeflection(g) => local(g).0[1],
        K::TipDeflectionZ(g) => local(g).0[2],
        // the rotation about the beam axis: exact for a pure twist, the axial part of the
        // relative rotation with bending
        K::TipTwist(g) => {
            let r = local(g).1;
            (r[(2, 1)] - r[(1, 2)]).atan2(r[(1, 1)] + r[(2, 2)])
        }
        K::JointCoordinate(j) => sys.joint_coordinate(m.joint_index[j], q),
        K::JointRate(j) => sys.joint_rate(m.joint_index[j], q, v),
        K::JointEffort(j) => sys.joint_effort(m.joint_index[j], &st.lambda, st.t),
        K::BodyX(b) => q[body(b)],
        K::BodyY(b) => q[body(b) + 1],
        K::BodyZ(b) => q[body(b) + 2],
        K::BodyRotation { body: b, row, col } => {
            let z = sys.body_coords(m.body_index[b], q);
            crate::mechanics::multibody3d::body::frame_of(&z).2[(row, col)]
        }
        K::JointPosition { joint, axis } => {
            let f = sys.joints[m.joint_index[joint]].frames[1];
            sys.frame_pose(f, q).0[axis]
        }
        K::EnergyKinetic => sys.energy(q, v).kinetic,
        K::EnergyStrain => sys.energy(q, v).strain,
        K::EnergyPotential => sys.energy(q, v).potential,
        K::EnergyTotal => sys.energy(q, v).total(),
        _ => common_output(m, kind),
    }
}

/// Outputs that do not depend on the kind of system.
fn common_output(m: &Model, kind: OutputKind) -> f64 {
    use OutputKind as K;
    let st = &m.state;
    match kind {
        K::EnergyWork => st.work,
        K::SolverSteps => m.stats.steps as f64,
        K::SolverNewtonIterations => m.stats.newton_iterations as f64,
        K::SolverJacobians => m.stats.jacobians as f64,
        K::SolverRejectedSteps => m.stats.rejected as f64,
        K::SolverSplitSteps => m.stats.split as f64,
        // of the integrator's own state (an interpolated state between two steps carries the
        // interpolation's error too)
        K::ConstraintResidual => {
            let mut g = nalgebra::DVector::zeros(m.system.m());
            m.system.constraints(&m.front.q, m.front.t, &mut g);
            g.amax()
        }
        K::NextEventTime => crate::unit::interface::next_event_time(&m.system, st.t),
        K::Shape { beam, point, axis } => m.shape.point(&m.system, &st.q, beam, point)[axis],
        K::BeamAxis(g, axis) => crate::unit::shape::axis(&m.system, &st.q, g)[axis],
        // no other output is offered by a scene whose system lacks it
        _ => f64::NAN,
    }
}

fn output(m: &Model, kind: OutputKind) -> f64 {
    use OutputKind as K;
    let sys = match &m.system {
        Mechanics::Planar(sys, _) => sys,
        Mechanics::Spatial(sys, index) => return spatial_output(m, sys, index, kind),
    };
    let st = &m.state;
    let (q, v) = (&st.q, &st.v);
    match kind {
        K::TipDeflection(g) => sys.beam_tip_deflection(g, q),
        K::TipX(g) => sys.beam_tip(g, q).0[0],
        K::TipY(g) => sys.beam_tip(g, q).0[1],
        K::TipPhi(g) => sys.beam_tip(g, q).1,
        K::MidDeflection(g) => sys.beam_transverse(g, q, sys.beam_mid(g, q)),
        K::SectionArea(g) => beam_section(sys, g).area,
        K::SectionSecondMoment(g) => beam_section(sys, g).second_moment,
        K::JointCoordinate(j) => sys.joint_coordinate(m.joint_index[j], q, v).0,
        K::JointRate(j) => sys.joint_coordinate(m.joint_index[j], q, v).1,
        K::JointEffort(j) => sys.joint_effort(m.joint_index[j], &st.lambda, st.t),
        K::BodyX(b) => q[sys.offsets[m.body_index[b]]],
        K::BodyY(b) => q[sys.offsets[m.body_index[b]] + 1],
        K::BodyPhi(b) => q[sys.offsets[m.body_index[b]] + 2],
        // a 3D scene run in the plane: a rotation about z
        K::BodyRotation { body: b, row, col } => {
            let (s, c) = q[sys.offsets[m.body_index[b]] + 2].sin_cos();
            [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]][row][col]
        }
        K::JointPosition { joint, axis } => {
            let f = sys.joints[m.joint_index[joint]].frames[1];
            let p = sys.frame_state(f, q, None).p;
            [p[0], p[1], 0.0][axis]
        }
        K::EnergyKinetic => sys.energy(q, v).kinetic,
        K::EnergyStrain => sys.energy(q, v).strain,
        K::EnergyPotential => sys.energy(q, v).potential,
        K::EnergyTotal => sys.energy(q, v).total(),
        K::TipZ(_) | K::TipDeflectionY(_) | K::TipDeflectionZ(_) | K::TipTwist(_) | K::BodyZ(_) => {
            planar_3d(sys, q, kind)
        }
        _ => common_output(m, kind),
    }
}

fn beam_section(
    sys: &crate::mechanics::multibody::System,
    g: usize,
) -> crate::mechanics::beam::section::Section {
    sys.beams[g].section
}

/// Values and derivatives of the system's inputs, 3 per input.
fn flat_inputs(sys: &Mechanics) -> Vec<f64> {
    sys.inputs()
        .iter()
        .flat_map(|u| [u.value, u.der1, u.der2])
        .collect()
}
