//! How the engine's cost grows with the model (`fmu-bench scaling`, `make bench-scaling`,
//! issue 46 item 3): C2's pendulum as a beam of n substructures of one element and as one
//! floating frame of n elements, n = 4 … 128. For each: the set-up (`Engine::new` of the scene
//! up to `exit_initialization`, ready to step) and the CPU time per step of a run at a fixed
//! step, with its counters (Newton iterations, iteration matrices) so that the time per
//! iteration shows. Samples are taken round by round (every model once per round, so that the
//! machine's load falls on all alike); the report gives medians and the exponent of a least
//! squares fit of log time on log n. Writes `SCALING.md`.

use crate::error::BenchError;
use crate::work_precision::clock;
use fmu_beam::{Engine, EngineError, Scene};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// The sizes n of both families.
pub const SIZES: [usize; 6] = [4, 8, 16, 32, 64, 128];
/// The fixed step (s) and the end of the timed runs (s): 200 steps.
const STEP: f64 = 1e-3;
const STOP: f64 = 0.2;
/// Communication step of the runs (s).
const COMM: f64 = 1e-2;
/// Newton's tolerance at the fixed step (as the peer bench's fixed-step runs).
const NEWTON: f64 = 1e-8;
/// Shortest timed sample (s): shorter set-ups are repeated in a batch.
const MIN_SAMPLE: f64 = 0.05;

/// A family of models: the scene file and how its beam is cut into n parts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// n substructures of one element each.
    Substructures,
    /// One floating frame of n elements.
    OneFrame,
}

impl Family {
    pub const ALL: [Family; 2] = [Family::Substructures, Family::OneFrame];

    fn name(self) -> &'static str {
        match self {
            Family::Substructures => "C2 pendulum, n substructures x 1 element",
            Family::OneFrame => "C2 pendulum, one frame of n elements",
        }
    }

    fn scene_file(self) -> &'static str {
        match self {
            Family::Substructures => "flexible_pendulum_substructured.toml",
            Family::OneFrame => "flexible_pendulum.toml",
        }
    }

    /// The family's scene with n parts at the bench's fixed step.
    fn scene(self, dir: &Path, n: usize) -> Result<Scene, BenchError> {
        let mut scene = Scene::load(&dir.join(self.scene_file()))?;
        let b = &mut scene.beams[0];
        match self {
            Family::Substructures => {
                b.elements = None;
                b.substructures = Some(n);
                b.elements_per_substructure = Some(1);
            }
            Family::OneFrame => {
                b.elements = Some(n);
                b.substructures = None;
                b.elements_per_substructure = None;
            }
        }
        scene.solver.adaptive = false;
        scene.solver.max_step = STEP;
        scene.solver.tolerance = NEWTON;
        scene.experiment.stop_time = STOP;
        let origin = format!("{} ({}, n = {n})", self.scene_file(), self.name());
        Ok(Scene::from_toml_str(&scene.to_toml_string(), &origin)?)
    }
}

/// One model: its counters and its samples.
#[derive(Debug, Clone)]
pub struct Measured {
    pub family: Family,
    pub n: usize,
    pub steps: i64,
    pub newton: i64,
    pub jacobians: i64,
    /// CPU seconds of one set-up, per round.
    pub setup: Vec<f64>,
    /// CPU seconds per step, per round.
    pub per_step: Vec<f64>,
    /// The final tip height (to compare builds).
    pub tip_y: f64,
}

/// A model's scene and the batches of set-ups and of runs that make a sample.
struct Model {
    scene: Scene,
    setups: usize,
    runs: usize,
}

/// The engine built from `scene` and ready to step.
fn set_up(scene: &Scene) -> Result<Engine, EngineError> {
    let mut e = Engine::new(scene.clone());
    e.exit_initialization()?;
    Ok(e)
}

/// CPU seconds of one set-up, the mean of `batch`.
fn time_setup(scene: &Scene, batch: usize) -> Result<f64, EngineError> {
    let origin = Instant::now();
    let c0 = clock(origin);
    for _ in 0..batch {
        drop(set_up(scene)?);
    }
    Ok((clock(origin) - c0) / batch as f64)
}

/// `batch` runs from fresh set-ups (made before the clock starts): CPU seconds of their steps
/// only, and the last run's counters (steps, Newton iterations, iteration matrices) and final
/// tip height.
fn time_runs(scene: &Scene, batch: usize) -> Result<(f64, [i64; 3], f64), EngineError> {
    let mut engines = (0..batch)
        .map(|_| set_up(scene))
        .collect::<Result<Vec<_>, _>>()?;
    let comms = (STOP / COMM).round() as usize;
    let origin = Instant::now();
    let c0 = clock(origin);
    for e in &mut engines {
        for k in 0..comms {
            e.do_step(k as f64 * COMM, COMM)?;
        }
    }
    let seconds = clock(origin) - c0;
    let Some(mut e) = engines.pop() else {
        return Ok((0.0, [0; 3], f64::NAN));
    };
    let mut read = |name: &str| -> Result<i64, EngineError> {
        match e.variables().by_name(name).map(|v| v.vr) {
            Some(vr) => e.get_integer(vr).map(i64::from),
            None => Ok(0),
        }
    };
    let counts = [
        read("solver.steps")?,
        read("solver.newton_iterations")?,
        read("solver.jacobians")?,
    ];
    let tip = match e.variables().by_name("beam.tip.y").map(|v| v.vr) {
        Some(vr) => e.get_real(vr)?,
        None => f64::NAN,
    };
    Ok((seconds, counts, tip))
}

/// The batch that makes a sample last at least [`MIN_SAMPLE`] from the wall seconds of one
/// (finer than the scheduler's CPU account).
fn batch(one: f64) -> usize {
    ((MIN_SAMPLE / one.max(1e-7)).ceil() as usize).clamp(1, 1000)
}

/// Runs the study: `rounds` samples of every family and size.
pub fn study(
    dir: &Path,
    rounds: usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Measured>, BenchError> {
    let engine = |origin: String| move |source| BenchError::Engine { origin, source };
    let mut models = Vec::new();
    let mut out = Vec::new();
    for family in Family::ALL {
        for n in SIZES {
            let scene = family.scene(dir, n)?;
            let origin = format!("{} n = {n}", family.name());
            // a trial sizes the set-up batch (and warms the caches)
            let start = Instant::now();
            drop(set_up(&scene).map_err(engine(origin.clone()))?);
            let setups = batch(start.elapsed().as_secs_f64());
            let start = Instant::now();
            let (_, [steps, newton, jacobians], tip_y) =
                time_runs(&scene, 1).map_err(engine(origin))?;
            let runs = batch(start.elapsed().as_secs_f64());
            progress(&format!(
                "{}: n = {n}: trial done ({steps} steps, {newton} Newton iterations)",
                family.name()
            ));
            models.push(Model {
                scene,
                setups,
                runs,
            });
            out.push(Measured {
                family,
                n,
                steps,
                newton,
                jacobians,
                setup: Vec::new(),
                per_step: Vec::new(),
                tip_y,
            });
        }
    }
    for round in 0..rounds {
        for (m, r) in models.iter().zip(out.iter_mut()) {
            let origin = format!("{} n = {}", r.family.name(), r.n);
            r.setup
                .push(time_setup(&m.scene, m.setups).map_err(engine(origin.clone()))?);
            let (seconds, [steps, ..], _) = time_runs(&m.scene, m.runs).map_err(engine(origin))?;
            r.per_step
                .push(seconds / (m.runs as f64 * steps.max(1) as f64));
        }
        progress(&format!("round {}/{rounds} done", round + 1));
    }
    Ok(out)
}

/// The median of samples.
fn median(s: &[f64]) -> f64 {
    let mut s = s.to_vec();
    s.sort_by(f64::total_cmp);
    s.get(s.len() / 2).copied().unwrap_or(f64::NAN)
}

/// The slope of the least squares line through (ln x, ln y).
pub fn exponent(points: &[(f64, f64)]) -> f64 {
    let k = points.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = points.iter().map(|&(x, y)| (x.ln(), y.ln())).unzip();
    let (mx, my) = (lx.iter().sum::<f64>() / k, ly.iter().sum::<f64>() / k);
    let sxy: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = lx.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// `SCALING.md`: one table per family and the fitted exponents.
pub fn markdown(rows: &[Measured], rounds: usize, header: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# How the engine's cost grows with the model\n\n{header}"
    );
    let _ = writeln!(
        s,
        "\nFixed step {STEP:.0e} s to {STOP} s (communication step {COMM:.0e} s), Newton's \
         tolerance {NEWTON:.0e}; medians of {rounds} rounds of CPU time (thread). Set-up: \
         `Engine::new` to `exit_initialization`. Exponents: least squares slope of ln time on \
         ln n from {} to {}.",
        SIZES[0],
        SIZES[SIZES.len() - 1]
    );
    let _ = writeln!(
        s,
        "\n| model | set-up exponent | µs/step exponent | µs/iteration exponent |\n|---|---|---|---|"
    );
    for f in Family::ALL {
        let mine: Vec<&Measured> = rows.iter().filter(|r| r.family == f).collect();
        let fit = |g: &dyn Fn(&Measured) -> f64| {
            exponent(&mine.iter().map(|r| (r.n as f64, g(r))).collect::<Vec<_>>())
        };
        let _ = writeln!(
            s,
            "| {} | {:.2} | {:.2} | {:.2} |",
            f.name(),
            fit(&|r| median(&r.setup)),
            fit(&|r| median(&r.per_step)),
            fit(&|r| median(&r.per_step) * r.steps as f64 / r.newton.max(1) as f64),
        );
    }
    for f in Family::ALL {
        let _ = writeln!(
            s,
            "\n## {}\n\n| n | set-up ms | µs/step | steps | Newton it. | it./step | \
             iteration matrices | µs/iteration | tip height (m) |\n\
             |---|---|---|---|---|---|---|---|---|",
            f.name()
        );
        for r in rows.iter().filter(|r| r.family == f) {
            let per_step = median(&r.per_step);
            let _ = writeln!(
                s,
                "| {} | {:.2} | {:.0} | {} | {} | {:.2} | {} | {:.1} | {:.9} |",
                r.n,
                median(&r.setup) * 1e3,
                per_step * 1e6,
                r.steps,
                r.newton,
                r.newton as f64 / r.steps.max(1) as f64,
                r.jacobians,
                per_step * r.steps as f64 / r.newton.max(1) as f64 * 1e6,
                r.tip_y,
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::exponent;

    #[test]
    fn exponent_of_a_power_law() {
        let pts: Vec<(f64, f64)> = [4.0, 8.0, 16.0, 128.0]
            .iter()
            .map(|&n: &f64| (n, 3.0 * n.powf(1.7)))
            .collect();
        assert!((exponent(&pts) - 1.7).abs() < 1e-12);
    }
}
