//! What a failed step's message says of its cause: the unit checks the causes it can see and
//! names those that hold, with their figures and what to change (`docs/robustness.md`, "When a
//! step fails"):
//!
//! (a) a force or torque input on a small effective inertia at the communication step in use
//!     (`unit::input_inertia`): it changed at this step, and either it is a drive whose
//!     inertia is below `SMALL_SHARE` of the rigid value, or the feedback seen between the last two
//!     communication points, k = |Δu / Δ(bᵀq')|, is beyond half the sampled loop's limit
//!     k h / J_eff = 2 (it mixes a stiffness's share and the beam's own response in);
//! (b) a beam without geometric stiffening spun at [`NEAR_SPIN`] × its first bending frequency
//!     or more, the spin being the mean rate of its chord (root to tip) over the last
//!     [`SPIN_POINTS`] communication points, so that an oscillation does not count as a spin;
//! (c) a runaway deflection: the validity monitor refused the step, or a floating frame is bent
//!     beyond 5 % of its length at the last good state.
//!
//! None holding, the message says the cause is unknown, with the step and the time.

use super::validity::beam_states;
use super::Engine;
use crate::error::EngineError;
use nalgebra::Vector3;

/// A spin at this share of a beam's first bending frequency or more counts as near it: the
/// share at which `auto` turns geometric stiffening on (`SPIN_RATIO`). A linear frame runs away
/// well before the spin reaches the frequency: C4's single frame at 0.48 ω₁ (Ω = 1.4 rad/s).
pub const NEAR_SPIN: f64 = crate::unit::effects::SPIN_RATIO;

/// Communication points over which a beam's spin is averaged.
pub const SPIN_POINTS: usize = 8;

/// The inputs and their joints' speeds at one communication point, as a doStep started there.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct InputProbe {
    pub(super) t: f64,
    /// Per entry of `Engine::inertias`: the input's value and its joint's speed bᵀq'.
    values: Vec<(f64, f64)>,
}

impl Engine {
    /// At the start of a doStep from the last good state: the inputs as set for this step and
    /// their joints' speeds (the previous point's kept for the diagnosis).
    pub(super) fn probe_inputs(&mut self) {
        let Some(m) = self.model.as_ref() else {
            return;
        };
        let values = self
            .inertias
            .iter()
            .flatten()
            .map(|i| (self.values[self.input_var(i.slot)], i.speed(&m.state.v)))
            .collect();
        let probe = InputProbe { t: m.time, values };
        match &self.probes[1] {
            Some(last) if last.t == probe.t => {}
            _ => self.probes[0] = self.probes[1].take(),
        }
        self.probes[1] = Some(probe);
    }

    /// After a good step: each beam's chord at t, for the spin of (b).
    pub(super) fn record_chords(&mut self, t: f64, chords: Vec<Vector3<f64>>) {
        if self.chords.len() == SPIN_POINTS {
            self.chords.pop_front();
        }
        self.chords.push_back((t, chords));
    }

    /// The failure of the step from t of size h, with the causes that hold (the state is back
    /// at the last good one).
    pub(super) fn diagnose(&self, err: EngineError, t: f64, h: f64) -> EngineError {
        if !err.is_discard() {
            return err;
        }
        let mut held = Vec::new();
        held.extend(self.small_inertia(h));
        held.extend(self.spin_near_bending());
        let (a_or_b, runaway) = (!held.is_empty(), self.runaway(&err));
        if let Some(r) = runaway {
            held.push(if a_or_b {
                let n = held.len();
                format!(
                    "{r} (the consequence of the cause{} above)",
                    if n > 1 { "s" } else { "" }
                )
            } else {
                format!(
                    "{r}: the floating frame's small-deformation model is out of its range; \
                     (more) substructures extend it"
                )
            });
        }
        let diagnosis = if held.is_empty() {
            format!(
                "The unit checked for an input on a small effective inertia, a beam spun near its \
                 first bending frequency and a runaway deflection, and found none: the cause is \
                 unknown (the step from t = {} s of {h:.3e} s failed; the last good state is kept)",
                rounded(t)
            )
        } else {
            format!("Cause found: {}", held.join("; "))
        };
        EngineError::Diagnosed {
            cause: Box::new(err),
            diagnosis,
        }
    }

    /// (a): each input that changed at this step and acts on a small effective inertia, or
    /// whose observed feedback is beyond half the sampled limit.
    fn small_inertia(&self, h: f64) -> Vec<String> {
        let [Some(prev), Some(now)] = &self.probes else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (i, inertia) in self.inertias.iter().flatten().enumerate() {
            let ((u0, y0), (u1, y1)) = (prev.values[i], now.values[i]);
            let (du, dy) = (u1 - u0, y1 - y0);
            if du == 0.0 {
                continue;
            }
            let j = inertia.effective;
            let gain = (dy != 0.0).then(|| (du / dy).abs());
            let over = gain.map(|g| g * h / j);
            if !(inertia.is_small() || over.is_some_and(|r| r > 1.0)) {
                continue;
            }
            let (ju, eu, su) = inertia.units();
            let per = su.trim_end_matches("/s");
            let rigid = if inertia.rigid.is_finite() {
                format!(
                    " ({:.2e} % of the {:.4} {ju} the attached bodies present when held rigid)",
                    100.0 * inertia.share(),
                    inertia.rigid
                )
            } else {
                String::new()
            };
            let observed = match gain {
                Some(g) => format!(
                    "; between t = {} s and {} s the input changed by {du:.3e} {eu} while its \
                     joint's speed changed by {dy:.3e} {su}: a feedback of about {g:.3e} {eu} s/{per}, \
                     {} × that limit (a shorter step, below {:.3e} s, would be within it)",
                    rounded(prev.t),
                    rounded(now.t),
                    times(g * h / (2.0 * j)),
                    2.0 * j / g,
                ),
                None => String::new(),
            };
            out.push(format!(
                "input '{}' acts on an effective {} of {j:.3e} {ju}{rigid}; at the communication \
                 step h = {h:.3e} s a loop that holds it over h is stable only for a damping gain \
                 below 2J/h = {:.3e} {eu} s/{per} and a stiffness below 4J/h² = {:.3e} {eu}/{per}\
                 {observed}; add rotor or hub inertia at this input (on both sides of a joint \
                 between two parts), reduce the communication step, or filter the input",
                inertia.name,
                if inertia.torque { "inertia" } else { "mass" },
                2.0 * j / h,
                4.0 * j / (h * h),
            ));
        }
        out
    }

    /// (b): each beam without geometric stiffening whose chord's mean spin over the last
    /// communication points is at least [`NEAR_SPIN`] × its first bending frequency.
    fn spin_near_bending(&self) -> Vec<String> {
        let (Some((t0, first)), Some((t1, last))) = (self.chords.front(), self.chords.back())
        else {
            return Vec::new();
        };
        if t1 <= t0 {
            return Vec::new();
        }
        let scene = self.scene_with(&self.values);
        let Some(m) = self.model.as_ref() else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (g, beam) in beam_states(m).iter().enumerate() {
            if g >= first.len().min(last.len()) {
                break;
            }
            // the rotations between consecutive chords add up; an oscillation's cancel
            let turned: Vector3<f64> = self
                .chords
                .iter()
                .zip(self.chords.iter().skip(1))
                .map(|((_, a), (_, b))| rotation(&a[g], &b[g]))
                .sum();
            let spin = turned.norm() / (t1 - t0);
            let Some((k, spec)) = scene
                .beams
                .iter()
                .enumerate()
                .find(|(_, b)| b.name == beam.name)
            else {
                continue;
            };
            let effects = &self.effects.beams[k];
            if effects.rigid || effects.options.geometric_stiffening {
                continue;
            }
            let w1 = crate::unit::effects::first_bending_frequency(spec);
            if spin >= NEAR_SPIN * w1 {
                out.push(format!(
                    "beam '{}' spins at {spin:.4} rad/s (its chord's mean rate over t = {} to \
                     {} s), {} × its first bending frequency {w1:.4} rad/s, without \
                     geometric stiffening: a linear floating frame spun near or above that \
                     frequency softens without bound; use (more) substructures or \
                     geometric_stiffening",
                    spec.name,
                    rounded(*t0),
                    rounded(*t1),
                    times(spin / w1)
                ));
            }
        }
        out
    }

    /// (c): the validity monitor's refusal, or the largest frame deflection beyond 5 % of its
    /// frame's length at the last good state.
    fn runaway(&self, err: &EngineError) -> Option<String> {
        match err.cause() {
            EngineError::Runaway {
                beam,
                deflection,
                length,
                ..
            } => {
                return Some(format!(
                    "a runaway deflection: frame '{beam}' bent {deflection:.3e} m, beyond its \
                     length {length} m"
                ))
            }
            EngineError::Stretched {
                beam,
                chord,
                length,
                ..
            } => {
                return Some(format!(
                    "a runaway deflection: beam '{beam}' reached {chord:.4} m from root to tip, \
                     more than its length {length} m"
                ))
            }
            _ => {}
        }
        let m = self.model.as_ref()?;
        let (frame, length, defl) = beam_states(m)
            .into_iter()
            .flat_map(|b| b.frames)
            .max_by(|a, b| (a.2 / a.1).total_cmp(&(b.2 / b.1)))?;
        (defl > 0.05 * length).then(|| {
            format!(
                "a runaway deflection: frame '{frame}' is bent {defl:.3e} m at the last good \
                 state, {:.1} % of its length {length} m (a floating frame covers a few %)",
                100.0 * defl / length
            )
        })
    }
}

/// A communication point's time without the rounding of its sums (0.013000000000000005).
fn rounded(t: f64) -> f64 {
    (t * 1e9).round() / 1e9
}

/// A ratio with three significant digits or so.
fn times(x: f64) -> String {
    if x >= 10.0 {
        format!("{x:.0}")
    } else {
        format!("{x:.2}")
    }
}

/// The rotation vector turning direction a into direction b (about a × b, by the angle between).
fn rotation(a: &Vector3<f64>, b: &Vector3<f64>) -> Vector3<f64> {
    let axis = a.cross(b);
    let s = axis.norm();
    if s == 0.0 {
        return Vector3::zeros();
    }
    axis * (s.atan2(a.dot(b)) / s)
}

/// What initialization says of each drive input on a small effective inertia (`Engine::built`):
/// information (the limits a sampled loop on it must keep), logged with fmi2OK; a loop that
/// breaks them is named in the failed step's message (cause (a)).
pub(super) fn inertia_notes(
    inertias: &[crate::unit::input_inertia::InputInertia],
    h: f64,
) -> Vec<String> {
    inertias
        .iter()
        .filter(|i| i.is_small())
        .map(|i| i.note(h))
        .collect()
}
