//! One of our peer settings run alone (`fmu-bench peer-run`): a case of [`peer::cases`], one of
//! its formulations and one setting as `ours_points.csv` names them, run over the case's grid
//! (or up to a shorter end time), scored against the reference, timed on the thread's CPU
//! clock, and printed as one JSON line with the counters that say where the time goes: steps,
//! refused steps, Newton iterations, iteration matrices, unknowns. `bench/peer/interleaved.py`
//! calls it between Exudyn's runs; under `valgrind --tool=callgrind` with `--samples 0` it is
//! the one run whose instructions are counted.

use super::peer::{self, PeerCase};
use super::{thread_cpu_seconds, Setting, MIN_SAMPLE};
use crate::error::BenchError;
use fmu_beam::integrator::{IterationMatrix, LinearSolver};
use fmu_beam::mechanics::{Equations, Mechanics};
use fmu_beam::{resolve_effects, Engine, EngineError, Scene};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// What to run.
#[derive(Debug, Clone)]
pub struct Request<'a> {
    pub scenes: &'a Path,
    pub references: &'a Path,
    /// As the points name it: `c2`, `c3_elastic`, `c3_rigid`, `c4_omega10`, `c4_omega4`.
    pub case: &'a str,
    /// A formulation of the case, e.g. `10 x 2 substructures`.
    pub formulation: &'a str,
    /// A setting as the points name it: `fixed step 1.0e-3 s`, `fixed step 1.0e-3 s,
    /// tolerance 1e-8`, `tolerance 1e-6`.
    pub setting: &'a str,
    /// End time (s) instead of the case's; a multiple of its communication step.
    pub stop: Option<f64>,
    /// Timed samples after the first run (0: the first run only, for callgrind). A sample is
    /// one run, or a batch of runs lasting at least [`MIN_SAMPLE`] s divided by its size.
    pub samples: usize,
}

/// A setting's name in the points back to the setting and its Newton tolerance (None: the
/// scene's).
pub fn parse_setting(name: &str) -> Option<(Setting, Option<f64>)> {
    let seconds = |s: &str| s.trim().strip_suffix(" s")?.trim().parse::<f64>().ok();
    if let Some(rest) = name.strip_prefix("tolerance ") {
        return Some((Setting::Tolerance(rest.trim().parse().ok()?), None));
    }
    let rest = name.strip_prefix("fixed step ")?;
    match rest.split_once(", tolerance ") {
        Some((h, t)) => Some((
            Setting::FixedStep(seconds(h)?),
            Some(t.trim().parse().ok()?),
        )),
        None => Some((Setting::FixedStep(seconds(rest)?), None)),
    }
}

/// The CPU seconds of the thread since `c0` (wall seconds since `start` where Linux does not
/// offer them).
fn since(start: Instant, c0: Option<f64>) -> f64 {
    match (c0, thread_cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => start.elapsed().as_secs_f64(),
    }
}

/// Runs the request; returns the JSON line.
pub fn run(r: &Request) -> Result<String, BenchError> {
    let bad = |message: String| BenchError::Input {
        origin: "peer-run".into(),
        message,
    };
    let cases = peer::cases();
    let names: Vec<&str> = cases.iter().map(|c| c.name).collect();
    let mut case: PeerCase = cases
        .iter()
        .find(|c| c.name == r.case)
        .cloned()
        .ok_or_else(|| bad(format!("no case {:?}; the cases: {names:?}", r.case)))?;
    let f = case
        .formulations
        .iter()
        .find(|f| f.name == r.formulation)
        .cloned()
        .ok_or_else(|| {
            let known: Vec<&str> = case.formulations.iter().map(|f| f.name).collect();
            bad(format!(
                "{} has no formulation {:?}; its formulations: {known:?}",
                case.name, r.formulation
            ))
        })?;
    let (setting, newton) = parse_setting(r.setting).ok_or_else(|| {
        bad(format!(
            "setting {:?}: `fixed step 1.0e-3 s`, `fixed step 1.0e-3 s, tolerance 1e-8` or \
             `tolerance 1e-6` expected",
            r.setting
        ))
    })?;
    if let Some(stop) = r.stop {
        let k = stop / case.comm;
        if !(stop > 0.0 && stop <= case.stop && (k - k.round()).abs() < 1e-9) {
            return Err(bad(format!(
                "--stop {stop}: a multiple of {} s up to {} s expected",
                case.comm, case.stop
            )));
        }
        case.stop = stop;
    }
    let base = Scene::load(&r.scenes.join(case.scene))?;
    let scene = peer::configure(&base, &f, setting, newton)?;
    let (names, rows) = peer::read_reference(&r.references.join(case.reference))?;
    let n = (case.stop / case.comm).round() as usize + 1;
    if rows.len() < n {
        return Err(bad(format!(
            "{}: {} rows, at least {n} expected",
            case.reference,
            rows.len()
        )));
    }
    let engine = |source| BenchError::Engine {
        origin: format!("{} ({}, {})", case.name, f.name, r.setting),
        source,
    };

    // the unknowns, and the build alone (wall time: the thread's account moves in ticks)
    let sys = Mechanics::build(&scene, &resolve_effects(&scene).effects);
    let (unknowns, rows_m) = (sys.n(), sys.m());
    let sparse = IterationMatrix::new(&sys, LinearSolver::Auto).is_sparse();
    let start = Instant::now();
    let mut e = Engine::new(scene.clone());
    e.exit_initialization().map_err(engine)?;
    let init = start.elapsed().as_secs_f64();
    drop(e);

    // the first run: outputs, counters, and the first sample if it lasts long enough
    let start = Instant::now();
    let (first, mut e) = peer::simulate_engine(&scene, &case).map_err(engine)?;
    let first_wall = start.elapsed().as_secs_f64();
    let mut counter = |name: &str| -> Result<i64, EngineError> {
        match e.variables().by_name(name).map(|v| v.vr) {
            Some(vr) => e.get_integer(vr).map(i64::from),
            None => Ok(0),
        }
    };
    let counters = [
        ("steps", counter("solver.steps").map_err(engine)?),
        (
            "rejected",
            counter("solver.rejected_steps").map_err(engine)?,
        ),
        ("split", counter("solver.split_steps").map_err(engine)?),
        (
            "newton_iterations",
            counter("solver.newton_iterations").map_err(engine)?,
        ),
        ("jacobians", counter("solver.jacobians").map_err(engine)?),
    ];
    drop(e);
    let mut samples = Vec::new();
    let batch = if first.seconds >= MIN_SAMPLE {
        samples.push(first.seconds);
        1
    } else {
        // sized from the wall time, finer than the thread's account and never below it
        (MIN_SAMPLE / first_wall.max(first.seconds).max(1e-6)).ceil() as usize
    };
    while r.samples > 0 && samples.len() < r.samples {
        let (start, c0) = (Instant::now(), thread_cpu_seconds());
        for _ in 0..batch {
            peer::simulate_engine(&scene, &case).map_err(engine)?;
        }
        samples.push(since(start, c0) / batch as f64);
    }
    samples.sort_by(f64::total_cmp);

    let mut json = format!(
        "{{\"case\": {:?}, \"formulation\": {:?}, \"setting\": {:?}, \"stop\": {}, \
         \"first_cpu\": {:.6e}, \"first_wall\": {:.6e}, \"init_wall\": {:.6e}, \"batch\": {batch}, \
         \"samples\": [",
        case.name, f.name, r.setting, case.stop, first.seconds, first_wall, init
    );
    for (k, s) in samples.iter().enumerate() {
        let _ = write!(json, "{}{s:.6e}", if k > 0 { ", " } else { "" });
    }
    json += "]";
    if !samples.is_empty() {
        let _ = write!(json, ", \"cpu\": {:.6e}", samples[samples.len() / 2]);
    }
    for (name, v) in counters {
        let _ = write!(json, ", \"{name}\": {v}");
    }
    let _ = write!(
        json,
        ", \"n\": {unknowns}, \"m\": {rows_m}, \"sparse\": {sparse}, \"errors\": {{"
    );
    for (k, ((col, _), y)) in case.outputs.iter().zip(&first.values).enumerate() {
        let at = names
            .iter()
            .position(|c| c == col)
            .ok_or_else(|| bad(format!("{}: no column {col}", case.reference)))?;
        let reference: Vec<f64> = rows[..n].iter().map(|row| row[at]).collect();
        let rel = peer::scored(y, &reference, peer::stride(&scene, &case));
        let _ = write!(
            json,
            "{}\"{col}\": {rel:.6e}",
            if k > 0 { ", " } else { "" }
        );
    }
    json += "}}";
    Ok(json)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every setting the peer study names reads back as itself.
    #[test]
    fn settings_read_back() {
        for (name, setting, newton) in [
            ("tolerance 1e-6", Setting::Tolerance(1e-6), None),
            ("fixed step 1.0e-3 s", Setting::FixedStep(1e-3), None),
            (
                "fixed step 2.5e-5 s, tolerance 1e-8",
                Setting::FixedStep(2.5e-5),
                Some(1e-8),
            ),
        ] {
            assert_eq!(parse_setting(name), Some((setting, newton)), "{name}");
        }
        assert_eq!(parse_setting("fixed step 1e-3"), None);
        assert_eq!(parse_setting("ne=2;h=0.001;rho_inf=0.9"), None);
    }
}
