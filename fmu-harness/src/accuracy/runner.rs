//! One run of a study: the scene at a setting (fixed step, Newton's tolerance, mesh), run in
//! process over the communication grid (by [`super::pool`]), counted and timed, within the
//! study's budget (runs, counted work) and drawn on the progress bar.

use super::cost::{Counts, Shape};
use super::estimate::Series;
use super::pool::Pool;
use super::run::{Failure, Job};
use super::{Role, Run, Setting};
use fmu_beam::Scene;
use std::time::Instant;

/// The flexible beams a mesh refinement doubles: not rigid, not from a matrix file.
pub(super) fn refinable(b: &fmu_beam::scene::BeamSpec) -> bool {
    !b.rigid && b.matrix_file.is_none() && b.matrix_text.is_none()
}

/// The scene at a setting (validated again: a refined mesh may pass a size limit).
pub(super) fn scene_at(base: &Scene, s: &Setting) -> Result<Scene, String> {
    let mut sc = base.clone();
    sc.solver.adaptive = false;
    sc.solver.max_step = s.step;
    sc.solver.tolerance = s.newton;
    for b in sc.beams.iter_mut().filter(|b| refinable(b)) {
        match b.substructures {
            Some(k) => b.substructures = Some(scaled(k, s.mesh)),
            None => b.elements = Some(scaled(b.elements.unwrap_or(1), s.mesh)),
        }
        if s.stiffening_switched {
            b.geometric_stiffening = !b.geometric_stiffening;
        }
    }
    let origin = format!("{} (h = {:e} s, mesh × 2^{})", base.name, s.step, s.mesh);
    Scene::from_toml_str(&sc.to_toml_string(), &origin).map_err(|e| e.to_string())
}

/// A count × 2^mesh; below 0 divided by 2^−mesh, rounded up (3 elements halve into 2: the
/// coarser mesh nearest half the scene's), never below 1.
fn scaled(count: usize, mesh: i32) -> usize {
    if mesh >= 0 {
        count << mesh
    } else {
        count.div_ceil(1 << -mesh).max(1)
    }
}

/// Whether some flexible beam has more than one element (or substructure): the mesh ladder
/// then also runs the halved mesh, coarser than the scene's.
pub(super) fn coarsenable(base: &Scene) -> bool {
    base.beams
        .iter()
        .filter(|b| refinable(b))
        .any(|b| b.substructures.unwrap_or(b.elements.unwrap_or(1)) > 1)
}

/// The mesh of a scene at `mesh`, as text.
pub(super) fn mesh_text(base: &Scene, mesh: i32) -> String {
    let parts: Vec<String> = base
        .beams
        .iter()
        .filter(|b| refinable(b))
        .map(|b| match b.substructures {
            Some(k) => format!(
                "{} {}×{}",
                b.name,
                scaled(k, mesh),
                b.elements_per_substructure.unwrap_or(1)
            ),
            None => format!("{} {} el.", b.name, scaled(b.elements.unwrap_or(1), mesh)),
        })
        .collect();
    if parts.is_empty() {
        "(no flexible beam)".into()
    } else {
        parts.join(", ")
    }
}

/// The grid and outputs a run records.
pub(super) struct Grid<'a> {
    pub(super) outputs: &'a [String],
    pub(super) start: f64,
    pub(super) comm: f64,
    pub(super) n: usize,
}

/// The study's runner: its budget (counted), its progress bar, and the pool that runs (or has
/// run ahead) what it asks for.
pub(super) struct Runner<'a> {
    pub(super) base: &'a Scene,
    pub(super) grid: Grid<'a>,
    pub(super) runs: Vec<Run>,
    pub(super) started: Instant,
    pub(super) max_runs: usize,
    /// The counted budget ([`super::cost`]).
    pub(super) max_work: f64,
    pub(super) notes: Vec<String>,
    pub(super) bar: indicatif::ProgressBar,
    pub(super) pool: &'a Pool,
    pub(super) interrupted: &'a dyn Fn() -> bool,
    /// Why the study stopped before its end (the wall-clock safety stop, an interrupt).
    pub(super) incomplete: Option<String>,
}

impl Runner<'_> {
    /// The counted work of the runs so far.
    pub(super) fn work(&self) -> f64 {
        self.runs.iter().map(|r| r.work).sum()
    }

    /// The job of `setting` on this study's grid.
    pub(super) fn job(&self, setting: &Setting) -> Result<Job, String> {
        Ok(Job {
            scene: scene_at(self.base, setting)?,
            outputs: self.grid.outputs.to_vec(),
            start: self.grid.start,
            comm: self.grid.comm,
            n: self.grid.n,
        })
    }

    /// Hands `settings` (first = soonest) to the pool's workers: the study will probably ask
    /// for them next.
    pub(super) fn speculate(&self, settings: &[Setting]) {
        if self.pool.workers() > 0 && self.incomplete.is_none() {
            self.pool
                .speculate(settings.iter().filter_map(|s| self.job(s).ok()).collect());
        }
    }

    /// Drops what was run ahead and not asked for: the study has gone past it.
    pub(super) fn forget(&self) {
        self.pool.forget(&[]);
    }

    /// Drops what was run ahead and not asked for, but `settings`.
    pub(super) fn forget_but(&self, settings: &[Setting]) {
        let keep: Vec<String> = settings
            .iter()
            .filter_map(|s| self.job(s).ok())
            .map(|j| j.key())
            .collect();
        self.pool.forget(&keep);
    }

    /// Runs `setting` unless the budget would be passed (runs, or counted work with this
    /// run's predicted work); the run's index. Nothing runs once the study was stopped.
    pub(super) fn run(&mut self, role: Role, setting: Setting, predicted: f64) -> Option<usize> {
        if self.incomplete.is_some() {
            return None;
        }
        let spent = self.work();
        if self.runs.len() >= self.max_runs || spent + predicted > self.max_work {
            self.notes.push(format!(
                "not run ({} runs, work {spent:.2} spent, this one predicted {predicted:.2}; \
                 budget {} runs, work {}): {} run at h = {:e} s, {}",
                self.runs.len(),
                self.max_runs,
                self.max_work,
                role.name(),
                setting.step,
                mesh_text(self.base, setting.mesh)
            ));
            return None;
        }
        self.bar.set_message(format!(
            "{} h = {:.2e} s, {}",
            role.name(),
            setting.step,
            mesh_text(self.base, setting.mesh)
        ));
        let (result, counts, work, seconds) = match self.job(&setting) {
            Err(m) => (Err(m), Counts::default(), 0.0, 0.0),
            Ok(job) => {
                let shape = Shape::of(&job.scene);
                let out = self.pool.take(job, self.interrupted);
                match out.result {
                    Ok((y, c)) => (Ok(y), c, shape.work(&c), out.seconds),
                    Err(Failure::Failed(m)) => (Err(m), Counts::default(), 0.0, out.seconds),
                    Err(Failure::Stopped) => {
                        let why = if self.pool.stop.load(std::sync::atomic::Ordering::Relaxed) {
                            "interrupted".to_string()
                        } else {
                            format!(
                                "the wall-clock safety stop ({:.0} s) fired during the {} run at \
                                 h = {:e} s, {}: the study is INCOMPLETE, its choice is that of \
                                 the runs before it",
                                self.pool.limit_seconds(),
                                role.name(),
                                setting.step,
                                mesh_text(self.base, setting.mesh)
                            )
                        };
                        self.notes.push(why.clone());
                        self.incomplete = Some(why);
                        return None;
                    }
                }
            }
        };
        self.runs.push(Run {
            role,
            setting,
            result,
            seconds,
            counts,
            work,
            errors: Vec::new(),
            true_errors: Vec::new(),
        });
        self.bar.inc(1);
        Some(self.runs.len() - 1)
    }

    pub(super) fn values(&self, i: usize) -> Option<&Series> {
        self.runs[i].result.as_ref().ok()
    }
}

/// The finest unbroken run of successes at the fine end of what a ladder ran (indices, coarse
/// to fine).
pub(super) fn fine_end(runner: &Runner, ladder: &[Option<usize>]) -> Vec<usize> {
    // rungs the budget left out (None) come last: they end no tail
    let mut tail: Vec<usize> = ladder
        .iter()
        .rev()
        .skip_while(|r| r.is_none())
        .map_while(|r| r.filter(|&i| runner.values(i).is_some()))
        .collect();
    tail.reverse();
    tail
}
