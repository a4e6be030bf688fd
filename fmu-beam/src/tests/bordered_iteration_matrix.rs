//! The iteration matrix of one floating frame of many elements on the bordered banded LU
//! (`integrator/bordered_band.rs`) against the dense LU: `LinearSolver::Auto` takes it for 32
//! elements and not for 4, it solves what the dense matrices of `Equations` give, a run ends at
//! the same tip height with the same Newton iterations as the dense path, and a band without
//! pivots goes to the dense LU.

use super::common::scene;
use super::sparse_iteration_matrix::{built, dense_matrix};
use crate::integrator::{iteration_scaling, IterationMatrix, LinearSolver, Stats, Stepper};
use crate::mechanics::multibody::Equations;
use crate::mechanics::Mechanics;
use crate::Scene;
use nalgebra::DVector;

/// C2's pendulum as one frame of `elements` at a fixed step of 1e-3 s.
fn one_frame(elements: usize) -> Scene {
    let mut s = scene("flexible_pendulum.toml");
    s.beams[0].elements = Some(elements);
    s.solver.adaptive = false;
    s.solver.max_step = 1e-3;
    s.solver.tolerance = 1e-8;
    Scene::from_toml_str(&s.to_toml_string(), "flexible_pendulum.toml").expect("valid")
}

/// The tip's height (m) at coordinates q.
fn tip_height(sys: &Mechanics, q: &DVector<f64>) -> f64 {
    let Mechanics::Planar(p) = sys else {
        panic!("a planar scene")
    };
    let beam = p.beam(0).expect("body 0 is the beam");
    beam.point(&beam.flange_b, p.body_coords(0, q)).0.y
}

#[test]
fn auto_takes_the_bordered_band_for_a_long_frame_only() {
    let (sys, _, _) = built(&one_frame(4));
    assert!(!IterationMatrix::new(&sys, LinearSolver::Auto).is_bordered());
    let (sys, _, _) = built(&one_frame(32));
    let blocks = sys.block_diagonal();
    for b in &blocks.blocks {
        if let crate::mechanics::multibody::Block::Band(a) = b {
            println!(
                "band block n {} head {} width {}",
                a.n(),
                a.head(),
                a.width()
            );
        }
    }
    println!("n {} m {}", sys.n(), sys.m());
    assert!(IterationMatrix::new(&sys, LinearSolver::Auto).is_bordered());
    assert!(!IterationMatrix::new(&sys, LinearSolver::Dense).is_bordered());
    assert!(!IterationMatrix::new(&sys, LinearSolver::Sparse).is_bordered());
}

#[test]
fn the_bordered_band_solves_what_the_dense_matrices_give() {
    let (sys, st, settings) = built(&one_frame(32));
    let (n, m) = (sys.n(), sys.m());
    let a = dense_matrix(&sys, &st, settings.max_step, settings.rho_inf);
    let w = iteration_scaling(settings.rho_inf, settings.max_step);
    let b = DVector::from_fn(n + m, |i, _| (i as f64 * 0.7).sin() + 0.1);
    let expected = a.clone().lu().solve(&b).expect("regular");
    let mut matrix = IterationMatrix::new(&sys, LinearSolver::Auto);
    assert!(matrix.factorize(&sys, &st.point(), w));
    assert_eq!(matrix.fallbacks(), 0);
    let mut x = b.clone();
    assert!(matrix.solve_mut(&mut x));
    let diff = (&x - &expected).amax() / expected.amax();
    assert!(
        diff < 1e-10,
        "relative difference to the dense LU {diff:.1e}"
    );
}

#[test]
fn a_32_element_frame_runs_to_the_same_tip_height_under_auto_and_dense() {
    let s = one_frame(32);
    let (sys, st0, settings) = built(&s);
    let mut ends = Vec::new();
    for linear in [LinearSolver::Auto, LinearSolver::Dense] {
        let mut st = st0.clone();
        let mut stepper = Stepper::with_linear_solver(&sys, settings, linear);
        let mut stats = Stats::default();
        stepper
            .step_to(&sys, &mut st, &mut stats, 0.1)
            .expect("steps");
        ends.push((tip_height(&sys, &st.q), stats));
    }
    let (auto, dense) = (&ends[0], &ends[1]);
    let diff = (auto.0 - dense.0).abs() / dense.0.abs();
    println!(
        "tip height {:.12} (Auto) / {:.12} (Dense), relative {diff:.1e}; Newton {} / {}",
        auto.0, dense.0, auto.1.newton_iterations, dense.1.newton_iterations
    );
    assert!(diff < 1e-9, "{diff:e}");
    assert_eq!(auto.1.steps, dense.1.steps);
    assert_eq!(auto.1.newton_iterations, dense.1.newton_iterations);
}

#[test]
fn a_band_without_pivots_falls_back_to_the_dense_lu() {
    // C_t alone at rest, without damping: the band is zero, the bordered LU refuses it and the
    // dense LU, not a wrong solution, says the matrix is singular
    let (sys, st, _) = built(&one_frame(32));
    let mut matrix = IterationMatrix::new(&sys, LinearSolver::Auto);
    let at = st.point();
    let rest = DVector::zeros(sys.n());
    let at = crate::mechanics::multibody::Point { v: &rest, ..at };
    let w = crate::integrator::Scaling {
        d: 0.0,
        cm: 0.0,
        cc: 1.0,
    };
    assert!(!matrix.factorize(&sys, &at, w));
    assert_eq!(matrix.fallbacks(), 1);
    assert!(matches!(
        matrix.refusal(),
        Some(crate::integrator::bordered_band::Refusal::TinyPivot { .. })
    ));
    assert!(!matrix.solve_mut(&mut DVector::zeros(sys.n() + sys.m())));
    // a regular matrix again: the bordered LU takes it back
    let w = iteration_scaling(1.0, 1e-3);
    assert!(matrix.factorize(&sys, &st.point(), w));
    assert_eq!((matrix.fallbacks(), matrix.refusal()), (1, None));
}
