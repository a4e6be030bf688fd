//! The peer comparison (`fmu-bench peer`, `make bench-peer`): C2–C4 run by this engine over
//! formulations and integrator settings, scored against the geometrically exact references of
//! `bench/reference/` (the same ones `bench/peer/sweep.py` scores Exudyn against), and the table
//! of CPU time ratios, ours / Exudyn's, of the cheapest run of each tool that meets a target
//! error. The scenes keep their shipped physics (the effects `auto` would choose); what is
//! swept is what a user sweeps: elements or substructures, and the fixed step or the tolerance.
//!
//! Error: max over the reference's grid of |y − y_ref| / max |y_ref|, as for the peer. Our runs
//! report every output on that grid (a unit without inputs steps across communication points
//! and interpolates, so the grid costs no steps).
//!
//! Over 600 lines: the peer comparison's cases, sweep, scoring, report and their tests kept
//! together; a benchmark, not the product.

use super::cases::{Edit, Formulation};
use super::{thread_cpu_seconds, timed, Series, Setting};
use crate::error::BenchError;
use fmu_beam::{Engine, EngineError, Scene};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What is compared: an output of the unit, or the chord angle of a beam from its tip (root
/// at the origin), unwrapped.
#[derive(Debug, Clone, Copy)]
pub enum Quantity {
    Output(&'static str),
    ChordAngle(&'static str),
}

/// A case of the comparison.
#[derive(Debug, Clone)]
pub struct PeerCase {
    /// As the peer's CSV names it (`c2`, `c3_rigid`, ...).
    pub name: &'static str,
    pub scene: &'static str,
    /// Under `bench/reference/`.
    pub reference: &'static str,
    /// (reference column, our quantity).
    pub outputs: &'static [(&'static str, Quantity)],
    pub comm: f64,
    pub stop: f64,
    pub formulations: Vec<Formulation>,
    pub settings: Vec<Setting>,
    /// CPU seconds of one run that this case's formulations may take before their tighter
    /// settings are skipped, where it is more than `--budget`: 0 where the budget is enough.
    pub least_budget: f64,
}

/// The error targets of the table.
pub const TARGETS: [f64; 4] = [1e-2, 1e-3, 1e-4, 1e-5];

use Edit::*;
use Setting::{FixedStep as H, Tolerance as Tol};

fn formulation(name: &'static str, edits: &[Edit]) -> Formulation {
    Formulation {
        name,
        edits: edits.to_vec(),
        settings: None,
    }
}

/// The cases, with the formulations and settings swept.
pub fn cases() -> Vec<PeerCase> {
    // from 2e-2 s, as the peer's coarsest step (bench/peer/sweep.py; 1e-2 s on C3 until
    // 2026-12-07, when both tools' rod of 2 met 1e-2 at 2e-2 s): at the loose targets the
    // cheapest setting of either tool is a coarse step on a coarse mesh
    let c3_settings = vec![
        H(2e-2),
        H(1e-2),
        H(4e-3),
        H(2e-3),
        H(1e-3),
        H(5e-4),
        H(2e-4),
        H(1e-4),
        H(5e-5),
        Tol(1e-4),
        Tol(1e-5),
        Tol(1e-6),
        Tol(1e-7),
    ];
    let c4_settings = vec![
        H(2e-2),
        H(1e-2),
        H(5e-3),
        H(2e-3),
        H(1e-3),
        H(5e-4),
        Tol(1e-4),
        Tol(1e-5),
        Tol(1e-6),
        Tol(1e-7),
    ];
    vec![
        PeerCase {
            name: "c2",
            scene: "flexible_pendulum_substructured.toml",
            reference: "c2.csv",
            outputs: &[
                ("chord_angle", Quantity::ChordAngle("beam")),
                ("tip_deflection", Quantity::Output("beam.tip.deflection")),
            ],
            comm: 1e-3,
            stop: 1.0,
            formulations: vec![
                formulation("5 x 2 substructures", &[Substructures("beam", 5, 2)]),
                formulation("10 x 2 substructures", &[Substructures("beam", 10, 2)]),
                formulation("20 x 2 substructures", &[Substructures("beam", 20, 2)]),
                // pinned, as the shipped single-frame scene (flexible_pendulum.toml)
                formulation(
                    "single frame, 10 elements",
                    &[Elements("beam", 10), Pinned("beam")],
                ),
                formulation(
                    "single frame, 6 elements",
                    &[Elements("beam", 6), Pinned("beam")],
                ),
                formulation(
                    "single frame, 4 elements",
                    &[Elements("beam", 4), Pinned("beam")],
                ),
                formulation("3 x 2 substructures", &[Substructures("beam", 3, 2)]),
                // between the doublings, as the peer's 6, 12 and 24 elements
                // (bench/peer/sweep.py; 2026-12-07)
                formulation(
                    "single frame, 8 elements",
                    &[Elements("beam", 8), Pinned("beam")],
                ),
                formulation("6 x 2 substructures", &[Substructures("beam", 6, 2)]),
                formulation("8 x 2 substructures", &[Substructures("beam", 8, 2)]),
                formulation("15 x 2 substructures", &[Substructures("beam", 15, 2)]),
                // the peer's cheapest at 1e-2 and 1e-3 is 2 elements
                formulation(
                    "single frame, 2 elements",
                    &[Elements("beam", 2), Pinned("beam")],
                ),
            ],
            settings: vec![
                H(1e-2),
                H(5e-3),
                H(2e-3),
                H(1e-3),
                H(5e-4),
                H(2e-4),
                H(1e-4),
                // the tip deflection's error is the phase of the modes at 260-430 Hz that the
                // release excites: it needs steps this short (issue 12); 1e-3 needs 1e-5 s and
                // about 40 elements (20 x 2: 2.9e-4; 2e-5 s: 1.6e-3 with any count)
                H(5e-5),
                H(2e-5),
                H(1e-5),
                Tol(1e-4),
                Tol(1e-5),
                Tol(1e-6),
                Tol(1e-7),
                Tol(1e-8),
            ],
            // the tip deflection at 1e-3 is decided at 1e-5 s (20 x 2: 6-10 s a run, after
            // 4-5 s at 2e-5 s): the default 4 s stopped it at 2e-5 s, out of the comparison
            // (the peer's sweep runs its 32 elements at 1e-5 s, 20-30 s)
            least_budget: 20.0,
        },
        PeerCase {
            name: "c3_elastic",
            scene: "slider_crank.toml",
            reference: "c3_elastic.csv",
            outputs: &[
                ("slider_position", Quantity::Output("slider.position")),
                ("rod_mid_deflection", Quantity::Output("rod.mid.deflection")),
            ],
            comm: 1e-3,
            stop: 1.6,
            formulations: vec![
                formulation(
                    "crank 3, rod 8",
                    &[Elements("crank", 3), Elements("rod", 8)],
                ),
                formulation(
                    "crank 2, rod 4",
                    &[Elements("crank", 2), Elements("rod", 4)],
                ),
                formulation(
                    "crank 6, rod 16",
                    &[Elements("crank", 6), Elements("rod", 16)],
                ),
                // the peer's cheapest at 1e-2 to 1e-4 is crank 1, rod 2
                formulation(
                    "crank 1, rod 2",
                    &[Elements("crank", 1), Elements("rod", 2)],
                ),
                // the meshes between the doublings, as the peer's rods of 3, 5 and 6 elements
                // with its crank of half as many (bench/peer/sweep.py): C3's targets fall
                // between the doublings (crank 2, rod 4 stops at 1.04e-2 of the rod's
                // mid-span as the step shrinks; crank 2, rod 5 stays within 7.7e-3)
                formulation(
                    "crank 1, rod 3",
                    &[Elements("crank", 1), Elements("rod", 3)],
                ),
                formulation(
                    "crank 2, rod 5",
                    &[Elements("crank", 2), Elements("rod", 5)],
                ),
                formulation(
                    "crank 3, rod 6",
                    &[Elements("crank", 3), Elements("rod", 6)],
                ),
            ],
            settings: c3_settings.clone(),
            least_budget: 0.0,
        },
        PeerCase {
            name: "c3_rigid",
            scene: "slider_crank_rigid_crank.toml",
            reference: "c3_rigid.csv",
            outputs: &[
                ("slider_position", Quantity::Output("slider.position")),
                ("rod_mid_deflection", Quantity::Output("rod.mid.deflection")),
            ],
            comm: 1e-3,
            stop: 1.6,
            formulations: vec![
                formulation("rod 4", &[Elements("rod", 4)]),
                formulation("rod 8", &[Elements("rod", 8)]),
                formulation("rod 16", &[Elements("rod", 16)]),
                formulation("rod 2", &[Elements("rod", 2)]),
                // between the doublings, as the peer's (bench/peer/sweep.py): rod 2 stops at
                // 1.04e-4 of the slider's travel as the step shrinks, rod 6 within 9.4e-6
                formulation("rod 3", &[Elements("rod", 3)]),
                formulation("rod 5", &[Elements("rod", 5)]),
                formulation("rod 6", &[Elements("rod", 6)]),
            ],
            settings: c3_settings,
            least_budget: 0.0,
        },
        PeerCase {
            name: "c4_omega10",
            scene: "spin_up_omega10.toml",
            reference: "c4_omega10.csv",
            outputs: &[("tip_deflection", Quantity::Output("beam.tip.deflection"))],
            comm: 1e-2,
            stop: 20.0,
            formulations: vec![
                formulation("5 x 1 substructures", &[Substructures("beam", 5, 1)]),
                formulation("10 x 1 substructures", &[Substructures("beam", 10, 1)]),
                formulation("20 x 1 substructures", &[Substructures("beam", 20, 1)]),
            ],
            settings: c4_settings.clone(),
            least_budget: 0.0,
        },
        PeerCase {
            name: "c4_omega4",
            scene: "spin_up_omega4.toml",
            reference: "c4_omega4.csv",
            outputs: &[("tip_deflection", Quantity::Output("beam.tip.deflection"))],
            comm: 1e-2,
            stop: 20.0,
            formulations: vec![
                formulation("3 x 1 substructures", &[Substructures("beam", 3, 1)]),
                formulation("5 x 1 substructures", &[Substructures("beam", 5, 1)]),
                formulation("10 x 1 substructures", &[Substructures("beam", 10, 1)]),
                // 1e-5 needs more: 10 x 1 stops near 1.1e-4 and 20 x 1 near 1.0-1.5e-5
                // whatever the step. The counts between the doublings (15, 30), as the peer's
                // meshes 12 and 24 (bench/peer/sweep.py): 30 x 1 reaches 2.1e-6 at 1e-3 s
                formulation("15 x 1 substructures", &[Substructures("beam", 15, 1)]),
                formulation("20 x 1 substructures", &[Substructures("beam", 20, 1)]),
                formulation("30 x 1 substructures", &[Substructures("beam", 30, 1)]),
                formulation("40 x 1 substructures", &[Substructures("beam", 40, 1)]),
                // two elements a substructure: 15 x 2 reaches 1e-5 at 1e-3 s (3.4e-6; 8.3e-6 at
                // 5e-4 s) with half the joints of 30 x 1 (2026-12-07); 12 x 2 stops near 1.2e-5,
                // 20 x 2 costs more than 30 x 1
                formulation("15 x 2 substructures", &[Substructures("beam", 15, 2)]),
            ],
            settings: c4_settings,
            least_budget: 0.0,
        },
    ]
}

/// One point of ours or of the peer: errors per output, CPU seconds (median, min, max).
#[derive(Debug, Clone)]
pub struct PeerPoint {
    pub case: String,
    pub output: String,
    pub tool: String,
    pub formulation: String,
    pub setting: String,
    pub error: f64,
    pub seconds: [f64; 3],
    pub steps: i64,
}

/// Columns of a reference CSV: names and rows.
pub(super) fn read_reference(path: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), BenchError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| BenchError::io(path, "reading the reference", e))?;
    let bad = |what: &str| BenchError::Input {
        origin: path.display().to_string(),
        message: what.to_string(),
    };
    let mut lines = text.lines();
    let names: Vec<String> = lines
        .next()
        .ok_or_else(|| bad("empty"))?
        .split(',')
        .map(|s| s.trim().to_string())
        .collect();
    let rows = lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            l.split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<Vec<f64>, _>>()
                .map_err(|_| bad("a row of numbers expected"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    if rows.iter().any(|r| r.len() != names.len()) {
        return Err(bad("rows of another length than the header"));
    }
    Ok((names, rows))
}

/// Newton tolerances of the fixed-step runs: the scene's own (1e-6), and 1e-8. At a fixed step
/// the tolerance bounds only Newton's error, weighted by |q| + the system's length: on C4,
/// 1e-6 × 8 m is as large as the 1e-5 target of a 0.53 m deflection (40 × 1 substructures at
/// 1e-3 s: 1.5e-5 at 1e-6, 4.0e-6 at 1e-8).
const FIXED_STEP_TOLERANCES: [Option<f64>; 2] = [None, Some(1e-8)];

/// A run's setting as the points name it: the integrator setting, and for a fixed step the
/// Newton tolerance when it is not the scene's.
fn setting_name(setting: Setting, newton: Option<f64>) -> String {
    match newton {
        Some(t) => format!("{setting}, tolerance {t:.0e}"),
        None => setting.to_string(),
    }
}

/// A setting as [`setting_name`] writes it, read back: the integrator setting, and a fixed
/// step's Newton tolerance where it is not the scene's.
pub(super) fn parse_setting(name: &str) -> Option<(Setting, Option<f64>)> {
    let (family, size) = family(name)?;
    match family.as_str() {
        "tolerance" => Some((Setting::Tolerance(size), None)),
        "fixed step" => Some((Setting::FixedStep(size), None)),
        f => {
            let t = f
                .strip_prefix("fixed step, tolerance ")?
                .trim()
                .parse()
                .ok()?;
            Some((Setting::FixedStep(size), Some(t)))
        }
    }
}

/// The scene of a formulation at a setting. A fixed step runs Newton at `newton`, or at the
/// scene's tolerance without it ([`FIXED_STEP_TOLERANCES`]); error control keeps the scene's
/// largest step.
/// The solver every setting starts from, whatever the scene ships (issue 34 tuned the shipped
/// scenes to fixed steps and tight Newton tolerances): error control at 1e-6 with the largest
/// step of the untuned scenes, 1/400 of the run within 1e-2 to 5e-2 s (C2, C3: 1e-2 s; C4:
/// 5e-2 s). A fixed step without its own Newton tolerance runs at this 1e-6.
fn untuned(s: &mut Scene) {
    s.solver.adaptive = true;
    s.solver.tolerance = 1e-6;
    s.solver.max_step = (s.experiment.stop_time / 400.0).clamp(1e-2, 5e-2);
}

pub(super) fn configure(
    base: &Scene,
    f: &Formulation,
    setting: Setting,
    newton: Option<f64>,
) -> Result<Scene, BenchError> {
    let mut s = f.apply(base);
    untuned(&mut s);
    match setting {
        Setting::Tolerance(t) => {
            s.solver.adaptive = true;
            s.solver.tolerance = t;
        }
        Setting::FixedStep(h) => {
            s.solver.adaptive = false;
            s.solver.max_step = h;
            if let Some(t) = newton {
                s.solver.tolerance = t;
            }
        }
    }
    let origin = format!(
        "{} ({}, {})",
        base.name,
        f.name,
        setting_name(setting, newton)
    );
    Ok(Scene::from_toml_str(&s.to_toml_string(), &origin)?)
}

/// How many of the case's grid points one communication step spans: a fixed step that is a
/// multiple of the grid and divides the run reports at its step points only (1 otherwise), as
/// the peer's runs at those steps are scored (`bench/peer/sweep.py`); both tools are then
/// asked the same, and neither pays for points between its steps.
pub(super) fn stride(scene: &Scene, case: &PeerCase) -> usize {
    let h = scene.solver.max_step;
    let k = (h / case.comm).round();
    let whole = |x: f64| (x - x.round()).abs() < 1e-9 * x.max(1.0);
    if scene.solver.adaptive || k < 2.0 || (k * case.comm - h).abs() > 1e-9 * h {
        return 1;
    }
    if whole(case.stop / h) {
        k as usize
    } else {
        1
    }
}

/// The error of `y` (at every `stride`-th point of the case's grid) against the reference on
/// that grid, relative to the reference's largest value over the whole grid.
pub(super) fn scored(y: &[f64], reference: &[f64], stride: usize) -> f64 {
    let at: Vec<f64> = reference.iter().step_by(stride).copied().collect();
    let (e, _) = super::error(y, &at);
    let scale = reference.iter().fold(0.0f64, |m, r| m.max(r.abs()));
    if scale > 0.0 && y.len() == at.len() {
        e / scale
    } else {
        f64::NAN
    }
}

/// Runs `scene` over the case's grid (every [`stride`]-th point); values per output of the
/// case, and the counters: steps, Newton iterations, iteration matrices.
pub(super) fn simulate(scene: &Scene, case: &PeerCase) -> Result<Series, EngineError> {
    simulate_engine(scene, case).map(|(series, _)| series)
}

/// [`simulate`], and the engine at the end of the run (its other counters).
pub(super) fn simulate_engine(
    scene: &Scene,
    case: &PeerCase,
) -> Result<(Series, Engine), EngineError> {
    let start = Instant::now();
    let cpu0 = thread_cpu_seconds();
    let mut e = Engine::new(scene.clone());
    e.exit_initialization()?;
    let vr = |e: &Engine, n: String| {
        e.variables()
            .by_name(&n)
            .map(|v| v.vr)
            .ok_or(EngineError::BadStep {
                message: format!("the unit has no output {n}"),
            })
    };
    let mut reads = Vec::new();
    for (_, q) in case.outputs {
        reads.push(match q {
            Quantity::Output(n) => vec![vr(&e, n.to_string())?],
            Quantity::ChordAngle(b) => {
                vec![vr(&e, format!("{b}.tip.x"))?, vr(&e, format!("{b}.tip.y"))?]
            }
        });
    }
    let comm = case.comm * stride(scene, case) as f64;
    let n = (case.stop / comm).round() as usize;
    let mut values = vec![Vec::with_capacity(n + 1); case.outputs.len()];
    for k in 0..=n {
        if k > 0 {
            e.do_step((k - 1) as f64 * comm, comm)?;
        }
        for (o, vrs) in reads.iter().enumerate() {
            let y = match vrs[..] {
                [v] => e.get_real(v)?,
                [x, y] => {
                    let a = e.get_real(y)?.atan2(e.get_real(x)?);
                    // unwrapped: continuous through −π
                    let tau = 2.0 * std::f64::consts::PI;
                    values[o]
                        .last()
                        .map_or(a, |&p: &f64| a + tau * ((p - a) / tau).round())
                }
                _ => f64::NAN,
            };
            values[o].push(y);
        }
    }
    let seconds = match (cpu0, thread_cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => start.elapsed().as_secs_f64(),
    };
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
    let series = Series {
        values,
        missing: Vec::new(),
        seconds,
        stats,
    };
    Ok((series, e))
}

/// Runs every case; `progress` receives a line per point. A setting whose run of a formulation
/// took more than `budget` CPU seconds ends that formulation's tighter settings of the same
/// mode.
pub fn study(
    scenes: &Path,
    references: &Path,
    cases: &[PeerCase],
    repeats: usize,
    budget: f64,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<PeerPoint>, BenchError> {
    let mut points = Vec::new();
    for case in cases {
        let budget = budget.max(case.least_budget);
        let base = Scene::load(&scenes.join(case.scene))?;
        let (names, rows) = read_reference(&references.join(case.reference))?;
        let n = (case.stop / case.comm).round() as usize + 1;
        if rows.len() != n {
            return Err(BenchError::Input {
                origin: case.reference.into(),
                message: format!("{} rows, {n} expected on the case's grid", rows.len()),
            });
        }
        let mut columns = Vec::new();
        for (col, _) in case.outputs {
            let k = names
                .iter()
                .position(|c| c == col)
                .ok_or(BenchError::Input {
                    origin: case.reference.into(),
                    message: format!("no column {col}"),
                })?;
            columns.push(rows.iter().map(|r| r[k]).collect::<Vec<f64>>());
        }
        // each fixed step at each Newton tolerance; a budget per mode: error control, and
        // fixed steps at each tolerance (each mode's settings run loose to tight)
        let runs: Vec<(Setting, Option<f64>, usize)> = case
            .settings
            .iter()
            .flat_map(|&setting| match setting {
                Setting::FixedStep(_) => FIXED_STEP_TOLERANCES
                    .iter()
                    .enumerate()
                    .map(|(k, &t)| (setting, t, 1 + k))
                    .collect::<Vec<_>>(),
                Setting::Tolerance(_) => vec![(setting, None, 0)],
            })
            .collect();
        for f in &case.formulations {
            let mut over_budget = [false; 1 + FIXED_STEP_TOLERANCES.len()];
            for &(setting, newton, mode) in &runs {
                if over_budget[mode] {
                    continue;
                }
                let name = setting_name(setting, newton);
                let scene = configure(&base, f, setting, newton)?;
                let run = || simulate(&scene, case);
                let line = match timed(&run, repeats) {
                    Ok((s, seconds, _)) => {
                        if seconds[0] > budget {
                            over_budget[mode] = true;
                        }
                        let mut line =
                            format!("{} {}, {name}: {:.3} s", case.name, f.name, seconds[0]);
                        for ((col, _), (y, r)) in
                            case.outputs.iter().zip(s.values.iter().zip(&columns))
                        {
                            let rel = scored(y, r, stride(&scene, case));
                            let _ = write!(line, ", {col} {rel:.2e}");
                            points.push(PeerPoint {
                                case: case.name.into(),
                                output: col.to_string(),
                                tool: "fmu-beam".into(),
                                formulation: f.name.into(),
                                setting: name.clone(),
                                error: rel,
                                seconds,
                                steps: s.stats[0],
                            });
                        }
                        line
                    }
                    Err(e) => format!("{} {}, {name}: failed: {e}", case.name, f.name),
                };
                progress(&line);
            }
        }
    }
    Ok(points)
}

/// The peer's points from `bench/peer/sweep.py`'s CSV.
pub fn read_peer(path: &Path) -> Result<Vec<PeerPoint>, BenchError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| BenchError::io(path, "reading the peer's points", e))?;
    let bad = |m: String| BenchError::Input {
        origin: path.display().to_string(),
        message: m,
    };
    let mut points = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let f = split_csv(line);
        if f.len() != 10 {
            return Err(bad(format!("line {}: 10 fields expected", i + 1)));
        }
        let num = |k: usize| {
            f[k].parse::<f64>()
                .map_err(|_| bad(format!("line {}: field {} is not a number", i + 1, k + 1)))
        };
        points.push(PeerPoint {
            case: f[0].clone(),
            output: f[1].clone(),
            tool: f[2].clone(),
            formulation: f[3].clone(),
            setting: f[4].clone(),
            error: num(5)?,
            seconds: [num(6)?, num(7)?, num(8)?],
            steps: f[9].parse().unwrap_or(0),
        });
    }
    Ok(points)
}

/// Fields of a CSV line, double quotes honoured.
fn split_csv(line: &str) -> Vec<String> {
    let (mut fields, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    for c in line.chars() {
        match c {
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(std::mem::take(&mut cur)),
            c => cur.push(c),
        }
    }
    fields.push(cur);
    fields
}

/// A setting as a family and its size, smaller being tighter: ours `fixed step 1.0e-3 s`,
/// `fixed step 1.0e-3 s, tolerance 1e-8` and `tolerance 1e-6` (families `fixed step`,
/// `fixed step, tolerance 1e-8`, `tolerance`), the peer's `ne=16;h=5e-05;rho_inf=0.9` (family
/// `ne=16;rho_inf=0.9`, size the step h).
fn family(setting: &str) -> Option<(String, f64)> {
    for mode in ["fixed step", "tolerance"] {
        if let Some(rest) = setting.strip_prefix(mode) {
            let (size, tail) = rest.split_once(',').unwrap_or((rest, ""));
            let value = size.trim().trim_end_matches(" s").parse().ok()?;
            let family = if tail.is_empty() {
                mode.to_string()
            } else {
                format!("{mode},{tail}")
            };
            return Some((family, value));
        }
    }
    let fields: Vec<&str> = setting.split(';').collect();
    let h = fields
        .iter()
        .find_map(|f| f.strip_prefix("h="))?
        .parse()
        .ok()?;
    let rest: Vec<&str> = fields
        .into_iter()
        .filter(|f| !f.starts_with("h="))
        .collect();
    Some((rest.join(";"), h))
}

/// Whether `p` meets `target` for good: it does, and so does every tighter setting of its
/// family run with the same formulation. A run whose error crosses below the target on its way
/// to a floor above it (the time error cancelling the formulation's) does not count: the next
/// tighter setting would not meet it, and neither would a user's.
fn meets(points: &[PeerPoint], p: &PeerPoint, target: f64) -> bool {
    if p.error > target {
        return false;
    }
    let Some((fam, size)) = family(&p.setting) else {
        return true;
    };
    points.iter().all(|q| {
        q.tool != p.tool
            || q.case != p.case
            || q.output != p.output
            || q.formulation != p.formulation
            || family(&q.setting).is_none_or(|(f, s)| f != fam || s >= size || q.error <= target)
    })
}

/// The cheapest point (median CPU) meeting `target` for good ([`meets`]), among those of
/// `tool` for (case, output).
pub(super) fn cheapest<'a>(
    points: &'a [PeerPoint],
    tool: &str,
    case: &str,
    output: &str,
    target: f64,
) -> Option<&'a PeerPoint> {
    points
        .iter()
        .filter(|p| p.tool == tool && p.case == case && p.output == output)
        .filter(|p| meets(points, p, target))
        .min_by(|a, b| a.seconds[0].total_cmp(&b.seconds[0]))
}

/// The error a point is held to on its output: the largest of its own and of every tighter
/// setting of its family run with the same formulation (the rule of [`meets`]: an error below
/// that of a tighter setting is luck).
fn counted_error(points: &[PeerPoint], p: &PeerPoint) -> f64 {
    let Some((fam, size)) = family(&p.setting) else {
        return p.error;
    };
    points
        .iter()
        .filter(|q| {
            q.tool == p.tool
                && q.case == p.case
                && q.output == p.output
                && q.formulation == p.formulation
                && family(&q.setting).is_some_and(|(f, s)| f == fam && s <= size)
        })
        .fold(p.error, |e, q| e.max(q.error))
}

/// One run of ours in item 5's table: its formulation and setting, its counted error on each
/// of the case's outputs (None where it has none), CPU time (median) and steps.
struct Run<'a> {
    formulation: &'a str,
    setting: &'a str,
    errors: Vec<Option<f64>>,
    cpu: f64,
    steps: i64,
}

impl Run<'_> {
    /// Whether it is at least as accurate as `other` on the first `scored` outputs.
    fn as_accurate_as(&self, other: &Run, scored: usize) -> bool {
        (0..scored).all(|k| match (self.errors[k], other.errors[k]) {
            (Some(a), Some(b)) => a <= b,
            _ => false,
        })
    }
}

/// Issue 12, item 5: each error-controlled run of ours against the cheapest fixed-step run of
/// the same formulation (at the default Newton tolerance) that is at least as accurate, errors
/// counted by [`counted_error`]; per case, the median, least and largest ratio of CPU times,
/// on the case's first output and on every output (a fixed run then counts only if it is as
/// accurate on each). Then, per run on the first output, the fixed step it is set against:
/// which runs decide a median.
pub fn error_control_table(cases: &[PeerCase], ours: &[PeerPoint]) -> String {
    let mut s = String::from(
        "## Error control against the best fixed step\n\n\
         Each error-controlled run (every tolerance and formulation swept) against the \
         cheapest fixed-step run of the same formulation at least as accurate, as the ratio of \
         their CPU times (median of the timed runs; issue 12 asks for at most 1.5). A run's \
         error is the largest of its own and of every tighter setting's of its family (the \
         rule above). `unmatched`: runs no fixed step is as accurate as.\n\n\
         | case | first output: median (least–largest), runs | every output: median \
         (least–largest), runs | unmatched (first / every) |\n|---|---|---|---|\n",
    );
    let mut details = String::from(
        "\n### The runs behind it (first output)\n\n\
         | case | formulation | setting | error | steps | CPU s | set against | its error | \
         its steps | its CPU s | ratio |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let fixed = |p: &PeerPoint| family(&p.setting).is_some_and(|(f, _)| f == "fixed step");
    let controlled = |p: &PeerPoint| family(&p.setting).is_some_and(|(f, _)| f == "tolerance");
    for case in cases {
        let outputs: Vec<&str> = case.outputs.iter().map(|(c, _)| *c).collect();
        let mine: Vec<&PeerPoint> = ours.iter().filter(|p| p.case == case.name).collect();
        let runs = |keep: &dyn Fn(&PeerPoint) -> bool| {
            let mut runs: Vec<Run> = Vec::new();
            for p in mine.iter().filter(|p| keep(p)) {
                let k = outputs.iter().position(|o| *o == p.output);
                let Some(k) = k else { continue };
                let at = runs
                    .iter()
                    .position(|r| r.formulation == p.formulation && r.setting == p.setting)
                    .unwrap_or_else(|| {
                        runs.push(Run {
                            formulation: &p.formulation,
                            setting: &p.setting,
                            errors: vec![None; outputs.len()],
                            cpu: p.seconds[0],
                            steps: p.steps,
                        });
                        runs.len() - 1
                    });
                runs[at].errors[k] = Some(counted_error(ours, p));
            }
            runs
        };
        let (fixed_runs, controlled_runs) = (runs(&fixed), runs(&controlled));
        let mut cells = Vec::new();
        let mut unmatched = Vec::new();
        for every in [false, true] {
            let scored = if every { outputs.len() } else { 1 };
            let mut ratios = Vec::new();
            let mut missing = 0;
            for run in &controlled_runs {
                let best = fixed_runs
                    .iter()
                    .filter(|f| f.formulation == run.formulation && f.as_accurate_as(run, scored))
                    .min_by(|a, b| a.cpu.total_cmp(&b.cpu));
                let error = |r: &Run| r.errors[0].map_or("-".into(), |e| format!("{e:.2e}"));
                match best {
                    Some(b) => {
                        ratios.push(run.cpu / b.cpu);
                        if !every {
                            let _ = writeln!(
                                details,
                                "| {} | {} | {} | {} | {} | {:.4} | {} | {} | {} | {:.4} | {:.2} |",
                                case.name,
                                run.formulation,
                                run.setting,
                                error(run),
                                run.steps,
                                run.cpu,
                                b.setting,
                                error(b),
                                b.steps,
                                b.cpu,
                                run.cpu / b.cpu
                            );
                        }
                    }
                    None => {
                        missing += 1;
                        if !every {
                            let _ = writeln!(
                                details,
                                "| {} | {} | {} | {} | {} | {:.4} | unmatched | | | | |",
                                case.name,
                                run.formulation,
                                run.setting,
                                error(run),
                                run.steps,
                                run.cpu
                            );
                        }
                    }
                }
            }
            ratios.sort_by(f64::total_cmp);
            cells.push(match ratios.len() {
                0 => "-".to_string(),
                n => {
                    let median = if n % 2 == 1 {
                        ratios[n / 2]
                    } else {
                        0.5 * (ratios[n / 2 - 1] + ratios[n / 2])
                    };
                    format!("{median:.2} ({:.2}–{:.2}), {n}", ratios[0], ratios[n - 1])
                }
            });
            unmatched.push(missing.to_string());
        }
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} |",
            case.name,
            cells[0],
            cells[1],
            unmatched.join(" / ")
        );
    }
    s + &details
}

/// `ours.csv`-style text of points.
pub fn csv(points: &[PeerPoint]) -> String {
    let mut s = String::from(
        "case,output,tool,formulation,setting,error,cpu_median,cpu_min,cpu_max,steps\n",
    );
    for p in points {
        let _ = writeln!(
            s,
            "{},{},{},\"{}\",\"{}\",{:.6e},{:.6e},{:.6e},{:.6e},{}",
            p.case,
            p.output,
            p.tool,
            p.formulation,
            p.setting,
            p.error,
            p.seconds[0],
            p.seconds[1],
            p.seconds[2],
            p.steps
        );
    }
    s
}

/// The report: the ratio table, then per target the two runs that set each ratio.
pub fn report(
    cases: &[PeerCase],
    ours: &[PeerPoint],
    theirs: &[PeerPoint],
    header: &str,
) -> String {
    let mut s =
        format!("# Against the peer: fmu-beam and Exudyn at equal accuracy\n\n{header}\n\n");
    s += "CPU time of the cheapest run of each tool whose largest error against the exact \
          reference (`bench/reference/`) is at most the target, as the ratio ours / Exudyn's \
          (median of the timed runs; below 1: we are faster). A run counts only if every \
          tighter setting of the same formulation (smaller fixed step, or tolerance) that ran \
          meets the target too: an error that crosses below the target on its way to a floor \
          above it is luck, not accuracy. `ours n.r.`: our sweep does not reach the target; \
          `peer n.r.`: Exudyn's does not.\n\n";
    s += "| case, output |";
    for t in TARGETS {
        let _ = write!(s, " {t:.0e} |");
    }
    s += "\n|---|";
    s += &"---|".repeat(TARGETS.len());
    s += "\n";
    let mut details = String::new();
    for case in cases {
        for (col, _) in case.outputs {
            let _ = write!(s, "| {} {col} |", case.name);
            for t in TARGETS {
                let a = cheapest(ours, "fmu-beam", case.name, col, t);
                let b = cheapest(theirs, "exudyn", case.name, col, t);
                let cell = match (a, b) {
                    (Some(a), Some(b)) => format!("{:.2}", a.seconds[0] / b.seconds[0]),
                    (None, Some(_)) => "ours n.r.".into(),
                    (Some(_), None) => "peer n.r.".into(),
                    (None, None) => "-".into(),
                };
                let _ = write!(s, " {cell} |");
                let show = |p: Option<&PeerPoint>| {
                    p.map_or("not reached".to_string(), |p| {
                        format!(
                            "{} at {}: error {:.2e}, {:.4} s ({:.4}–{:.4})",
                            p.formulation,
                            p.setting,
                            p.error,
                            p.seconds[0],
                            p.seconds[1],
                            p.seconds[2]
                        )
                    })
                };
                let _ = writeln!(
                    details,
                    "| {} {col} | {t:.0e} | {} | {} |",
                    case.name,
                    show(a),
                    show(b)
                );
            }
            s += "\n";
        }
    }
    s += "\n";
    s += &error_control_table(cases, ours);
    s += "\n## The runs behind each ratio\n\n| case, output | target | fmu-beam | Exudyn |\n|---|---|---|---|\n";
    s += &details;
    s
}

/// Writes `ours.csv` and `PEER.md` into `dir`; returns their paths.
pub fn write(dir: &Path, ours: &[PeerPoint], report: &str) -> Result<Vec<PathBuf>, BenchError> {
    std::fs::create_dir_all(dir).map_err(|e| BenchError::io(dir, "creating the directory", e))?;
    let a = dir.join("ours_points.csv");
    std::fs::write(&a, csv(ours)).map_err(|e| BenchError::io(&a, "writing", e))?;
    let b = dir.join("PEER.md");
    std::fs::write(&b, report).map_err(|e| BenchError::io(&b, "writing", e))?;
    Ok(vec![a, b])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(tool: &str, formulation: &str, setting: &str, error: f64, cpu: f64) -> PeerPoint {
        PeerPoint {
            case: "c2".into(),
            output: "chord_angle".into(),
            tool: tool.into(),
            formulation: formulation.into(),
            setting: setting.into(),
            error,
            seconds: [cpu; 3],
            steps: 0,
        }
    }

    #[test]
    fn a_fixed_step_above_the_grid_reports_at_its_step_points_only() {
        let base =
            Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/slider_crank.toml"))
                .expect("the shipped scene");
        let case = cases()
            .into_iter()
            .find(|c| c.name == "c3_elastic")
            .expect("c3");
        let f = &case.formulations[0];
        let at = |setting| {
            stride(
                &configure(&base, f, setting, None).expect("configured"),
                &case,
            )
        };
        assert_eq!(at(Setting::FixedStep(1e-2)), 10);
        assert_eq!(at(Setting::FixedStep(4e-3)), 4);
        assert_eq!(at(Setting::FixedStep(1e-3)), 1);
        assert_eq!(at(Setting::FixedStep(5e-4)), 1);
        // not a multiple of the grid, or not dividing the run: the whole grid
        assert_eq!(at(Setting::FixedStep(1.5e-3)), 1);
        assert_eq!(at(Setting::FixedStep(7e-3)), 1);
        assert_eq!(at(Setting::Tolerance(1e-4)), 1);
        // scored at the points reported, against the largest value of the whole reference
        let reference = [0.0, 1.0, 4.0, 1.0, 0.0];
        assert_eq!(scored(&[0.0, 4.5, 0.0], &reference, 2), 0.5 / 4.0);
        assert!(scored(&[0.0, 4.5], &reference, 2).is_nan());
    }

    #[test]
    fn setting_names_read_back() {
        for (setting, newton) in [
            (Setting::FixedStep(2e-5), None),
            (Setting::FixedStep(1e-3), Some(1e-8)),
            (Setting::Tolerance(1e-6), None),
        ] {
            let back = parse_setting(&setting_name(setting, newton));
            assert_eq!(back, Some((setting, newton)));
        }
        assert_eq!(parse_setting("ne=16;h=5e-05;rho_inf=0.9"), None);
    }

    #[test]
    fn settings_are_families_with_a_size() {
        assert_eq!(
            family("fixed step 1.0e-3 s"),
            Some(("fixed step".into(), 1e-3))
        );
        assert_eq!(family("tolerance 1e-6"), Some(("tolerance".into(), 1e-6)));
        assert_eq!(
            family("fixed step 1.0e-3 s, tolerance 1e-8"),
            Some(("fixed step, tolerance 1e-8".into(), 1e-3))
        );
        assert_eq!(
            family("ne=16;h=5e-05;rho_inf=0.9"),
            Some(("ne=16;rho_inf=0.9".into(), 5e-5))
        );
        assert_eq!(family("something else"), None);
    }

    /// The single frame of 6 elements on C2 (measured): its error crosses 1e-5 at tolerance
    /// 1e-6 (4.8e-6) on its way to its floor of 2.3e-5; the cheapest run that stays below
    /// 1e-5 is another formulation's.
    /// Our points are written so that `--ours-points` reads them back, settings with a comma
    /// included (it could not: the setting was unquoted).
    #[test]
    fn our_points_read_back() {
        let points = [
            point(
                "fmu-beam",
                "crank 3, rod 8",
                "fixed step 4.0e-3 s, tolerance 1e-8",
                1.5e-4,
                0.01,
            ),
            point("fmu-beam", "crank 3, rod 8", "tolerance 1e-6", 4.7e-5, 0.3),
        ];
        let path = std::env::temp_dir().join(format!("ours_points_{}.csv", std::process::id()));
        std::fs::write(&path, csv(&points)).unwrap();
        let back = read_peer(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(back.len(), 2);
        for (a, b) in points.iter().zip(&back) {
            assert_eq!((&a.formulation, &a.setting), (&b.formulation, &b.setting));
            assert_eq!((a.error, a.seconds), (b.error, b.seconds));
        }
    }

    /// Item 5's table: an error-controlled run is set against the cheapest fixed step at least
    /// as accurate, errors counted with the tighter settings' (a fixed step whose error is
    /// below a tighter step's is held to the tighter one's).
    #[test]
    fn error_control_is_set_against_the_cheapest_fixed_step_as_accurate_for_good() {
        let points = [
            point("fmu-beam", "f", "fixed step 4.0e-3 s", 1.3e-4, 0.010),
            point("fmu-beam", "f", "fixed step 2.0e-3 s", 5.6e-5, 0.020),
            point("fmu-beam", "f", "fixed step 1.0e-3 s", 7.9e-5, 0.040),
            point("fmu-beam", "f", "fixed step 2.0e-4 s", 2.5e-5, 0.130),
            point("fmu-beam", "f", "tolerance 1e-5", 4.0e-4, 0.030),
            point("fmu-beam", "f", "tolerance 1e-6", 6.0e-5, 0.260),
        ];
        // 2e-3 s is held to 1e-3 s's 7.9e-5: tolerance 1e-6 (6e-5) is set against 2e-4 s
        assert_eq!(counted_error(&points, &points[1]), 7.9e-5);
        assert_eq!(counted_error(&points, &points[3]), 2.5e-5);
        let cases: Vec<PeerCase> = cases().into_iter().filter(|c| c.name == "c2").collect();
        let table = error_control_table(&cases, &points);
        // ratios 0.030 / 0.010 = 3 and 0.260 / 0.130 = 2: median 2.5
        assert!(table.contains("| c2 | 2.50 (2.00–3.00), 2 |"), "{table}");
        // and each run with the fixed step it is set against
        assert!(
            table.contains("| c2 | f | tolerance 1e-6 | 6.00e-5 |")
                && table.contains("| fixed step 2.0e-4 s | 2.50e-5 |")
                && table.contains("| 2.00 |\n"),
            "{table}"
        );
    }

    #[test]
    fn an_error_that_crosses_the_target_on_its_way_to_a_floor_above_does_not_count() {
        let points = [
            point("fmu-beam", "six", "tolerance 1e-5", 1.2e-4, 0.013),
            point("fmu-beam", "six", "tolerance 1e-6", 4.8e-6, 0.036),
            point("fmu-beam", "six", "tolerance 1e-7", 2.2e-5, 0.108),
            point("fmu-beam", "six", "fixed step 2.0e-4 s", 1.9e-5, 0.039),
            point("fmu-beam", "ten", "fixed step 2.0e-4 s", 7.4e-6, 0.064),
            point("fmu-beam", "ten", "fixed step 1.0e-4 s", 2.9e-6, 0.120),
        ];
        assert!(!meets(&points, &points[1], 1e-5));
        assert!(meets(&points, &points[1], 1e-4));
        let best = cheapest(&points, "fmu-beam", "c2", "chord_angle", 1e-5).unwrap();
        assert_eq!((best.formulation.as_str(), best.seconds[0]), ("ten", 0.064));
        // the tightest run of a family has nothing tighter to contradict it
        let peer = [point(
            "exudyn",
            "ancf",
            "ne=16;h=5e-05;rho_inf=0.9",
            6e-4,
            1.5,
        )];
        assert!(meets(&peer, &peer[0], 1e-3));
    }
}
