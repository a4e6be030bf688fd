//! The equations an engine runs: the planar [`System`] (planar scenes, and 3D scenes whose
//! motion reduces to the plane) or the spatial [`System3`] (built in `from_scene/`). One
//! [`Equations`] implementation over both, so the integrator and the engine see one type.

use crate::error::EngineError;
use crate::mechanics::from_scene::SceneIndex;
use crate::mechanics::multibody::equations::{CoordinateKind, Equations, Point, Turning};
use crate::mechanics::multibody::law::{InputValue, Law};
use crate::mechanics::multibody::sparsity::{BlockDiagonal, JacobianRows};
use crate::mechanics::multibody::System;
use crate::mechanics::multibody3d::System3;
use nalgebra::DVector;
use std::ops::Range;

/// The system a scene builds, planar or spatial, as one [`Equations`].
#[derive(Debug, Clone)]
pub enum Mechanics {
    /// The planar system.
    Planar(System),
    /// The spatial system, with where the scene's parts are in it.
    Spatial(System3, SceneIndex),
}

/// Runs `$e` with `$s` bound to whichever system `$m` holds.
macro_rules! each {
    ($m:expr, $s:ident => $e:expr) => {
        match $m {
            Mechanics::Planar($s) => $e,
            Mechanics::Spatial($s, _) => $e,
        }
    };
}

impl Mechanics {
    /// Makes absolute time `origin` the system's time 0: every drive and load law is evaluated
    /// at `origin` + the system's time. The integrator then steps in the system's time, which
    /// double precision resolves at any start time as finely as at 0: a run started at `origin`
    /// takes the steps of one started at 0 (issue 45).
    pub fn set_time_origin(&mut self, origin: f64) {
        match self {
            Mechanics::Planar(s) => {
                let drives = s.joints.iter_mut().filter_map(|j| j.drive.as_mut());
                let loads = s.loads.iter_mut().filter_map(|l| l.scale.as_mut());
                for law in drives.map(|d| &mut d.law).chain(loads) {
                    law.origin = origin;
                }
            }
            Mechanics::Spatial(s, _) => {
                let drives = s.joints.iter_mut().filter_map(|j| j.drive.as_mut());
                let loads = s.loads.iter_mut().filter_map(|l| l.law.as_mut());
                for law in drives.map(|d| &mut d.law).chain(loads) {
                    law.origin = origin;
                }
            }
        }
    }

    /// The FMU inputs as the system holds them, by input slot.
    pub fn inputs(&self) -> &[InputValue] {
        each!(self, s => &s.inputs)
    }

    /// The FMU inputs, to set (the unit writes each input and its derivatives here).
    pub fn inputs_mut(&mut self) -> &mut Vec<InputValue> {
        each!(self, s => &mut s.inputs)
    }

    /// Whether this system holds the world component `part` of a load's constant force (0..3:
    /// x, y, z) or torque (3..6): a planar system holds x, y and the torque about z only.
    pub fn holds_load_part(&self, part: usize) -> bool {
        match self {
            Mechanics::Planar(_) => matches!(part, 0 | 1 | 5),
            Mechanics::Spatial(..) => part < 6,
        }
    }

    /// Sets the world component `part` ([`Mechanics::holds_load_part`]) of the constant force
    /// or torque of the scene load `name` (not an input load); false where the system holds
    /// no such load or part.
    pub fn set_load_part(&mut self, name: &str, part: usize, value: f64) -> bool {
        if !self.holds_load_part(part) {
            return false;
        }
        let slot = match self {
            Mechanics::Planar(s) => s
                .loads
                .iter_mut()
                .find(|l| l.name == name && l.inputs.is_none())
                .map(|l| match part {
                    0 | 1 => &mut l.force[part],
                    _ => &mut l.torque,
                }),
            Mechanics::Spatial(s, _) => s
                .loads
                .iter_mut()
                .filter(|l| !matches!(l.law.as_ref().map(|t| &t.law), Some(Law::Input(_))))
                .find(|l| l.name == name)
                .map(|l| match part {
                    0..3 => &mut l.force[part],
                    _ => &mut l.torque[part - 3],
                }),
        };
        slot.map(|x| *x = value).is_some()
    }

    /// How far each body's frame lies from `before` in `after` (coordinates of this system):
    /// (body name, distance of the frame's origin in m, angle it turned through in rad). A
    /// substructure's name is its beam's followed by `[i]` (planar) or `.i` (3D).
    pub fn frame_moves(
        &self,
        before: &DVector<f64>,
        after: &DVector<f64>,
    ) -> Vec<(String, f64, f64)> {
        match self {
            Mechanics::Planar(s) => s
                .bodies
                .iter()
                .zip(&s.offsets)
                .map(|(b, &o)| {
                    let d = (after[o] - before[o]).hypot(after[o + 1] - before[o + 1]);
                    (
                        b.name().to_string(),
                        d,
                        (after[o + 2] - before[o + 2]).abs(),
                    )
                })
                .collect(),
            Mechanics::Spatial(s, _) => s
                .bodies
                .iter()
                .zip(&s.offsets)
                .map(|(b, &o)| {
                    let d = (after.rows(o, 3) - before.rows(o, 3)).norm();
                    let (p0, p1) = (before.rows(o + 3, 4), after.rows(o + 3, 4));
                    let cos = (p0.dot(&p1) / (p0.norm() * p1.norm())).abs().min(1.0);
                    (b.name().to_string(), d, 2.0 * cos.acos())
                })
                .collect(),
        }
    }
}

impl Equations for Mechanics {
    fn n(&self) -> usize {
        each!(self, s => Equations::n(s))
    }
    fn m(&self) -> usize {
        each!(self, s => Equations::m(s))
    }
    fn length_scale(&self) -> f64 {
        each!(self, s => Equations::length_scale(s))
    }
    fn coordinate_kinds(&self) -> Vec<CoordinateKind> {
        each!(self, s => Equations::coordinate_kinds(s))
    }
    fn frame_coordinates(&self) -> Vec<usize> {
        each!(self, s => Equations::frame_coordinates(s))
    }
    fn initial_coordinates(&self) -> Result<DVector<f64>, EngineError> {
        each!(self, s => Equations::initial_coordinates(s))
    }
    fn body_ranges(&self) -> Vec<Range<usize>> {
        each!(self, s => Equations::body_ranges(s))
    }
    fn row_bodies(&self) -> Vec<[Option<usize>; 2]> {
        each!(self, s => Equations::row_bodies(s))
    }
    fn mass_blocks(&self, q: &DVector<f64>, m: &mut BlockDiagonal) {
        each!(self, s => Equations::mass_blocks(s, q, m))
    }
    fn block_diagonal(&self) -> BlockDiagonal {
        each!(self, s => Equations::block_diagonal(s))
    }
    fn body_residual(
        &self,
        q: &DVector<f64>,
        v: &DVector<f64>,
        a: &DVector<f64>,
        t: f64,
        r: &mut DVector<f64>,
    ) {
        each!(self, s => Equations::body_residual(s, q, v, a, t, r))
    }
    fn tangent_blocks(&self, at: &Point, kt: &mut BlockDiagonal, ct: &mut BlockDiagonal) {
        each!(self, s => Equations::tangent_blocks(s, at, kt, ct))
    }
    fn constraints(&self, q: &DVector<f64>, t: f64, g: &mut DVector<f64>) {
        each!(self, s => Equations::constraints(s, q, t, g))
    }
    fn jacobian_rows(&self, q: &DVector<f64>, t: f64, gm: &mut JacobianRows) {
        each!(self, s => Equations::jacobian_rows(s, q, t, gm))
    }
    fn constraints_and_rows(
        &self,
        q: &DVector<f64>,
        t: f64,
        g: &mut DVector<f64>,
        gm: &mut JacobianRows,
    ) {
        each!(self, s => Equations::constraints_and_rows(s, q, t, g, gm))
    }
    fn accel_bias(&self, q: &DVector<f64>, v: &DVector<f64>, t: f64, out: &mut DVector<f64>) {
        each!(self, s => Equations::accel_bias(s, q, v, t, out))
    }
    fn breakpoints(&self) -> Vec<f64> {
        each!(self, s => Equations::breakpoints(s))
    }
    fn joints_of_rows(&self, rows: &[usize]) -> Vec<String> {
        each!(self, s => Equations::joints_of_rows(s, rows))
    }
    fn power(&self, q: &DVector<f64>, v: &DVector<f64>, lambda: &DVector<f64>, t: f64) -> f64 {
        each!(self, s => Equations::power(s, q, v, lambda, t))
    }
    fn turning(&self) -> Option<Turning> {
        each!(self, s => Equations::turning(s))
    }
    fn condenses(&self) -> bool {
        each!(self, s => Equations::condenses(s))
    }
}
