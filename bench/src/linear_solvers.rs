//! Dense against sparse LU of the iteration matrix (`fmu-bench linear-solvers`, part of
//! `make bench`): C2's pendulum and C4's spin-up built with k substructures, and C1's beam
//! with e elements in one frame (one dense block), at fixed steps. For each model and each
//! [`LinearSolver`]: CPU time per step of a run (its steps only, not the build or the initial
//! state), per factorization and per solve of the iteration matrix at the initial state. The
//! samples are taken round by round (every model and solver once per round), so that the
//! machine's load falls on all alike; the report gives median, min and max, and the median of
//! the per-round ratios sparse / dense. Writes `LINEAR.md` and `linear_solvers.csv`.

use crate::error::BenchError;
use crate::work_precision::clock;
use fmu_beam::integrator::{
    initial_state, iteration_scaling, GaState, IterationMatrix, LinearSolver, Settings, Stats,
    Stepper,
};
use fmu_beam::mechanics::Equations;
use fmu_beam::mechanics::Mechanics;
use fmu_beam::resolve_effects as resolve;
use fmu_beam::{EngineError, Scene};
use nalgebra::DVector;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A family of models: a scene whose beam is cut into `k` parts.
#[derive(Debug, Clone, Copy)]
pub struct Family {
    pub name: &'static str,
    pub scene: &'static str,
    /// Elements per substructure; 0: `k` is the element count of one frame.
    pub elements_per_part: usize,
    pub step: f64,
    pub stop: f64,
    pub sizes: &'static [usize],
}

/// The families of `make bench`.
pub const FAMILIES: [Family; 3] = [
    Family {
        name: "C2 pendulum, k x 2",
        scene: "flexible_pendulum_substructured.toml",
        elements_per_part: 2,
        step: 1e-3,
        stop: 0.2,
        sizes: &[3, 5, 7, 10, 20, 40, 80],
    },
    Family {
        name: "C4 spin-up, k x 1",
        scene: "spin_up_omega10.toml",
        elements_per_part: 1,
        step: 1e-2,
        stop: 2.0,
        sizes: &[3, 5, 7, 10, 20, 40, 80],
    },
    Family {
        name: "C1 beam, one frame of e elements",
        scene: "cantilever_free_vibration.toml",
        elements_per_part: 0,
        step: 5e-4,
        stop: 0.1,
        sizes: &[10, 20, 40, 80],
    },
];

/// Shortest timed sample (s): shorter work is repeated in a batch (the scheduler's account
/// moves in ticks).
const MIN_SAMPLE: f64 = 0.05;
/// Communication step of the runs (s).
const COMM: f64 = 1e-2;

/// Median, min and max of samples.
fn spread(mut s: Vec<f64>) -> [f64; 3] {
    s.sort_by(f64::total_cmp);
    [s[s.len() / 2], s[0], s[s.len() - 1]]
}

/// One model with one solver: what it is, its counters and its samples (s per unit).
#[derive(Debug, Clone)]
pub struct Measured {
    pub family: &'static str,
    pub k: usize,
    pub n: usize,
    pub m: usize,
    /// Stored entries of the sparse pattern.
    pub nnz: usize,
    pub linear: LinearSolver,
    /// What [`LinearSolver::Auto`] picks for this model.
    pub auto_sparse: bool,
    pub steps: u64,
    pub newton: u64,
    pub factorizations: u64,
    pub per_step: Vec<f64>,
    pub per_factorization: Vec<f64>,
    pub per_solve: Vec<f64>,
    /// The run's final coordinates (to compare dense with sparse).
    pub q_end: DVector<f64>,
}

/// A built model ready to be timed.
struct Model {
    sys: Mechanics,
    start: GaState,
    settings: Settings,
    stop: f64,
}

impl Model {
    fn new(dir: &Path, f: &Family, k: usize) -> Result<Model, BenchError> {
        let mut scene = Scene::load(&dir.join(f.scene))?;
        let b = &mut scene.beams[0];
        if f.elements_per_part == 0 {
            b.elements = Some(k);
            b.substructures = None;
            b.elements_per_substructure = None;
        } else {
            b.elements = None;
            b.substructures = Some(k);
            b.elements_per_substructure = Some(f.elements_per_part);
        }
        scene.solver.adaptive = false;
        scene.solver.max_step = f.step;
        scene.solver.tolerance = crate::work_precision::FIXED_STEP_NEWTON_TOLERANCE;
        let origin = format!("{} ({}, k = {k})", f.scene, f.name);
        let scene = Scene::from_toml_str(&scene.to_toml_string(), &origin)?;
        let sys = Mechanics::build(&scene, &resolve(&scene).effects);
        let settings = Settings::from_scene(&scene);
        let start = initial_state(&sys, 0.0, &settings).map_err(|source| BenchError::Engine {
            origin: origin.clone(),
            source,
        })?;
        Ok(Model {
            sys,
            start,
            settings,
            stop: f.stop,
        })
    }

    /// Runs `batch` fresh runs; returns the CPU seconds of their steps, the last run's
    /// counters and final state.
    fn runs(
        &self,
        linear: LinearSolver,
        batch: usize,
    ) -> Result<(f64, Stats, GaState), EngineError> {
        let fresh = Stepper::with_linear_solver(&self.sys, self.settings, linear);
        let mut work: Vec<(Stepper, GaState)> = (0..batch)
            .map(|_| (fresh.clone(), self.start.clone()))
            .collect();
        let mut stats = Stats::default();
        let comms = (self.stop / COMM).round() as usize;
        let origin = Instant::now();
        let c0 = clock(origin);
        for (stepper, st) in &mut work {
            stats = Stats::default();
            for i in 1..=comms {
                stepper.step_to(&self.sys, st, &mut stats, i as f64 * COMM)?;
            }
        }
        let seconds = clock(origin) - c0;
        let (_, last) = work.pop().expect("a run");
        Ok((seconds, stats, last))
    }

    /// The iteration matrix at the initial state, factorized once.
    fn lu(&self, linear: LinearSolver) -> Lu<'_> {
        let n = self.sys.n() + self.sys.m();
        let mut lu = Lu {
            model: self,
            matrix: IterationMatrix::new(&self.sys, linear),
            rhs: DVector::from_fn(n, |i, _| 1.0 + i as f64 / n as f64),
            x: DVector::zeros(n),
        };
        lu.factorize();
        lu
    }
}

/// A model's iteration matrix at the initial state and a right-hand side.
struct Lu<'a> {
    model: &'a Model,
    matrix: IterationMatrix,
    rhs: DVector<f64>,
    x: DVector<f64>,
}

impl Lu<'_> {
    fn factorize(&mut self) {
        let (m, s) = (self.model, &self.model.start);
        let w = iteration_scaling(m.settings.rho_inf, m.settings.max_step);
        let ok = self.matrix.factorize(&m.sys, &s.point(), w);
        assert!(ok, "the iteration matrix at the initial state is singular");
    }

    fn solve(&mut self) {
        self.x.copy_from(&self.rhs);
        assert!(self.matrix.solve_mut(&mut self.x), "no solution");
    }

    /// CPU seconds of `count` calls of `f`.
    fn timed(&mut self, count: usize, f: fn(&mut Self)) -> f64 {
        let origin = Instant::now();
        let c0 = clock(origin);
        for _ in 0..count {
            f(self);
        }
        clock(origin) - c0
    }
}

/// The batch that makes a sample last at least [`MIN_SAMPLE`], from the wall time of one
/// (finer than the scheduler's CPU account, and never shorter than the CPU time).
fn batch_for(one: impl FnOnce()) -> usize {
    let start = Instant::now();
    one();
    (MIN_SAMPLE / start.elapsed().as_secs_f64().max(1e-7)).ceil() as usize
}

/// Runs the study: `rounds` samples of every family, size and solver.
pub fn study(
    dir: &Path,
    rounds: usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Measured>, BenchError> {
    let engine = |origin: String| move |source| BenchError::Engine { origin, source };
    // (model, its row in `out`, batch sizes of runs, factorizations and solves)
    let mut timed: Vec<(usize, usize, [usize; 3])> = Vec::new();
    let mut models = Vec::new();
    let mut out = Vec::new();
    for f in &FAMILIES {
        for &k in f.sizes {
            let model = Model::new(dir, f, k)?;
            let (n, m) = (model.sys.n(), model.sys.m());
            let auto = IterationMatrix::new(&model.sys, LinearSolver::Auto).is_sparse();
            let nnz = IterationMatrix::new(&model.sys, LinearSolver::Sparse).nnz();
            for linear in [LinearSolver::Dense, LinearSolver::Sparse] {
                // a trial sizes the batches (and warms the caches)
                let origin = format!("{} k = {k} ({linear:?})", f.name);
                let (_, stats, end) = model.runs(linear, 1).map_err(engine(origin))?;
                let mut lu = model.lu(linear);
                let batches = [
                    batch_for(|| drop(model.runs(linear, 1))),
                    batch_for(|| lu.factorize()),
                    batch_for(|| lu.solve()),
                ];
                timed.push((models.len(), out.len(), batches));
                out.push(Measured {
                    family: f.name,
                    k,
                    n,
                    m,
                    nnz,
                    linear,
                    auto_sparse: auto,
                    steps: stats.steps,
                    newton: stats.newton_iterations,
                    factorizations: stats.jacobians,
                    per_step: Vec::new(),
                    per_factorization: Vec::new(),
                    per_solve: Vec::new(),
                    q_end: end.q,
                });
            }
            progress(&format!(
                "{}: k = {k}, n + m = {}: trial runs done",
                f.name,
                n + m
            ));
            models.push(model);
        }
    }
    for round in 0..rounds {
        for &(mi, i, [runs, factorizations, solves]) in &timed {
            let (model, r) = (&models[mi], &mut out[i]);
            let origin = format!("{} k = {} ({:?})", r.family, r.k, r.linear);
            let (seconds, stats, _) = model.runs(r.linear, runs).map_err(engine(origin))?;
            let mut lu = model.lu(r.linear);
            let fs = lu.timed(factorizations, Lu::factorize);
            let ss = lu.timed(solves, Lu::solve);
            r.per_step
                .push(seconds / (runs as f64 * stats.steps.max(1) as f64));
            r.per_factorization.push(fs / factorizations as f64);
            r.per_solve.push(ss / solves as f64);
        }
        progress(&format!("round {}/{rounds} done", round + 1));
    }
    Ok(out)
}

/// The median of the per-round ratios b / a.
fn ratio(a: &[f64], b: &[f64]) -> f64 {
    spread(a.iter().zip(b).map(|(x, y)| y / x).collect())[0]
}

/// `LINEAR.md`: one table per family, dense and sparse side by side.
pub fn markdown(rows: &[Measured], rounds: usize, header: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Dense and sparse LU of the iteration matrix\n\n{header}"
    );
    let us = |x: f64| format!("{:.0}", x * 1e6);
    for f in &FAMILIES {
        let _ = writeln!(
            s,
            "\n## {} (fixed step {:.0e} s, {} s)\n\n\
             | k | n + m | nnz | auto | steps | fact. | dense µs/step | sparse µs/step | \
             sparse / dense | sparse µs/step/k | dense µs/fact. | sparse µs/fact. | \
             sparse / dense | dense µs/solve | sparse µs/solve | max abs Δq |\n\
             |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
            f.name, f.step, f.stop
        );
        for &k in f.sizes {
            let find = |l| {
                rows.iter()
                    .find(|r| r.family == f.name && r.k == k && r.linear == l)
            };
            let (Some(d), Some(p)) = (find(LinearSolver::Dense), find(LinearSolver::Sparse)) else {
                continue;
            };
            let (ds, ps) = (spread(d.per_step.clone()), spread(p.per_step.clone()));
            let (df, pf) = (
                spread(d.per_factorization.clone()),
                spread(p.per_factorization.clone()),
            );
            let (dv, pv) = (spread(d.per_solve.clone()), spread(p.per_solve.clone()));
            let dq = (&d.q_end - &p.q_end).amax();
            let _ = writeln!(
                s,
                "| {k} | {} | {} | {} | {} | {} | {} ({}–{}) | {} ({}–{}) | {:.2} | {:.1} | \
                 {} ({}–{}) | {} ({}–{}) | {:.2} | {:.1} | {:.1} | {dq:.1e} |",
                d.n + d.m,
                p.nnz,
                if d.auto_sparse { "sparse" } else { "dense" },
                p.steps,
                p.factorizations,
                us(ds[0]),
                us(ds[1]),
                us(ds[2]),
                us(ps[0]),
                us(ps[1]),
                us(ps[2]),
                ratio(&d.per_step, &p.per_step),
                ps[0] * 1e6 / k as f64,
                us(df[0]),
                us(df[1]),
                us(df[2]),
                us(pf[0]),
                us(pf[1]),
                us(pf[2]),
                ratio(&d.per_factorization, &p.per_factorization),
                dv[0] * 1e6,
                pv[0] * 1e6,
            );
        }
    }
    let _ = writeln!(
        s,
        "\nµs: CPU microseconds of the thread, median (min–max) of {rounds} rounds; ratios: \
         median of the per-round ratios. A step's time is its share of a run's steps (Newton \
         iterations, the factorizations the run needed, residuals); a factorization's and a \
         solve's are at the initial state. nnz: stored entries of the sparse pattern (body \
         blocks, G and Gᵀ); max abs Δq: the largest difference of the final coordinates of the \
         dense and the sparse run."
    );
    s
}

/// `linear_solvers.csv`: one line per model and solver.
pub fn csv(rows: &[Measured]) -> String {
    let mut s = String::from(
        "family,k,n,m,nnz,solver,auto,steps,newton,factorizations,\
         step_median,step_min,step_max,fact_median,fact_min,fact_max,solve_median\n",
    );
    for r in rows {
        let (st, fa, so) = (
            spread(r.per_step.clone()),
            spread(r.per_factorization.clone()),
            spread(r.per_solve.clone()),
        );
        let _ = writeln!(
            s,
            "{},{},{},{},{},{:?},{},{},{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
            r.family,
            r.k,
            r.n,
            r.m,
            r.nnz,
            r.linear,
            if r.auto_sparse { "sparse" } else { "dense" },
            r.steps,
            r.newton,
            r.factorizations,
            st[0],
            st[1],
            st[2],
            fa[0],
            fa[1],
            fa[2],
            so[0]
        );
    }
    s
}

/// Writes `LINEAR.md` and `linear_solvers.csv` into `dir`.
pub fn write(
    dir: &Path,
    rows: &[Measured],
    rounds: usize,
    header: &str,
) -> Result<Vec<PathBuf>, BenchError> {
    std::fs::create_dir_all(dir).map_err(|e| BenchError::io(dir, "creating the directory", e))?;
    let md = dir.join("LINEAR.md");
    let table = dir.join("linear_solvers.csv");
    std::fs::write(&md, markdown(rows, rounds, header))
        .map_err(|e| BenchError::io(&md, "writing the report", e))?;
    std::fs::write(&table, csv(rows)).map_err(|e| BenchError::io(&table, "writing the CSV", e))?;
    Ok(vec![md, table])
}
