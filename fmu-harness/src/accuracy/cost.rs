//! What a run costs, counted rather than timed, so that a study ranks settings and keeps to its
//! budget the same way on an idle machine and a loaded one (issue 46 item 1). The engine counts
//! its steps, Newton iterations and iteration matrices; the scene gives the size of what each
//! of them works on. [`Shape::work`] weighs the counts by the work each does, in seconds of
//! the machine where the weights were fitted (docs/accuracy.md, "What a run costs").

use fmu_beam::integrator::{IterationMatrix, LinearSolver};
use fmu_beam::mechanics::{Equations, Mechanics};
use fmu_beam::Scene;

/// What the engine counted over a run, and the grid it recorded.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Internal steps accepted.
    pub steps: u64,
    /// Newton corrections solved for (residuals evaluated and solved with the factors).
    pub iterations: u64,
    /// Iteration matrices evaluated and factorized.
    pub jacobians: u64,
    /// Communication points recorded (the outputs read, the state interpolated there).
    pub points: u64,
}

/// The sizes a run's work grows with, from the scene alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shape {
    /// Unknowns of the iteration matrix (coordinates and constraint rows), n + m.
    pub unknowns: f64,
    /// The sum over floating frames (and rigid bodies) of their coordinates squared: each
    /// frame's mass, stiffness and inertia blocks are dense over its own coordinates, and an
    /// iteration matrix is assembled and factorized block by block. Where the engine
    /// factorizes by the bordered banded LU (one frame of 16 elements or more), a banded
    /// block counts the entries it stores instead ([`banded_blocks`]).
    pub blocks: f64,
    /// Coordinates of the largest frame (or body).
    pub largest: f64,
}

/// Seconds per Newton iteration and unknown: a residual, its constraints and a solve with the
/// factors grow with n + m (the factors are banded along a chain of frames).
pub const PER_ITERATION_UNKNOWN: f64 = 7.8e-8;

/// Seconds per iteration matrix and block entry: each frame's dense blocks evaluated and
/// factorized.
pub const PER_JACOBIAN_BLOCK: f64 = 4.3e-8;

/// Seconds per communication point and unknown: the state interpolated and the outputs read.
pub const PER_POINT_UNKNOWN: f64 = 3.2e-8;

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
            blocks: banded_blocks(scene).unwrap_or(blocks),
            largest,
        }
    }

    /// The counted cost of a run of this shape, in seconds of the machine the weights were
    /// fitted on (docs/accuracy.md, "What a run costs": within 1.11× of the CPU time, geometric
    /// standard deviation, over the C2–C4 sweeps' runs of 0.05 s or more). The same counts give
    /// the same number on every machine and under any load.
    pub fn work(&self, c: &Counts) -> f64 {
        PER_ITERATION_UNKNOWN * c.iterations as f64 * self.unknowns
            + PER_JACOBIAN_BLOCK * c.jacobians as f64 * self.blocks
            + PER_POINT_UNKNOWN * c.points as f64 * self.unknowns
    }
}

/// The entries the scene's blocks store, where the engine factorizes its iteration matrix by
/// the bordered banded LU (`fmu_beam::integrator::prefers_bordered`); None where it does not.
/// A banded frame's blocks are assembled and factorized in time linear in its coordinates
/// (docs/accuracy.md, "How the cost grows with the model"). Counted as its coordinates
/// squared, one frame of 64 elements read 5.3 times its CPU time per step (0.90 ms against
/// 0.17 ms measured by `make bench-scaling`, 2026-12-06, with its counts: 3.7 Newton
/// iterations and 0.52 iteration matrices a step), 128 elements 10.7 times (3.4 ms against
/// 0.32 ms); counted by its stored entries, 0.76 and 0.81 times.
fn banded_blocks(scene: &Scene) -> Option<f64> {
    let sys = Mechanics::build(scene, &fmu_beam::resolve_effects(scene).effects);
    if !IterationMatrix::new(&sys, LinearSolver::Auto).is_bordered() {
        return None;
    }
    Some(
        sys.block_diagonal()
            .blocks
            .iter()
            .map(|b| b.stored() as f64)
            .sum(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// C2's pendulum as one frame of `elements` (the shipped scene's text, its count changed).
    fn one_frame(elements: usize) -> Scene {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../scenes/flexible_pendulum.toml"
        );
        let text = std::fs::read_to_string(path).unwrap();
        assert!(text.contains("elements = 10\n"));
        let text = text.replace("elements = 10\n", &format!("elements = {elements}\n"));
        Scene::from_toml_str(&text, "flexible_pendulum.toml").unwrap()
    }

    /// A frame the engine factorizes dense weighs its coordinates squared; one it factorizes
    /// by the bordered banded LU, the entries its blocks store (linear in its elements).
    #[test]
    fn a_banded_frame_weighs_what_it_stores() {
        let dense = Shape::of(&one_frame(10));
        // the frame's 3 + 3 × 10 coordinates
        assert!(banded_blocks(&one_frame(10)).is_none());
        assert_eq!(dense.blocks, 33.0 * 33.0, "{dense:?}");
        let (b64, b128) = (Shape::of(&one_frame(64)), Shape::of(&one_frame(128)));
        let squared = |s: &Shape| s.largest * s.largest;
        println!("64: {b64:?}, 128: {b128:?}");
        assert!(b64.blocks < 0.1 * squared(&b64), "{b64:?}");
        // linear: twice the elements, about twice the entries
        let growth = b128.blocks / b64.blocks;
        assert!((1.9..2.1).contains(&growth), "{growth}");
    }

    /// The weights as documented: given counts on a given shape weigh one number, bit for bit.
    #[test]
    fn the_work_of_given_counts_is_one_number() {
        let shape = Shape {
            unknowns: 177.0,
            blocks: 1620.0,
            largest: 9.0,
        };
        let c = Counts {
            steps: 86_207,
            iterations: 199_973,
            jacobians: 10_000,
            points: 1000,
        };
        let w = shape.work(&c);
        let expected: f64 =
            7.8e-8 * 199_973.0 * 177.0 + 4.3e-8 * 10_000.0 * 1620.0 + 3.2e-8 * 1000.0 * 177.0;
        assert_eq!(w.to_bits(), expected.to_bits());
        assert_eq!(shape.work(&c).to_bits(), w.to_bits());
    }
}
