//! One run of the accuracy study: a scene at a setting, stepped over its grid of communication
//! points, with its outputs and the engine's counters. A run can stop at a communication point
//! and go on later on any thread ([`Run`]), bit for bit as if never paused: the pool pauses a
//! run ahead for one the study asks for (`pool.rs`).

use super::cost::Counts;
use super::estimate::Series;
use fmu_beam::{Engine, Scene};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// What a run needs: the scene at its setting and the grid it records.
#[derive(Debug, Clone)]
pub(super) struct Job {
    pub(super) scene: Scene,
    pub(super) outputs: Vec<String>,
    pub(super) start: f64,
    pub(super) comm: f64,
    pub(super) n: usize,
}

impl Job {
    /// The job's identity: its scene's canonical text and its grid.
    pub(super) fn key(&self) -> String {
        format!(
            "{}\n# grid {:e} {:e} {} {}",
            self.scene.to_toml_string(),
            self.start,
            self.comm,
            self.n,
            self.outputs.join(",")
        )
    }
}

/// Why a run has no result.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Failure {
    /// The engine refused the scene or failed a step: a property of the setting.
    Failed(String),
    /// Stopped from outside (the wall-clock safety stop, an interrupt, a cancelled
    /// speculation): not a property of the setting.
    Stopped,
}

/// A finished run: its outputs and counters, or why not; and its CPU seconds.
#[derive(Debug, Clone)]
pub(super) struct Outcome {
    pub(super) result: Result<(Series, Counts), Failure>,
    pub(super) seconds: f64,
}

/// CPU seconds this thread has run (the scheduler's account), where Linux says (None
/// elsewhere): the accuracy study's and the benchmarks' clock.
pub fn thread_cpu_seconds() -> Option<f64> {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()?
        .split_whitespace()
        .next()?
        .parse::<f64>()
        .ok()
        .map(|ns| ns * 1e-9)
}

/// A run between two communication points: its engine and what it recorded so far, resumable
/// on any thread (a worker pauses a run the study has not asked for when the study asks for
/// another and no worker is free; the run goes on later, bit for bit as if never paused).
pub(super) struct Run {
    job: Box<Job>,
    engine: Engine,
    vrs: Vec<u32>,
    values: Series,
    /// The next communication point to record.
    next: usize,
    /// CPU seconds spent on it so far.
    pub(super) seconds: f64,
}

/// A run not under way: not begun, or paused.
pub(super) enum Pending {
    Fresh(Box<Job>),
    Paused(Box<Run>),
}

/// Where a stretch of a run ended.
pub(super) enum Stretch {
    Ended(Outcome),
    Paused(Box<Run>),
}

/// Runs `job` over its grid: the outputs at every point and the engine's counters; stops at a
/// communication point once any of `stop` is raised or `deadline` has passed.
/// `interrupted`, where given, is asked about five times a second.
#[cfg(test)]
pub(super) fn simulate(
    job: &Job,
    stop: &[&AtomicBool],
    deadline: Option<Instant>,
    interrupted: Option<&dyn Fn() -> bool>,
) -> Outcome {
    to_the_end(
        Pending::Fresh(Box::new(job.clone())),
        stop,
        deadline,
        interrupted,
    )
}

/// Runs `pending` on until it ends (nothing pauses it).
pub(super) fn to_the_end(
    mut pending: Pending,
    stop: &[&AtomicBool],
    deadline: Option<Instant>,
    interrupted: Option<&dyn Fn() -> bool>,
) -> Outcome {
    loop {
        match stretch(pending, stop, None, deadline, interrupted) {
            Stretch::Ended(o) => return o,
            Stretch::Paused(run) => pending = Pending::Paused(run),
        }
    }
}

/// Runs `pending` on from where it is until it ends (done, failed or stopped) or, at a
/// communication point, `pause` is raised.
pub(super) fn stretch(
    pending: Pending,
    stop: &[&AtomicBool],
    pause: Option<&AtomicBool>,
    deadline: Option<Instant>,
    interrupted: Option<&dyn Fn() -> bool>,
) -> Stretch {
    let wall = Instant::now();
    let cpu0 = thread_cpu_seconds();
    let spent = |before: f64| {
        before
            + match (cpu0, thread_cpu_seconds()) {
                (Some(a), Some(b)) => b - a,
                _ => wall.elapsed().as_secs_f64(),
            }
    };
    let mut run = match pending {
        Pending::Paused(r) => r,
        Pending::Fresh(job) => match begin(job) {
            Ok(r) => Box::new(r),
            Err(f) => {
                return Stretch::Ended(Outcome {
                    result: Err(f),
                    seconds: spent(0.0),
                })
            }
        },
    };
    match go_on(&mut run, stop, pause, deadline, interrupted) {
        Some(result) => Stretch::Ended(Outcome {
            result,
            seconds: spent(run.seconds),
        }),
        None => {
            run.seconds = spent(run.seconds);
            Stretch::Paused(run)
        }
    }
}

/// The run of `job` at its first communication point, before it is recorded.
fn begin(job: Box<Job>) -> Result<Run, Failure> {
    let failed = |m: String| Failure::Failed(m);
    let mut engine = Engine::new(job.scene.clone());
    let vrs: Vec<u32> = job
        .outputs
        .iter()
        .map(|o| {
            engine
                .variables()
                .by_name(o)
                .map(|v| v.vr)
                .ok_or_else(|| failed(format!("the unit has no output {o}")))
        })
        .collect::<Result<_, _>>()?;
    engine
        .exit_initialization()
        .map_err(|x| failed(x.to_string()))?;
    let values = vec![Vec::with_capacity(job.n + 1); vrs.len()];
    Ok(Run {
        job,
        engine,
        vrs,
        values,
        next: 0,
        seconds: 0.0,
    })
}

/// Steps `run` on point by point: its result once it ends, None where `pause` stopped it at a
/// communication point (ready to go on; each call records at least one point).
fn go_on(
    run: &mut Run,
    stop: &[&AtomicBool],
    pause: Option<&AtomicBool>,
    deadline: Option<Instant>,
    interrupted: Option<&dyn Fn() -> bool>,
) -> Option<Result<(Series, Counts), Failure>> {
    let mut asked = Instant::now();
    let failed = |m: String| Some(Err(Failure::Failed(m)));
    let Run {
        job,
        engine: e,
        vrs,
        values,
        next,
        ..
    } = run;
    while *next <= job.n {
        let k = *next;
        let now = Instant::now();
        if let Some(f) = interrupted.filter(|_| now.duration_since(asked) >= POLL) {
            asked = now;
            if f() {
                return Some(Err(Failure::Stopped));
            }
        }
        if stop.iter().any(|s| s.load(Ordering::Relaxed)) || deadline.is_some_and(|d| now > d) {
            return Some(Err(Failure::Stopped));
        }
        if k > 0 {
            let t = job.start + (k - 1) as f64 * job.comm;
            if let Err(x) = e.do_step(t, job.comm) {
                return failed(format!("at t = {t} s: {x}"));
            }
        }
        for (v, &vr) in values.iter_mut().zip(vrs.iter()) {
            match e.get_real(vr) {
                Ok(y) => v.push(y),
                Err(x) => return failed(x.to_string()),
            }
        }
        *next += 1;
        // at least one point a stretch: a run paused over and over still gets on
        if *next <= job.n && pause.is_some_and(|p| p.load(Ordering::Relaxed)) {
            return None;
        }
    }
    let mut count = |name: &str| match e.variables().by_name(name).map(|v| v.vr) {
        Some(vr) => u64::try_from(e.get_integer(vr).unwrap_or(0)).unwrap_or(0),
        None => 0,
    };
    let counts = Counts {
        steps: count("solver.steps"),
        iterations: count("solver.newton_iterations"),
        jacobians: count("solver.jacobians"),
        points: job.n as u64,
    };
    Some(Ok((std::mem::take(values), counts)))
}

/// How often a waiting or running study asks whether it was interrupted.
pub(super) const POLL: Duration = Duration::from_millis(200);

#[cfg(test)]
pub(super) mod tests {
    use super::super::cost::Shape;
    use super::*;

    /// A run's counted cost is a property of its setting: the same number, bit for bit, on
    /// every run (here three, one of them on another thread while this one also runs).
    #[test]
    fn the_counted_cost_is_the_same_number_on_every_run() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes/slider_crank_rigid_crank.toml");
        let mut scene = Scene::load(&path).unwrap();
        scene.solver.max_step = 5e-3;
        let job = Job {
            scene,
            outputs: vec!["slider.position".into()],
            start: 0.0,
            comm: 1e-2,
            n: 40,
        };
        let shape = Shape::of(&job.scene);
        let counted = |o: Outcome| {
            let (y, c) = o.result.unwrap();
            (y, c, shape.work(&c).to_bits())
        };
        let first = counted(simulate(&job, &[], None, None));
        let (second, third) = std::thread::scope(|s| {
            let other = s.spawn(|| counted(simulate(&job, &[], None, None)));
            let here = counted(simulate(&job, &[], None, None));
            (here, other.join().unwrap())
        });
        assert!(
            first.1.iterations > first.1.steps && first.1.jacobians > 0,
            "{:?}",
            first.1
        );
        assert!(f64::from_bits(first.2) > 0.0);
        assert_eq!(first, second);
        assert_eq!(first, third);
    }

    pub(in super::super) fn crank_job(n: usize, max_step: f64) -> Job {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes/slider_crank_rigid_crank.toml");
        let mut scene = Scene::load(&path).unwrap();
        scene.solver.max_step = max_step;
        Job {
            scene,
            outputs: vec!["slider.position".into()],
            start: 0.0,
            comm: 1e-2,
            n,
        }
    }

    /// A run paused at every communication point and gone on with (here on another thread
    /// each time) ends with the uninterrupted run's outputs and counters, bit for bit.
    #[test]
    fn a_run_paused_at_every_point_ends_as_an_uninterrupted_one() {
        let job = crank_job(12, 2e-3);
        let whole = simulate(&job, &[], None, None).result.unwrap();
        let pause = AtomicBool::new(true);
        let mut pending = Pending::Fresh(Box::new(job.clone()));
        let mut stretches = 0;
        let out = loop {
            stretches += 1;
            let s = std::thread::scope(|t| {
                t.spawn(|| stretch(pending, &[], Some(&pause), None, None))
                    .join()
                    .unwrap()
            });
            match s {
                Stretch::Ended(o) => break o,
                Stretch::Paused(run) => {
                    assert!(run.seconds >= 0.0);
                    pending = Pending::Paused(run)
                }
            }
        };
        // one point a stretch: the start and each of the 12 steps
        assert_eq!(stretches, 13);
        let (y, c) = out.result.unwrap();
        assert_eq!(y.len(), 1);
        assert_eq!(y[0].len(), 13);
        let bits = |v: &Series| -> Vec<u64> { v[0].iter().map(|x| x.to_bits()).collect() };
        assert_eq!(bits(&y), bits(&whole.0));
        assert_eq!(
            (c.steps, c.iterations, c.jacobians, c.points),
            (
                whole.1.steps,
                whole.1.iterations,
                whole.1.jacobians,
                whole.1.points
            )
        );
    }
}
