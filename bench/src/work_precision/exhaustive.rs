//! The exhaustive sweep behind the accuracy study's choice (`fmu-bench exhaustive`, `make
//! bench-exhaustive`; issue 46 item 1): every mesh the study can reach (each flexible beam's
//! count scaled by 2^j, halving rounded up, and the halved mesh doubled) at every fixed step of
//! its grid (quarter octaves down from the study's coarsest step) at Newton's 1e-6, each run
//! scored against the exact reference, counted (steps, Newton iterations, iteration matrices,
//! [`fmu_harness::accuracy::cost`]) and timed. A mesh's walk stops where its error meets the
//! tightest target with the largest safety factor, where it stops falling (its floor), or
//! where a run takes more than `--max-cpu` seconds. [`report`] then finds the cheapest setting
//! meeting each target with the study's own safety factor and sets the study's choice beside
//! it, and fits the counted costs to the CPU seconds.

use super::{Series, Timing};
use crate::error::BenchError;
use fmu_beam::{Engine, EngineError, Scene};
use fmu_harness::accuracy::cost::{Counts, Shape};
use std::fmt::Write as _;
use std::path::Path;

mod fit;
mod points_csv;
pub use fit::fit_table;
pub use points_csv::{csv, read};

/// One case of the sweep, as the Makefile's ACCURACY_CASES names it.
#[derive(Debug, Clone, Copy)]
pub struct Case {
    pub name: &'static str,
    pub scene: &'static str,
    pub output: &'static str,
    /// The reference's column (under `bench/reference/<name>.csv`).
    pub column: &'static str,
    /// The grid the error is measured on (the reference's).
    pub comm: f64,
    /// The study's coarsest step (`--step`): the grid of steps is this / 2^(i/4).
    pub step: f64,
}

/// The cases of `make bench-accuracy`.
pub const CASES: [Case; 5] = [
    Case {
        name: "c4_omega10",
        scene: "spin_up_omega10.toml",
        output: "beam.tip.deflection",
        column: "tip_deflection",
        comm: 1e-2,
        step: 5e-2,
    },
    Case {
        name: "c4_omega4",
        scene: "spin_up_omega4.toml",
        output: "beam.tip.deflection",
        column: "tip_deflection",
        comm: 1e-2,
        step: 5e-2,
    },
    Case {
        name: "c3_rigid",
        scene: "slider_crank_rigid_crank.toml",
        output: "slider.position",
        column: "slider_position",
        comm: 1e-3,
        step: 1e-2,
    },
    Case {
        name: "c3_elastic",
        scene: "slider_crank.toml",
        output: "slider.position",
        column: "slider_position",
        comm: 1e-3,
        step: 1e-2,
    },
    Case {
        name: "c2",
        scene: "flexible_pendulum_substructured.toml",
        output: "beam.tip.deflection",
        column: "tip_deflection",
        comm: 1e-3,
        step: 1e-2,
    },
];

/// The targets of the table.
pub const TARGETS: [f64; 3] = [1e-2, 1e-3, 1e-4];

/// The study's safety factors (`fmu_harness::accuracy::SAFETY_OBSERVED`, `SAFETY_ASSUMED`).
pub const MARGINS: [f64; 2] = [
    fmu_harness::accuracy::SAFETY_OBSERVED,
    fmu_harness::accuracy::SAFETY_ASSUMED,
];

/// Newton's tolerance of every run (the study's coarsest rung in `make bench-accuracy`).
pub const NEWTON: f64 = 1e-6;

/// A mesh's walk stops when its error has not fallen below this share of its best so far over
/// the last [`FLOOR_RUNS`] steps (two halvings): it has reached the mesh's floor.
pub const FLOOR_SHARE: f64 = 0.8;
pub const FLOOR_RUNS: usize = 8;

/// Quarter octaves below the coarsest step at most (12 halvings).
pub const MAX_STEPS: usize = 48;

/// One run of the sweep.
#[derive(Debug, Clone)]
pub struct Point {
    pub case: String,
    /// Each flexible beam's count, as text (`crank 2 el., rod 4 el.`).
    pub mesh: String,
    pub step: f64,
    pub newton: f64,
    /// The error against the reference, or why the run failed.
    pub error: Result<f64, String>,
    pub counts: Counts,
    pub shape: Shape,
    /// CPU seconds of one run: median, least (of the timed samples).
    pub cpu: [f64; 2],
}

impl Point {
    pub fn work(&self) -> f64 {
        self.shape.work(&self.counts)
    }
}

/// The flexible beams a mesh scales (as the study: not rigid, not from a matrix file).
fn refinable(b: &fmu_beam::scene::BeamSpec) -> bool {
    !b.rigid && b.matrix_file.is_none() && b.matrix_text.is_none()
}

fn scaled(count: usize, j: i32) -> usize {
    if j >= 0 {
        count << j
    } else {
        count.div_ceil(1 << -j).max(1)
    }
}

/// The meshes the study can reach from `base`: each count × 2^j for j in −2..=2 (halving
/// rounded up), and the halved mesh doubled once and twice (the re-centred study's ladder);
/// each as its counts, coarse first.
pub fn meshes(base: &Scene) -> Vec<Vec<usize>> {
    let counts: Vec<usize> = base
        .beams
        .iter()
        .filter(|b| refinable(b))
        .map(|b| b.substructures.unwrap_or(b.elements.unwrap_or(1)))
        .collect();
    let mut all: Vec<Vec<usize>> = (-2..=2)
        .map(|j| counts.iter().map(|&c| scaled(c, j)).collect())
        .chain((1..=2).map(|j| counts.iter().map(|&c| scaled(scaled(c, -1), j)).collect()))
        .collect();
    all.sort_by_key(|m: &Vec<usize>| m.iter().sum::<usize>());
    all.dedup();
    all
}

/// `base` with each flexible beam's count from `mesh`, at a fixed `step` and Newton's `newton`.
pub fn scene_at(base: &Scene, mesh: &[usize], step: f64, newton: f64) -> Result<Scene, String> {
    let mut s = base.clone();
    s.solver.adaptive = false;
    s.solver.max_step = step;
    s.solver.tolerance = newton;
    for (b, &c) in s.beams.iter_mut().filter(|b| refinable(b)).zip(mesh) {
        match b.substructures {
            Some(_) => b.substructures = Some(c),
            None => b.elements = Some(c),
        }
    }
    Scene::from_toml_str(&s.to_toml_string(), &base.name).map_err(|e| e.to_string())
}

/// The mesh as text.
pub fn mesh_text(s: &Scene) -> String {
    s.beams
        .iter()
        .filter(|b| refinable(b))
        .map(|b| match b.substructures {
            Some(k) => format!(
                "{} {k}×{}",
                b.name,
                b.elements_per_substructure.unwrap_or(1)
            ),
            None => format!("{} {} el.", b.name, b.elements.unwrap_or(1)),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Runs `scene` over `case`'s grid up to its stop time: the output, with the counters in
/// `stats` (steps, Newton iterations, iteration matrices).
fn simulate(scene: &Scene, case: &Case) -> Result<Series, EngineError> {
    let start = std::time::Instant::now();
    let c0 = super::clock(start);
    let mut e = Engine::new(scene.clone());
    e.exit_initialization()?;
    let vr = e
        .variables()
        .by_name(case.output)
        .map(|v| v.vr)
        .ok_or(EngineError::BadStep {
            message: format!("the unit has no output {}", case.output),
        })?;
    let n =
        ((scene.experiment.stop_time - scene.experiment.start_time) / case.comm).round() as usize;
    let mut y = Vec::with_capacity(n + 1);
    for k in 0..=n {
        if k > 0 {
            e.do_step(
                scene.experiment.start_time + (k - 1) as f64 * case.comm,
                case.comm,
            )?;
        }
        y.push(e.get_real(vr)?);
    }
    let seconds = super::clock(start) - c0;
    let mut stat = |name| {
        e.variables()
            .by_name(name)
            .map(|v| v.vr)
            .map_or(Ok(0), |v| e.get_integer(v).map(i64::from))
    };
    let stats = [
        stat("solver.steps")?,
        stat("solver.newton_iterations")?,
        stat("solver.jacobians")?,
    ];
    Ok(Series {
        values: vec![y],
        missing: Vec::new(),
        seconds,
        stats,
    })
}

/// The counters of a run (`points` communication points).
fn counts(s: &Series, points: u64) -> Counts {
    let c = |x: i64| u64::try_from(x).unwrap_or(0);
    Counts {
        steps: c(s.stats[0]),
        iterations: c(s.stats[1]),
        jacobians: c(s.stats[2]),
        points,
    }
}

/// Runs and times `scene` (`samples` timed samples after the first run, batched where short),
/// scored against `reference`.
pub fn point(
    case: &Case,
    scene: &Scene,
    reference: &[f64],
    samples: usize,
) -> Result<(f64, Counts, [f64; 2]), EngineError> {
    let run = || simulate(scene, case);
    let mut t = Timing::start(&run)?;
    while t.samples.len() < samples.max(1) {
        t.sample()?;
    }
    let y = &t.first.values[0];
    let error = if y.len() == reference.len() {
        super::error(y, reference).1
    } else {
        f64::NAN
    };
    let c = counts(&t.first, y.len().saturating_sub(1) as u64);
    let (_, [median, least, _], _) = t.finish();
    Ok((error, c, [median, least]))
}

/// The reference column of `case` (its grid checked against the case's).
pub fn reference(references: &Path, case: &Case, base: &Scene) -> Result<Vec<f64>, BenchError> {
    let path = references.join(format!("{}.csv", case.name));
    let (names, rows) = super::peer::read_reference(&path)?;
    let col = names
        .iter()
        .position(|c| c == case.column)
        .ok_or_else(|| BenchError::Input {
            origin: path.display().to_string(),
            message: format!("no column {}", case.column),
        })?;
    let n = ((base.experiment.stop_time - base.experiment.start_time) / case.comm).round() as usize;
    if rows.len() < n + 1
        || rows
            .iter()
            .take(n + 1)
            .enumerate()
            .any(|(k, r)| (r[0] - k as f64 * case.comm).abs() > 1e-6 * case.comm)
    {
        return Err(BenchError::Input {
            origin: path.display().to_string(),
            message: format!(
                "not on the grid of {} s up to {} s",
                case.comm, base.experiment.stop_time
            ),
        });
    }
    Ok(rows.iter().take(n + 1).map(|r| r[col]).collect())
}

/// The sweep of one case; `progress` gets a line per run.
pub fn sweep(
    scenes: &Path,
    references: &Path,
    case: &Case,
    max_cpu: f64,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Point>, BenchError> {
    let base = Scene::load(&scenes.join(case.scene))?;
    let reference = reference(references, case, &base)?;
    let tightest = TARGETS.iter().copied().fold(f64::INFINITY, f64::min) / MARGINS[1];
    let mut points = Vec::new();
    for mesh in meshes(&base) {
        let mut errors: Vec<f64> = Vec::new();
        let mut failures_after_success = 0;
        for i in 0..MAX_STEPS {
            let step = grid_step(case.step, i);
            let scene = scene_at(&base, &mesh, step, NEWTON).map_err(|m| BenchError::Input {
                origin: case.name.into(),
                message: m,
            })?;
            let samples = 2;
            let p = match point(case, &scene, &reference, samples) {
                Ok((e, counts, cpu)) => Point {
                    case: case.name.into(),
                    mesh: mesh_text(&scene),
                    step,
                    newton: NEWTON,
                    error: Ok(e),
                    counts,
                    shape: Shape::of(&scene),
                    cpu,
                },
                Err(e) => Point {
                    case: case.name.into(),
                    mesh: mesh_text(&scene),
                    step,
                    newton: NEWTON,
                    error: Err(e.to_string()),
                    counts: Counts::default(),
                    shape: Shape::of(&scene),
                    cpu: [f64::NAN; 2],
                },
            };
            progress(&format!(
                "{} {} h = {step:.3e}: {} ({:.3} CPU s, work {:.3})",
                case.name,
                p.mesh,
                match &p.error {
                    Ok(e) => format!("{e:.3e}"),
                    Err(m) => format!("failed: {m}"),
                },
                p.cpu[0],
                p.work()
            ));
            let (ok, cpu) = (p.error.clone().ok(), p.cpu[0]);
            points.push(p);
            match ok {
                Some(e) => {
                    failures_after_success = 0;
                    errors.push(e);
                    if e <= tightest || cpu > max_cpu {
                        break;
                    }
                    let k = errors.len();
                    if k > FLOOR_RUNS {
                        let before = errors[..k - FLOOR_RUNS]
                            .iter()
                            .copied()
                            .fold(f64::INFINITY, f64::min);
                        let recent = errors[k - FLOOR_RUNS..]
                            .iter()
                            .copied()
                            .fold(f64::INFINITY, f64::min);
                        if recent > FLOOR_SHARE * before {
                            break;
                        }
                    }
                }
                None if !errors.is_empty() => {
                    failures_after_success += 1;
                    if failures_after_success >= 4 {
                        break;
                    }
                }
                None => {}
            }
        }
    }
    Ok(points)
}

/// The `i`-th step of the grid below `h0`: the time ladder's h0 / 2^k where i = 4k, else the
/// quarter octave the study's relaxation reaches (h0 / 2^(i/4), rounded down to three digits).
pub fn grid_step(h0: f64, i: usize) -> f64 {
    if i.is_multiple_of(4) {
        h0 / 2f64.powi((i / 4) as i32)
    } else {
        let x = h0 / 2f64.powf(i as f64 / 4.0);
        let m = 10f64.powi(2 - x.log10().floor() as i32);
        (x * m).floor() / m
    }
}

/// The cheapest point of `case` (by counted work) whose error times `margin` meets `target`;
/// `for_good`: and so does every point of its mesh at a smaller step (a dip of the error
/// between the step's and the mesh's errors that cancel is luck no estimate can certify: the
/// peer bench's rule).
pub fn cheapest<'a>(
    points: &'a [Point],
    case: &str,
    target: f64,
    margin: f64,
    for_good: bool,
) -> Option<&'a Point> {
    let meets = |p: &Point| p.error.as_ref().is_ok_and(|&e| e * margin <= target);
    points
        .iter()
        .filter(|p| p.case == case && meets(p))
        .filter(|p| {
            !for_good
                || points
                    .iter()
                    .filter(|q| q.case == case && q.mesh == p.mesh && q.step < p.step)
                    .all(|q| q.error.is_err() || meets(q))
        })
        .min_by(|a, b| a.work().total_cmp(&b.work()))
}

/// What a study wrote of itself (`study.json` beside its `chosen.toml`).
#[derive(Debug, Clone)]
pub struct StudySummary {
    pub margin: f64,
    pub incomplete: Option<String>,
    /// The chosen run's counted work and its true error (where judged).
    pub work: f64,
    pub true_error: Option<f64>,
    pub label: String,
    /// The study's own counted work and CPU seconds.
    pub study_work: f64,
    pub study_cpu: f64,
}

/// Reads `<studies>/<case>-<target>/study.json`; None where there is none or no choice.
pub fn read_study(studies: &Path, case: &str, target: f64) -> Option<StudySummary> {
    let dir = studies.join(format!("{case}-{target:.0e}"));
    let text = std::fs::read_to_string(dir.join("study.json")).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    let c = v.get("choice")?;
    Some(StudySummary {
        margin: v.get("margin")?.as_f64()?,
        incomplete: v
            .get("incomplete")
            .and_then(|x| x.as_str())
            .map(String::from),
        work: c.get("work")?.as_f64()?,
        true_error: c.get("true_error").and_then(serde_json::Value::as_f64),
        label: format!(
            "{} at {:.3e} s, Newton {:.0e}",
            c.get("mesh")?.as_str()?,
            c.get("step")?.as_f64()?,
            c.get("newton")?.as_f64()?
        ),
        study_work: v.get("work")?.as_f64()?,
        study_cpu: v.get("cpu_s")?.as_f64()?,
    })
}

/// The study's chosen scene and the sweep's cheapest, timed in the same rounds (the order
/// alternating): CPU seconds per round of each.
pub fn timed_pair(
    scenes: &Path,
    case: &Case,
    chosen: &Path,
    cheapest: &Point,
    rounds: usize,
) -> Result<(Vec<f64>, Vec<f64>), BenchError> {
    let base = Scene::load(&scenes.join(case.scene))?;
    let mine = Scene::load(chosen)?;
    let mesh: Vec<usize> = parse_mesh(&cheapest.mesh);
    let theirs =
        scene_at(&base, &mesh, cheapest.step, cheapest.newton).map_err(|m| BenchError::Input {
            origin: case.name.into(),
            message: m,
        })?;
    let engine = |e| BenchError::Engine {
        origin: case.name.into(),
        source: e,
    };
    let run_mine = || simulate(&mine, case);
    let run_theirs = || simulate(&theirs, case);
    let mut a = Timing::start(&run_mine).map_err(engine)?;
    let mut b = Timing::start(&run_theirs).map_err(engine)?;
    a.samples.clear();
    b.samples.clear();
    for round in 0..rounds.max(1) {
        if round % 2 == 0 {
            a.sample().map_err(engine)?;
            b.sample().map_err(engine)?;
        } else {
            b.sample().map_err(engine)?;
            a.sample().map_err(engine)?;
        }
    }
    Ok((a.samples, b.samples))
}

/// The counts of a mesh's text (`crank 2 el., rod 4 el.` → [2, 4]; `beam 10×2` → [10]).
fn parse_mesh(text: &str) -> Vec<usize> {
    text.split(", ")
        .filter_map(|part| {
            let w = part.split_whitespace().nth(1)?;
            w.split('×').next()?.parse().ok()
        })
        .collect()
}

/// The table: per case and target, the study's choice (where `studies` holds it) against the
/// sweep's cheapest meeting the target for good with the study's safety factor, in counted
/// work and in CPU seconds timed in the same rounds, and the cheapest single run meeting it;
/// without a study, the sweep's cheapest at both factors.
pub fn report(
    scenes: &Path,
    points: &[Point],
    studies: Option<&Path>,
    rounds: usize,
    progress: &mut dyn FnMut(&str),
) -> String {
    let mut s = String::from(
        "| case | target | the study's choice (factor): true error, work (the study's own work, \
         CPU s) | the sweep's cheapest for good at that factor: error, work | work ratio | CPU \
         ratio, median (min–max) | the cheapest single run: error, work (ratio) |\n\
         |---|---|---|---|---|---|---|\n",
    );
    let text = |p: &Point| {
        format!(
            "{} at {:.3e} s: {:.2e}, {:.3}",
            p.mesh,
            p.step,
            p.error.as_ref().map_or(f64::NAN, |e| *e),
            p.work()
        )
    };
    for case in CASES
        .iter()
        .filter(|c| points.iter().any(|p| p.case == c.name))
    {
        for target in TARGETS {
            let study = studies.and_then(|d| read_study(d, case.name, target));
            let Some(st) = study else {
                let best: Vec<String> = MARGINS
                    .iter()
                    .map(|&m| {
                        cheapest(points, case.name, target, m, true)
                            .map_or("none".into(), |p| format!("×{m}: {}", text(p)))
                    })
                    .collect();
                let _ = writeln!(
                    s,
                    "| {} | {target:.0e} | no study (no choice) | {} | | | |",
                    case.name,
                    best.join("; ")
                );
                continue;
            };
            let choice = format!(
                "{} (×{}{}): {}, {:.3} ({:.1}, {:.1} CPU s)",
                st.label,
                st.margin,
                if st.incomplete.is_some() {
                    ", INCOMPLETE"
                } else {
                    ""
                },
                st.true_error.map_or("?".into(), |e| format!("{e:.2e}")),
                st.work,
                st.study_work,
                st.study_cpu
            );
            let single = cheapest(points, case.name, target, st.margin, false)
                .map_or("none".to_string(), |p| {
                    format!("{} ({:.2})", text(p), st.work / p.work())
                });
            let Some(best) = cheapest(points, case.name, target, st.margin, true) else {
                let _ = writeln!(
                    s,
                    "| {} | {target:.0e} | {choice} | none in the sweep | | | {single} |",
                    case.name
                );
                continue;
            };
            let chosen = studies
                .unwrap_or(Path::new("."))
                .join(format!("{}-{target:.0e}", case.name))
                .join("chosen.toml");
            progress(&format!("timing {} at {target:.0e}", case.name));
            let cpu = match timed_pair(scenes, case, &chosen, best, rounds) {
                Ok((a, b)) => {
                    let r: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x / y).collect();
                    let [m, lo, hi] = super::choice::spread(&r);
                    format!("{m:.2} ({lo:.2}–{hi:.2})")
                }
                Err(e) => format!("not timed: {e}"),
            };
            let _ = writeln!(
                s,
                "| {} | {target:.0e} | {choice} | {} | **{:.2}** | {cpu} | {single} |",
                case.name,
                text(best),
                st.work / best.work()
            );
        }
    }
    s
}
