//! What a run costs, counted rather than timed, so that a study ranks settings and keeps to its
//! budget the same way on an idle machine and a loaded one (issue 46 item 1). The engine counts
//! its steps, Newton iterations and iteration matrices; the scene gives the size of what each
//! of them works on. [`Shape::work`] weighs the counts by the work each does, in units of
//! [`WORK_UNIT`] (about a CPU second on the machine where the weights were fitted:
//! docs/accuracy.md, "What a run costs").

use fmu_beam::Scene;

/// What the engine counted over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Internal steps accepted.
    pub steps: u64,
    /// Newton corrections solved for (residuals evaluated and solved with the factors).
    pub iterations: u64,
    /// Iteration matrices evaluated and factorized.
    pub jacobians: u64,
}

/// The sizes a run's work grows with, from the scene alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shape {
    /// Unknowns of the iteration matrix (coordinates and constraint rows), n + m.
    pub unknowns: f64,
    /// The sum over floating frames (and rigid bodies) of their coordinates squared: each
    /// frame's mass, stiffness and inertia blocks are dense over its own coordinates, so a
    /// residual or an iteration matrix costs this much on top of what grows with n + m.
    pub blocks: f64,
    /// Coordinates of the largest frame (or body).
    pub largest: f64,
}

/// The work weighed as in [`Shape::work`] that takes about a CPU second where it was fitted.
pub const WORK_UNIT: f64 = 1.0;

/// Weights of [`Shape::work`], fitted on the C2–C4 sweeps (docs/accuracy.md): seconds per
/// (Newton iteration × unknown), per (iteration × block entry), per (iteration matrix ×
/// block entry) and per (step × unknown).
pub const PER_ITERATION_UNKNOWN: f64 = 1.0e-7;
pub const PER_ITERATION_BLOCK: f64 = 1.0e-8;
pub const PER_JACOBIAN_BLOCK: f64 = 1.0e-8;
pub const PER_STEP_UNKNOWN: f64 = 1.0e-7;

impl Shape {
    /// The shape of `scene` as the engine builds it (a 3D scene whose motion is planar runs
    /// with the planar element).
    pub fn of(scene: &Scene) -> Shape {
        let planar = scene.planar_reduction().ok();
        let s = planar.as_ref().unwrap_or(scene);
        let three = s.is_3d();
        let (rigid, per_element) = if three { (7.0, 6.0) } else { (3.0, 3.0) };
        let mut blocks = 0.0;
        let mut largest: f64 = 0.0;
        for b in &s.beams {
            let (per_frame, frames) = Scene::beam_layout(b);
            let flex = if b.rigid {
                0.0
            } else {
                let full = per_element * per_frame as f64;
                b.modes.map_or(full, |k| (k as f64).min(full))
            };
            let c = rigid + flex;
            blocks += frames as f64 * c * c;
            largest = largest.max(c);
        }
        blocks += s.bodies.len() as f64 * rigid * rigid;
        if !s.bodies.is_empty() {
            largest = largest.max(rigid);
        }
        Shape {
            unknowns: s.size().unknowns() as f64,
            blocks,
            largest,
        }
    }

    /// The counted cost of a run of this shape: the same counts give the same number on every
    /// machine and under any load.
    pub fn work(&self, c: &Counts) -> f64 {
        let (i, j, s) = (c.iterations as f64, c.jacobians as f64, c.steps as f64);
        (i * (PER_ITERATION_UNKNOWN * self.unknowns + PER_ITERATION_BLOCK * self.blocks)
            + j * PER_JACOBIAN_BLOCK * self.blocks
            + s * PER_STEP_UNKNOWN * self.unknowns)
            / WORK_UNIT
    }
}
