//! fmi2SetReal, fmi2SetInteger, fmi2SetBoolean and fmi2SetRealInputDerivatives, all or nothing
//! (issue 35): every value of a call is checked first (reference and type, finite, settable
//! now, the parameters against the scene's rules together), and only an accepted call changes
//! the instance.

use super::*;

/// One checked change of an fmi2Set* call, applied only when the whole call is accepted.
#[derive(Debug, Clone, Copy)]
enum Change {
    /// The value of the input variable `i` (input slot `slot`).
    Input { i: usize, slot: usize, value: f64 },
    /// The derivative of `order` (1 or 2) of the input variable `i` (input slot `slot`).
    Derivative {
        i: usize,
        slot: usize,
        order: usize,
        value: f64,
    },
    /// The value of the parameter variable `i`.
    Parameter { i: usize, value: f64 },
}

impl Engine {
    /// fmi2SetRealInputDerivatives of one input: its derivative of `order` (1 or 2).
    pub fn set_input_derivative(
        &mut self,
        vr: u32,
        order: i32,
        value: f64,
    ) -> Result<(), EngineError> {
        self.set_input_derivatives(&[vr], &[order], &[value])
    }

    /// fmi2SetRealInputDerivatives: derivatives of `order` (1 or 2) of Real inputs, used to
    /// extrapolate them over the next communication step; all or nothing (a refused call
    /// changes nothing).
    pub fn set_input_derivatives(
        &mut self,
        vr: &[u32],
        order: &[i32],
        value: &[f64],
    ) -> Result<(), EngineError> {
        let mut changes = Vec::with_capacity(vr.len());
        for ((&r, &k), &v) in vr.iter().zip(order).zip(value) {
            changes.push(self.check_input_derivative(r, k, v)?);
        }
        for c in &changes {
            self.apply(c);
        }
        Ok(())
    }

    /// The change of one input derivative, or why it is refused.
    fn check_input_derivative(
        &self,
        vr: u32,
        order: i32,
        value: f64,
    ) -> Result<Change, EngineError> {
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
        Ok(Change::Derivative {
            i,
            slot,
            order: order as usize,
            value,
        })
    }

    /// Sets several Real variables as one fmi2SetReal call (all or nothing, as
    /// [`Engine::set_many`]).
    pub fn set_reals(&mut self, vr: &[u32], value: &[f64]) -> Result<(), EngineError> {
        self.set_many(vr, VarType::Real, value)
    }

    /// Sets several variables of one type as one fmi2Set* call, all or nothing: every value is
    /// checked first (its reference and type, finite, settable now, the parameters against the
    /// scene's rules together), and a refused call changes nothing. Then the inputs' values are
    /// applied before the inputs' derivatives (a value resets its derivatives), whatever the
    /// order of the references.
    pub fn set_many(&mut self, vr: &[u32], ty: VarType, value: &[f64]) -> Result<(), EngineError> {
        let mut changes = Vec::with_capacity(vr.len());
        for (&r, &v) in vr.iter().zip(value) {
            changes.push(self.check_set(r, ty, v)?);
        }
        let parameters: Vec<(usize, f64)> = changes
            .iter()
            .filter_map(|c| match *c {
                Change::Parameter { i, value } => Some((i, value)),
                _ => None,
            })
            .collect();
        let settings = if parameters.is_empty() {
            None
        } else {
            Some(self.check_parameters(&parameters)?)
        };
        for c in changes
            .iter()
            .filter(|c| !matches!(c, Change::Derivative { .. }))
        {
            self.apply(c);
        }
        for c in changes
            .iter()
            .filter(|c| matches!(c, Change::Derivative { .. }))
        {
            self.apply(c);
        }
        if let Some(settings) = settings {
            let loads = self.wanted_loads();
            match &mut self.model {
                Some(m) if self.initialized => {
                    m.stepper.set_settings(settings);
                    // what the outputs at this point see; the step to come meets the change
                    tunable_loads::write_loads(&mut m.system, &self.load_parts, &loads);
                    self.feedthrough = Default::default();
                }
                _ => self.model = None,
            }
        }
        Ok(())
    }

    pub(super) fn set(&mut self, vr: u32, ty: VarType, value: f64) -> Result<(), EngineError> {
        self.set_many(&[vr], ty, &[value])
    }

    /// What setting `value` on `vr` would change, or why it is refused (nothing changed yet;
    /// a parameter's value is checked against the scene's rules with the call's others).
    fn check_set(&self, vr: u32, ty: VarType, value: f64) -> Result<Change, EngineError> {
        let i = self.lookup(vr, ty)?;
        let var = &self.table.variables[i];
        let name = var.name.clone();
        if !value.is_finite() {
            return Err(EngineError::NonFiniteValue { name, value });
        }
        match var.binding {
            Binding::InputDerivative { slot, order } => {
                return Ok(Change::Derivative {
                    i: self.input_var(slot),
                    slot,
                    order: order as usize,
                    value,
                })
            }
            Binding::Input(slot) => return Ok(Change::Input { i, slot, value }),
            _ => {}
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
        if let (true, Binding::Parameter(target), Some(m)) =
            (self.initialized, var.binding, &self.model)
        {
            if tunable_loads::part_of(target).is_some_and(|p| !m.system.holds_load_part(p)) {
                return Err(EngineError::NotSettable {
                    name,
                    reason: "the scene runs as planar and this component is out of its plane"
                        .into(),
                });
            }
        }
        Ok(Change::Parameter { i, value })
    }

    /// The solver settings of the parameter values with `changes` applied, if the scene's rules
    /// accept them all. A refusal names the first value the rules refuse on its own, or (where
    /// only the combination breaks a rule) the call's last one.
    fn check_parameters(&self, changes: &[(usize, f64)]) -> Result<Settings, EngineError> {
        let with = |changes: &[(usize, f64)]| {
            let mut trial = self.values.clone();
            for &(i, v) in changes {
                trial[i] = v;
            }
            let scene = self.scene_with(&trial);
            scene.validate("parameters").map(|()| scene)
        };
        match with(changes) {
            Ok(scene) => Ok(Settings::from_scene(&scene)),
            Err(joint) => {
                let alone = changes
                    .iter()
                    .find_map(|c| with(std::slice::from_ref(c)).err().map(|e| (*c, e)));
                let &last = changes.last().expect("at least one change");
                let ((i, value), e) = alone.unwrap_or((last, joint));
                let rule = match e {
                    crate::scene::SceneError::Invalid { rule, .. } => rule,
                    other => other.to_string(),
                };
                Err(EngineError::InvalidValue {
                    name: self.table.variables[i].name.clone(),
                    value,
                    rule,
                })
            }
        }
    }

    /// Applies a checked change.
    fn apply(&mut self, c: &Change) {
        match *c {
            Change::Input { i, slot, value } => {
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
            }
            Change::Derivative {
                i,
                slot,
                order,
                value,
            } => {
                self.input_ders[i][order - 1] = value;
                if let Some(m) = &mut self.model {
                    let u = &mut m.system.inputs_mut()[slot];
                    if order == 1 {
                        u.der1 = value;
                    } else {
                        u.der2 = value;
                    }
                }
            }
            Change::Parameter { i, value } => self.values[i] = value,
        }
    }
}
