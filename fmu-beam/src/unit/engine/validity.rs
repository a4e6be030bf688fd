//! The validity monitor: a floating frame assumes small deformation; a beam that leaves that
//! range is warned about once, one that runs away refuses the step.

use super::Engine;
use crate::error::EngineError;
use crate::mechanics::Mechanics;

/// Relative stretch of a beam's chord (root to tip) beyond which the step is refused.
const STRETCH_LIMIT: f64 = 0.01;

impl Engine {
    /// The validity monitor: a floating frame assumes small deformation. Beyond 5 % of its
    /// length it warns once per beam; beyond its length the solution has run away (a linear
    /// beam spun above its first bending frequency) and the step is refused, as it is when a
    /// beam's chord (root to tip) is longer than the beam.
    pub(super) fn monitor_validity(&mut self) -> Result<(), EngineError> {
        let Engine {
            model,
            warned,
            messages,
            ..
        } = self;
        let m = model.as_ref().expect("model built");
        let (q, t) = (&m.state.q, m.state.t);
        match &m.system {
            Mechanics::Planar(sys) => {
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
