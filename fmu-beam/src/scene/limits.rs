//! The limits of what a scene sizes (issue 35): names, counts of parts, the unit's memory and
//! variables ([`Scene::size`]); each refusal gives the figure and the limit
//! ([`super::rules`] holds the limits and their texts).

use super::rules as r;
use super::validate::{Checker, SceneError};
use super::Scene;

/// At most [`r::MAX_BEAMS`] beams, [`r::MAX_PARTS`] bodies, joints and loads.
pub(super) fn parts(ck: &Checker, s: &Scene) -> Result<(), SceneError> {
    let parts = [
        ("beam", s.beams.len(), r::MAX_BEAMS),
        ("body", s.bodies.len(), r::MAX_PARTS),
        ("joint", s.joints.len(), r::MAX_PARTS),
        ("load", s.loads.len(), r::MAX_PARTS),
    ];
    for (field, n, max) in parts {
        if n > max {
            return Err(ck.fail_with(
                &r::PARTS_MAX,
                field,
                format!("{n} entries"),
                &format!(": at most {max} here"),
            ));
        }
    }
    Ok(())
}

/// A `description` of at most [`r::MAX_DESCRIPTION_LENGTH`] characters, each one XML 1.0 holds
/// ([`r::xml_char`]: it goes into modelDescription.xml).
pub(super) fn description(ck: &Checker, s: &Scene) -> Result<(), SceneError> {
    let chars = s.description.chars().count();
    if chars > r::MAX_DESCRIPTION_LENGTH {
        return Err(ck.fail(
            &r::DESCRIPTION_LENGTH,
            "description",
            format!("a text of {chars} characters"),
        ));
    }
    if let Some((k, c)) = s
        .description
        .chars()
        .enumerate()
        .find(|(_, c)| !r::xml_char(*c))
    {
        return Err(ck.fail(
            &r::XML_TEXT,
            "description",
            format!("a text with U+{:04X} at character {}", c as u32, k + 1),
        ));
    }
    Ok(())
}

/// The unit's matrices within [`r::MAX_UNIT_MEMORY`], its variables within
/// [`r::MAX_VARIABLES`].
pub(super) fn size(ck: &Checker, s: &Scene) -> Result<(), SceneError> {
    let size = s.size();
    if size.memory > r::MAX_UNIT_MEMORY {
        return Err(ck.fail_with(
            &r::UNIT_MEMORY,
            "beam",
            format!("{} bytes", size.memory),
            &format!(
                ": {} coordinates and {} constraint rows would need about {} MiB",
                size.coordinates,
                size.constraints,
                size.memory >> 20
            ),
        ));
    }
    if size.variables > r::MAX_VARIABLES {
        return Err(ck.fail(
            &r::VARIABLES_MAX,
            "beam",
            format!("about {} variables", size.variables),
        ));
    }
    Ok(())
}

/// `text` if it has at most `max` characters, else its first `max / 2` and how many it has: a
/// message stays short whatever the scene holds.
pub(crate) fn abbreviate(text: &str, max: usize) -> String {
    let n = text.chars().count();
    if n <= max {
        return text.to_string();
    }
    let head: String = text.chars().take(max / 2).collect();
    format!("{head}… ({n} characters)")
}

/// A name of at most [`r::MAX_NAME_LENGTH`] characters.
pub(super) fn name_fits(ck: &Checker, field: &str, name: &str) -> Result<(), SceneError> {
    let n = name.chars().count();
    if n > r::MAX_NAME_LENGTH {
        return Err(ck.fail_with(
            &r::NAME_LENGTH,
            field,
            format!("{name:?}"),
            &format!(": this one has {n}"),
        ));
    }
    Ok(())
}
