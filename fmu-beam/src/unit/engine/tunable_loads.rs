//! Tunable loads (issue 31): a load's constant force and torque components are tunable
//! parameters. A change between communication steps is met as a jump of a force input is: the
//! integrator lands on the communication point with the loads its last step had, restarts there
//! from accelerations consistent with them, and meets the new loads
//! ([`Model::meet_inputs`](super::Model)). A load's time law stays fixed.

use super::{Engine, Model};
use crate::mechanics::Mechanics;
use crate::unit::variables::{Binding, ParamTarget, Variability, VariableTable};

/// One tunable load component: its variable, the scene load's name, and which world component
/// (0..3 force x, y, z; 3..6 torque x, y, z).
#[derive(Debug, Clone)]
pub(super) struct LoadPart {
    var: usize,
    load: String,
    part: usize,
}

/// The world component a load parameter sets (force 0..3, torque 3..6), if it is one.
pub(super) fn part_of(target: ParamTarget) -> Option<usize> {
    match target {
        ParamTarget::LoadForce(_, k) => Some(k),
        ParamTarget::LoadTorque(_, k) => Some(3 + k),
        _ => None,
    }
}

/// The tunable load components of `table` (loads of `scene`).
pub(super) fn load_parts(table: &VariableTable, scene: &crate::scene::Scene) -> Vec<LoadPart> {
    table
        .variables
        .iter()
        .enumerate()
        .filter(|(_, v)| v.variability == Variability::Tunable)
        .filter_map(|(var, v)| match v.binding {
            Binding::Parameter(
                t @ (ParamTarget::LoadForce(l, _) | ParamTarget::LoadTorque(l, _)),
            ) => Some(LoadPart {
                var,
                load: scene.loads[l].name.clone(),
                part: part_of(t)?,
            }),
            _ => None,
        })
        .collect()
}

/// Writes `values` (one per part of `parts`) into the system's loads; the parts the system does
/// not hold (out of the plane of a 3D scene run as planar) are refused when set, so skipped.
pub(super) fn write_loads(system: &mut Mechanics, parts: &[LoadPart], values: &[f64]) {
    for (p, &v) in parts.iter().zip(values) {
        system.set_load_part(&p.load, p.part, v);
    }
}

impl Engine {
    /// The tunable load components as set now, one per [`LoadPart`].
    pub(super) fn wanted_loads(&self) -> Vec<f64> {
        self.load_parts.iter().map(|p| self.values[p.var]).collect()
    }
}

impl Model {
    /// Whether the loads set for the next step differ from those the last step had.
    pub(super) fn loads_changed(&self, wanted: &[f64]) -> bool {
        self.applied_loads.len() != wanted.len()
            || self.applied_loads.iter().zip(wanted).any(|(a, b)| a != b)
    }
}
