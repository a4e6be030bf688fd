//! The start of a scene whose joints are given a coordinate or a rate (`joint.initial`, issue
//! 31): a twin of the system, with a motion row on each revolute and prismatic joint that has no
//! motion drive, places the bodies and sets them moving ([`integrator::given_start`]).

use crate::error::EngineError;
use crate::integrator::{self, CoordinateStart};
use crate::mechanics::from_scene::input_slots;
use crate::mechanics::{Equations, Mechanics};
use crate::scene::{DriveKind, DriveSpec, JointKind, LawSpec, Scene};
use crate::unit::effects::Effects;
use nalgebra::DVector;

/// Coordinates q and velocities q' at the start.
type Start = (DVector<f64>, DVector<f64>);

/// The coordinates and velocities at the start of `system` (built from `scene`, its inputs set,
/// its time 0 at absolute time `origin`) that meet the joints' initial coordinates and rates,
/// or `None` if the scene gives none.
pub(super) fn given(
    scene: &Scene,
    effects: &Effects,
    system: &Mechanics,
    origin: f64,
) -> Result<Option<Start>, EngineError> {
    let gives = |j: &crate::scene::JointSpec| {
        j.initial
            .as_ref()
            .is_some_and(|i| i.position.is_some() || i.speed.is_some())
    };
    if !scene.joints.iter().any(gives) {
        return Ok(None);
    }
    let mut twin = scene.clone();
    let mut listed = Vec::new();
    for j in &mut twin.joints {
        let moving = matches!(j.kind, JointKind::Revolute | JointKind::Prismatic)
            && !j
                .drive
                .as_ref()
                .is_some_and(|d| d.kind == DriveKind::Motion);
        if !moving {
            continue;
        }
        let start = j.initial.take().unwrap_or_default();
        // the row: the coordinate less the value given (0 if none: then only its rate counts)
        j.drive = Some(DriveSpec {
            kind: DriveKind::Motion,
            law: LawSpec {
                law: "constant".into(),
                value: Some(start.position.unwrap_or(0.0)),
                time_constant: None,
                until: None,
                omega: None,
                ramp_time: None,
                table: None,
            },
        });
        listed.push((j.name.clone(), start));
    }
    let mut twin_system = Mechanics::build(&twin, effects);
    twin_system.set_time_origin(origin);
    // the inputs as set now, by name (a joint's input effort drive is not in the twin)
    let slots = input_slots(scene);
    for (k, slot) in input_slots(&twin).iter().enumerate() {
        if let Some(r) = slots.iter().position(|s| s.name == slot.name) {
            twin_system.inputs_mut()[k] = system.inputs()[r];
        }
    }
    let m = twin_system.m();
    let mut starts = Vec::with_capacity(listed.len());
    for (name, start) in &listed {
        // a motion drive's row is its joint's last
        let row = (0..m)
            .rev()
            .find(|&r| twin_system.joints_of_rows(&[r]).first() == Some(name))
            .ok_or_else(|| EngineError::InitialState {
                message: format!("joint '{name}': no coordinate row to start from"),
            })?;
        starts.push(CoordinateStart {
            row,
            held: start.position.is_some(),
            speed: start.speed,
        });
    }
    integrator::given_start(&twin_system, 0.0, &starts).map(Some)
}
