//! `fmu-harness accuracy`: an accuracy study of any scene. The scene runs in process (the
//! engine's rlib, no packaging) at a ladder of settings: a time ladder (fixed step h0, h0/2, …
//! with the Newton tolerance divided by 4 at each halving, so that Newton's error falls as fast
//! as the step's), then a mesh ladder (every flexible beam's elements, or substructures where it
//! has them, doubled) at one step of the time ladder; each goes on past its asked length while
//! none of its runs is within half the target, or while its observed order is implausible (not
//! in the asymptotic range) and its finest difference above a tenth of the target. Each run's
//! error on the chosen outputs is estimated from the runs themselves ([`estimate`]):
//! Richardson's extrapolation of each ladder with its observed order, the two corrections added
//! to one limit. The cheapest pair (step, mesh) whose predicted error (its time and mesh errors
//! added over time) times a safety factor meets the target is run, checked against a run
//! refined in both, and probed for Newton's share and for the geometric stiffening's (a choice
//! of physics). Before it runs, the choice is relaxed (a larger step up to the coarser rung, at
//! the coarsest rung's Newton tolerance) where that run's own estimate meets the target; the
//! mesh ladder also offers the halved mesh (each count halved, rounded up). [`report`] writes
//! the table, [`plot`] the work-precision chart.
//!
//! Over 600 lines: the study is one sequence (ladders, limit, choice, its relaxation, checks)
//! whose steps share the runs and their estimates; split, each part would take most of them as
//! arguments.

pub mod cost;
pub mod estimate;
mod options;
pub mod plot;
mod pool;
mod recentre;
pub mod report;
mod run;
pub use run::thread_cpu_seconds;
mod runner;
pub mod truth;

use cost::Counts;
use estimate::{distance, distances, peaks, richardson, shifted, Ladder, Series};
use fmu_beam::{Engine, Scene, VarType};
pub use options::{AccuracyError, Options, DEFAULT_MAX_SECONDS, DEFAULT_MAX_WORK, MAX_JOBS};
use pool::Pool;
use runner::{coarsenable, fine_end, mesh_text, refinable, scene_at, Grid, Runner};
use std::time::Instant;

/// The generalized-α scheme's order in time (Chung & Hulbert 1993, with α_m, α_f, β, γ from ρ∞).
pub const TIME_ORDER: f64 = 2.0;

/// The order assumed for the mesh where three levels do not measure it: the lowest that
/// floating-frame Euler–Bernoulli meshes show on the validation cases (substructured beams:
/// chord rotations), so that an assumed order overstates rather than understates the error.
pub const MESH_ORDER: f64 = 2.0;

/// Newton's tolerance is divided by this at each halving of the step (h² like the step's error).
pub const NEWTON_PER_HALVING: f64 = 4.0;

/// The Newton probe divides the chosen setting's tolerance by this.
pub const NEWTON_PROBE: f64 = 100.0;

/// What a run is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    Time,
    Mesh,
    /// The chosen setting, where no ladder ran it.
    Chosen,
    /// The chosen setting refined in step and mesh.
    Finer,
    /// The chosen setting with Newton's tolerance / [`NEWTON_PROBE`].
    Newton,
    /// The chosen setting with every flexible beam's geometric stiffening switched.
    Stiffening,
}

impl Role {
    pub fn name(self) -> &'static str {
        match self {
            Role::Time => "time",
            Role::Mesh => "mesh",
            Role::Chosen => "chosen",
            Role::Finer => "finer",
            Role::Newton => "newton",
            Role::Stiffening => "stiffening",
        }
    }
}

/// One setting of the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setting {
    /// The fixed step (s).
    pub step: f64,
    /// Newton's tolerance.
    pub newton: f64,
    /// The mesh: each flexible beam's elements (or substructures) × 2^mesh (−1: halved,
    /// rounded up).
    pub mesh: i32,
    /// Every flexible beam's geometric stiffening switched.
    pub stiffening_switched: bool,
}

/// One run of the study.
#[derive(Debug, Clone)]
pub struct Run {
    pub role: Role,
    pub setting: Setting,
    /// The outputs on the grid, or why the run failed.
    pub result: Result<Series, String>,
    /// CPU seconds of the run (its thread's; wall seconds where Linux does not say): reported,
    /// never used to decide (they change with the load).
    pub seconds: f64,
    /// What the engine counted, and the counted work ([`cost::Shape::work`]) the study ranks
    /// settings and keeps to its budget by.
    pub counts: Counts,
    pub work: f64,
    /// Per output, the estimated error (against the study's limit); empty until estimated.
    pub errors: Vec<f64>,
    /// Per output, the error against `--reference` (empty without one).
    pub true_errors: Vec<f64>,
}

impl Run {
    /// The error against the reference (largest over the outputs), where there is one.
    pub fn true_error(&self) -> Option<f64> {
        (!self.true_errors.is_empty()).then(|| self.true_errors.iter().copied().fold(0.0, f64::max))
    }

    /// The estimated error (largest over the outputs), if the run succeeded.
    pub fn error(&self) -> Option<f64> {
        (self.result.is_ok() && !self.errors.is_empty())
            .then(|| self.errors.iter().copied().fold(0.0, f64::max))
    }
}

/// The cheapest setting found for the target, and how sure the study is of it.
#[derive(Debug, Clone)]
pub struct Choice {
    pub setting: Setting,
    /// The ladder's setting it was relaxed from (a larger step, up to the coarser rung, and
    /// the coarsest rung's Newton tolerance), or the same where the relaxed run missed.
    pub ladder: Setting,
    /// Before the run: the norm of its time error (at the scene's mesh) plus its mesh error
    /// (at the mesh ladder's step), added as functions of time (they may cancel; their norms'
    /// sum, `time_share + mesh_share`, bounds it).
    pub predicted: f64,
    /// The difference to the finer run the estimate expects: each error divided by 2^order.
    pub expected_difference: f64,
    pub time_share: f64,
    pub mesh_share: f64,
    /// Counted work predicted from the ladders' runs.
    pub predicted_work: f64,
    /// Its run's index in [`Study::runs`].
    pub run: usize,
    /// The finer run's index, and the difference to it (the study's norm).
    pub finer: Option<(usize, f64)>,
    /// The difference to the Newton probe: Newton's share of the error.
    pub newton_share: Option<f64>,
    /// The difference when geometric stiffening is switched (or why it could not be).
    pub stiffening_change: Option<Result<f64, String>>,
    /// The scene at the chosen setting, as TOML (the command writes it as `chosen.toml`).
    pub scene_toml: String,
}

/// A finished study.
#[derive(Debug, Clone)]
pub struct Study {
    pub scene: String,
    pub outputs: Vec<String>,
    pub target: f64,
    pub start: f64,
    pub stop: f64,
    pub comm: f64,
    /// The mesh of each level from −1 (halved) up, as text (`beam 10 el.`).
    pub meshes: Vec<String>,
    pub runs: Vec<Run>,
    pub time: Option<Ladder>,
    pub mesh: Option<Ladder>,
    /// The time ladder's level at which the mesh ladder ran.
    pub mesh_step_level: usize,
    /// The choice's predicted error times this meets the target ([`SAFETY_OBSERVED`],
    /// [`SAFETY_ASSUMED`]).
    pub margin: f64,
    /// Per time level and per mesh level (from the coarsest that ran): the estimated shares.
    pub time_shares: Vec<Option<f64>>,
    pub mesh_shares: Vec<Option<f64>>,
    pub choice: Option<Choice>,
    /// Runs left out by the budget, and other remarks.
    pub notes: Vec<String>,
    /// The study's own cost: counted work and CPU seconds of its runs, wall seconds (a first
    /// study's included, where this one is re-centred).
    pub work: f64,
    pub cpu_seconds: f64,
    pub wall_seconds: f64,
    /// Why the study stopped before its end (its wall-clock safety stop fired): its choice is
    /// then that of the runs before the stop, and may differ from a complete study's.
    pub incomplete: Option<String>,
    /// Runs run at once (the pool's workers; 1: one after another).
    pub jobs: usize,
    /// Runs the workers ran ahead that the study did not ask for (stopped part-way or
    /// finished), and their CPU seconds: what running ahead cost.
    pub unused: (usize, f64),
    /// Times a run ahead was paused on a worker for one the study asked for (and went on later,
    /// the same bit for bit).
    pub pauses: usize,
    /// Runs of a first study that are not in `runs` (this one is re-centred on its mesh).
    pub earlier_runs: usize,
}

impl Study {
    /// The text of the mesh at `mesh` (−1: the halved one), as the table writes it.
    pub fn mesh_name(&self, mesh: i32) -> &str {
        self.meshes
            .get((mesh + 1).max(0) as usize)
            .map_or("", String::as_str)
    }

    /// Whether the runs were judged against a reference.
    pub fn judged(&self) -> bool {
        self.runs.iter().any(|r| !r.true_errors.is_empty())
    }

    /// The time ladder's step at `level`.
    pub fn step(&self, level: usize) -> f64 {
        self.runs
            .iter()
            .find(|r| r.role == Role::Time)
            .map_or(0.0, |r| r.setting.step)
            / 2f64.powi(level as i32)
    }
}

/// The choice's predicted error times this must meet the target, where every ladder's order
/// is observed (Roache 1997's factor for three grids or more).
pub const SAFETY_OBSERVED: f64 = 1.25;

/// The same where an order is assumed (fewer than three runs, or not in the asymptotic range).
pub const SAFETY_ASSUMED: f64 = 3.0;

/// Values of one run (grid points × outputs): every run is kept until the estimates are made.
pub const MAX_VALUES: usize = 1_000_000;

/// The time ladder's most levels, extensions included.
pub const MAX_TIME_LEVELS: usize = 12;

/// The mesh ladder's most levels (the scene's mesh × 32), extensions included.
pub const MAX_MESH_LEVELS: usize = 6;

/// A ladder's extrapolation (from its finest unbroken successes), its limit, and each rung's
/// distance to the limit (its share of the error).
struct Estimate {
    ladder: Option<Ladder>,
    limit: Series,
    shares: Vec<Option<f64>>,
}

fn estimate(r: &Runner, rungs: &[Option<usize>], peaks: &[f64], nominal: f64) -> Option<Estimate> {
    let tail = fine_end(r, rungs);
    let series: Vec<Series> = tail.iter().filter_map(|&i| r.values(i).cloned()).collect();
    let ladder = richardson(&series.iter().collect::<Vec<_>>(), peaks, nominal);
    let limit = match &ladder {
        Some(l) => l.limit.clone(),
        None => series.last()?.clone(),
    };
    let shares = rungs
        .iter()
        .map(|i| {
            i.and_then(|i| r.values(i))
                .map(|y| distance(y, &limit, peaks))
        })
        .collect();
    Some(Estimate {
        ladder,
        limit,
        shares,
    })
}

/// Whether a ladder past its asked length may stop: it has two runs or more, one of them
/// within half the target, and it is not out of its asymptotic range (an implausible observed
/// order) while its finest difference is above a tenth of the target: its estimate would then
/// be unsure at the target's own scale, and refining further is what finds the range (Roache
/// 1997).
fn ladder_done(r: &Runner, rungs: &[Option<usize>], nominal: f64, target: f64) -> bool {
    let Some(&finest) = fine_end(r, rungs).last() else {
        return false;
    };
    let Some(pk) = r.values(finest).map(peaks) else {
        return false;
    };
    let Some(Estimate {
        ladder: Some(l),
        shares,
        ..
    }) = estimate(r, rungs, &pk, nominal)
    else {
        return false;
    };
    let meets = shares.iter().flatten().any(|&s| s <= target / 2.0);
    let unsettled = matches!(
        l.source,
        estimate::OrderSource::Nominal { observed: Some(_) }
    ) && l.differences.last().is_some_and(|&d| d > target / 10.0);
    meets && !unsettled
}

/// The checks of a chosen `setting`: the finer run (step halved, Newton's tolerance / 4, the
/// mesh doubled where there is one), the Newton probe and the stiffening switched (where there
/// is a mesh: the third is run only then).
fn checks(setting: Setting, has_mesh: bool) -> [Setting; 3] {
    [
        Setting {
            step: setting.step / 2.0,
            newton: (setting.newton / NEWTON_PER_HALVING).max(1e-14),
            mesh: setting.mesh + i32::from(has_mesh),
            stiffening_switched: false,
        },
        Setting {
            newton: (setting.newton / NEWTON_PROBE).max(1e-15),
            ..setting
        },
        Setting {
            stiffening_switched: true,
            ..setting
        },
    ]
}

/// `x` rounded down to three significant digits (a step a scene can carry as written).
fn three_digits_down(x: f64) -> f64 {
    let m = 10f64.powi(2 - x.log10().floor() as i32);
    (x * m).floor() / m
}

/// Runs the study of `scene`; where it chooses a mesh other than the scene's, or the halved
/// mesh could meet the target, runs it again at that mesh ([`recentre`]).
pub fn study(scene: &Scene, opts: &Options) -> Result<Study, crate::HarnessError> {
    study_with(scene, opts, &|| false)
}

/// [`study`], asking `interrupted` about five times a second (the Python API passes
/// `check_signals`): once it says yes, every run stops and the study returns
/// [`AccuracyError::Interrupted`].
pub fn study_with(
    scene: &Scene,
    opts: &Options,
    interrupted: &dyn Fn() -> bool,
) -> Result<Study, crate::HarnessError> {
    opts.check()?;
    let jobs = opts.jobs();
    let workers = if jobs > 1 { jobs } else { 0 };
    let pool = Pool::new(workers, opts.max_seconds);
    let result = std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| pool.work());
        }
        let out = (|| {
            let first = study_of(scene, opts, &pool, interrupted, opts.recentre, None)?;
            Ok(if opts.recentre {
                recentre::recentred(scene, opts, first, &pool, interrupted)
            } else {
                first
            })
        })();
        pool.shut_down();
        out
    });
    if pool.stop.load(std::sync::atomic::Ordering::Relaxed) {
        return Err(AccuracyError::Interrupted.into());
    }
    let unused = pool.unused();
    let pauses = pool.pauses();
    result.map(|mut s: Study| {
        s.jobs = jobs;
        s.unused = unused;
        s.pauses = pauses;
        s
    })
}

/// The grid a study of `scene` compares its runs on: its start, communication step and number
/// of steps (points after the start), from `opts` or the scene's experiment.
pub fn grid(scene: &Scene, opts: &Options) -> Result<(f64, f64, usize), AccuracyError> {
    let start = scene.experiment.start_time;
    let stop = opts.stop.unwrap_or(scene.experiment.stop_time);
    let comm = opts.comm.unwrap_or(scene.experiment.step_size);
    if stop <= start {
        return Err(AccuracyError::BadOption {
            name: "stop",
            value: stop.to_string(),
            rule: "must be after the experiment's start time",
        });
    }
    let points = ((stop - start) / comm).round().max(1.0);
    if points * opts.outputs.len() as f64 > MAX_VALUES as f64 {
        return Err(AccuracyError::BadOption {
            name: "comm",
            value: comm.to_string(),
            rule: "the grid times the outputs may hold at most 1e6 values per run (every run \
                   is kept for the estimates): give a coarser --comm or a shorter --stop",
        });
    }
    Ok((start, comm, points as usize))
}

/// The mesh a study re-centred on `first`'s choice runs at ([`recentre`]): the chosen mesh
/// where it is not the scene's, else the halved one where its own estimated error times the
/// safety factor is within the target; None where the study is not re-centred.
pub(crate) fn recentre_mesh(
    chosen_mesh: i32,
    halved_error: Option<f64>,
    margin: f64,
    target: f64,
) -> Option<i32> {
    match chosen_mesh {
        0 if halved_error.is_some_and(|e| e * margin < target) => Some(-1),
        0 => None,
        m => Some(m),
    }
}

/// The rung of a time ladder from `h0` whose step is `h` (h0 / 2^k), if any.
fn level_of(h0: f64, h: f64) -> Option<usize> {
    let k = (h0 / h).log2().round();
    (k.is_finite() && (0.0..MAX_TIME_LEVELS as f64).contains(&k))
        .then_some(k as usize)
        .filter(|&k| (h0 / 2f64.powi(k as i32) - h).abs() <= 1e-9 * h)
}

/// One study of `base` (its runs through `pool`); `ahead`: a re-centred study may follow,
/// whose mesh and time ladders are handed to the pool as soon as the choice says which mesh it
/// runs at; `mesh_hint`: the step an earlier study ran its mesh ladder at, whose meshes are run
/// ahead during the time ladder.
fn study_of(
    base: &Scene,
    opts: &Options,
    pool: &Pool,
    interrupted: &dyn Fn() -> bool,
    ahead: bool,
    mesh_hint: Option<f64>,
) -> Result<Study, crate::HarnessError> {
    let base = base.clone();
    {
        let e = Engine::new(base.clone());
        let reals: Vec<String> = e
            .variables()
            .variables
            .iter()
            .filter(|v| v.ty == VarType::Real)
            .map(|v| v.name.clone())
            .collect();
        for o in &opts.outputs {
            if !reals.contains(o) {
                return Err(AccuracyError::UnknownOutput {
                    name: o.clone(),
                    available: reals,
                }
                .into());
            }
        }
    }
    let (start, comm, n) = grid(&base, opts)?;
    let reference = match (&opts.reference, &opts.reference_values) {
        (_, Some(values)) => {
            if values.len() != opts.outputs.len() || values.iter().any(|v| v.len() != n + 1) {
                return Err(AccuracyError::BadOption {
                    name: "reference",
                    value: format!("{} series", values.len()),
                    rule: "one series per output, on the study's grid",
                }
                .into());
            }
            Some(values.clone())
        }
        (Some((path, columns)), None) => Some(truth::read(path, columns, start, comm, n)?),
        (None, None) => None,
    };
    let h0 = opts.step.unwrap_or(comm.max(base.solver.max_step));
    let tol0 = opts
        .newton
        .unwrap_or(base.solver.tolerance.min(opts.target / 10.0))
        .max(1e-13);
    let planned = opts.levels + opts.mesh_levels.saturating_sub(1) + 4;
    let bar = if opts.progress {
        let b = indicatif::ProgressBar::new(planned as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} runs {elapsed} {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let mut r = Runner {
        base: &base,
        grid: Grid {
            outputs: &opts.outputs,
            start,
            comm,
            n,
        },
        runs: Vec::new(),
        started: Instant::now(),
        max_runs: opts.max_runs,
        max_work: opts.max_work,
        notes: Vec::new(),
        bar,
        pool,
        interrupted,
        incomplete: None,
    };
    let at = |level: usize, mesh: i32| Setting {
        step: h0 / 2f64.powi(level as i32),
        newton: (tol0 / NEWTON_PER_HALVING.powi(level as i32)).max(1e-14),
        mesh,
        stiffening_switched: false,
    };

    // the time ladder, coarse to fine (each halving about doubles the cost); past
    // `opts.levels` it goes on while no step's share is within half the target, or while its
    // order is not observed and its finest difference is above a tenth of the target
    let mut time_runs: Vec<Option<usize>> = Vec::new();
    let mut last_cost = 0.0;
    // run ahead: the asked steps, finest (longest) first, and one step past them
    let asked: Vec<Setting> = (0..=opts.levels).rev().map(|k| at(k, 0)).collect();
    r.speculate(&asked[1..]);
    r.speculate(&asked[..1]);
    // run ahead, after those: the mesh ladder at the step an earlier study of this scene ran
    // it at (`mesh_hint`: the re-centred study's mesh phase then finds its longest runs under way)
    let has_mesh = base.beams.iter().any(refinable);
    let meshes_at = |level: usize| -> Vec<Setting> {
        let mut v: Vec<Setting> = (1..opts.mesh_levels.max(2))
            .rev()
            .map(|j| at(level, j as i32))
            .collect();
        if coarsenable(&base) {
            v.push(at(level, -1));
        }
        v
    };
    let hinted = match mesh_hint.and_then(|h| level_of(h0, h)) {
        Some(k) if has_mesh && opts.mesh_levels > 1 => meshes_at(k),
        _ => Vec::new(),
    };
    r.speculate(&hinted);
    for k in 0..MAX_TIME_LEVELS {
        if k >= opts.levels
            && (time_runs.last() == Some(&None)
                || ladder_done(&r, &time_runs, TIME_ORDER, opts.target))
        {
            break;
        }
        if k + 1 >= opts.levels && k + 1 < MAX_TIME_LEVELS {
            r.speculate(&[at(k + 1, 0)]);
        }
        let i = r.run(Role::Time, at(k, 0), 2.0 * last_cost);
        if let Some(i) = i {
            last_cost = r.runs[i].work;
        }
        time_runs.push(i);
    }
    r.forget_but(&hinted);
    let time_tail = fine_end(&r, &time_runs);
    let Some(&finest) = time_tail.last() else {
        if r.incomplete.is_some() {
            return Err(AccuracyError::Stopped {
                seconds: opts.max_seconds,
            }
            .into());
        }
        let first = r.runs.iter().find_map(|x| x.result.clone().err());
        return Err(AccuracyError::NothingRan {
            step: h0,
            first: first.unwrap_or_else(|| "the budget ran out".into()),
        }
        .into());
    };
    let peaks = peaks(r.values(finest).unwrap_or(&Vec::new()));
    let Some(Estimate {
        ladder: time,
        limit: time_limit,
        shares: time_shares,
    }) = estimate(&r, &time_runs, &peaks, TIME_ORDER)
    else {
        unreachable!("the time ladder has a successful run")
    };
    if time.is_none() {
        r.notes.push(
            "one run of the time ladder succeeded: its time error is not estimated (0)".into(),
        );
    }

    // the mesh ladder, at the coarsest step whose time share is within a quarter of the
    // target (the mesh runs are then settings the choice can take), else the finest; past
    // `opts.mesh_levels` it goes on as the time ladder does
    let tail_levels: Vec<usize> = (0..time_runs.len())
        .filter(|&k| time_runs[k].is_some_and(|i| time_tail.contains(&i)))
        .collect();
    let mesh_level = tail_levels
        .iter()
        .copied()
        .find(|&k| time_shares[k].is_some_and(|s| s <= opts.target / 4.0))
        .unwrap_or(tail_levels[tail_levels.len() - 1]);
    let mut mesh_runs: Vec<Option<usize>> = vec![time_runs[mesh_level]];
    if has_mesh {
        // run ahead: the asked meshes, finest first, the halved one, and one mesh past them
        // (what was run ahead at another step is dropped)
        let ahead_meshes = meshes_at(mesh_level);
        r.forget_but(&ahead_meshes);
        r.speculate(&ahead_meshes);
        let mut cost = time_runs[mesh_level].map_or(0.0, |i| r.runs[i].work);
        for j in 1..MAX_MESH_LEVELS {
            if j >= opts.mesh_levels
                && (mesh_runs.last() == Some(&None)
                    || ladder_done(&r, &mesh_runs, MESH_ORDER, opts.target))
            {
                break;
            }
            if j + 1 >= opts.mesh_levels && j + 1 < MAX_MESH_LEVELS {
                r.speculate(&[at(mesh_level, j as i32 + 1)]);
            }
            let i = r.run(Role::Mesh, at(mesh_level, j as i32), 2.5 * cost);
            if let Some(i) = i {
                cost = r.runs[i].work;
            }
            mesh_runs.push(i);
        }
    } else if opts.mesh_levels > 1 {
        r.notes
            .push("the scene has no flexible beam to refine: no mesh ladder".into());
    }
    let mesh_estimate = estimate(&r, &mesh_runs, &peaks, MESH_ORDER);
    let mesh = mesh_estimate.as_ref().and_then(|e| e.ladder.clone());
    // the limit: the mesh ladder's, moved by the time ladder's correction at its step
    let base_at_mesh_step = time_runs[mesh_level].and_then(|i| r.values(i)).cloned();
    let (limit, mut mesh_shares) = match (&mesh, &mesh_estimate, &base_at_mesh_step) {
        (Some(m), Some(e), Some(b)) => (shifted(&m.limit, &time_limit, b), e.shares.clone()),
        _ => (time_limit.clone(), vec![Some(0.0)]),
    };
    // a halved mesh (rounded up: 3 elements give 2): not in the extrapolation, a candidate whose
    // share is its distance to the mesh ladder's limit (the scene's mesh may be finer than the
    // target needs); `offset` is the scene's mesh's index in `mesh_runs`
    let mut offset = 0;
    if let (Some(e), true) = (&mesh_estimate, mesh.is_some() && coarsenable(&base)) {
        let cost = mesh_runs[0].map_or(0.0, |i| r.runs[i].work) / 2.0;
        if let Some(i) = r.run(Role::Mesh, at(mesh_level, -1), cost) {
            let share = r.values(i).map(|y| distance(y, &e.limit, &peaks));
            mesh_runs.insert(0, Some(i));
            mesh_shares.insert(0, share);
            offset = 1;
        }
    }
    r.forget();
    if has_mesh && opts.mesh_levels > 1 && mesh.is_none() {
        r.notes.push(
            "fewer than two meshes ran: the discretization error is not estimated (0)".into(),
        );
    }
    if !has_mesh || opts.mesh_levels == 1 {
        r.notes
            .push("the discretization error is not estimated: one mesh only".into());
    }

    // the choice: the cheapest (step, mesh) whose predicted error meets the target
    let cost_of = |k: usize, j: usize, r: &Runner| -> Option<f64> {
        let c = r.runs[time_runs[k]?].work;
        let m0 = r.runs[mesh_runs[offset]?].work;
        let mj = r.runs[(*mesh_runs.get(j)?)?].work;
        Some(c * mj / m0.max(1e-9))
    };
    // a candidate's error, as a function of time: its time error (at the scene's mesh) plus
    // its mesh error (at the mesh ladder's step), each weighted; the two may cancel
    let mesh_limit = mesh_estimate.as_ref().map(|e| e.limit.clone());
    let error_of = |k: usize, j: usize, wt: f64, wx: f64, r: &Runner| -> Option<Series> {
        let y = r.values(time_runs[k]?)?;
        let mut e: Series = y
            .iter()
            .zip(&time_limit)
            .map(|(a, b)| a.iter().zip(b).map(|(u, v)| wt * (u - v)).collect())
            .collect();
        if let Some(ml) = &mesh_limit {
            let z = r.values((*mesh_runs.get(j)?)?)?;
            for ((o, zo), lo) in e.iter_mut().zip(z).zip(ml) {
                for ((x, u), v) in o.iter_mut().zip(zo).zip(lo) {
                    *x += wx * (u - v);
                }
            }
        }
        Some(e)
    };
    // Roache's safety factors of the grid convergence index: 1.25 where every ladder's
    // order is observed, 3 where one is assumed
    let observed = |l: &Option<Ladder>| {
        l.as_ref()
            .is_some_and(|l| l.source == estimate::OrderSource::Observed)
    };
    let margin = if observed(&time) && (observed(&mesh) || !has_mesh || opts.mesh_levels == 1) {
        SAFETY_OBSERVED
    } else {
        SAFETY_ASSUMED
    };
    let zero: Series = time_limit.iter().map(|o| vec![0.0; o.len()]).collect();
    let mut best: Option<(usize, usize, f64, f64)> = None;
    for (k, ts) in time_shares.iter().enumerate() {
        for (j, ms) in mesh_shares.iter().enumerate() {
            if ts.is_none() || ms.is_none() {
                continue;
            }
            let Some(c) = cost_of(k, j, &r) else { continue };
            let Some(e) = error_of(k, j, 1.0, 1.0, &r) else {
                continue;
            };
            let predicted = distance(&e, &zero, &peaks);
            if predicted * margin <= opts.target && best.is_none_or(|b| c < b.3) {
                best = Some((k, j, predicted, c));
            }
        }
    }
    let order = |l: &Option<Ladder>, default| l.as_ref().map_or(default, |l| l.order);
    let p_time = order(&time, TIME_ORDER);
    let mut choice = None;
    if let Some((k, j, ladder_predicted, ladder_work)) = best {
        let ladder_setting = at(k, j as i32 - offset as i32);
        // relaxed: the largest step up to the coarser rung (quarter octaves) that the time
        // ladder's order predicts to meet, at Newton's tolerance of the coarsest rung (the
        // ladder's tighter ones are for its differences); kept only if its run's estimated
        // error (its distance to the limit, which holds its Newton error) meets the target
        let stretch = (0..4)
            .rev()
            .map(|i| 2f64.powf(f64::from(i) / 4.0))
            .filter(|&s| k > 0 || s == 1.0)
            .find_map(|s| {
                let e = error_of(k, j, s.powf(p_time), 1.0, &r)?;
                let d = distance(&e, &zero, &peaks);
                (d * margin <= opts.target).then_some((s, d))
            });
        let mut picked = (ladder_setting, 1.0, ladder_predicted, ladder_work);
        let relaxed_of = |s: f64| Setting {
            step: if s > 1.0 {
                three_digits_down(ladder_setting.step * s)
            } else {
                ladder_setting.step
            },
            newton: tol0,
            ..ladder_setting
        };
        // run ahead: the setting the relaxation probably keeps, its checks, and the time
        // ladder of the re-centred study that may follow (its steps at the chosen mesh)
        let likely = stretch.map_or(ladder_setting, |(s, _)| relaxed_of(s));
        let mut ahead_runs = vec![likely];
        ahead_runs.extend(
            checks(likely, has_mesh)
                .into_iter()
                .take(2 + usize::from(has_mesh)),
        );
        if ahead {
            let halved_error = (offset == 1)
                .then(|| mesh_runs[0].and_then(|i| r.values(i)))
                .flatten()
                .map(|y| distance(y, &limit, &peaks));
            if let Some(m) =
                recentre_mesh(j as i32 - offset as i32, halved_error, margin, opts.target)
            {
                // its mesh ladder at this study's mesh step, finest first (the longest runs of
                // all: a core takes them while the other checks this choice)
                if has_mesh && opts.mesh_levels > 1 {
                    ahead_runs.extend(
                        (1..opts.mesh_levels.max(2))
                            .rev()
                            .map(|i| at(mesh_level, m + i as i32)),
                    );
                }
                // as deep as this study's ladder went (the finest first: the longest)
                ahead_runs.extend(
                    (0..time_runs.len().max(opts.levels))
                        .rev()
                        .map(|k| Setting {
                            mesh: m,
                            ..at(k, 0)
                        }),
                );
            }
        }
        r.speculate(&ahead_runs);
        if let Some((s, d)) = stretch {
            let relaxed = relaxed_of(s);
            if relaxed != ladder_setting {
                let seconds = ladder_work / s;
                let kept = r.run(Role::Chosen, relaxed, seconds).and_then(|i| {
                    let e = distance(r.values(i)?, &limit, &peaks);
                    if e * margin <= opts.target {
                        Some(i)
                    } else {
                        r.notes.push(format!(
                            "relaxed setting h = {:e} s, Newton's tolerance {:.0e}: estimated \
                             error {e:.2e} × {margin} misses the target; \
                             the ladder's setting h = {:e} s, tolerance {:.0e} kept",
                            relaxed.step,
                            relaxed.newton,
                            ladder_setting.step,
                            ladder_setting.newton
                        ));
                        None
                    }
                });
                if kept.is_some() {
                    picked = (relaxed, s, d, seconds);
                }
            }
        }
        let (setting, s, predicted, predicted_work) = picked;
        let existing = r
            .runs
            .iter()
            .position(|x| x.setting == setting && x.result.is_ok());
        let run = existing.or_else(|| r.run(Role::Chosen, setting, predicted_work));
        if let Some(run) = run.filter(|&i| r.values(i).is_some()) {
            let [finer_setting, newton_setting, stiffening_setting] = checks(setting, has_mesh);
            let finer_cost = predicted_work * if has_mesh { 5.0 } else { 2.0 };
            // a ladder's run at that setting serves (C4: the mesh ladder ran at the step above)
            let finer = r
                .runs
                .iter()
                .position(|x| x.setting == finer_setting && x.result.is_ok())
                .or_else(|| r.run(Role::Finer, finer_setting, finer_cost))
                .and_then(|i| Some((i, r.values(i)?)))
                .map(|(i, y)| {
                    (
                        i,
                        distance(y, &r.runs[run].result.clone().unwrap_or_default(), &peaks),
                    )
                });
            let probe = |r: &mut Runner, role, s: Setting| -> Option<Result<f64, String>> {
                let i = r.run(role, s, predicted_work * 1.5)?;
                let chosen = r.values(run)?;
                Some(match &r.runs[i].result {
                    Ok(y) => Ok(distance(y, chosen, &peaks)),
                    Err(e) => Err(e.clone()),
                })
            };
            let newton_share = probe(&mut r, Role::Newton, newton_setting).and_then(Result::ok);
            let stiffening_change = if has_mesh {
                probe(&mut r, Role::Stiffening, stiffening_setting)
            } else {
                None
            };
            // the finer run has each error divided by 2^order: the difference to expect
            let expected_difference = error_of(
                k,
                j,
                s.powf(p_time) * (1.0 - 0.5f64.powf(p_time)),
                if has_mesh {
                    1.0 - 0.5f64.powf(order(&mesh, MESH_ORDER))
                } else {
                    0.0
                },
                &r,
            )
            .map_or(f64::NAN, |e| distance(&e, &zero, &peaks));
            choice = Some(Choice {
                setting,
                ladder: ladder_setting,
                predicted,
                expected_difference,
                time_share: time_shares[k].unwrap_or(0.0) * s.powf(p_time),
                mesh_share: mesh_shares[j].unwrap_or(0.0),
                predicted_work,
                run,
                finer,
                newton_share,
                stiffening_change,
                scene_toml: scene_at(&base, &setting)
                    .map(|s| s.to_toml_string())
                    .unwrap_or_default(),
            });
        }
    }
    r.bar.finish_and_clear();
    if !ahead {
        r.forget();
    }

    // every run's estimated error against the limit
    for run in &mut r.runs {
        if let Ok(y) = &run.result {
            run.errors = distances(y, &limit, &peaks);
        }
    }
    let cpu_seconds = r.runs.iter().map(|x| x.seconds).sum();
    let work = r.work();
    let mut study = Study {
        scene: base.name.clone(),
        outputs: opts.outputs.clone(),
        target: opts.target,
        start,
        stop: start + n as f64 * comm,
        comm,
        meshes: (-1..=MAX_MESH_LEVELS as i32)
            .map(|j| mesh_text(&base, j))
            .collect(),
        runs: r.runs,
        time,
        mesh,
        mesh_step_level: mesh_level,
        margin,
        time_shares,
        mesh_shares,
        choice,
        notes: r.notes,
        work,
        cpu_seconds,
        wall_seconds: r.started.elapsed().as_secs_f64(),
        earlier_runs: 0,
        incomplete: r.incomplete,
        jobs: 1,
        unused: (0, 0.0),
        pauses: 0,
    };
    if let Some(reference) = &reference {
        truth::judge(&mut study, reference);
    }
    Ok(study)
}
