//! The 3D section of the study (issue 4): cases C5 and C6 (CASES.md, 3D paper §5) built in
//! code with [`System3`] (the models of scenes/rollup_3d*.toml and pendulum_3d*.toml, with
//! their parameters swept here) and integrated by the same
//! generalized-α, swept over substructures, elements and integrator settings against the exact
//! roll-up (C5) and an untimed fine run (C6); then the 3D paper's fast variants (§6), the
//! frozen-inertia beam ([`InertiaModel::Frozen`]) and the beam from a matrix file
//! ([`matrix_file`]), timed against the full model on C6 and on a spin-up, where the
//! quadratic-velocity terms the variants drop are large enough to see; and what the planar
//! reduction saves: a 3D scene with planar motion (scenes/rollup_3d_z.toml) with the planar
//! element that `formulation = "auto"` picks, against the 3D element.
//!
//! Over 600 lines: the 3D section of the study (its cases built in code, their runs, their report)
//! kept together; a benchmark, not the product.

use super::report;
use super::{
    blank, thread_cpu_seconds, timed, timed_together, Options, Point, Run, Series, Setting, Status,
    Timed, EFFECTS_REPEATS, FIXED_STEP_NEWTON_TOLERANCE,
};
use crate::error::BenchError;
use fmu_beam::integrator::{initial_state, GaState, Settings, Stats, Stepper};
use fmu_beam::mechanics::matrix_file_beam;
use fmu_beam::mechanics::Drive;
use fmu_beam::mechanics::DriveKind;
use fmu_beam::mechanics::FloatingFrame;
use fmu_beam::mechanics::SpatialSection;
use fmu_beam::mechanics::{spatial_element_mass, spatial_element_stiffness};
use fmu_beam::mechanics::{Body3, Frame3, JointKind, Load3, RigidBody3, System3};
use fmu_beam::mechanics::{InertiaModel, SpatialBeam, SpatialBeamProps};
use fmu_beam::mechanics::{Law, TimeLaw};
use fmu_beam::scene::matrix_file::{self, MatrixFile};
use fmu_beam::{EngineError, Scene};
use nalgebra::{DMatrix, Matrix3, Vector3};
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::time::Instant;

/// Names the `--cases` filter knows for this section (`3D` selects all four): C5, C6, the
/// fast variants (F3) and the planar reduction (P3).
pub const NAMES: [&str; 4] = ["C5", "C6", "F3", "P3"];

/// The scene of the planar-reduction measurement.
const P3_SCENE: &str = "rollup_3d_z.toml";

/// P3: the scene through the engine with the element `auto` picks, and forced to the 3D one:
/// the table's text (timings median (min–max) of `repeats` runs, interleaved).
fn planar_reduction(scenes_dir: &std::path::Path, repeats: usize) -> Result<String, BenchError> {
    let base = Scene::load(&scenes_dir.join(P3_SCENE))?;
    let mut spatial = base.clone();
    spatial.formulation = fmu_beam::scene::Formulation::Spatial;
    let run_of = |scene: Scene| {
        move || -> Result<Series, EngineError> {
            measured(|| {
                let mut e = fmu_beam::Engine::new(scene.clone());
                let vr = |n: &str| e.variables().by_name(n).map(|v| v.vr);
                let outs: Vec<u32> = [
                    "beam.tip.x",
                    "beam.tip.y",
                    "solver.steps",
                    "solver.newton_iterations",
                    "solver.jacobians",
                ]
                .iter()
                .filter_map(|n| vr(n))
                .collect();
                e.exit_initialization()?;
                let h = scene.experiment.step_size;
                let steps = (scene.experiment.stop_time / h).round() as usize;
                let mut values = vec![Vec::new(), Vec::new()];
                for k in 0..steps {
                    e.do_step(k as f64 * h, h)?;
                    values[0].push(e.get_real(outs[0])?);
                    values[1].push(e.get_real(outs[1])?);
                }
                let mut count = |i: usize| e.get_integer(outs[i]).map(|x| x as u64);
                let stats = Stats {
                    steps: count(2)?,
                    newton_iterations: count(3)?,
                    jacobians: count(4)?,
                    ..Stats::default()
                };
                Ok((values, stats))
            })
        }
    };
    let (planar_run, spatial_run) = (run_of(base.clone()), run_of(spatial));
    let timed = timed_together(&[&planar_run, &spatial_run], repeats);
    let mut rows = Vec::new();
    for t in timed {
        let (series, cpu, _) = t.map_err(|source| BenchError::Engine {
            origin: format!("{P3_SCENE} (planar reduction)"),
            source,
        })?;
        rows.push((series, cpu));
    }
    let diff = (0..2)
        .map(|k| {
            rows[0].0.values[k]
                .iter()
                .zip(&rows[1].0.values[k])
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    let mut s = format!(
        "### The planar reduction: a 3D scene with planar motion\n\n\
         `{P3_SCENE}` (C5 about z, {} s, the scene's own solver settings: fixed step {:.0e} s, \
         Newton tolerance {:.0e}) through the engine: with `formulation = \"auto\"` its motion \
         stays in the x–y plane and it runs with the planar element; with `formulation = \
         \"spatial\"` with the 3D element. CPU s of the whole run, median (min–max) of {} \
         interleaved runs. Largest difference of the tip's x and y over the run: {diff:.1e} m \
         (L = 1 m; Newton's stopping error at this tolerance, see `tests/test_3d.py`).\n\n\
         | element | CPU s median (min–max) | time / planar | steps | Newton | LU |\n\
         |---|---|---|---|---|---|\n",
        base.experiment.stop_time,
        base.solver.max_step,
        base.solver.tolerance,
        repeats.max(1)
    );
    for (name, (series, cpu)) in ["planar (auto)", "3D (spatial)"].iter().zip(&rows) {
        let _ = writeln!(
            s,
            "| {name} | {:.3} ({:.3}–{:.3}) | {:.1} | {} | {} | {} |",
            cpu[0],
            cpu[1],
            cpu[2],
            cpu[0] / rows[0].1[0],
            series.stats[0],
            series.stats[1],
            series.stats[2]
        );
    }
    Ok(s)
}

// C5/C6's beam (CASES.md): steel, 0.02 × 0.06285 m rectangle.
const RHO: f64 = 7800.0;
const E: f64 = 210e9;
const G: f64 = 8.077e10;
const AREA: f64 = 0.02 * 0.06285;
const IY: f64 = 4.138e-7;
const IZ: f64 = 4.19e-8;
const TORSION: f64 = 1.33242e-7;

/// Spectral radius at infinity of every 3D run (the scenes' default).
const RHO_INF: f64 = 0.9;

// C5: L = 1, tip moment 2π E I_z / L about z (the weak axis) ramped linearly over C5_RAMP,
// then held; q_f damped mass-proportionally (every mode decays at α/2 = 100 /s), so that
// the tip settles; the figures are the means over the last C5_WINDOW.
const C5_LENGTH: f64 = 1.0;
const C5_RAMP: f64 = 0.5;
const C5_STOP: f64 = 0.8;
const C5_WINDOW: f64 = 0.1;
const C5_ALPHA: f64 = 200.0;
const C5_COMM: f64 = 1e-2;

// C6: L = 0.2, revolute about world y at flange a, horizontal along X, gravity −Z, 1 s.
const C6_LENGTH: f64 = 0.2;
const C6_STOP: f64 = 1.0;
const C6_COMM: f64 = 1e-2;

// Spin-up (for the fast variants): C5's beam (L = 1, first in-plane bending 16.8 Hz) on a
// revolute about world z, driven by the planar paper's eq. (18) to SPIN_OMEGA in SPIN_RAMP,
// undamped, no gravity; output the tip's in-plane deflection in the root frame.
const SPIN_LENGTH: f64 = 1.0;
const SPIN_OMEGA: f64 = 40.0;
const SPIN_RAMP: f64 = 1.0;
const SPIN_STOP: f64 = 1.5;
const SPIN_COMM: f64 = 1e-2;

/// The 3D section of the report: the two sweeps and the fast variants' tables.
#[derive(Debug, Clone)]
pub struct Results {
    pub sweeps: Vec<Sweep>,
    pub variants: Vec<VariantTable>,
    /// The planar-reduction table (P3), as text.
    pub reduction: Option<String>,
    /// Wall seconds the section took.
    pub seconds: f64,
}

/// C5 or C6 swept over formulations and integrator settings.
#[derive(Debug, Clone)]
pub struct Sweep {
    pub name: &'static str,
    pub title: &'static str,
    /// Outputs whose error is reported; the first is the main one.
    pub outputs: &'static [&'static str],
    pub formulations: Vec<String>,
    /// The model, the reference and the choices, as text.
    pub setup: String,
    pub points: Vec<Point>,
}

/// A fast variant's table: the full model first, then the variants, at one setting.
#[derive(Debug, Clone)]
pub struct VariantTable {
    pub title: &'static str,
    pub output: &'static str,
    pub setup: String,
    pub rows: Vec<Point>,
}

/// The integrator settings of `setting` (as [`Setting`] sets a scene's `solver`).
fn integrator(setting: Setting, comm: f64) -> Settings {
    match setting {
        Setting::Tolerance(t) => Settings {
            adaptive: true,
            tolerance: t,
            max_step: comm,
            rho_inf: RHO_INF,
            step_budget: fmu_beam::integrator::DEFAULT_STEP_BUDGET,
        },
        Setting::FixedStep(h) => Settings {
            adaptive: false,
            tolerance: FIXED_STEP_NEWTON_TOLERANCE,
            max_step: h,
            rho_inf: RHO_INF,
            step_budget: fmu_beam::integrator::DEFAULT_STEP_BUDGET,
        },
    }
}

fn section() -> SpatialSection {
    SpatialSection::given(AREA, IY, IZ, TORSION)
}

fn props(length: f64, elements: usize, inertia: InertiaModel, alpha: f64) -> SpatialBeamProps {
    SpatialBeamProps {
        length,
        elements,
        frame: FloatingFrame::Tangent,
        rho: RHO,
        e: E,
        g: G,
        section: section(),
        rayleigh_alpha: alpha,
        rayleigh_beta: 0.0,
        inertia,
    }
}

/// The one-element matrices of C5's section over `length`, written as a matrix file and
/// read back through its parser (the file's checks included).
fn element_file(length: f64) -> Result<MatrixFile, BenchError> {
    let s = section();
    let m = spatial_element_mass(RHO * s.area, RHO * s.polar_moment, length);
    let k = spatial_element_stiffness(
        E * s.area,
        G * s.torsion_constant,
        E * s.iy,
        E * s.iz,
        length,
    );
    let to = |a: [[f64; 12]; 12]| DMatrix::from_fn(12, 12, |i, j| a[i][j]);
    let text = MatrixFile {
        length,
        mass: to(m),
        stiffness: to(k),
    }
    .to_text("C5's section, one element (spatial_element::mass and ::stiffness)");
    Ok(matrix_file::parse(&text, "bench element")?)
}

/// What a beam of the variants' tables is.
#[derive(Debug, Clone, Copy)]
enum Model<'a> {
    /// The rigid twin: same mass and inertia as the undeformed beam (C6 only).
    Rigid,
    /// `elements` elements in one floating frame.
    Beam {
        elements: usize,
        inertia: InertiaModel,
    },
    /// The beam of a matrix file (one element, frozen inertia).
    File(&'a MatrixFile),
}

/// Adds the beam of `model` (flange a at the origin, along X); returns its beam group (None
/// for the rigid twin) and its frame at flange a, rotated by `root`.
fn add_model(
    sys: &mut System3,
    model: Model,
    length: f64,
    root: Matrix3<f64>,
) -> (Option<usize>, usize) {
    match model {
        Model::Rigid => {
            let beam = SpatialBeam::new("beam", &props(length, 1, InertiaModel::Full, 0.0));
            let b = sys.add_rigid(
                RigidBody3::of_beam(&beam, vec![("a".into(), Vector3::zeros(), root)]),
                Vector3::zeros(),
                Matrix3::identity(),
            );
            (None, sys.rigid_frame(b, "a"))
        }
        Model::Beam { elements, inertia } => {
            let g = sys.add_beam(
                "beam",
                &props(length, elements, inertia, 0.0),
                1,
                Vector3::zeros(),
                Matrix3::identity(),
            );
            (Some(g), sys.beam_frame(g, false, root))
        }
        Model::File(file) => {
            // the full one-element beam's place in q, then the file's beam in its stead
            // (same frame kind and element count: the same coordinates)
            let g = sys.add_beam(
                "beam",
                &props(length, 1, InertiaModel::Frozen, 0.0),
                1,
                Vector3::zeros(),
                Matrix3::identity(),
            );
            let b = sys.beams[g].bodies.start;
            let beam = matrix_file_beam(file, "beam", FloatingFrame::Tangent, 0.0, 0.0);
            assert_eq!(beam.nflex(), sys.bodies[b].nflex(), "same coordinates");
            sys.bodies[b] = Body3::Beam(Box::new(beam));
            (Some(g), sys.beam_frame(g, false, root))
        }
    }
}

/// x shifted by whole turns to lie within π of `prev`.
fn unwrap(prev: f64, x: f64) -> f64 {
    x + 2.0 * PI * ((prev - x) / (2.0 * PI)).round()
}

/// Integrates `sys` from its assembled initial state to `stop`, calling `record` at t = 0 and
/// at every communication point.
fn integrate(
    sys: &System3,
    settings: Settings,
    comm: f64,
    stop: f64,
    mut record: impl FnMut(&GaState),
) -> Result<Stats, EngineError> {
    let mut st = initial_state(sys, 0.0, &settings)?;
    let mut stepper = Stepper::new(sys, settings);
    let mut stats = Stats::default();
    record(&st);
    for k in 1..=(stop / comm).round() as usize {
        stepper.step_to(sys, &mut st, &mut stats, k as f64 * comm)?;
        record(&st);
    }
    Ok(stats)
}

/// Runs `f` (build a model and integrate it) on the thread's CPU clock.
fn measured(
    f: impl FnOnce() -> Result<(Vec<Vec<f64>>, Stats), EngineError>,
) -> Result<Series, EngineError> {
    let start = Instant::now();
    let cpu0 = thread_cpu_seconds();
    let (values, stats) = f()?;
    let seconds = match (cpu0, thread_cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => start.elapsed().as_secs_f64(),
    };
    Ok(Series {
        values,
        missing: Vec::new(),
        seconds,
        stats: [
            stats.steps as i64,
            stats.newton_iterations as i64,
            stats.jacobians as i64,
        ],
    })
}

/// C5 in `k` substructures of one element: [[mid-span point's distance from the exact one /
/// L], [tip distance from the root / L], [tip rotation about z (rad)]], means over the last
/// C5_WINDOW.
fn c5(k: usize, setting: Setting) -> Result<Series, EngineError> {
    measured(|| {
        let beam = props(C5_LENGTH, 1, InertiaModel::Full, C5_ALPHA);
        let mut sys = System3::new(None);
        let id = Matrix3::identity();
        let g = sys.add_beam("beam", &beam, k, Vector3::zeros(), id);
        let fw = sys.world_frame(Vector3::zeros(), id);
        let fa = sys.beam_frame(g, false, id);
        sys.add_joint("clamp", JointKind::Weld, fw, fa, None);
        let tip = sys.beam_frame(g, true, id);
        sys.add_load(Load3 {
            name: "moment".into(),
            frame: tip,
            force: Vector3::zeros(),
            torque: Vector3::new(0.0, 0.0, 2.0 * PI * E * IZ / C5_LENGTH),
            law: Some(TimeLaw {
                law: Law::Table(vec![[0.0, 0.0], [C5_RAMP, 1.0]]),
                until: None,
                origin: 0.0,
            }),
        });
        // mid-span: in substructure j at x_local (exact: (0, L/π, 0), the circle's far point)
        let l = C5_LENGTH / k as f64;
        let j = ((0.5 * C5_LENGTH / l).floor() as usize).min(k - 1);
        let body = sys.beams[g].bodies.start + j;
        let Body3::Beam(part) = &sys.bodies[body] else {
            unreachable!("beam groups hold beams")
        };
        let mid = Frame3::on_body(body, part.point_map(0.5 * C5_LENGTH - j as f64 * l), id);
        let exact_mid = Vector3::new(0.0, C5_LENGTH / PI, 0.0);
        let (mut angle, mut n, mut mean, mut rot, mut off) =
            (0.0, 0usize, Vector3::zeros(), 0.0, Vector3::zeros());
        let stats = integrate(&sys, integrator(setting, C5_COMM), C5_COMM, C5_STOP, |st| {
            let (x, a) = sys.beam_tip(g, &st.q);
            angle = unwrap(angle, a[(1, 0)].atan2(a[(0, 0)]));
            if st.t > C5_STOP - C5_WINDOW - 1e-9 {
                mean += x;
                rot += angle;
                off += mid.pose(Some(sys.body_coords(body, &st.q))).0 - exact_mid;
                n += 1;
            }
        })?;
        let n = n as f64;
        Ok((
            vec![
                vec![off.norm() / n / C5_LENGTH],
                vec![mean.norm() / n / C5_LENGTH],
                vec![rot / n],
            ],
            stats,
        ))
    })
}

/// C6 with `model`: [[hinge angle (unwrapped) at every communication point]].
fn c6(model: Model, setting: Setting) -> Result<Series, EngineError> {
    measured(|| {
        let mut sys = System3::new(Some(Vector3::new(0.0, 0.0, -9.81)));
        // joint axes: z along world y (x0 = X, y0 = −Z)
        let axes = Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0);
        let fw = sys.world_frame(Vector3::zeros(), axes);
        let (_, f1) = add_model(&mut sys, model, C6_LENGTH, axes);
        let hinge = sys.add_joint("hinge", JointKind::Revolute, fw, f1, None);
        let mut angles = Vec::new();
        let stats = integrate(&sys, integrator(setting, C6_COMM), C6_COMM, C6_STOP, |st| {
            let a = sys.joint_coordinate(hinge, &st.q);
            angles.push(angles.last().map_or(a, |&p| unwrap(p, a)));
        })?;
        Ok((vec![angles], stats))
    })
}

/// The spin-up with `model`: [[tip deflection in the root frame, in the plane of rotation]].
fn spin_up(model: Model, setting: Setting) -> Result<Series, EngineError> {
    measured(|| {
        let mut sys = System3::new(None);
        let id = Matrix3::identity();
        let fw = sys.world_frame(Vector3::zeros(), id);
        let (g, fa) = add_model(&mut sys, model, SPIN_LENGTH, id);
        let g = g.expect("the spin-up turns a beam");
        let drive = Drive {
            kind: DriveKind::Motion,
            law: TimeLaw {
                law: Law::SpinUp {
                    omega: SPIN_OMEGA,
                    ramp: SPIN_RAMP,
                },
                until: None,
                origin: 0.0,
            },
        };
        sys.add_joint("hub", JointKind::Revolute, fw, fa, Some(drive));
        let mut tip = Vec::new();
        let stats = integrate(
            &sys,
            integrator(setting, SPIN_COMM),
            SPIN_COMM,
            SPIN_STOP,
            |st| tip.push(sys.beam_tip_local(g, &st.q).y),
        )?;
        Ok((vec![tip], stats))
    })
}

/// A point not run yet, with three compared outputs.
fn point(case: &'static str, output: &'static str, formulation: &str, setting: Setting) -> Point {
    blank(case, output, 3, formulation, setting)
}

/// Puts a timing's counters and CPU seconds into `p`; returns the series (None: failed).
fn take(p: &mut Point, timing: Timed) -> Option<Series> {
    match timing {
        Ok((s, seconds, runs)) => {
            p.runs = runs;
            p.seconds = seconds;
            [p.steps, p.newton, p.factorizations] = s.stats;
            Some(s)
        }
        Err(e) => {
            p.status = Status::Failed(e.to_string());
            None
        }
    }
}

/// Scores a run of a time series against `reference`: [error at the end, max error over
/// the run], each also over max |reference|.
fn score_series(p: &mut Point, s: Series, reference: &[f64]) {
    let y = &s.values[0];
    let scale = reference.iter().fold(0.0f64, |m, r| m.max(r.abs()));
    let end = (y[y.len() - 1] - reference[reference.len() - 1]).abs();
    let max = super::error(y, reference).0;
    p.errors = vec![end, max];
    p.relative = vec![end / scale, max / scale];
    p.values = s.values.into_iter().next().unwrap_or_default();
}

/// One progress line.
fn line(p: &Point) -> String {
    match &p.status {
        Status::Ok => format!(
            "{}: {} at {}: error {:.2e} ({:.1e} relative), {:.3} s CPU (median of {}), {} steps",
            p.case,
            p.formulation,
            p.setting,
            p.errors[0],
            p.relative[0],
            p.seconds[0],
            p.runs,
            p.steps
        ),
        Status::Failed(m) | Status::Skipped(m) => {
            format!("{}: {} at {}: {m}", p.case, p.formulation, p.setting)
        }
    }
}

use Setting::{FixedStep as H, Tolerance as Tol};

/// C5's substructure counts and settings.
const C5_SUBSTRUCTURES: [usize; 4] = [2, 5, 10, 20];
const C5_SETTINGS: [Setting; 3] = [H(1e-2), Tol(1e-3), Tol(1e-4)];
/// Fixed steps only up to this count: at 20 substructures a fixed-step run takes ≈ 9 s,
/// about 2.5 times error control's at the same error.
const C5_FIXED_UP_TO: usize = 10;

/// C6's element counts (0: the rigid twin), settings and reference.
const C6_ELEMENTS: [usize; 4] = [0, 1, 2, 4];
const C6_SETTINGS: [Setting; 7] = [
    H(1e-3),
    H(3e-4),
    H(1e-4),
    Tol(1e-4),
    Tol(1e-5),
    Tol(1e-6),
    Tol(1e-7),
];
const C6_REFERENCE: (usize, Setting) = (8, H(2.5e-5));

/// The fast variants' settings: C6 and the spin-up, fixed steps (the same steps for every
/// row, so that the time ratio is the cost of an evaluation).
const F3_C6_SETTING: Setting = H(1e-3);
const F3_SPIN_SETTING: Setting = H(1e-3);

fn c6_name(elements: usize) -> String {
    match elements {
        0 => "rigid twin".into(),
        1 => "1 element".into(),
        n => format!("{n} elements"),
    }
}

/// What C5's sweep shows, with its numbers: the pass criteria over every run, the mid-span
/// error per substructure count and how little the integrator setting moves it.
fn c5_findings(points: &[Point]) -> String {
    let ok: Vec<&Point> = points.iter().filter(|p| p.ok()).collect();
    let worst = |i: usize| ok.iter().map(|p| p.relative[i]).fold(0.0f64, f64::max);
    let mut per_k = Vec::new();
    let mut spread = 0.0f64;
    for k in C5_SUBSTRUCTURES {
        let name = format!("{k} substructures");
        let mids: Vec<f64> = ok
            .iter()
            .filter(|p| p.formulation == name)
            .map(|p| p.relative[0])
            .collect();
        if let (Some(lo), Some(hi)) = (
            mids.iter().copied().reduce(f64::min),
            mids.iter().copied().reduce(f64::max),
        ) {
            per_k.push((k, lo));
            spread = spread.max(hi / lo - 1.0);
        }
    }
    let steps: Vec<i64> = ok
        .iter()
        .filter(|p| matches!(p.setting, Setting::FixedStep(_)))
        .map(|p| p.steps)
        .collect();
    let fixed_steps = match (steps.iter().min(), steps.iter().max()) {
        (Some(lo), Some(hi)) => format!("{lo}–{hi}"),
        _ => "no".into(),
    };
    let nominal = C5_SETTINGS
        .iter()
        .find_map(|s| match s {
            Setting::FixedStep(h) => Some(format!("{:.0} ({h:.0e} s)", C5_STOP / h)),
            Setting::Tolerance(_) => None,
        })
        .unwrap_or_default();
    let orders: Vec<String> = per_k
        .windows(2)
        .map(|w| {
            format!(
                "{:.2}",
                (w[0].1 / w[1].1).ln() / (w[1].0 as f64 / w[0].0 as f64).ln()
            )
        })
        .collect();
    format!(
        "Over every run the tip stays within {:.1e} L of the root and its rotation within \
         {:.1e} of 2π, for every k: each substructure under the end moment takes the same \
         linear shape (slope M l / EI, deflection M l² / 2EI), turned by 2π/k from the previous \
         one, so the k chords close for any k ≥ 2 and the pass criteria measure only the \
         settling and the integrator. The shape shows the discretization: mid-span error {} \
         (smallest over the settings), observed order {} in k between successive counts. The \
         integrator setting moves a count's mid-span error by at most {:.1} %, so the tighter \
         settings only cost time. The fixed-step runs take {} internal steps where {} were \
         asked for: the engine quarters a step whose Newton iteration does not converge.",
        worst(1),
        worst(2),
        per_k
            .iter()
            .map(|(k, m)| format!("{m:.2e} (k = {k})"))
            .collect::<Vec<_>>()
            .join(", "),
        orders.join(", "),
        100.0 * spread,
        fixed_steps,
        nominal
    )
}

/// C6's phase lag behind the rigid twin at 1 s, (θ_rigid − θ) / θ̇ with θ̇ at 1 s from the
/// reference (one-sided difference), per element count and fixed step: a table. `ends` holds
/// the angle at 1 s of every run (element count, fixed step).
fn c6_lag(ends: &[(usize, Setting, f64)], reference: &[f64], moved: f64) -> String {
    let n = reference.len() - 1;
    let rate = (3.0 * reference[n] - 4.0 * reference[n - 1] + reference[n - 2]) / (2.0 * C6_COMM);
    let end = |k: usize, setting: Setting| {
        ends.iter()
            .find(|e| e.0 == k && e.1 == setting)
            .map(|e| e.2)
    };
    let mut steps: Vec<Setting> = Vec::new();
    let mut counts: Vec<usize> = Vec::new();
    for &(k, h, _) in ends {
        if !steps.contains(&h) {
            steps.push(h);
        }
        if k > 0 && !counts.contains(&k) {
            counts.push(k);
        }
    }
    let mut s = format!(
        "Phase lag of the flexible pendulum behind its rigid twin at 1 s, (θ_rigid − θ) / θ̇ \
         (θ̇ = {rate:.4} rad/s), both at the same fixed step; the last column's runs are \
         untimed. The reference's change at half its step is {:.1e} s of lag: a lag below \
         that, or one that changes sign from step to step, is not resolved by these runs: \
         the twin's own time error and Newton's stopping error are larger than the lag. \
         Against the exact rigid pendulum, with the flexible runs converged by error control \
         at 1e-9, the lag is 3.7e-8 / 5.7e-8 / 6.2e-8 s for 1 / 2 / 4 elements \
         (`c6_flexible_pendulum_lags_its_rigid_twin` in `fmu-beam/src/tests/spatial_system.rs`).\n\n\
         | elements |{}\n|---|{}\n",
        moved / rate.abs(),
        steps.iter().map(|s| format!(" {s} |")).collect::<String>(),
        "---|".repeat(steps.len())
    );
    for k in counts {
        let _ = write!(s, "| {} |", c6_name(k));
        for &h in &steps {
            let lag = end(0, h)
                .zip(end(k, h))
                .map_or("–".into(), |(r, a)| format!("{:.2e} s", (r - a) / rate));
            let _ = write!(s, " {lag} |");
        }
        s += "\n";
    }
    s
}

/// Runs the 3D section for the names in `chosen` (of [`NAMES`]); `progress` receives a line
/// per point.
pub fn study(
    scenes_dir: &std::path::Path,
    chosen: &[&str],
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Results, BenchError> {
    let started = Instant::now();
    let mut tick = |text: &str| {
        let el = started.elapsed().as_secs();
        progress(&format!("[3D, {:>2}:{:02}] {text}", el / 60, el % 60));
    };
    let engine = |what: String| {
        move |source| BenchError::Engine {
            origin: what,
            source,
        }
    };
    let mut sweeps = Vec::new();
    if chosen.contains(&"C5") {
        let mut points = Vec::new();
        let mut formulations = Vec::new();
        for k in C5_SUBSTRUCTURES {
            let name = format!("{k} substructures");
            formulations.push(name.clone());
            let mut over: Vec<&'static str> = Vec::new();
            for setting in C5_SETTINGS {
                if k > C5_FIXED_UP_TO && matches!(setting, Setting::FixedStep(_)) {
                    continue;
                }
                let mut p = point("C5", "mid-span off the circle", &name, setting);
                if over.contains(&setting.mode()) {
                    p.status = Status::Skipped(format!(
                        "skipped: a looser {} setting took more than the budget of {} s",
                        setting.mode(),
                        options.budget
                    ));
                } else if let Some(s) = take(&mut p, timed(&|| c5(k, setting), options.repeats)) {
                    let (m, d, rot) = (s.values[0][0], s.values[1][0], s.values[2][0]);
                    let e = (rot - 2.0 * PI).abs();
                    p.errors = vec![m * C5_LENGTH, d * C5_LENGTH, e];
                    p.relative = vec![m, d, e / (2.0 * PI)];
                    p.values = vec![m, d, rot];
                    if p.seconds[0] > options.budget {
                        over.push(setting.mode());
                    }
                }
                tick(&line(&p));
                points.push(p);
            }
        }
        let setup = format!(
            "Built in code (`multibody3d::System3`; 3D scene files come later). Cantilever L = \
             {C5_LENGTH} m, ρ = {RHO}, A = 0.02 × 0.06285 m², I_y = {IY:e}, I_z = {IZ:e}, J_t = \
             {TORSION:e} m⁴, E = {E:e}, G = {G:e} Pa, welded to the world at flange a, in k \
             substructures of one element each (tangent frames welded flange b → flange a). Tip \
             moment M = 2π E I_z / L about z (the weak axis) ramped linearly over {C5_RAMP} s, \
             held to {C5_STOP} s; q_f damped by mass-proportional Rayleigh α = {C5_ALPHA} /s \
             (every mode decays at α/2) so that the beam settles; ρ∞ = {RHO_INF}. **Exact**: a \
             circle of radius L/2π, the tip back at the root turned by 2π, the mid-span point at \
             (0, L/π, 0). Errors of the means over the last {C5_WINDOW} s (poses read every \
             {C5_COMM} s): the mid-span point's distance from the exact one (relative: over L; \
             the main output), the tip's distance from the root (relative: over L) and |tip \
             rotation − 2π| (relative: over 2π), the last two CASES.md's pass criteria (1 %). The \
             strong axis is left out of the timed sweep (`fmu-beam/src/tests/spatial_system.rs` \
             closes both).\n\n{}",
            c5_findings(&points)
        );
        sweeps.push(Sweep {
            name: "C5",
            title: "3D static roll-up of a cantilever by a tip moment",
            outputs: &[
                "mid-span off the circle",
                "tip distance from root",
                "tip rotation − 2π",
            ],
            formulations,
            setup,
            points,
        });
    }
    if chosen.contains(&"C6") {
        let (n_ref, s_ref) = C6_REFERENCE;
        let model = |n: usize| match n {
            0 => Model::Rigid,
            n => Model::Beam {
                elements: n,
                inertia: InertiaModel::Full,
            },
        };
        let r = c6(model(n_ref), s_ref)
            .map_err(engine(format!("C6 reference run ({})", c6_name(n_ref))))?;
        let reference = r.values[0].clone();
        let last = reference[reference.len() - 1];
        // the reference's own uncertainty: the same run at a finer setting
        let finer = match s_ref {
            Setting::FixedStep(h) => Setting::FixedStep(h / 2.0),
            Setting::Tolerance(t) => Setting::Tolerance(t / 10.0),
        };
        let check = c6(model(n_ref), finer)
            .map_err(engine(format!("C6 reference check ({})", c6_name(n_ref))))?;
        let moved = (check.values[0][check.values[0].len() - 1] - last).abs();
        let described = format!(
            "{} at {s_ref} ({} steps, {:.1} s CPU, untimed): angle at 1 s {last:.9} rad; at \
             {finer} it moves by {moved:.2e} rad ({:.1e} relative), so errors below that are \
             not resolved",
            c6_name(n_ref),
            r.stats[0],
            r.seconds,
            moved / reference.iter().fold(0.0f64, |m, r| m.max(r.abs()))
        );
        tick(&format!("C6: reference: {described}"));
        let mut points = Vec::new();
        let mut formulations = Vec::new();
        for n in C6_ELEMENTS {
            let name = c6_name(n);
            formulations.push(name.clone());
            let mut over: Vec<&'static str> = Vec::new();
            for setting in C6_SETTINGS {
                let mut p = point("C6", "hinge angle at 1 s", &name, setting);
                if over.contains(&setting.mode()) {
                    p.status = Status::Skipped(format!(
                        "skipped: a looser {} setting took more than the budget of {} s",
                        setting.mode(),
                        options.budget
                    ));
                } else if let Some(s) =
                    take(&mut p, timed(&|| c6(model(n), setting), options.repeats))
                {
                    score_series(&mut p, s, &reference);
                    if p.seconds[0] > options.budget {
                        over.push(setting.mode());
                    }
                }
                tick(&line(&p));
                points.push(p);
            }
        }
        // the angle at 1 s of every fixed-step run, and of the rigid twin and every element
        // count at the reference's setting (untimed)
        let mut ends: Vec<(usize, Setting, f64)> = points
            .iter()
            .filter(|p| p.ok() && matches!(p.setting, Setting::FixedStep(_)))
            .filter_map(|p| {
                let k = C6_ELEMENTS
                    .into_iter()
                    .find(|&k| c6_name(k) == p.formulation)?;
                Some((k, p.setting, *p.values.last()?))
            })
            .collect();
        for k in C6_ELEMENTS {
            let r = c6(model(k), s_ref).map_err(engine(format!(
                "C6 at the reference setting ({})",
                c6_name(k)
            )))?;
            ends.push((k, s_ref, r.values[0][r.values[0].len() - 1]));
        }
        ends.push((n_ref, s_ref, reference[reference.len() - 1]));
        tick(&format!(
            "C6: every element count at {s_ref} (untimed, for the phase lag)"
        ));
        let lag = c6_lag(&ends, &reference, moved);
        let setup = format!(
            "Built in code. C5's beam with L = {C6_LENGTH} m in one floating frame (tangent at \
             flange a), revolute about world y at flange a, released at rest horizontal along X, \
             gravity −Z, {C6_STOP} s; undamped; ρ∞ = {RHO_INF}. The rigid twin is a rigid body \
             with the undeformed beam's mass and inertia. **Reference**: {described}. Error = \
             |angle − reference| at 1 s (relative: over max |reference angle|); `max over the \
             run` compares every {C6_COMM} s.\n\n{}",
            lag
        );
        sweeps.push(Sweep {
            name: "C6",
            title: "3D flexible pendulum (1 s)",
            outputs: &["hinge angle at 1 s", "hinge angle, max over the run"],
            formulations,
            setup,
            points,
        });
    }
    let mut variants = Vec::new();
    if chosen.contains(&"F3") {
        let files = [element_file(C6_LENGTH)?, element_file(SPIN_LENGTH)?];
        // clamped beam, first bending about z: (β₁L)² √(E I_z / (ρ A L⁴)), β₁L = 1.87510
        let omega1 = 1.87510f64.powi(2) * (E * IZ / (RHO * AREA * SPIN_LENGTH.powi(4))).sqrt();
        let models = |file| {
            [
                (
                    "full, 1 element",
                    Model::Beam {
                        elements: 1,
                        inertia: InertiaModel::Full,
                    },
                ),
                (
                    "frozen inertia, 1 element",
                    Model::Beam {
                        elements: 1,
                        inertia: InertiaModel::Frozen,
                    },
                ),
                ("matrix file, 1 element", Model::File(file)),
                (
                    "full, 4 elements (discretization context)",
                    Model::Beam {
                        elements: 4,
                        inertia: InertiaModel::Full,
                    },
                ),
            ]
        };
        let cases: [(&'static str, &'static str, Setting, String); 2] = [
            (
                "C6: hinge angle",
                "hinge angle",
                F3_C6_SETTING,
                format!("C6 as above (L = {C6_LENGTH} m), {C6_STOP} s"),
            ),
            (
                "spin-up: tip deflection in the root frame",
                "tip deflection",
                F3_SPIN_SETTING,
                format!(
                    "C5's beam, L = {SPIN_LENGTH} m (first clamped in-plane bending ω₁ = \
                     {omega1:.1} rad/s), flange a on a revolute about world z driven by the \
                     planar paper's eq. (18) to Ω = {SPIN_OMEGA} rad/s in {SPIN_RAMP} s, then \
                     held to {SPIN_STOP} s; undamped, no gravity; output the tip's in-plane \
                     deflection in the root frame every {SPIN_COMM} s. (Ω/ω₁)² = {:.3}: the \
                     full model's quadratic-velocity terms with q_f (centrifugal softening, \
                     Coriolis) are what the variants drop. The 3D models run without geometric \
                     stiffening, so at this spin neither is the physical answer (as in \
                     planar C4, where the linear single frame runs away without it); the table \
                     measures only what the variants leave out",
                    (SPIN_OMEGA / omega1).powi(2)
                ),
            ),
        ];
        for (i, (title, output, setting, about)) in cases.into_iter().enumerate() {
            let rows = models(&files[i]);
            let runs: Vec<Box<Run>> = rows
                .iter()
                .map(|&(_, m)| -> Box<Run> {
                    if i == 0 {
                        Box::new(move || c6(m, setting))
                    } else {
                        Box::new(move || spin_up(m, setting))
                    }
                })
                .collect();
            let refs: Vec<&Run> = runs.iter().map(|r| r.as_ref()).collect();
            let repeats = options.repeats.max(EFFECTS_REPEATS);
            let mut out = Vec::new();
            let mut full: Option<Vec<f64>> = None;
            let timings = timed_together(&refs, repeats);
            for (j, ((name, _), timing)) in rows.iter().zip(timings).enumerate() {
                let case = if i == 0 { "C6" } else { "spin-up" };
                let mut p = point(case, output, name, setting);
                if let Some(s) = take(&mut p, timing) {
                    if j == 0 {
                        full = Some(s.values[0].clone());
                    }
                    if let Some(r) = &full {
                        score_series(&mut p, s, r);
                    }
                }
                tick(&line(&p));
                out.push(p);
            }
            variants.push(VariantTable {
                title,
                output,
                setup: format!(
                    "{about}; {setting}, rows timed round by round ({repeats} samples each). \
                     The matrix file holds the element's own 12 × 12 mass and stiffness, \
                     written by `MatrixFile::to_text` and read back by `matrix_file::parse` \
                     (once, untimed; each run builds the beam from it)."
                ),
                rows: out,
            });
        }
    }
    let reduction = if chosen.contains(&"P3") {
        tick("P3: planar reduction of rollup_3d_z");
        Some(planar_reduction(scenes_dir, options.repeats)?)
    } else {
        None
    };
    Ok(Results {
        sweeps,
        variants,
        reduction,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// The fast variants' table: time against the full model's, and the change of the output.
fn variant_table(t: &VariantTable) -> String {
    let full = &t.rows[0];
    let mut s = format!(
        "| model | CPU s median (min–max) | time / full | steps | Newton | {0} at the end | \
         change from full at the end (relative) | change from full, max over the run \
         (relative) |\n|---|---|---|---|---|---|---|---|\n",
        t.output
    );
    for p in &t.rows {
        match &p.status {
            Status::Ok => {
                let ratio = if full.ok() {
                    report::sig3(p.seconds[0] / full.seconds[0])
                } else {
                    "–".into()
                };
                let _ = writeln!(
                    s,
                    "| {} | {} | {ratio} | {} | {} | {:.6e} | {} ({}) | {} ({}) |",
                    p.formulation,
                    report::cpu(p),
                    p.steps,
                    p.newton,
                    p.values.last().copied().unwrap_or(f64::NAN),
                    report::sci(p.errors[0]),
                    report::sci(p.relative[0]),
                    report::sci(p.errors[1]),
                    report::sci(p.relative[1]),
                );
            }
            Status::Failed(m) | Status::Skipped(m) => {
                let _ = writeln!(s, "| {} | {m} | – | – | – | – | – | – |", p.formulation);
            }
        }
    }
    s
}

/// The 3D section of REPORT.md.
pub fn markdown(r: &Results) -> String {
    let mut s = format!(
        "## 3D (issue 4): C5, C6 and the fast variants\n\n\
         The spatial multibody layer (`fmu_beam::mechanics::System3`, quaternion frames, \
         finite-difference tangents) through the same generalized-α, timed as above (thread CPU \
         time, median (min–max) of the samples; a run includes building the model). This \
         section took {:.0} s wall time.\n\n",
        r.seconds
    );
    for w in &r.sweeps {
        let _ = writeln!(
            s,
            "### {}: {}\n\n{}\n\n![{0}: error against CPU time]({0}.png)\n\n{}\n{}",
            w.name,
            w.title,
            w.setup,
            report::summary_of(&w.formulations, &w.points),
            report::points_table(w.outputs, false, &w.points)
        );
    }
    if !r.variants.is_empty() {
        s += "### Fast variants (3D paper §6): frozen inertia and the matrix-file beam\n\n\
              The frozen-inertia beam (`InertiaModel::Frozen`) keeps the mass matrix at q_f = 0 \
              and the quadratic-velocity terms of the undeformed beam's rigid motion; the \
              matrix-file beam (`matrix_file`) has only 12 × 12 nodal matrices, so it gets the \
              same frozen treatment. Time / full is the median CPU time over the full model's; \
              change from full is |y − y_full| at the same setting (relative: over max \
              |y_full|).\n\n";
        for t in &r.variants {
            let _ = writeln!(s, "#### {}\n\n{}\n\n{}", t.title, t.setup, variant_table(t));
        }
    }
    if let Some(r) = &r.reduction {
        s += r;
        s += "\n";
    }
    s
}

/// The section's rows of `points.csv` (kind sweep for C5 and C6, variants for the rest).
pub fn csv_rows(r: &Results, row: &mut dyn FnMut(&str, &Point)) {
    for w in &r.sweeps {
        for p in &w.points {
            row("sweep", p);
        }
    }
    for t in &r.variants {
        for p in &t.rows {
            row("variants", p);
        }
    }
}
