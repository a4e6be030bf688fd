//! The rules of a joint's start (`joint.initial`): only a revolute or prismatic joint without
//! a motion drive has one, and its values are finite.

use super::rules as r;
use super::validate::{Checker, SceneError};
use super::{DriveKind, JointKind, JointSpec};

/// Checks the start of joint `j`, the scene's `field` (`joint[i]`).
pub(super) fn validate_start(ck: &Checker, j: &JointSpec, field: &str) -> Result<(), SceneError> {
    let Some(start) = &j.initial else {
        return Ok(());
    };
    let at = format!("{field}.initial");
    if !matches!(j.kind, JointKind::Revolute | JointKind::Prismatic) {
        return Err(ck.fail(&r::JOINT_INITIAL_KIND, &at, format!("{:?}", j.kind)));
    }
    if j.drive
        .as_ref()
        .is_some_and(|d| d.kind == DriveKind::Motion)
    {
        return Err(ck.fail(&r::JOINT_INITIAL_MOTION, &at, "a motion drive"));
    }
    for (name, v) in [("position", start.position), ("speed", start.speed)] {
        if let Some(v) = v {
            ck.finite(&format!("{at}.{name}"), v)?;
        }
    }
    Ok(())
}
