//! FMU state (fmi2GetFMUstate, fmi2SerializeFMUstate): a snapshot of everything that changes
//! while an instance runs, its restore (all or nothing: a refused one leaves the instance as it
//! was), and its byte form (versioned, fingerprinted by the scene, closed by a checksum, read
//! back with bounds checks and the scene's rules on its parameter values).

use super::{Engine, Model, ModelState, Snapshot};
use crate::error::EngineError;
use crate::integrator::{write_vec, GaState, Memory, Reader, Stats};

const STATE_MAGIC: &[u8; 8] = b"FMUBEAM\0";
const STATE_VERSION: u32 = 8;

/// FNV-1a (64 bit) of `bytes` from `seed`: the scene's fingerprint and the serialized state's
/// checksum. Any one changed byte changes it (each step is a bijection of the running value).
fn fnv1a(seed: u64, bytes: &[u8]) -> u64 {
    bytes.iter().fold(seed, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

impl Engine {
    /// fmi2GetFMUstate: a copy of everything that changes while the instance runs.
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            identity: self.fingerprint(),
            initialized: self.initialized,
            start_time: self.start_time,
            values: self.values.clone(),
            input_ders: self.input_ders.clone(),
            model: self.model.as_ref().map(Model::save),
        }
    }

    /// fmi2SetFMUstate: the instance as it was at `s` (the model rebuilt from its parameter
    /// values, the integration state put back). A state of another model is refused, and a
    /// refused restore leaves the instance exactly as it was.
    pub fn restore(&mut self, s: &Snapshot) -> Result<(), EngineError> {
        if s.identity != self.fingerprint() || s.values.len() != self.values.len() {
            return Err(EngineError::BadState {
                message: "the state belongs to another model (its scene differs)".into(),
            });
        }
        let before = (
            std::mem::replace(&mut self.values, s.values.clone()),
            std::mem::replace(&mut self.input_ders, s.input_ders.clone()),
            std::mem::replace(&mut self.start_time, s.start_time),
            self.model.take(),
            std::mem::replace(&mut self.initialized, false),
        );
        let result = self
            .check_experiment(s.start_time, None)
            .map_err(|e| EngineError::BadState {
                message: format!("its start time: {e}"),
            })
            .and_then(|()| self.put_back_model(s));
        match result {
            Ok(()) => self.initialized = s.initialized,
            Err(_) => {
                (
                    self.values,
                    self.input_ders,
                    self.start_time,
                    self.model,
                    self.initialized,
                ) = before;
            }
        }
        result
    }

    /// The model of the values just restored, with the integration state of `s`.
    fn put_back_model(&mut self, s: &Snapshot) -> Result<(), EngineError> {
        let Some(saved) = &s.model else {
            return Ok(());
        };
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
        if saved.applied_inputs.len() != m.applied_inputs.len()
            || saved.applied_loads.len() != m.applied_loads.len()
        {
            return Err(EngineError::BadState {
                message: "the state has another number of inputs or tunable loads".into(),
            });
        }
        if let Some(why) = implausible(m, saved) {
            return Err(EngineError::BadState {
                message: format!("it is no state of this model: {why}"),
            });
        }
        m.put_back(saved.clone());
        Ok(())
    }

    /// A fingerprint of the scene, so that a state is only restored into the same model.
    fn fingerprint(&self) -> u64 {
        *self
            .identity
            .get_or_init(|| Engine::identity_of(&self.scene))
    }

    /// The fingerprint of a scene: FNV-1a over its canonical text.
    pub(super) fn identity_of(scene: &crate::scene::Scene) -> u64 {
        fnv1a(FNV_OFFSET, scene.to_toml_string().as_bytes())
    }

    /// fmi2SerializeFMUstate: `s` as bytes, headed by the format's magic, version and the
    /// scene's fingerprint.
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
                w.extend_from_slice(&ms.time.to_le_bytes());
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
                write_vec(&mut w, &ms.applied_loads);
                ms.memory.write(&mut w);
            }
        }
        let sum = fnv1a(FNV_OFFSET, &w);
        w.extend_from_slice(&sum.to_le_bytes());
        w
    }

    /// fmi2DeSerializeFMUstate: the snapshot of [`Engine::serialize`]'s bytes, every length
    /// checked; bytes of another version or scene, bytes whose checksum does not match (a
    /// changed or truncated state), and parameter values the scene's rules refuse are refused.
    pub fn deserialize(&self, bytes: &[u8]) -> Result<Snapshot, EngineError> {
        let bad = |m: &str| EngineError::BadState {
            message: m.to_string(),
        };
        let Some(split) = bytes.len().checked_sub(8) else {
            return Err(bad("not a serialized state of this FMU (too short)"));
        };
        let (bytes, sum) = bytes.split_at(split);
        let mut r = Reader::new(bytes);
        if r.take(8)? != STATE_MAGIC {
            return Err(bad(
                "not a serialized state of this FMU (wrong magic bytes)",
            ));
        }
        if r.u32()? != STATE_VERSION {
            return Err(bad("serialized state of another format version"));
        }
        if sum != fnv1a(FNV_OFFSET, bytes).to_le_bytes() {
            return Err(bad(
                "the serialized state is corrupt (its checksum does not match its bytes)",
            ));
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
                let time = r.f64()?;
                let state = GaState::read(&mut r)?;
                let front = GaState::read(&mut r)?;
                let back = match r.u8()? {
                    0 => None,
                    1 => Some(GaState::read(&mut r)?),
                    _ => return Err(bad("corrupt flag")),
                };
                Some(ModelState {
                    time,
                    state,
                    front,
                    back,
                    stats: Stats::read(&mut r)?,
                    applied_inputs: r.vec()?,
                    applied_loads: r.vec()?,
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
        if let Err(e) = self.scene_with(&values).validate("serialized state") {
            return Err(EngineError::BadState {
                message: format!("its parameter values break the scene's rules: {e}"),
            });
        }
        if let Some(m) = &model {
            let finite = |st: &GaState| {
                st.t.is_finite()
                    && st.h.is_finite()
                    && [&st.q, &st.v, &st.acc, &st.qdd, &st.lambda]
                        .iter()
                        .all(|x| x.iter().all(|v| v.is_finite()))
            };
            let states = [Some(&m.state), Some(&m.front), m.back.as_ref()];
            let mut applied = m.applied_inputs.iter().chain(&m.applied_loads);
            if !states.into_iter().flatten().all(finite) || !applied.all(|v| v.is_finite()) {
                return Err(bad("non-finite values in the integration state"));
            }
        }
        let snapshot = Snapshot {
            identity: self.fingerprint(),
            initialized,
            start_time,
            values,
            input_ders,
            model,
        };
        // checked as fmi2SetFMUstate will check it (on a copy: this instance stays as it is),
        // so that a state no restore takes is refused when read
        self.clone().restore(&snapshot)?;
        Ok(snapshot)
    }
}

/// Why `saved` cannot be a state of the model `m` built from its parameter values, if it
/// cannot: its times not those of a run from `m`'s start (the communication point at or after
/// the start, the system's time its distance from the start, the integrator at most one
/// largest step past it and the step before at most there), or a state or the integrator's
/// memory implausible for `m`'s system (`Stepper::implausible`: coordinates, rates and
/// multipliers within bounds, the proposed step within the stepper's, the joints closed).
fn implausible(m: &Model, saved: &ModelState) -> Option<String> {
    use crate::scene::Short;
    let (time, st, front) = (saved.time, &saved.state, &saved.front);
    if !(time.is_finite() && time >= m.origin) {
        return Some(format!(
            "its time {} s is not a finite time at or after its start {} s",
            Short(time),
            Short(m.origin)
        ));
    }
    let since = time - m.origin;
    if !crate::integrator::within(st.t - since, 2.0 * super::times::resolution(time)) {
        return Some(format!(
            "its time since the start, {} s, is not its time {} s less its start {} s",
            Short(st.t),
            Short(time),
            Short(m.origin)
        ));
    }
    let largest = crate::scene::MAX_STEP;
    let ahead = front.t - st.t;
    if !(ahead >= -1e-6 * largest && ahead <= largest) {
        return Some(format!(
            "the integrator is {} s from the communication point, beyond one largest step ({} s)",
            Short(ahead),
            Short(largest)
        ));
    }
    if let Some(back) = &saved.back {
        if !(back.t <= front.t && st.t - back.t <= largest) {
            return Some("the state before the integrator's last step is not before it".into());
        }
    }
    let sys = &m.system;
    let stepper = &m.stepper;
    stepper
        .implausible(sys, st, "the state at the communication point", false)
        .or_else(|| stepper.implausible(sys, front, "the integrator's state", true))
        .or_else(|| {
            let back = saved.back.as_ref()?;
            stepper.implausible(
                sys,
                back,
                "the state before the integrator's last step",
                true,
            )
        })
        .or_else(|| stepper.implausible_memory(sys, &saved.memory, front.t))
}
