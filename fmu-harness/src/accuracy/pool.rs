//! The study's runs on several threads (`--jobs`). The study itself stays one sequence: it asks
//! for one run at a time and decides from its result what to run next, as a serial study does.
//! Runs it will probably ask for next are handed to the pool beforehand ([`Pool::speculate`]):
//! worker threads run them while the study waits for others, and a run the study then asks for
//! is already done or under way. What the study does not ask for is cancelled and never
//! enters its table, so that the choice and every figure are the serial study's (a run is the
//! same bit for bit on any thread); only CPU and wall seconds differ.

use super::run::{stretch, to_the_end, Failure, Job, Outcome, Pending, Stretch, POLL};
use std::collections::{HashMap, HashSet, VecDeque};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

enum State {
    /// Waiting for a worker; `u64`: its rank (lower = sooner; 0: the study asks for it).
    Queued(Pending, u64),
    /// On a worker: its stop flag, its pause flag and its rank.
    Running(Arc<AtomicBool>, Arc<AtomicBool>, u64),
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
    /// The rank the next speculated job gets.
    next_rank: u64,
    /// Runs paused for an asked one.
    paused: usize,
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

    /// A worker's loop: the first queued job, run (or run on where paused), stored; until
    /// [`Pool::shut_down`]. A run paused for an asked one goes back to the queue, right behind
    /// the jobs the study asks for.
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
            if !matches!(g.states.get(&key), Some(State::Queued(..))) {
                continue;
            }
            let Some(State::Queued(pending, rank)) = g.states.remove(&key) else {
                continue;
            };
            let cancel = Arc::new(AtomicBool::new(false));
            let pause = Arc::new(AtomicBool::new(false));
            g.states.insert(
                key.clone(),
                State::Running(cancel.clone(), pause.clone(), rank),
            );
            drop(g);
            let out = stretch(
                pending,
                &[&self.stop, &cancel],
                Some(&pause),
                self.deadline,
                None,
            );
            g = self.lock();
            match out {
                Stretch::Paused(run) => {
                    g.paused += 1;
                    let at = g
                        .queue
                        .iter()
                        .position(|k| !matches!(g.states.get(k), Some(State::Queued(_, 0))))
                        .unwrap_or(g.queue.len());
                    g.states
                        .insert(key.clone(), State::Queued(Pending::Paused(run), rank));
                    g.queue.insert(at, key);
                }
                Stretch::Ended(out) if matches!(out.result, Err(Failure::Stopped)) => {
                    g.states.remove(&key);
                    g.stopped.0 += 1;
                    g.stopped.1 += out.seconds;
                }
                Stretch::Ended(out) => {
                    g.states.insert(key, State::Done(out));
                }
            }
            self.changed.notify_all();
        }
    }

    /// Where the study asks for `key` and every worker runs something else, pauses the run it
    /// will want last (the highest rank), unless one is pausing already.
    fn make_room(&self, g: &Inner, key: &str) {
        let mut running = 0;
        let mut last: Option<(&AtomicBool, u64)> = None;
        for (k, s) in &g.states {
            if let State::Running(_, pause, rank) = s {
                if k == key || pause.load(Ordering::Relaxed) {
                    return;
                }
                running += 1;
                if last.is_none_or(|(_, r)| *rank > r) {
                    last = Some((pause, *rank));
                }
            }
        }
        if running >= self.workers {
            if let Some((pause, _)) = last {
                pause.store(true, Ordering::Relaxed);
            }
        }
    }

    /// What the workers ran and the study did not take: runs, CPU seconds (stopped part-way,
    /// paused and never gone on with, or finished).
    pub(super) fn unused(&self) -> (usize, f64) {
        let g = self.lock();
        let (mut n, mut seconds) = g.stopped;
        for (k, s) in &g.states {
            match s {
                State::Done(o) if !g.taken.contains(k) => {
                    n += 1;
                    seconds += o.seconds;
                }
                State::Queued(Pending::Paused(r), _) => {
                    n += 1;
                    seconds += r.seconds;
                }
                _ => {}
            }
        }
        (n, seconds)
    }

    /// How many times a run was paused for one the study asked for.
    pub(super) fn pauses(&self) -> usize {
        self.lock().paused
    }

    /// Ends the workers' loops (queued jobs are dropped, running ones stopped).
    pub(super) fn shut_down(&self) {
        let mut g = self.lock();
        g.shutdown = true;
        g.queue.clear();
        for s in g.states.values() {
            if let State::Running(c, ..) = s {
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
                g.next_rank += 1;
                let rank = g.next_rank;
                g.states.insert(
                    key.clone(),
                    State::Queued(Pending::Fresh(Box::new(job)), rank),
                );
                g.queue.push_back(key);
            }
        }
        self.changed.notify_all();
    }

    /// Drops the queued (and paused) jobs and stops the running ones that `keep` does not
    /// name: the study has gone past them.
    pub(super) fn forget(&self, keep: &[String]) {
        let mut g = self.lock();
        let Inner {
            states,
            queue,
            stopped,
            ..
        } = &mut *g;
        queue.retain(|k| {
            let kept = keep.contains(k);
            if !kept {
                if let Some(State::Queued(Pending::Paused(r), _)) = states.remove(k) {
                    stopped.0 += 1;
                    stopped.1 += r.seconds;
                }
            }
            kept
        });
        for (k, s) in states.iter() {
            if let State::Running(c, ..) = s {
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
            match g.states.get_mut(&key) {
                Some(State::Done(o)) => {
                    let o = o.clone();
                    g.taken.insert(key);
                    return o;
                }
                Some(State::Running(..)) => {
                    if interrupted() {
                        self.stop.store(true, Ordering::Relaxed);
                    }
                    g = self
                        .changed
                        .wait_timeout(g, POLL)
                        .map(|(g, _)| g)
                        .unwrap_or_else(|p| p.into_inner().0);
                }
                Some(State::Queued(_, rank)) if self.workers > 0 => {
                    // asked for now: first in the queue, and a worker for it
                    *rank = 0;
                    g.queue.retain(|k| k != &key);
                    g.queue.push_front(key.clone());
                    self.make_room(&g, &key);
                    self.changed.notify_all();
                    if interrupted() {
                        self.stop.store(true, Ordering::Relaxed);
                    }
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
                    g.states.insert(
                        key.clone(),
                        State::Queued(Pending::Fresh(Box::new(job.clone())), 0),
                    );
                    g.queue.push_front(key.clone());
                    self.changed.notify_all();
                }
                Some(State::Queued(..)) | None => {
                    if self.stop.load(Ordering::Relaxed)
                        || self.deadline.is_some_and(|d| Instant::now() > d)
                    {
                        return stopped();
                    }
                    g.queue.retain(|k| k != &key);
                    let pending = match g.states.remove(&key) {
                        Some(State::Queued(p, _)) => p,
                        _ => Pending::Fresh(Box::new(job.clone())),
                    };
                    let cancel = Arc::new(AtomicBool::new(false));
                    let pause = Arc::new(AtomicBool::new(false));
                    g.states
                        .insert(key.clone(), State::Running(cancel.clone(), pause, 0));
                    drop(g);
                    let poll = || {
                        let i = interrupted();
                        if i {
                            self.stop.store(true, Ordering::Relaxed);
                        }
                        i
                    };
                    let out =
                        to_the_end(pending, &[&self.stop, &cancel], self.deadline, Some(&poll));
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

#[cfg(test)]
mod tests {
    use super::super::run::simulate;
    use super::super::run::tests::crank_job;
    use super::*;
    use fmu_beam::Scene;

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

    /// With its one worker busy with a run ahead, a run the study asks for pauses it: the asked
    /// run is done first, the paused one goes on afterwards and ends as if never paused.
    #[test]
    fn an_asked_run_pauses_a_run_ahead_that_then_ends_unchanged() {
        let ahead = crank_job(300, 2e-4);
        let asked = crank_job(5, 2e-3);
        let pool = Pool::new(1, 600.0);
        std::thread::scope(|s| {
            s.spawn(|| pool.work());
            pool.speculate(vec![ahead.clone()]);
            // wait until the worker runs it
            while !matches!(
                pool.lock().states.get(&ahead.key()),
                Some(State::Running(..))
            ) {
                std::thread::sleep(Duration::from_millis(1));
            }
            let o = pool.take(asked.clone(), &|| false);
            assert_eq!(
                o.result.unwrap().0,
                simulate(&asked, &[], None, None).result.unwrap().0
            );
            assert_eq!(pool.pauses(), 1, "the run ahead was not paused");
            let a = pool.take(ahead.clone(), &|| false);
            pool.shut_down();
            let whole = simulate(&ahead, &[], None, None).result.unwrap();
            let (y, c) = a.result.unwrap();
            assert_eq!(y, whole.0);
            assert_eq!((c.steps, c.iterations), (whole.1.steps, whole.1.iterations));
            assert_eq!(pool.unused(), (0, 0.0));
        });
    }
}
