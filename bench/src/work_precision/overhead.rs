//! The unit's own cost per communication step (issue 12: at most 2 µs beyond the steps): the
//! same internal steps driven by few long and by many short doSteps, the difference in CPU time
//! over the difference in doSteps. A unit without inputs (C1, fixed step 1e-3 s) steps across
//! communication points and interpolates its outputs; so does a unit with inputs while they are
//! held (the flexible arm under a held torque, fixed step 1e-4 s, whose steps end on the
//! communication points); in both the internal steps do not change with the communication
//! step, so what differs is the doSteps' own work.

use super::thread_cpu_seconds;
use crate::error::BenchError;
use fmu_beam::{Engine, EngineError, Scene};
use std::fmt::Write as _;
use std::path::Path;

/// (scene, fixed step, simulated time, long communication step, short communication step)
const RUNS: [(&str, f64, f64, f64, f64); 2] = [
    ("cantilever_free_vibration.toml", 1e-3, 1.0, 1e-2, 1e-5),
    ("flexible_arm.toml", 1e-4, 1.0, 1e-2, 1e-4),
];

/// CPU seconds of a run of `scene` at a fixed step `h` to `stop` in doSteps of `hc`.
fn run(scene: &Scene, h: f64, stop: f64, hc: f64) -> Result<f64, EngineError> {
    let mut s = scene.clone();
    s.solver.adaptive = false;
    s.solver.max_step = h;
    let mut e = Engine::new(s);
    e.exit_initialization()?;
    let c0 = thread_cpu_seconds().unwrap_or(0.0);
    let n = (stop / hc).round() as usize;
    for k in 0..n {
        e.do_step(k as f64 * hc, hc)?;
    }
    Ok(thread_cpu_seconds().unwrap_or(0.0) - c0)
}

/// The table of the report: per scene, µs per doStep beyond the steps (median, min, max of
/// `repeats` pairs of runs, each pair timed back to back).
pub fn table(scenes: &Path, repeats: usize) -> Result<String, BenchError> {
    let mut s = String::from(
        "## The unit's own cost per communication step\n\n\
         The same internal steps driven by doSteps of two sizes; (CPU of the short doSteps − CPU \
         of the long ones) / (number of short − long doSteps); median (min–max) of the pairs.\n\n\
         | scene | fixed step | doSteps | µs per doStep beyond the steps |\n|---|---|---|---|\n",
    );
    for (file, h, stop, long, short) in RUNS {
        let scene = Scene::load(&scenes.join(file))?;
        let engine = |e| BenchError::Engine {
            origin: format!("{file} (doStep overhead)"),
            source: e,
        };
        let extra = ((stop / short).round() - (stop / long).round()).max(1.0);
        let mut us: Vec<f64> = (0..repeats.max(1))
            .map(|_| {
                let a = run(&scene, h, stop, long)?;
                let b = run(&scene, h, stop, short)?;
                Ok((b - a) / extra * 1e6)
            })
            .collect::<Result<_, EngineError>>()
            .map_err(engine)?;
        us.sort_by(f64::total_cmp);
        let _ = writeln!(
            s,
            "| {file} | {h:.0e} s | {long:.0e} s vs {short:.0e} s | {:.2} ({:.2}–{:.2}) |",
            us[us.len() / 2],
            us[0],
            us[us.len() - 1]
        );
    }
    Ok(s)
}
