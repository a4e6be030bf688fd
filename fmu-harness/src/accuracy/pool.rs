//! The study's runs on several threads (`--jobs`). The study itself stays one sequence: it asks
//! for one run at a time and decides from its result what to run next, as a serial study does.
//! Runs it will probably ask for next are handed to the pool beforehand ([`Pool::speculate`]):
//! worker threads run them while the study waits for others, and a run the study then asks for
//! is already done or under way. What the study does not ask for is cancelled and never
//! enters its table, so that the choice and every figure are the serial study's (a run is the
//! same bit for bit on any thread); only CPU and wall seconds differ.

use super::cost::Counts;
use super::estimate::Series;
use fmu_beam::{Engine, Scene};
use std::collections::{HashMap, HashSet, VecDeque};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
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

/// Runs `job` over its grid: the outputs at every point and the engine's counters; stops at a
/// communication point once any of `stop` is raised or `deadline` has passed.
/// `interrupted`, where given, is asked about five times a second.
pub(super) fn simulate(
    job: &Job,
    stop: &[&AtomicBool],
    deadline: Option<Instant>,
    interrupted: Option<&dyn Fn() -> bool>,
) -> Outcome {
    let wall = Instant::now();
    let cpu0 = thread_cpu_seconds();
    let result = simulate_inner(job, stop, deadline, interrupted);
    let seconds = match (cpu0, thread_cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => wall.elapsed().as_secs_f64(),
    };
    Outcome { result, seconds }
}

fn simulate_inner(
    job: &Job,
    stop: &[&AtomicBool],
    deadline: Option<Instant>,
    interrupted: Option<&dyn Fn() -> bool>,
) -> Result<(Series, Counts), Failure> {
    let mut asked = Instant::now();
    let failed = |m: String| Failure::Failed(m);
    let mut e = Engine::new(job.scene.clone());
    let vrs: Vec<u32> = job
        .outputs
        .iter()
        .map(|o| {
            e.variables()
                .by_name(o)
                .map(|v| v.vr)
                .ok_or_else(|| failed(format!("the unit has no output {o}")))
        })
        .collect::<Result<_, _>>()?;
    e.exit_initialization().map_err(|x| failed(x.to_string()))?;
    let mut values = vec![Vec::with_capacity(job.n + 1); vrs.len()];
    for k in 0..=job.n {
        let now = Instant::now();
        if let Some(f) = interrupted.filter(|_| now.duration_since(asked) >= POLL) {
            asked = now;
            if f() {
                return Err(Failure::Stopped);
            }
        }
        if stop.iter().any(|s| s.load(Ordering::Relaxed)) || deadline.is_some_and(|d| now > d) {
            return Err(Failure::Stopped);
        }
        if k > 0 {
            let t = job.start + (k - 1) as f64 * job.comm;
            e.do_step(t, job.comm)
                .map_err(|x| failed(format!("at t = {t} s: {x}")))?;
        }
        for (v, &vr) in values.iter_mut().zip(&vrs) {
            v.push(e.get_real(vr).map_err(|x| failed(x.to_string()))?);
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
    Ok((values, counts))
}

enum State {
    Queued(Box<Job>),
    Running(Arc<AtomicBool>),
    Done(Outcome),
}

#[derive(Default)]
struct Inner {
    states: HashMap<String, State>,
    queue: VecDeque<String>,
    shutdown: bool,
    /// The jobs the study took.
    taken: HashSet<String>,
    /// Runs stopped before their end (gone past), and their CPU seconds.
    stopped: (usize, f64),
}

/// The runs of one study, shared by its thread and the workers.
pub(super) struct Pool {
    inner: Mutex<Inner>,
    changed: Condvar,
    /// Raised to stop every run (an interrupt).
    pub(super) stop: AtomicBool,
    /// The wall-clock safety stop.
    pub(super) deadline: Option<Instant>,
    limit: f64,
    /// Worker threads: 0 runs everything on the study's thread, in order.
    workers: usize,
}

impl Pool {
    /// A pool for `workers` worker threads (0: the study's thread runs everything), whose runs
    /// stop `max_seconds` of wall time from now.
    pub(super) fn new(workers: usize, max_seconds: f64) -> Pool {
        Pool {
            inner: Mutex::new(Inner::default()),
            changed: Condvar::new(),
            stop: AtomicBool::new(false),
            deadline: Instant::now().checked_add(Duration::from_secs_f64(max_seconds.min(1e9))),
            limit: max_seconds,
            workers,
        }
    }

    /// The safety stop's seconds from the start (0 without one).
    pub(super) fn limit_seconds(&self) -> f64 {
        self.limit
    }

    pub(super) fn workers(&self) -> usize {
        self.workers
    }

    fn lock(&self) -> MutexGuard<'_, Inner> {
        // a worker that panicked cannot leave the map half-changed: take it as it is
        self.inner.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// A worker's loop: the first queued job, run, stored; until [`Pool::shut_down`].
    pub(super) fn work(&self) {
        let mut g = self.lock();
        loop {
            if g.shutdown {
                return;
            }
            let Some(key) = g.queue.pop_front() else {
                g = self.changed.wait(g).unwrap_or_else(|p| p.into_inner());
                continue;
            };
            let cancel = Arc::new(AtomicBool::new(false));
            let Some(State::Queued(job)) =
                g.states.insert(key.clone(), State::Running(cancel.clone()))
            else {
                continue;
            };
            drop(g);
            let out = simulate(&job, &[&self.stop, &cancel], self.deadline, None);
            g = self.lock();
            if matches!(out.result, Err(Failure::Stopped)) {
                g.states.remove(&key);
                g.stopped.0 += 1;
                g.stopped.1 += out.seconds;
            } else {
                g.states.insert(key, State::Done(out));
            }
            self.changed.notify_all();
        }
    }

    /// What the workers ran and the study did not take: runs, CPU seconds (stopped part-way
    /// or finished).
    pub(super) fn unused(&self) -> (usize, f64) {
        let g = self.lock();
        let (mut n, mut seconds) = g.stopped;
        for (k, s) in &g.states {
            if let State::Done(o) = s {
                if !g.taken.contains(k) {
                    n += 1;
                    seconds += o.seconds;
                }
            }
        }
        (n, seconds)
    }

    /// Ends the workers' loops (queued jobs are dropped, running ones stopped).
    pub(super) fn shut_down(&self) {
        let mut g = self.lock();
        g.shutdown = true;
        g.queue.clear();
        for s in g.states.values() {
            if let State::Running(c) = s {
                c.store(true, Ordering::Relaxed);
            }
        }
        self.changed.notify_all();
    }

    /// Queues `jobs` (first = soonest) for the workers, where not queued, running or done.
    pub(super) fn speculate(&self, jobs: Vec<Job>) {
        if self.workers == 0 {
            return;
        }
        let mut g = self.lock();
        for job in jobs {
            let key = job.key();
            if !g.states.contains_key(&key) {
                g.states.insert(key.clone(), State::Queued(Box::new(job)));
                g.queue.push_back(key);
            }
        }
        self.changed.notify_all();
    }

    /// Drops the queued jobs and stops the running ones that `keep` does not name: the study
    /// has gone past them.
    pub(super) fn forget(&self, keep: &[String]) {
        let mut g = self.lock();
        let Inner { states, queue, .. } = &mut *g;
        queue.retain(|k| {
            let kept = keep.contains(k);
            if !kept {
                states.remove(k);
            }
            kept
        });
        for (k, s) in states.iter() {
            if let State::Running(c) = s {
                if !keep.contains(k) {
                    c.store(true, Ordering::Relaxed);
                }
            }
        }
    }

    /// The outcome of `job`: done already, or awaited where a worker runs it, or run here.
    /// `interrupted` is asked about five times a second meanwhile (and raises `stop`).
    pub(super) fn take(&self, job: Job, interrupted: &dyn Fn() -> bool) -> Outcome {
        let key = job.key();
        let mut g = self.lock();
        loop {
            match g.states.get(&key) {
                Some(State::Done(o)) => {
                    let o = o.clone();
                    g.taken.insert(key);
                    return o;
                }
                Some(State::Running(_)) => {
                    if interrupted() {
                        self.stop.store(true, Ordering::Relaxed);
                    }
                    g = self
                        .changed
                        .wait_timeout(g, POLL)
                        .map(|(g, _)| g)
                        .unwrap_or_else(|p| p.into_inner().0);
                }
                Some(State::Queued(_)) if self.workers > 0 => {
                    // asked for now: first in the queue
                    g.queue.retain(|k| k != &key);
                    g.queue.push_front(key.clone());
                    self.changed.notify_all();
                    g = self
                        .changed
                        .wait_timeout(g, POLL)
                        .map(|(g, _)| g)
                        .unwrap_or_else(|p| p.into_inner().0);
                }
                None if self.workers > 0 => {
                    if self.stop.load(Ordering::Relaxed)
                        || self.deadline.is_some_and(|d| Instant::now() > d)
                    {
                        return stopped();
                    }
                    g.states
                        .insert(key.clone(), State::Queued(Box::new(job.clone())));
                    g.queue.push_front(key.clone());
                    self.changed.notify_all();
                }
                Some(State::Queued(_)) | None => {
                    if self.stop.load(Ordering::Relaxed)
                        || self.deadline.is_some_and(|d| Instant::now() > d)
                    {
                        return stopped();
                    }
                    g.queue.retain(|k| k != &key);
                    let cancel = Arc::new(AtomicBool::new(false));
                    g.states.insert(key.clone(), State::Running(cancel.clone()));
                    drop(g);
                    let poll = || {
                        let i = interrupted();
                        if i {
                            self.stop.store(true, Ordering::Relaxed);
                        }
                        i
                    };
                    let out = simulate(&job, &[&self.stop, &cancel], self.deadline, Some(&poll));
                    g = self.lock();
                    if matches!(out.result, Err(Failure::Stopped)) {
                        g.states.remove(&key);
                    } else {
                        g.states.insert(key.clone(), State::Done(out.clone()));
                        g.taken.insert(key);
                    }
                    self.changed.notify_all();
                    return out;
                }
            }
        }
    }
}

fn stopped() -> Outcome {
    Outcome {
        result: Err(Failure::Stopped),
        seconds: 0.0,
    }
}

/// How often a waiting or running study asks whether it was interrupted.
const POLL: Duration = Duration::from_millis(200);

#[cfg(test)]
mod tests {
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

    /// A job the study has gone past is stopped and never stored; one it asks for is run
    /// (here by the study's own thread, the pool having no worker).
    #[test]
    fn a_forgotten_job_is_dropped_and_an_asked_one_is_run() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes/slider_crank_rigid_crank.toml");
        let job = Job {
            scene: Scene::load(&path).unwrap(),
            outputs: vec!["slider.position".into()],
            start: 0.0,
            comm: 1e-2,
            n: 5,
        };
        let pool = Pool::new(0, 600.0);
        pool.speculate(vec![job.clone()]);
        pool.forget(&[]);
        assert!(pool.lock().states.is_empty());
        let o = pool.take(job.clone(), &|| false);
        assert_eq!(o.result.unwrap().0[0].len(), 6);
        // stopped from outside: no result, and nothing stored
        pool.stop.store(true, Ordering::Relaxed);
        let mut other = job;
        other.n = 6;
        assert!(matches!(
            pool.take(other, &|| false).result,
            Err(Failure::Stopped)
        ));
    }
}
