//! Work-precision study of the validation cases (`fmu-bench work-precision`, `make bench`):
//! for each case of [`cases::cases`], every formulation (element count, substructures, rigid
//! parts, modal truncation, geometric stiffening) at every integrator setting (error control at
//! a tolerance, or a fixed step), the error of the case's outputs against one reference per
//! case ([`cases::Reference`]: a closed form, or an untimed run of a finer formulation) versus
//! the CPU time; then, for chosen models, each effect of [`fmu_beam::EFFECTS`]
//! switched off in turn, and `effects = "auto"`. Runs the engine directly (no FMI layer),
//! `repeats` times per point, and reports the CPU time of the thread (the scheduler's account
//! in /proc; wall time where Linux does not offer it) as median / min / max. [`report`] writes
//! `points.csv` and `REPORT.md`. [`spatial`] adds the 3D cases, built in code.
//!
//! Over 600 lines: the study's loop, its timing and the effects table with their tests; a
//! benchmark, not the product.

pub mod cases;
pub mod choice;
pub mod exact;
pub mod exhaustive;
pub mod overhead;
pub mod peer;
pub mod peer_run;
pub mod report;
pub mod spatial;

use crate::error::BenchError;
use cases::{Case, Formulation, Reference};
use fmu_beam::scene::EffectsSpec;
use fmu_beam::{resolve_effects as resolve, EFFECTS};
use fmu_beam::{Engine, EngineError, Scene};
use fmu_harness::accuracy::thread_cpu_seconds;
use std::path::Path;
use std::time::Instant;

/// The tolerance that stops Newton in fixed-step runs.
pub const FIXED_STEP_NEWTON_TOLERANCE: f64 = 1e-10;

/// How the integrator is set for one point: error control at a tolerance, or a fixed step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Setting {
    Tolerance(f64),
    FixedStep(f64),
}

impl Setting {
    pub fn mode(self) -> &'static str {
        match self {
            Setting::Tolerance(_) => "adaptive",
            Setting::FixedStep(_) => "fixed",
        }
    }

    pub fn value(self) -> f64 {
        match self {
            Setting::Tolerance(v) | Setting::FixedStep(v) => v,
        }
    }

    /// The scene with this integrator setting; error control may step up to `comm`.
    fn apply(self, scene: &mut Scene, comm: f64) {
        match self {
            Setting::Tolerance(t) => {
                scene.solver.adaptive = true;
                scene.solver.tolerance = t;
                scene.solver.max_step = comm;
            }
            Setting::FixedStep(h) => {
                // with a fixed step the tolerance only stops Newton: tight, so that the step
                // alone sets the error (a loose Newton error accumulates over many steps)
                scene.solver.adaptive = false;
                scene.solver.max_step = h;
                scene.solver.tolerance = FIXED_STEP_NEWTON_TOLERANCE;
            }
        }
    }
}

impl std::fmt::Display for Setting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Setting::Tolerance(t) => write!(f, "tolerance {t:.0e}"),
            Setting::FixedStep(h) => write!(f, "fixed step {h:.1e} s"),
        }
    }
}

/// How a point ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    Ok,
    /// The engine refused a step (the message says where and why).
    Failed(String),
    /// Not run: a looser setting of the same formulation already took longer than the budget.
    Skipped(String),
}

/// One timed point: a model at an integrator setting.
#[derive(Debug, Clone)]
pub struct Point {
    pub case: &'static str,
    /// The main output (the one `errors[0]` is of).
    pub output: &'static str,
    pub formulation: String,
    pub setting: Setting,
    /// `all`, `auto` or `no <effect>` (the effects rows); `all` in the sweep.
    pub effects: String,
    pub status: Status,
    pub runs: usize,
    /// CPU seconds of one run: median, min, max.
    pub seconds: [f64; 3],
    pub steps: i64,
    pub newton: i64,
    pub factorizations: i64,
    /// Per output of the case: max |y − y_ref| over the communication points (NaN: no
    /// reference for that output).
    pub errors: Vec<f64>,
    /// `errors` over max |y_ref|.
    pub relative: Vec<f64>,
    /// Outputs the model does not offer (a rigid beam has no deflection), taken as 0.
    pub missing: Vec<String>,
    /// Error of the main output against the case's [`cases::Check`], where it applies.
    pub check: Option<f64>,
    /// The main output at the communication points (empty when the run failed).
    pub values: Vec<f64>,
}

impl Point {
    pub fn ok(&self) -> bool {
        self.status == Status::Ok
    }
}

/// An effects row: the point and what the report says about it.
#[derive(Debug, Clone)]
pub struct EffectRow {
    pub point: Point,
    /// The effect switched off, or None for `all` and `auto`.
    pub removed: Option<&'static str>,
    /// What `auto` chose differently from `all`; why a removed term is zero in this case.
    pub note: String,
}

/// One case's results.
#[derive(Debug, Clone)]
pub struct CaseResult {
    pub case: Case,
    /// What the errors are measured against.
    pub reference: String,
    pub points: Vec<Point>,
    /// Per model of `case.effects`: its rows, `all` first.
    pub effects: Vec<Vec<EffectRow>>,
    /// The check's own figure (C2: the rigid pendulum's period), as text.
    pub check: Option<String>,
}

/// Values of each output at the communication points, and the run's counters.
struct Series {
    values: Vec<Vec<f64>>,
    missing: Vec<String>,
    seconds: f64,
    stats: [i64; 3],
}

/// Simulates `scene` (already at its integrator setting) over the case's communication grid.
fn simulate(scene: &Scene, case: &Case) -> Result<Series, EngineError> {
    let start = Instant::now();
    let cpu0 = thread_cpu_seconds();
    let mut e = Engine::new(scene.clone());
    let vr = |e: &Engine, n: &str| e.variables().by_name(n).map(|v| v.vr);
    e.exit_initialization()?;
    let outs: Vec<Option<u32>> = case.outputs.iter().map(|o| vr(&e, o)).collect();
    let read = |e: &mut Engine| -> Result<Vec<f64>, EngineError> {
        outs.iter()
            .map(|v| v.map_or(Ok(0.0), |v| e.get_real(v)))
            .collect()
    };
    let n = (case.stop / case.comm).round() as usize;
    let mut values = vec![Vec::with_capacity(n + 1); outs.len()];
    let mut push = |row: Vec<f64>| {
        for (v, y) in values.iter_mut().zip(row) {
            v.push(y);
        }
    };
    push(read(&mut e)?);
    for k in 0..n {
        e.do_step(k as f64 * case.comm, case.comm)?;
        push(read(&mut e)?);
    }
    let seconds = match (cpu0, thread_cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => start.elapsed().as_secs_f64(),
    };
    let mut stat = |name| vr(&e, name).map_or(Ok(0), |v| e.get_integer(v).map(i64::from));
    let stats = [
        stat("solver.steps")?,
        stat("solver.newton_iterations")?,
        stat("solver.jacobians")?,
    ];
    let missing = case
        .outputs
        .iter()
        .zip(&outs)
        .filter(|(_, v)| v.is_none())
        .map(|(o, _)| o.to_string())
        .collect();
    Ok(Series {
        values,
        missing,
        seconds,
        stats,
    })
}

/// CPU seconds of the thread, or wall seconds since `start` where Linux does not offer them.
pub(crate) fn clock(start: Instant) -> f64 {
    thread_cpu_seconds().unwrap_or_else(|| start.elapsed().as_secs_f64())
}

/// Shortest timed sample (s): the scheduler's account moves in ticks (4 ms here), so runs
/// shorter than this are timed in batches and the batch's time divided by its size.
pub const MIN_SAMPLE: f64 = 0.1;

/// One run of a model: its outputs, counters and CPU seconds.
type Run<'a> = dyn Fn() -> Result<Series, EngineError> + 'a;

/// A model being timed: its first run's results, the batch size and the samples so far.
struct Timing<'a> {
    run: &'a Run<'a>,
    first: Series,
    n: usize,
    samples: Vec<f64>,
}

impl<'a> Timing<'a> {
    /// Runs the model once, and sizes the batch of runs one sample takes (≥ MIN_SAMPLE s).
    fn start(run: &'a Run<'a>) -> Result<Timing<'a>, EngineError> {
        let first = run()?;
        let mut t = Timing {
            run,
            first,
            n: 1,
            samples: Vec::new(),
        };
        let s = t.first.seconds;
        if s >= MIN_SAMPLE {
            t.samples.push(s);
        } else if s >= 0.02 {
            // long enough to size the batch from (several scheduler ticks)
            t.n = (MIN_SAMPLE / s).ceil() as usize;
        } else {
            // double the batch until it lasts MIN_SAMPLE; that batch is the first sample
            loop {
                t.n *= 2;
                let total = t.batch()?;
                if total >= MIN_SAMPLE || t.n >= 1 << 16 {
                    t.samples.push(total / t.n as f64);
                    break;
                }
            }
        }
        Ok(t)
    }

    /// CPU seconds of a batch of `n` runs.
    fn batch(&self) -> Result<f64, EngineError> {
        let origin = Instant::now();
        let c0 = clock(origin);
        for _ in 0..self.n {
            (self.run)()?;
        }
        Ok(clock(origin) - c0)
    }

    /// One more sample: a batch's time over its size.
    fn sample(&mut self) -> Result<(), EngineError> {
        let t = self.batch()?;
        self.samples.push(t / self.n as f64);
        Ok(())
    }

    /// The first run's results, the CPU seconds of one run (median, min, max over the
    /// samples), and the number of runs timed.
    fn finish(mut self) -> (Series, [f64; 3], usize) {
        self.samples.sort_by(f64::total_cmp);
        let m = self.samples.len();
        let s = &self.samples;
        (self.first, [s[m / 2], s[0], s[m - 1]], m * self.n)
    }
}

/// A timed model: the first run's results, CPU seconds of one run (median, min, max), runs.
type Timed = Result<(Series, [f64; 3], usize), EngineError>;

/// Times one model: `repeats` samples.
fn timed(run: &Run, repeats: usize) -> Timed {
    let mut t = Timing::start(run)?;
    while t.samples.len() < repeats.max(1) {
        t.sample()?;
    }
    Ok(t.finish())
}

/// Times several models round by round (one sample of each per round), so that a change of
/// the machine's load during the measurement falls on all of them alike.
fn timed_together<'a>(runs: &[&'a Run<'a>], repeats: usize) -> Vec<Timed> {
    let mut ts: Vec<Result<Timing<'a>, EngineError>> =
        runs.iter().map(|r| Timing::start(*r)).collect();
    for _ in 0..repeats.max(1) {
        for t in &mut ts {
            let failed = match t {
                Ok(x) if x.samples.len() < repeats.max(1) => x.sample().err(),
                _ => None,
            };
            if let Some(e) = failed {
                *t = Err(e);
            }
        }
    }
    ts.into_iter().map(|t| t.map(Timing::finish)).collect()
}

/// Timed runs per model in the effects tables (interleaved, see `timed_together`).
pub const EFFECTS_REPEATS: usize = 5;

/// A formulation's scene at a setting and with `effects`, checked by the scene rules.
fn build(
    base: &Scene,
    case: &Case,
    f: &Formulation,
    setting: Setting,
    effects: EffectsSpec,
) -> Result<Scene, BenchError> {
    let mut s = f.apply(base);
    setting.apply(&mut s, case.comm);
    s.effects = effects;
    let origin = format!("{} ({}, {setting})", base.name, f.name);
    Ok(Scene::from_toml_str(&s.to_toml_string(), &origin)?)
}

/// Largest |y − r| and its ratio to max |r|.
fn error(y: &[f64], r: &[f64]) -> (f64, f64) {
    let e = y
        .iter()
        .zip(r)
        .fold(0.0f64, |m, (y, r)| m.max((y - r).abs()));
    let scale = r.iter().fold(0.0f64, |m, r| m.max(r.abs()));
    (e, if scale > 0.0 { e / scale } else { f64::NAN })
}

/// The study's knobs.
#[derive(Debug, Clone)]
pub struct Options {
    /// Timed runs per point (median, min and max are reported).
    pub repeats: usize,
    /// CPU seconds of one run above which the tighter settings of the same formulation and
    /// integrator mode are skipped.
    pub budget: f64,
}

/// Runs the study for `cases`; `progress` receives a line per point.
pub fn study(
    scenes_dir: &Path,
    cases: &[Case],
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<CaseResult>, BenchError> {
    let total: usize = cases
        .iter()
        .map(|c| {
            1 + c
                .formulations
                .iter()
                .map(|f| f.settings.as_ref().unwrap_or(&c.settings).len())
                .sum::<usize>()
                + c.effects.len() * (EFFECTS.len() + 2)
        })
        .sum();
    let started = Instant::now();
    let mut done = 0usize;
    let mut tick = |line: &str, progress: &mut dyn FnMut(&str)| {
        done += 1;
        let el = started.elapsed().as_secs();
        progress(&format!(
            "[{done:>3}/{total}, {:>2}:{:02}] {line}",
            el / 60,
            el % 60
        ));
    };
    let mut results = Vec::new();
    for case in cases {
        let base = Scene::load(&scenes_dir.join(case.scene))?;
        let times: Vec<f64> = (0..=((case.stop / case.comm).round() as usize))
            .map(|k| k as f64 * case.comm)
            .collect();
        let (reference, described): (Vec<Vec<f64>>, String) = match &case.reference {
            Reference::Exact { what, values } => {
                let mut r = vec![values(&base, &times)];
                r.extend((1..case.outputs.len()).map(|_| Vec::new()));
                (r, what.to_string())
            }
            Reference::Run {
                formulation,
                setting,
            } => {
                let scene = build(&base, case, formulation, *setting, EffectsSpec::default())?;
                let s = simulate(&scene, case).map_err(|source| BenchError::Engine {
                    origin: format!("{} reference run ({})", case.name, formulation.name),
                    source,
                })?;
                let text = format!(
                    "a run of the finest formulation, {}, at {setting} ({} steps, {:.1} s CPU, \
                     untimed); every formulation is compared with it",
                    formulation.name, s.stats[0], s.seconds
                );
                (s.values, text)
            }
        };
        tick(&format!("{}: reference: {described}", case.name), progress);
        let check = case.check.as_ref().map(|c| (c, (c.values)(&base, &times)));
        let score = |p: &mut Point, timing: Timed| {
            let (s, seconds, runs) = match timing {
                Ok(x) => x,
                Err(m) => {
                    p.status = Status::Failed(m.to_string());
                    return;
                }
            };
            p.runs = runs;
            p.seconds = seconds;
            [p.steps, p.newton, p.factorizations] = s.stats;
            for (i, (y, r)) in s.values.iter().zip(&reference).enumerate() {
                if !r.is_empty() {
                    (p.errors[i], p.relative[i]) = error(y, r);
                }
            }
            if let Some((c, exact)) = &check {
                if c.formulation == p.formulation {
                    p.check = Some(error(&s.values[0], exact).0);
                }
            }
            p.missing = s.missing;
            p.values = s.values.into_iter().next().unwrap_or_default();
        };
        let line = |p: &Point| {
            match &p.status {
            Status::Ok => format!(
                "{}: {} at {}{}: error {:.2e} ({:.1e} relative), {:.3} s CPU (median of {}), {} steps",
                p.case,
                p.formulation,
                p.setting,
                if p.effects == "all" {
                    String::new()
                } else {
                    format!(", effects {}", p.effects)
                },
                p.errors[0],
                p.relative[0],
                p.seconds[0],
                p.runs,
                p.steps
            ),
            Status::Failed(m) | Status::Skipped(m) => format!(
                "{}: {} at {}, effects {}: {m}",
                p.case, p.formulation, p.setting, p.effects
            ),
        }
        };
        let mut points = Vec::new();
        for f in &case.formulations {
            let mut over: Vec<&'static str> = Vec::new();
            for &setting in f.settings.as_ref().unwrap_or(&case.settings) {
                let p = if over.contains(&setting.mode()) {
                    Point {
                        status: Status::Skipped(format!(
                            "skipped: a looser {} setting took more than the budget of {} s",
                            setting.mode(),
                            options.budget
                        )),
                        ..skeleton(case, f.name, setting)
                    }
                } else {
                    let scene = build(&base, case, f, setting, EffectsSpec::default())?;
                    let mut p = skeleton(case, f.name, setting);
                    score(&mut p, timed(&|| simulate(&scene, case), options.repeats));
                    if p.ok() && p.seconds[0] > options.budget {
                        over.push(setting.mode());
                    }
                    p
                };
                tick(&line(&p), progress);
                points.push(p);
            }
        }
        let mut effects = Vec::new();
        for &(name, setting) in &case.effects {
            let f = case.formulation(name);
            let full_scene = build(&base, case, f, setting, EffectsSpec::default())?;
            let full = resolve(&full_scene);
            let auto_scene = build(&base, case, f, setting, EffectsSpec::Mode("auto".into()))?;
            let auto = resolve(&auto_scene);
            // (row, its scene or why the scene rules refused it)
            let mut rows: Vec<(EffectRow, Result<Scene, String>)> = Vec::new();
            let row = |effects: String, removed, note| EffectRow {
                point: Point {
                    effects,
                    ..skeleton(case, f.name, setting)
                },
                removed,
                note,
            };
            rows.push((
                row("all".into(), None, "the full model".into()),
                Ok(full_scene),
            ));
            for (effect, _) in EFFECTS {
                let list = EFFECTS
                    .iter()
                    .map(|(e, _)| e.to_string())
                    .filter(|e| e != effect)
                    .collect();
                let scene = build(&base, case, f, setting, EffectsSpec::List(list))
                    .map_err(|e| format!("refused: {e}"));
                let note = zero_here(effect, &full, &auto).unwrap_or_default();
                rows.push((row(format!("no {effect}"), Some(effect), note), scene));
            }
            rows.push((
                row("auto".into(), None, auto_differs(&full, &auto)),
                Ok(auto_scene),
            ));
            let runs: Vec<_> = rows
                .iter()
                .filter_map(|(_, s)| s.as_ref().ok())
                .map(|s| move || simulate(s, case))
                .collect();
            let runnable: Vec<&Run> = runs.iter().map(|r| r as &Run).collect();
            let repeats = options.repeats.max(EFFECTS_REPEATS);
            let mut timings = timed_together(&runnable, repeats).into_iter();
            let rows: Vec<EffectRow> = rows
                .into_iter()
                .map(|(mut r, scene)| {
                    match scene {
                        Ok(_) => score(&mut r.point, timings.next().expect("one per scene")),
                        Err(m) => r.point.status = Status::Failed(m),
                    }
                    tick(&line(&r.point), progress);
                    r
                })
                .collect();
            effects.push(rows);
        }
        let check = case.check.as_ref().map(|c| {
            format!(
                "{} = {:.6} s (CASES.md: 1.22275 s)",
                c.what,
                exact::rigid_pendulum_period(&base)
            )
        });
        results.push(CaseResult {
            case: case.clone(),
            reference: described,
            points,
            effects,
            check,
        });
    }
    Ok(results)
}

/// A point that was not run.
fn skeleton(case: &Case, formulation: &str, setting: Setting) -> Point {
    blank(
        case.name,
        case.outputs[0],
        case.outputs.len(),
        formulation,
        setting,
    )
}

/// A point not run yet: `outputs` compared outputs, the first named `output`.
fn blank(
    case: &'static str,
    output: &'static str,
    outputs: usize,
    formulation: &str,
    setting: Setting,
) -> Point {
    Point {
        case,
        output,
        formulation: formulation.to_string(),
        setting,
        effects: "all".into(),
        status: Status::Ok,
        runs: 0,
        seconds: [f64::NAN; 3],
        steps: 0,
        newton: 0,
        factorizations: 0,
        errors: vec![f64::NAN; outputs],
        relative: vec![f64::NAN; outputs],
        missing: Vec::new(),
        check: None,
        values: Vec::new(),
    }
}

/// Why switching `effect` off changes nothing in this model, if so: `auto` finds the term zero
/// for every subject (no gravity field, frames that never rotate, no damping coefficients), or
/// no beam of the full model has it (geometric stiffening not asked for).
fn zero_here(
    effect: &str,
    full: &fmu_beam::Resolution,
    auto: &fmu_beam::Resolution,
) -> Option<String> {
    let structural = ["gravity", "quadratic_velocity", "rayleigh_damping"];
    if effect == "geometric_stiffening" {
        let on = full
            .effects
            .beams
            .iter()
            .any(|b| !b.rigid && b.options.geometric_stiffening);
        return (!on).then(|| "zero here: no beam of the model has it".to_string());
    }
    if !structural.contains(&effect) {
        return None;
    }
    let ds: Vec<_> = auto
        .decisions
        .iter()
        .filter(|d| d.effect == effect)
        .collect();
    if ds.is_empty() || ds.iter().any(|d| d.setting != "off") {
        return None;
    }
    let mut why: Vec<String> = ds.iter().map(|d| d.why.clone()).collect();
    why.dedup();
    Some(format!("zero here: {}", why.join("; ")))
}

/// What `auto` resolved differently from `all`.
fn auto_differs(full: &fmu_beam::Resolution, auto: &fmu_beam::Resolution) -> String {
    let diff: Vec<String> =
        auto.decisions
            .iter()
            .filter(|d| {
                !full.decisions.iter().any(|f| {
                    f.effect == d.effect && f.subject == d.subject && f.setting == d.setting
                })
            })
            .map(|d| {
                if d.subject == "scene" {
                    format!("{} {}", d.effect, d.setting)
                } else {
                    format!("{} of {} {}", d.effect, d.subject, d.setting)
                }
            })
            .collect();
    if diff.is_empty() {
        "auto keeps every effect of the full model".into()
    } else {
        format!("auto: {}", diff.join(", "))
    }
}

/// The report's opening: how it was measured and how long it took.
pub fn header(options: &Options, wall_seconds: f64) -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!(
        "Generated by `make bench` (`fmu-bench work-precision`, then \
         `tests/plot_work_precision.py`) in {:.0} s wall time on {cores} cores ({cpu}). \
         CPU time is the thread's own account from the Linux scheduler (`/proc/thread-self/\
         schedstat`), so other load on the machine changes it little; each point is the median \
         (min–max) of {} timed samples of the engine itself (no FMI layer, no output recording beyond the \
         compared outputs). A run whose median exceeds {} s ends the sweep of tighter settings of \
         its formulation and integrator mode (marked skipped). Fixed-step runs stop Newton at \
         {FIXED_STEP_NEWTON_TOLERANCE:.0e}; error-control runs use the tolerance for both and may \
         step up to the communication step. Runs shorter than {MIN_SAMPLE} s are timed in \
         batches (the scheduler's account moves in ticks). Identical work timed at different \
         moments can differ by 10–25 % on a shared machine: the effects tables time their rows \
         round by round ({} samples each) so that they share the machine's state, and time \
         ratios within ≈ 10–15 % of 1 are noise.\n",
        wall_seconds,
        options.repeats,
        options.budget,
        options.repeats.max(EFFECTS_REPEATS)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shipped(name: &str) -> Scene {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
        Scene::load(&dir.join(name)).unwrap()
    }

    /// Every formulation of `make bench` and `make bench-peer` is a scene the rules accept,
    /// built on the shipped scene as it is now (a shipped scene that gained geometric stiffness
    /// once made the rigid C2 formulation a refused scene, and `make bench` stopped there).
    #[test]
    fn every_bench_formulation_is_an_accepted_scene() {
        for case in cases::cases() {
            let base = shipped(case.scene);
            let mut all: Vec<&Formulation> = case.formulations.iter().collect();
            if let Reference::Run { formulation, .. } = &case.reference {
                all.push(formulation);
            }
            for f in all {
                for &setting in &case.settings {
                    if let Err(e) = build(&base, &case, f, setting, EffectsSpec::default()) {
                        panic!("{} {}: {e}", case.name, f.name);
                    }
                }
            }
        }
        for case in peer::cases() {
            let base = shipped(case.scene);
            for f in &case.formulations {
                for &setting in &case.settings {
                    if let Err(e) = peer::configure(&base, f, setting, Some(1e-8)) {
                        panic!("{} {}: {e}", case.name, f.name);
                    }
                }
            }
        }
    }
}
