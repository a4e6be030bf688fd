//! How messages name a scene's parts (issue 32): a beam, body, joint or load by the name the
//! user gave it (`joint "elbow".frames[0]`), by its index only where the name cannot serve.

use super::rules as r;
use super::validate::is_identifier;
use super::Scene;

/// How a message names item `i` of a scene's list `word` (`beam`, `body`, `joint`, `load`)
/// whose items have the given names: by the name the user gave it (`joint "elbow"`) when that
/// is an identifier of at most [`r::MAX_NAME_LENGTH`] characters that no other item of the list
/// has, else by its index (`joint[5]`). A field follows it: `joint "elbow".frames[0]`.
pub fn part_path(word: &str, i: usize, names: &[&str]) -> String {
    names
        .get(i)
        .filter(|name| names.iter().filter(|n| n == name).count() == 1)
        .and_then(|name| by_name(word, name))
        .unwrap_or_else(|| format!("{word}[{i}]"))
}

/// [`part_path`] of every item of a list at once (linear in its length).
pub fn part_paths(word: &str, names: &[&str]) -> Vec<String> {
    let mut count: std::collections::HashMap<&str, usize> = Default::default();
    for n in names {
        *count.entry(n).or_default() += 1;
    }
    names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            Some(name)
                .filter(|name| count[*name] == 1)
                .and_then(|name| by_name(word, name))
                .unwrap_or_else(|| format!("{word}[{i}]"))
        })
        .collect()
}

/// `word "name"`, for a name that can serve in a message: an identifier of at most
/// [`r::MAX_NAME_LENGTH`] characters.
fn by_name(word: &str, name: &str) -> Option<String> {
    (is_identifier(name) && name.chars().count() <= r::MAX_NAME_LENGTH)
        .then(|| format!("{word} \"{name}\""))
}

/// The kinds of named parts of a scene, as messages name them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Part {
    Beam,
    Body,
    Joint,
    Load,
}

impl Scene {
    /// How a message names part `i` of a kind ([`part_path`]).
    pub(crate) fn path_of(&self, kind: Part, i: usize) -> String {
        let (word, names): (&str, Vec<&str>) = match kind {
            Part::Beam => ("beam", self.beams.iter().map(|b| b.name.as_str()).collect()),
            Part::Body => (
                "body",
                self.bodies.iter().map(|b| b.name.as_str()).collect(),
            ),
            Part::Joint => (
                "joint",
                self.joints.iter().map(|j| j.name.as_str()).collect(),
            ),
            Part::Load => ("load", self.loads.iter().map(|l| l.name.as_str()).collect()),
        };
        part_path(word, i, &names)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_paths_at_once_are_each_path() {
        let names = ["arm", "arm", "el bow", "hub", ""];
        let each: Vec<String> = (0..names.len())
            .map(|i| part_path("joint", i, &names))
            .collect();
        assert_eq!(part_paths("joint", &names), each);
        assert_eq!(
            each,
            [
                "joint[0]",
                "joint[1]",
                "joint[2]",
                "joint \"hub\"",
                "joint[4]"
            ]
        );
    }
}
