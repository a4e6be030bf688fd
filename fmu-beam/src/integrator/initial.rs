//! Consistent initial conditions: assemble the mechanism (g(q) = 0), then solve for the
//! accelerations and multipliers that the equations of motion give at rest.

use super::iteration_matrix::{IterationMatrix, LinearSolver, Scaling};
use super::{GaState, Settings};
use crate::error::EngineError;
use crate::multibody::Equations;
use crate::scene::Scene;
use nalgebra::{DMatrix, DVector};

const ASSEMBLY_ITERATIONS: usize = 50;

/// Builds the state at `t0` from the scene's initial configuration.
pub fn initial_state<S: Equations + ?Sized>(
    sys: &S,
    scene: &Scene,
    t0: f64,
    settings: &Settings,
) -> Result<GaState, EngineError> {
    let (n, m) = (sys.n(), sys.m());
    let mut q = sys.initial_coordinates(scene)?;
    let v = DVector::zeros(n);
    let tol = 1e-12 * sys.length_scale().max(1.0);
    let mut g = DVector::zeros(m);
    let mut gm = DMatrix::zeros(m, n);
    if m > 0 {
        sys.constraint_jacobian(&q, t0, &mut gm);
        check_rank(sys, &gm, t0)?;
        let frames = sys.frame_coordinates();
        let mut iterations = 0;
        let mut last_residual = f64::INFINITY;
        loop {
            sys.constraints(&q, t0, &mut g);
            let residual = g.amax();
            if residual <= tol {
                break;
            }
            if iterations >= ASSEMBLY_ITERATIONS || !residual.is_finite() {
                let rows: Vec<usize> = (0..m).filter(|&i| g[i].abs() > tol).collect();
                return Err(EngineError::Assembly {
                    t: t0,
                    residual,
                    joints: sys.joints_of_rows(&rows).join(", "),
                    tolerance: tol,
                    iterations,
                });
            }
            sys.constraint_jacobian(&q, t0, &mut gm);
            // Gauss–Newton on the frame coordinates only: assembling a mechanism places its
            // bodies, it must not deform a beam to close a loop. Least squares (SVD), because a
            // beam held at both ends over-determines its frame.
            let gr = DMatrix::from_fn(m, frames.len(), |i, j| gm[(i, frames[j])]);
            let dr = gr
                .svd(true, true)
                .solve(&g, 1e-12)
                .map_err(|_| EngineError::Assembly {
                    t: t0,
                    residual,
                    joints: sys.joints_of_rows(&(0..m).collect::<Vec<_>>()).join(", "),
                    tolerance: tol,
                    iterations,
                })?;
            for (j, &k) in frames.iter().enumerate() {
                q[k] -= dr[j];
            }
            if (iterations > 5 && residual > 0.5 * last_residual)
                || !dr.iter().all(|x| x.is_finite())
            {
                // not converging: no placement of the bodies satisfies the joints
                iterations = ASSEMBLY_ITERATIONS;
                continue;
            }
            last_residual = residual;
            iterations += 1;
        }
    }
    let (qdd, lambda) = consistent_accelerations(sys, &q, &v, t0)?;
    let h = if settings.adaptive {
        settings.max_step.min(1e-3)
    } else {
        settings.max_step
    };
    Ok(GaState {
        t: t0,
        h,
        acc: qdd.clone(),
        qdd,
        lambda,
        q,
        v,
        work: 0.0,
    })
}

/// Refuses redundant joints: G must have full row rank.
fn check_rank<S: Equations + ?Sized>(
    sys: &S,
    gm: &DMatrix<f64>,
    t: f64,
) -> Result<(), EngineError> {
    let m = gm.nrows();
    let svd = gm.transpose().svd(false, true);
    let smax = svd.singular_values.amax();
    let weak: Vec<usize> = match &svd.v_t {
        Some(vt) => (0..m)
            .filter(|&k| svd.singular_values[k] <= 1e-10 * smax.max(1e-300))
            .flat_map(|k| {
                let row = vt.row(k).into_owned();
                (0..m).filter(move |&i| row[i].abs() > 1e-6)
            })
            .collect(),
        None => Vec::new(),
    };
    if weak.is_empty() {
        return Ok(());
    }
    Err(EngineError::InitialState {
        message: format!(
            "redundant constraints at t = {t} s: joint(s) {} fix the same motion twice; \
             remove one or free a direction",
            sys.joints_of_rows(&weak).join(", ")
        ),
    })
}

/// Solves [[M, Gᵀ], [G, 0]] [q''; λ] = [-r(q, q', 0); -bias], dense or sparse by the system's
/// size ([`LinearSolver::Auto`]).
pub fn consistent_accelerations<S: Equations + ?Sized>(
    sys: &S,
    q: &DVector<f64>,
    v: &DVector<f64>,
    t: f64,
) -> Result<(DVector<f64>, DVector<f64>), EngineError> {
    let (n, m) = (sys.n(), sys.m());
    let mut r = DVector::zeros(n);
    sys.body_residual(q, v, &DVector::zeros(n), t, &mut r);
    let mut bias = DVector::zeros(m);
    sys.accel_bias(q, v, t, &mut bias);
    let mut x = DVector::zeros(n + m);
    x.rows_mut(0, n).copy_from(&(-r));
    x.rows_mut(n, m).copy_from(&(-bias));
    let mut matrix = IterationMatrix::new(sys, LinearSolver::Auto);
    let w = Scaling {
        d: 0.0,
        cm: 1.0,
        cc: 0.0,
    };
    let (zero_n, zero_m) = (DVector::zeros(n), DVector::zeros(m));
    let solved = matrix.factorize(sys, q, v, &zero_n, &zero_m, t, w)
        && matrix.solve_mut(&mut x)
        && x.iter().all(|v| v.is_finite());
    if !solved {
        return Err(EngineError::InitialState {
            message: format!(
                "the mass matrix is singular at t = {t} s on motions the joints leave free \
                 (a body without mass or inertia that nothing holds)"
            ),
        });
    }
    Ok((x.rows(0, n).into_owned(), x.rows(n, m).into_owned()))
}
