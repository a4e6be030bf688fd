//! Issue 45, item 4: a doStep's budget is counted in work (`integrator::work_units`: Newton
//! iterations times unknowns, factorizations times unknowns squared), not in internal steps, so
//! that any doStep returns within seconds on every shipped scene. Counted in steps, doStep(0,
//! 1e6) ran 287 s on rollup_3d and 66 s on spin_up_omega10 before the budget ended it.
//! `worst_do_step_of_every_shipped_scene` (ignored: a benchmark, run it with `--ignored
//! --nocapture`) measures each scene's doStep(0, 1e6); no test asserts a time.

use crate::common;
use common::vr;
use fmu_beam::integrator::{work_units, IterationMatrix, LinearSolver, DEFAULT_STEP_BUDGET};
use fmu_beam::mechanics::{Equations, Mechanics};
use fmu_beam::{Engine, EngineError, Scene};
use std::time::Instant;

fn shipped_scenes() -> Vec<Scene> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 29);
    files.iter().map(|p| Scene::load(p).unwrap()).collect()
}

/// The number of unknowns (n + m) of the scene's system and the work units of a factorization
/// of its iteration matrix.
fn unknowns(s: &Scene) -> (u64, u64) {
    let sys = Mechanics::build(s, &fmu_beam::resolve_effects(s).effects);
    let entries = IterationMatrix::new(&sys, LinearSolver::Auto).factorization_units();
    ((sys.n() + sys.m()) as u64, entries)
}

/// Every doStep of every shipped scene's DefaultExperiment does less than a fiftieth of the
/// default budget's work (the largest, rollup_3d's with 64 substructures, 4.9e5 units of 3e7:
/// a step cut short there factorizes its matrix of 1 280 unknowns several times).
#[test]
fn every_default_experiment_steps_far_within_the_budget() {
    let mut worst = (String::new(), 0u64);
    for s in shipped_scenes() {
        let (size, entries) = unknowns(&s);
        let (h, stop) = (s.experiment.step_size, s.experiment.stop_time);
        let mut e = Engine::new(s.clone());
        e.exit_initialization().unwrap();
        let count = |e: &mut Engine| {
            let n = |e: &mut Engine, name: &str| e.get_integer(vr(e, name)).unwrap() as u64;
            (n(e, "solver.newton_iterations"), n(e, "solver.jacobians"))
        };
        let mut before = count(&mut e);
        for k in 0..(stop / h).round() as usize {
            match e.do_step(k as f64 * h, h) {
                Ok(()) => {}
                // the single frame spun past its range ends by design (docs/effects.md)
                Err(err) if err.ends_run() => break,
                Err(err) => panic!("{} at step {k}: {err}", s.name),
            }
            let after = count(&mut e);
            let work = work_units(after.0 - before.0, after.1 - before.1, size, entries);
            if work > worst.1 {
                worst = (s.name.clone(), work);
            }
            before = after;
        }
    }
    eprintln!("the largest doStep of a DefaultExperiment: {worst:?}");
    assert!(worst.1 < DEFAULT_STEP_BUDGET / 50, "{worst:?}");
}

/// doStep(0, 1e6) ends in the work budget, a Discard that says so, with the last good state
/// kept.
#[test]
fn a_do_step_of_a_million_seconds_ends_in_the_work_budget() {
    let mut e = Engine::new(common::scene("flexible_pendulum.toml"));
    e.exit_initialization().unwrap();
    let err = e.do_step(0.0, 1e6).unwrap_err();
    match err.cause() {
        EngineError::WorkBudget { work, budget, .. } => {
            assert_eq!(*budget, DEFAULT_STEP_BUDGET);
            assert!(work >= budget, "{err}");
        }
        _ => panic!("not the budget: {err}"),
    }
    assert!(err.is_discard() && !err.ends_run());
    let text = err.to_string();
    assert!(
        text.contains("work budget") && text.contains("solver.step_budget = 30000000"),
        "{text}"
    );
    assert_eq!(e.time(), 0.0);
}

/// The benchmark of the worst doStep: doStep(0, 1e6) on every shipped scene, its time and how
/// it ended (a line per scene).
#[test]
#[ignore]
fn worst_do_step_of_every_shipped_scene() {
    let mut worst = 0.0f64;
    for s in shipped_scenes() {
        let (size, entries) = unknowns(&s);
        let mut e = Engine::new(s.clone());
        e.exit_initialization().unwrap();
        let started = Instant::now();
        let result = e.do_step(0.0, 1e6);
        let took = started.elapsed().as_secs_f64();
        worst = worst.max(took);
        let how = match &result {
            Ok(()) => "fmi2OK".to_string(),
            Err(err) => match err.cause() {
                EngineError::WorkBudget {
                    work, attempts, t, ..
                } => format!("work budget: {work} units, {attempts} steps, t = {t:.4} s"),
                other => other.to_string().chars().take(90).collect::<String>(),
            },
        };
        println!(
            "{:34} {size:4} unknowns {entries:7} per LU {took:7.2} s  {how}",
            s.name
        );
    }
    println!("worst: {worst:.2} s");
}

/// The budget a master may set is bounded too: ten times the default (about a minute of work
/// at most). The largest fmi2Integer was accepted, and the fuzz stage found a doStep of the
/// pendulum that then ran 151 s.
#[test]
fn the_largest_budget_is_ten_times_the_default() {
    let mut e = Engine::new(common::scene("flexible_pendulum.toml"));
    let budget = vr(&e, "solver.step_budget");
    let err = e.set_integer(budget, i32::MAX).unwrap_err().to_string();
    assert!(err.contains("[1, 300000000]"), "{err}");
    e.set_integer(budget, 300_000_000).unwrap();
    assert_eq!(10 * DEFAULT_STEP_BUDGET, 300_000_000);
}
