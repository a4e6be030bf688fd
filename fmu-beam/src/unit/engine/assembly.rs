//! What assembly moved (issue 32): where a scene's joint asks for `assemble = true`, the unit
//! moves the parts together at initialization, and says which joints were apart, which parts it
//! moved and by how much. (Without that key the scene's validation refuses frames that do not
//! meet: rule `joint_gap`.)

use crate::mechanics::Mechanics;
use crate::scene::{show_length, Scene};
use nalgebra::DVector;

/// The message that reports an assembly, or what the motion drives' laws at the start moved;
/// None where no joint asks for assembly and no motion drive moved a part. `before` and `after`
/// are the coordinates as placed and as assembled.
pub(super) fn report(
    scene: &Scene,
    system: &Mechanics,
    before: &DVector<f64>,
    after: &DVector<f64>,
) -> Option<String> {
    let asked: Vec<usize> = (0..scene.joints.len())
        .filter(|&i| scene.joints[i].assemble)
        .collect();
    if asked.is_empty() {
        return driven_start(scene, system, before, after);
    }
    let gaps: Vec<String> = asked
        .iter()
        .filter_map(|&i| scene.joint_gap(i, &scene.joints[i]))
        .map(|g| {
            let j = &scene.joints[g.joint];
            format!(
                "joint {:?} ({:?} and {:?}) {} m apart",
                j.name,
                j.frames[0],
                j.frames[1],
                show_length(g.gap)
            )
        })
        .collect();
    let allowed = scene.gap_allowed();
    let moved = moved_parts(scene, system, before, after);
    let moved = if moved.is_empty() {
        format!(
            "it moved no part by more than {} m or {} rad",
            show_length(allowed),
            show_length(crate::scene::GAP_TOLERANCE)
        )
    } else {
        format!(
            "it moved {} (the others by less than {} m)",
            moved.join("; "),
            show_length(allowed)
        )
    };
    Some(format!(
        "assembly at initialization (assemble = true): {}; {moved}",
        gaps.join(", ")
    ))
}

/// Where no joint asks for assembly: a motion drive whose law at the start differs from the
/// joint's coordinate as placed turns (or shifts) the parts to meet it; that move is said, with
/// the drives that may have caused it, rather than made silently.
fn driven_start(
    scene: &Scene,
    system: &Mechanics,
    before: &DVector<f64>,
    after: &DVector<f64>,
) -> Option<String> {
    let drives: Vec<String> = scene
        .joints
        .iter()
        .filter(|j| {
            j.drive
                .as_ref()
                .is_some_and(|d| d.kind == crate::scene::DriveKind::Motion)
        })
        .map(|j| format!("{:?}", j.name))
        .collect();
    if drives.is_empty() {
        return None;
    }
    let moved = moved_parts(scene, system, before, after);
    if moved.is_empty() {
        return None;
    }
    Some(format!(
        "initialization moved {} from where the scene places them, to start the motion drives \
         of joint {} at their laws' values at the start time (and any joint's initial position \
         given); place the parts there, or start the laws at the placed coordinates",
        moved.join("; "),
        drives.join(", ")
    ))
}

/// Per scene part moved by more than the scene's gap allowance (or turned by more than
/// `GAP_TOLERANCE`) between `before` and `after`: its largest move and turn over its bodies (a
/// beam's substructures), as "beam "name" by … m, turned by … rad (… degrees)".
fn moved_parts(
    scene: &Scene,
    system: &Mechanics,
    before: &DVector<f64>,
    after: &DVector<f64>,
) -> Vec<String> {
    let allowed = scene.gap_allowed();
    let mut parts: Vec<(String, f64, f64)> = Vec::new();
    for (body, d, a) in system.frame_moves(before, after) {
        let name = body.split(['[', '.']).next().unwrap_or(&body).to_string();
        match parts.iter_mut().find(|p| p.0 == name) {
            Some(p) => {
                p.1 = p.1.max(d);
                p.2 = p.2.max(a);
            }
            None => parts.push((name, d, a)),
        }
    }
    parts
        .iter()
        .filter(|(_, d, a)| *d > allowed || *a > crate::scene::GAP_TOLERANCE)
        .map(|(name, d, a)| {
            let kind = if scene.beam(name).is_some() {
                "beam"
            } else {
                "body"
            };
            format!(
                "{kind} {name:?} by {} m, turned by {} rad ({} degrees)",
                show_length(*d),
                show_length(*a),
                show_length(a.to_degrees())
            )
        })
        .collect()
}
