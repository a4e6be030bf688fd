//! Work-precision study of the validation cases: the error of a case's main output against a
//! reference run at a tight tolerance, versus the time the engine took, over the integrator
//! tolerance. Runs the engine directly (no FMI layer), several times per point, and reports
//! the CPU time of the thread (the scheduler's account in /proc; wall time where Linux does
//! not offer it) as median / min / max.

use crate::error::HarnessError;
use fmu_beam::{Engine, Scene};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A case: its scene, the output whose error is measured, the simulated time and the
/// communication step.
#[derive(Debug, Clone)]
pub struct Case {
    pub name: &'static str,
    pub scene: &'static str,
    pub output: &'static str,
    pub stop: f64,
    pub comm: f64,
}

/// The validation cases C1–C4 (CASES.md), with the output each is judged on.
pub const CASES: &[Case] = &[
    Case {
        name: "C1",
        scene: "cantilever_free_vibration.toml",
        output: "beam.tip.deflection",
        stop: 2.0,
        comm: 1e-2,
    },
    Case {
        name: "C2",
        scene: "flexible_pendulum.toml",
        output: "hinge.angle",
        stop: 1.0,
        comm: 1e-2,
    },
    Case {
        name: "C2-tip",
        scene: "flexible_pendulum.toml",
        output: "beam.tip.deflection",
        stop: 1.0,
        comm: 1e-2,
    },
    Case {
        name: "C3",
        scene: "slider_crank.toml",
        output: "slider.position",
        stop: 1.6,
        comm: 1e-2,
    },
    Case {
        name: "C3-rigid-crank",
        scene: "slider_crank_rigid_crank.toml",
        output: "slider.position",
        stop: 1.6,
        comm: 1e-2,
    },
    Case {
        name: "C4-omega10",
        scene: "spin_up_omega10.toml",
        output: "beam.tip.deflection",
        stop: 20.0,
        comm: 1e-1,
    },
    Case {
        name: "C4-omega10-stiffened",
        scene: "spin_up_omega10_stiffened.toml",
        output: "beam.tip.deflection",
        stop: 20.0,
        comm: 1e-1,
    },
];

/// The tolerance that stops Newton in fixed-step runs.
pub const FIXED_STEP_NEWTON_TOLERANCE: f64 = 1e-10;

/// How the integrator is set for one point: error control at a tolerance, or a fixed step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Setting {
    Tolerance(f64),
    FixedStep(f64),
}

impl std::fmt::Display for Setting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Setting::Tolerance(t) => write!(f, "tolerance {t:.0e}"),
            Setting::FixedStep(h) => write!(f, "fixed step {h:.0e} s"),
        }
    }
}

/// One point of the study.
#[derive(Debug, Clone)]
pub struct Point {
    pub case: &'static str,
    pub output: &'static str,
    pub setting: Setting,
    pub runs: usize,
    pub seconds: [f64; 3],
    pub steps: i64,
    pub newton: i64,
    pub jacobians: i64,
    /// Largest |y - y_ref| over the communication points, and its ratio to max |y_ref|.
    pub error: f64,
    pub relative: f64,
}

struct Series {
    values: Vec<f64>,
    seconds: f64,
    stats: [i64; 3],
}

/// CPU seconds this thread has run, from the scheduler's account; None where Linux does not
/// offer it.
fn thread_cpu_seconds() -> Option<f64> {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()?
        .split_whitespace()
        .next()?
        .parse::<f64>()
        .ok()
        .map(|ns| ns * 1e-9)
}

fn simulate(scene: &Scene, case: &Case, setting: Setting) -> Result<Series, HarnessError> {
    let fail = |e| HarnessError::Engine {
        origin: case.scene.to_string(),
        source: e,
    };
    let start = Instant::now();
    let cpu0 = thread_cpu_seconds();
    let mut e = Engine::new(scene.clone());
    let vr = |e: &Engine, n: &str| e.variables().by_name(n).map(|v| v.vr);
    let adaptive = vr(&e, "solver.adaptive").expect("every scene has solver.adaptive");
    match setting {
        Setting::Tolerance(t) => {
            e.set_boolean(adaptive, true).map_err(fail)?;
            let tol = vr(&e, "solver.tolerance").expect("every scene has solver.tolerance");
            e.set_real(tol, t).map_err(fail)?;
        }
        Setting::FixedStep(h) => {
            e.set_boolean(adaptive, false).map_err(fail)?;
            let max_step = vr(&e, "solver.max_step").expect("every scene has solver.max_step");
            e.set_real(max_step, h).map_err(fail)?;
            // with a fixed step the tolerance only stops Newton: tight, so that the step
            // alone sets the error (a loose Newton error accumulates over thousands of steps)
            let tol = vr(&e, "solver.tolerance").expect("every scene has solver.tolerance");
            e.set_real(tol, FIXED_STEP_NEWTON_TOLERANCE).map_err(fail)?;
        }
    }
    e.exit_initialization().map_err(fail)?;
    let out = vr(&e, case.output)
        .unwrap_or_else(|| panic!("{} has no output {}", case.scene, case.output));
    let n = (case.stop / case.comm).round() as usize;
    let mut values = Vec::with_capacity(n + 1);
    values.push(e.get_real(out).map_err(fail)?);
    for k in 0..n {
        e.do_step(k as f64 * case.comm, case.comm).map_err(fail)?;
        values.push(e.get_real(out).map_err(fail)?);
    }
    let seconds = match (cpu0, thread_cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => start.elapsed().as_secs_f64(),
    };
    let mut stat = |name| {
        vr(&e, name)
            .map_or(Ok(0), |v| e.get_integer(v).map(i64::from))
            .map_err(fail)
    };
    let stats = [
        stat("solver.steps")?,
        stat("solver.newton_iterations")?,
        stat("solver.jacobians")?,
    ];
    Ok(Series {
        values,
        seconds,
        stats,
    })
}

/// Runs the study for `cases` over `settings`, `repeats` timings each, against a reference at
/// `reference_tolerance`; `progress` receives a line per point.
pub fn study(
    scenes_dir: &Path,
    cases: &[Case],
    settings: &[Setting],
    repeats: usize,
    reference_tolerance: f64,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Point>, HarnessError> {
    let mut points = Vec::new();
    for case in cases {
        let scene = Scene::load(&scenes_dir.join(case.scene))?;
        progress(&format!(
            "{}: reference run at tolerance {reference_tolerance:.0e}",
            case.name
        ));
        let reference = simulate(&scene, case, Setting::Tolerance(reference_tolerance))?;
        let scale = reference
            .values
            .iter()
            .fold(0.0f64, |m, y| m.max(y.abs()))
            .max(1e-300);
        for &setting in settings {
            let mut times = Vec::with_capacity(repeats);
            let mut last = None;
            for _ in 0..repeats.max(1) {
                let s = simulate(&scene, case, setting)?;
                times.push(s.seconds);
                last = Some(s);
            }
            let s = last.expect("at least one run");
            times.sort_by(f64::total_cmp);
            let error = s
                .values
                .iter()
                .zip(&reference.values)
                .fold(0.0f64, |m, (y, r)| m.max((y - r).abs()));
            let p = Point {
                case: case.name,
                output: case.output,
                setting,
                runs: times.len(),
                seconds: [times[times.len() / 2], times[0], times[times.len() - 1]],
                steps: s.stats[0],
                newton: s.stats[1],
                jacobians: s.stats[2],
                error,
                relative: error / scale,
            };
            progress(&format!(
                "{}: {setting}: error {error:.2e} ({:.1e} relative), {:.4} s median of {}, {} steps",
                case.name, p.relative, p.seconds[0], p.runs, p.steps
            ));
            points.push(p);
        }
    }
    Ok(points)
}

fn mode(s: Setting) -> &'static str {
    match s {
        Setting::Tolerance(_) => "adaptive",
        Setting::FixedStep(_) => "fixed",
    }
}

fn value(s: Setting) -> f64 {
    match s {
        Setting::Tolerance(v) | Setting::FixedStep(v) => v,
    }
}

pub fn csv(points: &[Point]) -> String {
    let mut s = String::from(
        "case,output,mode,setting,runs,cpu_seconds_median,cpu_seconds_min,cpu_seconds_max,steps,newton_iterations,factorizations,error_max,error_relative\n",
    );
    for p in points {
        let _ = writeln!(
            s,
            "{},{},{},{:e},{},{:.6},{:.6},{:.6},{},{},{},{:e},{:e}",
            p.case,
            p.output,
            mode(p.setting),
            value(p.setting),
            p.runs,
            p.seconds[0],
            p.seconds[1],
            p.seconds[2],
            p.steps,
            p.newton,
            p.jacobians,
            p.error,
            p.relative
        );
    }
    s
}

pub fn markdown(points: &[Point]) -> String {
    let mut s = String::from(
        "| case | output | integrator | error (max over the run) | relative | CPU time median (min–max) s | steps | Newton | factorizations |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for p in points {
        let _ = writeln!(
            s,
            "| {} | `{}` | {} | {:.2e} | {:.1e} | {:.4} ({:.4}–{:.4}) | {} | {} | {} |",
            p.case,
            p.output,
            p.setting,
            p.error,
            p.relative,
            p.seconds[0],
            p.seconds[1],
            p.seconds[2],
            p.steps,
            p.newton,
            p.jacobians
        );
    }
    s
}

/// Writes `work_precision.csv` and `work_precision.md` into `out_dir`.
pub fn write(out_dir: &Path, points: &[Point]) -> Result<Vec<PathBuf>, HarnessError> {
    std::fs::create_dir_all(out_dir)
        .map_err(|e| HarnessError::io(out_dir, "creating the output directory", e))?;
    let mut written = Vec::new();
    for (name, text) in [
        ("work_precision.csv", csv(points)),
        ("work_precision.md", markdown(points)),
    ] {
        let path = out_dir.join(name);
        std::fs::write(&path, text).map_err(|e| HarnessError::io(&path, "writing", e))?;
        written.push(path);
    }
    Ok(written)
}
