//! The iteration matrix factorized sparse (faer's LU) against dense (nalgebra's): the assembly
//! from body blocks and constraint rows solves the system that the dense matrices of
//! `Equations` give, on a planar chain and on a 3D one; runs on either path agree to rounding;
//! `LinearSolver::Auto` follows its rule; a model on the sparse path restores its FMU state
//! bit for bit; the matrix of a planar system turned as a whole is the turned matrix, which
//! lets a spinning chain keep its factors; and the error estimate's filter through the matrix
//! weighs each mode as the step resolves it.

use super::common::{scene, vr};
use crate::integrator::iteration_matrix::{prefers_sparse, SPARSE_MIN_SIZE};
use crate::integrator::{
    initial_state, iteration_scaling, GaState, IterationMatrix, LinearSolver, Settings, Stats,
    Stepper,
};
use crate::mechanics::multibody::{Equations, Turning};
use crate::mechanics::Mechanics;
use crate::unit::effects::resolve;
use crate::{Engine, Scene};
use nalgebra::{DMatrix, DVector};

/// `file` with its first beam in `k` substructures (of its own elements each), at a fixed step.
fn substructured(file: &str, k: usize, step: f64) -> Scene {
    let mut s = scene(file);
    s.beams[0].substructures = Some(k);
    s.solver.adaptive = false;
    s.solver.max_step = step;
    s.solver.tolerance = 1e-10;
    Scene::from_toml_str(&s.to_toml_string(), file).expect("valid")
}

/// The system of `s`, its consistent initial state and its integrator settings.
pub(super) fn built(s: &Scene) -> (Mechanics, GaState, Settings) {
    let sys = Mechanics::build(s, &resolve(s).effects);
    let settings = Settings::from_scene(s);
    let st = initial_state(&sys, 0.0, &settings).expect("assembles");
    (sys, st, settings)
}

/// [[d K_t + c_m M + c_c C_t, Gᵀ], [G, 0]] from the dense methods of `Equations`.
pub(super) fn dense_matrix(sys: &Mechanics, st: &GaState, h: f64, rho_inf: f64) -> DMatrix<f64> {
    let (n, m) = (sys.n(), sys.m());
    let (mut mm, mut kt, mut ct) = (
        DMatrix::zeros(n, n),
        DMatrix::zeros(n, n),
        DMatrix::zeros(n, n),
    );
    let mut g = DMatrix::zeros(m, n);
    sys.mass_matrix(&st.q, &mut mm);
    sys.tangents(&st.point(), &mut kt, &mut ct);
    sys.constraint_jacobian(&st.q, st.t, &mut g);
    let w = iteration_scaling(rho_inf, h);
    let mut a = DMatrix::zeros(n + m, n + m);
    a.view_mut((0, 0), (n, n))
        .copy_from(&(kt * w.d + mm * w.cm + ct * w.cc));
    a.view_mut((0, n), (n, m)).copy_from(&g.transpose());
    a.view_mut((n, 0), (m, n)).copy_from(&g);
    a
}

/// Both factorizations of the assembled matrix solve what the dense matrices give.
fn solves_like_the_dense_matrices(s: &Scene) {
    let (sys, st, settings) = built(s);
    let a = dense_matrix(&sys, &st, settings.max_step, settings.rho_inf);
    let dim = a.nrows();
    let b = DVector::from_fn(dim, |i, _| (i as f64 * 0.7).sin() + 0.1);
    let w = iteration_scaling(settings.rho_inf, settings.max_step);
    for linear in [LinearSolver::Dense, LinearSolver::Sparse] {
        let mut matrix = IterationMatrix::new(&sys, linear);
        assert_eq!(matrix.is_sparse(), linear == LinearSolver::Sparse);
        assert!(matrix.factorize(&sys, &st.point(), w));
        let mut x = b.clone();
        assert!(matrix.solve_mut(&mut x));
        let residual = (&a * &x - &b).amax() / b.amax();
        println!(
            "{}: n + m = {dim}, {linear:?}: nnz {}, |A x - b| / |b| = {residual:.1e}",
            s.name,
            matrix.nnz()
        );
        assert!(residual < 1e-10, "{linear:?}: {residual:e}");
    }
}

#[test]
fn both_factorizations_solve_the_assembled_planar_and_spatial_chains() {
    solves_like_the_dense_matrices(&substructured(
        "flexible_pendulum_substructured.toml",
        8,
        1e-3,
    ));
    solves_like_the_dense_matrices(&substructured("spin_up_omega10.toml", 6, 1e-2));
    solves_like_the_dense_matrices(&substructured("rollup_3d.toml", 4, 1e-3));
}

/// Final coordinates of a fixed-step run on each path.
fn runs_agree(s: &Scene, stop: f64) {
    let (sys, st0, settings) = built(s);
    let mut ends = Vec::new();
    for linear in [LinearSolver::Dense, LinearSolver::Sparse] {
        let mut st = st0.clone();
        let mut stepper = Stepper::with_linear_solver(&sys, settings, linear);
        let mut stats = Stats::default();
        stepper
            .step_to(&sys, &mut st, &mut stats, stop)
            .expect("steps");
        assert_eq!(stepper.is_sparse(), linear == LinearSolver::Sparse);
        ends.push((st.q, stats));
    }
    let diff = (&ends[0].0 - &ends[1].0).amax();
    println!(
        "{}: {} steps, dense {} / sparse {} Newton iterations, max |Δq| = {diff:.1e}",
        s.name, ends[0].1.steps, ends[0].1.newton_iterations, ends[1].1.newton_iterations
    );
    assert_eq!(ends[0].1.steps, ends[1].1.steps);
    assert!(diff < 1e-10 * ends[0].0.amax().max(1.0), "{diff:e}");
}

#[test]
fn dense_and_sparse_runs_agree_to_rounding() {
    runs_agree(
        &substructured("flexible_pendulum_substructured.toml", 12, 1e-3),
        0.1,
    );
    runs_agree(&substructured("rollup_3d.toml", 5, 1e-3), 0.02);
}

#[test]
fn auto_is_dense_for_small_systems_and_one_dominant_body_and_sparse_for_long_chains() {
    let size = |s: &Scene| {
        let sys = Mechanics::build(s, &resolve(s).effects);
        let largest = sys.body_ranges().iter().map(|r| r.len()).max().unwrap();
        let auto = IterationMatrix::new(&sys, LinearSolver::Auto).is_sparse();
        (sys.n() + sys.m(), largest, auto)
    };
    let (n, _, auto) = size(&scene("flexible_pendulum.toml"));
    assert!(
        !auto && n < SPARSE_MIN_SIZE,
        "one frame of 10 elements: {n}"
    );
    let mut c1 = scene("cantilever_free_vibration.toml");
    c1.beams[0].elements = Some(60);
    let (n, l, auto) = size(&c1);
    assert!(
        !auto && n >= SPARSE_MIN_SIZE,
        "one beam of 60 elements: {n}, block {l}"
    );
    let (n, l, auto) = size(&substructured("spin_up_omega10.toml", 40, 1e-2));
    assert!(
        auto && prefers_sparse(n, l),
        "C4 with 40 substructures: {n}"
    );
}

/// FMU state of a model on the sparse path (C2 with 20 substructures): a snapshot taken
/// mid-run, restored or deserialized, continues bit for bit (the factors are not in the
/// state: they are computed again at the stored point).
#[test]
fn a_sparse_model_restores_its_state_bit_for_bit() {
    let mut s = scene("flexible_pendulum_substructured.toml");
    s.beams[0].substructures = Some(20);
    let s = Scene::from_toml_str(&s.to_toml_string(), "c2_k20.toml").unwrap();
    let sys = Mechanics::build(&s, &resolve(&s).effects);
    assert!(IterationMatrix::new(&sys, LinearSolver::Auto).is_sparse());
    let mut e = Engine::new(s);
    let angle = vr(&e, "hinge.angle");
    e.exit_initialization().unwrap();
    for k in 0..10 {
        e.do_step(k as f64 * 0.01, 0.01).unwrap();
    }
    let snap = e.snapshot();
    let bytes = e.serialize(&snap);
    let run = |e: &mut Engine| -> Vec<u64> {
        (10..25)
            .map(|k| {
                e.do_step(k as f64 * 0.01, 0.01).unwrap();
                e.get_real(angle).unwrap().to_bits()
            })
            .collect()
    };
    let first = run(&mut e);
    e.restore(&snap).unwrap();
    assert_eq!(run(&mut e), first);
    let back = e.deserialize(&bytes).unwrap();
    e.restore(&back).unwrap();
    assert_eq!(run(&mut e), first);
}

/// `st` with every body turned by δ about the world origin: positions, velocities and
/// accelerations of the body frames and the joints' world-vector multipliers turn, the angles
/// grow by δ, the elastic coordinates stay.
fn turned(turning: &Turning, n: usize, st: &GaState, delta: f64) -> GaState {
    let mut out = st.clone();
    let (s, c) = delta.sin_cos();
    let turn = |x: &mut DVector<f64>, i: usize| {
        let (a, b) = (x[i], x[i + 1]);
        x[i] = c * a - s * b;
        x[i + 1] = s * a + c * b;
    };
    for &p in &turning.pairs {
        if p < n {
            for x in [&mut out.q, &mut out.v, &mut out.qdd, &mut out.acc] {
                turn(x, p);
            }
        } else {
            turn(&mut out.lambda, p - n);
        }
    }
    for &k in &turning.angles {
        out.q[k] += delta;
    }
    out
}

/// The matrix R that turns the unknowns' (x, y) pairs by δ.
fn turn_matrix(turning: &Turning, dim: usize, delta: f64) -> DMatrix<f64> {
    let mut r = DMatrix::identity(dim, dim);
    let (s, c) = delta.sin_cos();
    for &p in &turning.pairs {
        r[(p, p)] = c;
        r[(p, p + 1)] = -s;
        r[(p + 1, p)] = s;
        r[(p + 1, p + 1)] = c;
    }
    r
}

/// The planar equations are invariant to turning the whole system (without gravity, whose
/// tangent is fixed in the world): the iteration matrix at the turned state is R S Rᵀ, to
/// rounding, for a spinning chain of substructures (a hub drive, welds) and for a rotor of a
/// rigid hub and a flexible blade on revolute joints; so Newton may use S's factors there
/// (`Stepper::solve_turned`).
#[test]
fn the_iteration_matrix_of_a_turned_system_is_the_turned_matrix() {
    for (file, k, stop) in [
        ("spin_up_omega10.toml", Some(6), 8.0),
        ("hinged_blade.toml", None, 0.5),
    ] {
        let mut s = scene(file);
        if let Some(k) = k {
            s.beams[0].substructures = Some(k);
        }
        s.world.gravity = [0.0; 3];
        let s = Scene::from_toml_str(&s.to_toml_string(), file).expect("valid");
        let (sys, mut st, settings) = built(&s);
        // a state that moves, deforms and carries reactions
        let mut stepper = Stepper::new(&sys, settings);
        stepper
            .step_to(&sys, &mut st, &mut Stats::default(), stop)
            .expect("steps");
        let turning = sys.turning().expect("planar");
        let (n, dim) = (sys.n(), sys.n() + sys.m());
        let h = 1e-3;
        let a = dense_matrix(&sys, &st, h, settings.rho_inf);
        for delta in [0.3, -2.0] {
            let at = dense_matrix(&sys, &turned(&turning, n, &st, delta), h, settings.rho_inf);
            let r = turn_matrix(&turning, dim, delta);
            let diff = (&at - &r * &a * r.transpose()).amax() / a.amax();
            println!("{file}: δ = {delta}: |S(turned) - R S Rᵀ| / |S| = {diff:.1e}");
            assert!(diff < 1e-12, "{file}, δ = {delta}: {diff:e}");
        }
    }
}

/// What the turned factors save: a chain spinning up keeps one iteration matrix for most of
/// its run (C4 at Ω = 10 with 10 substructures, 5e-3 s: 946 matrices for 4000 steps before
/// the factors were turned, 49 after).
#[test]
fn a_spinning_chain_keeps_its_iteration_matrix() {
    let s = substructured("spin_up_omega10.toml", 10, 5e-3);
    let (sys, mut st, mut settings) = built(&s);
    settings.tolerance = 1e-6;
    let mut stepper = Stepper::new(&sys, settings);
    let mut stats = Stats::default();
    stepper
        .step_to(&sys, &mut st, &mut stats, 20.0)
        .expect("steps");
    println!(
        "{} steps, {} Newton iterations, {} iteration matrices",
        stats.steps, stats.newton_iterations, stats.jacobians
    );
    assert_eq!(stats.steps, 4000);
    assert!(stats.jacobians * 40 < stats.steps, "{stats:?}");
}

/// The filter of the error estimate (`IterationMatrix::filter`, issue 12 item 5) on the
/// substructured pendulum at rest: each mode φ of the linearized system (K φ = ω² M φ on the
/// motions the joints leave free, K the matrix's own tangent) comes out as φ c_m / (c_m + d ω²),
/// the swing (ω = 0) whole and the highest modes nearly gone; and what crosses the joints (a
/// vector Gᵀ z) keeps its part across them, G x = G e. Dense and sparse alike.
#[test]
fn the_error_filter_weighs_each_mode_as_the_step_resolves_it() {
    let mut s = scene("flexible_pendulum_substructured.toml");
    s.beams[0].substructures = Some(20);
    let s = Scene::from_toml_str(&s.to_toml_string(), "c2_k20.toml").unwrap();
    let (sys, st, _) = built(&s);
    let (n, m) = (sys.n(), sys.m());
    let (h, rho_inf) = (1e-3, 0.7);
    let w = iteration_scaling(rho_inf, h);
    let a = dense_matrix(&sys, &st, h, rho_inf);
    let mut mm = DMatrix::zeros(n, n);
    sys.mass_matrix(&st.q, &mut mm);
    // the matrix's stiffness (its tangents at rest, no velocities) and G
    let k = (a.view((0, 0), (n, n)) - &mm * w.cm) / w.d;
    let g = a.view((n, 0), (m, n)).into_owned();
    // modes on the null space of G: K φ = ω² M φ there
    let mut square = DMatrix::zeros(n, n);
    square.view_mut((0, 0), (m, n)).copy_from(&g);
    let svd = square.svd(false, true);
    let vt = svd.v_t.expect("v_t");
    let smax = svd.singular_values.amax();
    let free: Vec<_> = (0..n)
        .filter(|&i| svd.singular_values[i] <= 1e-10 * smax)
        .map(|i| vt.row(i).transpose())
        .collect();
    let rank = n - free.len();
    let basis = DMatrix::from_columns(&free);
    let (mr, kr) = (
        basis.transpose() * &mm * &basis,
        basis.transpose() * &k * &basis,
    );
    let l = ((&mr + mr.transpose()) * 0.5)
        .cholesky()
        .expect("M > 0")
        .l();
    let li = l.try_inverse().expect("regular");
    let red = &li * ((&kr + kr.transpose()) * 0.5) * li.transpose();
    let eig = ((&red + red.transpose()) * 0.5).symmetric_eigen();
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    // the swing, the first bending mode, the modes nearest ωh = 1 and 3, the highest
    let nearest = |x: f64| {
        *order
            .iter()
            .min_by(|&&i, &&j| {
                let d = |k: usize| (eig.eigenvalues[k].max(0.0).sqrt() * h - x).abs();
                d(i).total_cmp(&d(j))
            })
            .expect("modes")
    };
    let picks = [
        order[0],
        order[1],
        nearest(1.0),
        nearest(3.0),
        order[order.len() - 1],
    ];
    for linear in [LinearSolver::Dense, LinearSolver::Sparse] {
        let mut matrix = IterationMatrix::new(&sys, linear);
        assert!(matrix.factorize(&sys, &st.point(), w));
        let mut rhs = DVector::zeros(n + m);
        for &i in &picks {
            let omega = eig.eigenvalues[i].max(0.0).sqrt();
            let phi = &basis * (li.transpose() * eig.eigenvectors.column(i));
            let pass = w.cm / (w.cm + w.d * omega * omega);
            let mut e = phi.clone();
            assert!(matrix.filter(&mut e, &mut rhs));
            let off = (&e - &phi * pass).amax() / phi.amax();
            println!(
                "{linear:?}: ωh = {:.3e}, passes {pass:.3e}, off by {off:.1e}",
                omega * h
            );
            // the eigenvectors' own accuracy, ω² spanning ten decades: 1.4e-8 on the swing
            assert!(off < 1e-6, "{linear:?}, ωh = {}: {off:e}", omega * h);
        }
        // across the joints: G x = G e
        let z = DVector::from_fn(m, |i, _| (i as f64 * 1.3).cos());
        let mut e = g.transpose() * &z;
        let ge = &g * &e;
        assert!(matrix.filter(&mut e, &mut rhs));
        let off = (&g * &e - &ge).amax() / ge.amax();
        assert!(off < 1e-10, "{linear:?}: G x − G e = {off:e}");
    }
    println!("n = {n}, m = {m}, free motions {}", n - rank);
}
