//! The cost model of the effects: an operation count of one step (residual, tangents, LU of
//! the iteration matrix) of the resolved system, and each effect's share of it, as
//! `fmu-harness explain` prints it; `make bench` measures the time.

use super::*;

/// Operations (the unit of [`step_cost`]) to read every shape output of beam `b` once: each
/// coordinate read evaluates its point, S_p q_f over the frame's n_f coordinates, a rotation
/// and a translation.
pub(super) fn shape_read_cost(b: &BeamSpec, e: &BeamEffects) -> f64 {
    let nf = if e.rigid {
        0
    } else {
        let nodal = nodal_coordinates(b, Scene::beam_layout(b).0, e.options.axial);
        e.options.modes.map_or(nodal, |m| m.min(nodal))
    };
    let points = crate::unit::shape::stations(b, e.rigid).len() as f64;
    2.0 * points * (2.0 * nf as f64 + 6.0)
}

/// Deformation coordinates of one frame of beam `b` with `elements` elements.
pub(super) fn nodal_coordinates(b: &BeamSpec, elements: usize, axial: bool) -> usize {
    let _ = b; // both frames (tangent, pinned) remove three nodal coordinates
    let full = 3 * (elements + 1) - 3;
    if axial {
        full
    } else {
        full - elements // u of every node but the one the frame already removes
    }
}

/// Number of coordinates of the resolved system.
pub(super) fn coordinates(scene: &Scene, effects: &Effects) -> usize {
    frames(scene, effects)
        .iter()
        .map(|f| 3 + f.nf)
        .sum::<usize>()
        + 3 * scene.bodies.len()
}

/// One floating frame of the resolved system, for the cost model.
pub(super) struct FrameCost {
    nf: usize,
    elements: usize,
    options: BeamOptions,
}

pub(super) fn frames(scene: &Scene, effects: &Effects) -> Vec<FrameCost> {
    let mut out = Vec::new();
    for (b, e) in scene.beams.iter().zip(&effects.beams) {
        let (elements, k) = Scene::beam_layout(b);
        let k = if e.rigid { 1 } else { k };
        let nf = if e.rigid {
            0
        } else {
            let nodal = nodal_coordinates(b, elements, e.options.axial);
            e.options.modes.map_or(nodal, |m| m.min(nodal))
        };
        for _ in 0..k {
            out.push(FrameCost {
                nf,
                elements,
                options: e.options,
            });
        }
    }
    out
}

/// Operation count of one step with ≈ 3 Newton iterations: residuals and tangents of every
/// frame, and one LU of the iteration matrix (n + m unknowns).
pub(super) fn step_cost(scene: &Scene, effects: &Effects) -> f64 {
    let mut ops = 0.0;
    let mut n = 3.0 * scene.bodies.len() as f64;
    for f in frames(scene, effects) {
        let nf = f.nf as f64;
        n += 3.0 + nf;
        if f.nf == 0 {
            ops += 60.0; // a rigid body's residual and tangents
            continue;
        }
        // residual (×3) and tangents (×1): mass coupling and stiffness are always there
        let mut per = 4.0 * nf * nf + 20.0 * nf;
        if f.options.quadratic_velocity {
            per += 3.0 * nf * nf;
        }
        if f.options.damping {
            per += 2.0 * nf * nf;
        }
        if f.options.geometric_stiffening {
            per += f.elements as f64 * 4.0 * 6.0 * 6.0 * 4.0;
            if f.options.modes.is_some() {
                per += 2.0 * nf * nf * nf; // projection of the tangent
            }
        }
        if effects.gravity {
            per += 4.0 * nf;
        }
        ops += per;
    }
    if effects.gravity {
        ops += 10.0 * scene.bodies.len() as f64;
    }
    // joints: ≈ 3 equations per joint
    let m = 3.0 * (scene.joints.len() + scene.beams.len()) as f64;
    ops + (n + m).powi(3) / 3.0
}
