//! A built model's integration: where the integrator is against the communication point,
//! landing there when the inputs change, and advancing to the next point.

use super::{Model, ModelState};
use crate::error::EngineError;
use crate::integrator::{self, GaState};
use crate::mechanics::multibody::law::InputValue;
use crate::mechanics::Mechanics;

/// Within this fraction of `max_step` of a communication point, the integrator's state counts
/// as on it (not past it).
const SNAP: f64 = 1e-6;

impl Model {
    /// Whether the integrator stepped past the communication point t0 (beyond rounding).
    pub(super) fn is_past(&self, t0: f64) -> bool {
        self.front.t > t0 + SNAP * self.stepper.settings.max_step
    }

    /// At the communication point t0, with the system's inputs set for the step to come and
    /// `ended` the ones the last step ended with: lands the integrator on t0 if it stepped past
    /// it (its last step redone from the state before it, with the inputs it had), and where the
    /// inputs jump, restarts the scheme there from the consistent accelerations with `ended` and
    /// meets the jump; `next_loads` writes the tunable loads of the step to come into the system
    /// (it holds the last step's until then). The front is replaced only when all of it
    /// succeeded.
    pub(super) fn meet_inputs(
        &mut self,
        t0: f64,
        h: f64,
        jump: bool,
        ended: Vec<InputValue>,
        next_loads: impl FnOnce(&mut Mechanics),
    ) -> Result<(), EngineError> {
        let next = std::mem::replace(self.system.inputs_mut(), ended);
        let landed = self.land_with_ended_inputs(t0, jump);
        *self.system.inputs_mut() = next;
        next_loads(&mut self.system);
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
    pub(super) fn land_with_ended_inputs(
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

    pub(super) fn save(&self) -> ModelState {
        ModelState {
            time: self.time,
            state: self.state.clone(),
            front: self.front.clone(),
            back: self.back.clone(),
            stats: self.stats,
            applied_inputs: self.applied_inputs.clone(),
            applied_loads: self.applied_loads.clone(),
            memory: self.stepper.memory().clone(),
        }
    }

    /// [`Model::save`] into the storage of the last save (`spare`), without allocating where
    /// the sizes are the same.
    pub(super) fn save_reusing(&mut self) -> ModelState {
        let Some(mut s) = self.spare.take() else {
            return self.save();
        };
        let ModelState {
            time,
            state,
            front,
            back,
            stats,
            applied_inputs,
            applied_loads,
            memory,
        } = &mut s;
        *time = self.time;
        state.clone_from(&self.state);
        front.clone_from(&self.front);
        back.clone_from(&self.back);
        *stats = self.stats;
        applied_inputs.clone_from(&self.applied_inputs);
        applied_loads.clone_from(&self.applied_loads);
        memory.clone_from(self.stepper.memory());
        s
    }

    pub(super) fn put_back(&mut self, s: ModelState) {
        self.time = s.time;
        self.state = s.state;
        self.front = s.front;
        self.back = s.back;
        self.stats = s.stats;
        self.applied_inputs = s.applied_inputs;
        self.applied_loads = s.applied_loads;
        self.stepper.restore_memory(s.memory);
    }

    /// Advances the state at the communication point to `t_end`: the integrator goes on from
    /// its front until it reaches `t_end` (a unit whose inputs changed at the last point lands
    /// on it, `Engine::sync_inputs`), and the state at `t_end` is the front where it ends
    /// there, else interpolated inside the last step.
    pub(super) fn advance(&mut self, t_end: f64) -> Result<(), EngineError> {
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
