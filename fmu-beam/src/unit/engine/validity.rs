//! The validity monitor: a floating frame assumes small deformation; a beam that leaves that
//! range is warned about once, one that runs away refuses the step.

use super::{Engine, Model};
use crate::error::EngineError;
use crate::mechanics::multibody3d::Body3;
use crate::mechanics::Mechanics;
use nalgebra::Vector3;

/// Relative stretch of a beam's chord (root to tip) beyond which the step is refused.
const STRETCH_LIMIT: f64 = 0.01;

impl Engine {
    /// The validity monitor: a floating frame assumes small deformation. Beyond 5 % of its
    /// length it warns once per beam; beyond its length the solution has run away (a linear
    /// beam spun above its first bending frequency) and the step is refused, as it is when a
    /// beam's chord (root to tip) is longer than the beam. A good state's chords are kept.
    pub(super) fn monitor_validity(&mut self) -> Result<(), EngineError> {
        let m = self.model.as_ref().expect("model built");
        let t = m.time;
        let beams = beam_states(m);
        for (g, beam) in beams.iter().enumerate() {
            let frames = beam.frames.iter().copied();
            let head = (beam.name, beam.length, beam.chord.norm());
            check_beam(head, frames, t, &mut self.warned[g], &mut self.messages)?;
        }
        // the chords of a good state, for the spin a diagnosis reads
        self.record_chords(t, beams.into_iter().map(|b| b.chord).collect());
        Ok(())
    }
}

/// A beam at one state, as the validity monitor and the diagnosis of a failed step read it;
/// its names borrowed from the model (the monitor runs at every communication point).
pub(super) struct BeamState<'m> {
    /// The beam's name in the scene.
    pub name: &'m str,
    /// Its length (m).
    pub length: f64,
    /// From root to tip, world axes (m; z = 0 in a planar scene).
    pub chord: Vector3<f64>,
    /// Each floating frame: name, length (m), largest transverse deflection (m).
    pub frames: Vec<(&'m str, f64, f64)>,
}

/// Every beam of the model at its current communication point, in the system's order.
pub(super) fn beam_states(m: &Model) -> Vec<BeamState<'_>> {
    let q = &m.state.q;
    match &m.system {
        Mechanics::Planar(sys) => sys
            .beams
            .iter()
            .enumerate()
            .map(|(g, grp)| {
                let z0 = sys.body_coords(grp.bodies.start, q);
                let (tip, _) = sys.beam_tip(g, q);
                let frames = grp.bodies.clone().filter_map(|body| {
                    let b = sys.beam(body)?;
                    let defl = b.largest_transverse(sys.body_coords(body, q));
                    Some((b.name.as_str(), b.length, defl))
                });
                BeamState {
                    name: grp.name.as_str(),
                    length: grp.length,
                    chord: Vector3::new(tip[0] - z0[0], tip[1] - z0[1], 0.0),
                    frames: frames.collect(),
                }
            })
            .collect(),
        Mechanics::Spatial(sys, index) => sys
            .beams
            .iter()
            .zip(&index.beam_frames)
            .map(|(grp, &(root, tip))| {
                let frames = grp.bodies.clone().filter_map(|body| {
                    let Body3::Beam(b) = &sys.bodies[body] else {
                        return None;
                    };
                    let z = sys.body_coords(body, q);
                    let defl = b.largest_transverse(z.rows(7, b.nflex()));
                    Some((b.name.as_str(), b.length, defl))
                });
                BeamState {
                    name: grp.name.as_str(),
                    length: grp.length,
                    chord: sys.frame_pose(tip, q).0 - sys.frame_pose(root, q).0,
                    frames: frames.collect(),
                }
            })
            .collect(),
    }
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
                 floating frame: more substructures extend it (for a spinning beam, or \
                 geometric_stiffening); where an input acts on a small effective inertia (said \
                 at initialization, log category logInformation), a sampled loop on it grows \
                 the deflection",
                100.0 * defl / length
            ));
        }
    }
    Ok(())
}
