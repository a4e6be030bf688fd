//! One run of a study: the scene at a setting (fixed step, Newton's tolerance, mesh), run in
//! process over the communication grid, timed, within the study's budget (runs, wall seconds)
//! and drawn on the progress bar.

use super::estimate::Series;
use super::{Role, Run, Setting, COARSE_CPU};
use fmu_beam::{Engine, Scene};
use std::time::Instant;

/// CPU seconds this thread has run (the scheduler's account), where Linux says.
pub(super) fn thread_cpu_seconds() -> Option<f64> {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()?
        .split_whitespace()
        .next()?
        .parse::<f64>()
        .ok()
        .map(|ns| ns * 1e-9)
}

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

/// Runs `scene` over the grid: the outputs at every point, the steps taken.
pub(super) fn simulate(scene: Scene, grid: &Grid) -> Result<(Series, i64), String> {
    let mut e = Engine::new(scene);
    let vrs: Vec<u32> = grid
        .outputs
        .iter()
        .map(|o| {
            e.variables()
                .by_name(o)
                .map(|v| v.vr)
                .ok_or_else(|| format!("the unit has no output {o}"))
        })
        .collect::<Result<_, _>>()?;
    e.exit_initialization().map_err(|x| x.to_string())?;
    let mut values = vec![Vec::with_capacity(grid.n + 1); vrs.len()];
    for k in 0..=grid.n {
        if k > 0 {
            let t = grid.start + (k - 1) as f64 * grid.comm;
            e.do_step(t, grid.comm)
                .map_err(|x| format!("at t = {t} s: {x}"))?;
        }
        for (v, &vr) in values.iter_mut().zip(&vrs) {
            v.push(e.get_real(vr).map_err(|x| x.to_string())?);
        }
    }
    let steps = match e.variables().by_name("solver.steps").map(|v| v.vr) {
        Some(vr) => i64::from(e.get_integer(vr).unwrap_or(0)),
        None => 0,
    };
    Ok((values, steps))
}

/// The study's runner: its budget and its progress bar.
pub(super) struct Runner<'a> {
    pub(super) base: &'a Scene,
    pub(super) grid: Grid<'a>,
    pub(super) runs: Vec<Run>,
    pub(super) started: Instant,
    pub(super) max_runs: usize,
    pub(super) max_seconds: f64,
    pub(super) notes: Vec<String>,
    pub(super) bar: indicatif::ProgressBar,
}

impl Runner<'_> {
    /// Runs `setting` unless the budget would be passed (runs, or wall seconds with this run's
    /// predicted cost); the run's index.
    pub(super) fn run(&mut self, role: Role, setting: Setting, predicted: f64) -> Option<usize> {
        let spent = self.started.elapsed().as_secs_f64();
        if self.runs.len() >= self.max_runs || spent + predicted > self.max_seconds {
            self.notes.push(format!(
                "not run ({} runs, {spent:.1} s spent, this one predicted {predicted:.2} s; \
                 budget {} runs, {} s): {} run at h = {:e} s, {}",
                self.runs.len(),
                self.max_runs,
                self.max_seconds,
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
        let wall = Instant::now();
        let cpu0 = thread_cpu_seconds();
        let outcome = scene_at(self.base, &setting).and_then(|s| simulate(s, &self.grid));
        let seconds = match (cpu0, thread_cpu_seconds()) {
            (Some(a), Some(b)) if b - a >= COARSE_CPU => b - a,
            _ => wall.elapsed().as_secs_f64(),
        };
        let (result, steps) = match outcome {
            Ok((v, s)) => (Ok(v), s),
            Err(e) => (Err(e), 0),
        };
        self.runs.push(Run {
            role,
            setting,
            result,
            seconds,
            steps,
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
