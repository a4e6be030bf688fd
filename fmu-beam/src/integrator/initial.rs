//! Consistent initial conditions: assemble the mechanism (g(q) = 0), then solve for the
//! accelerations and multipliers that the equations of motion give at rest.

use super::iteration_matrix::{IterationMatrix, LinearSolver, Scaling};
use super::{GaState, Settings};
use crate::error::EngineError;
use crate::mechanics::multibody::{Equations, Point};
use nalgebra::{DMatrix, DVector};

const ASSEMBLY_ITERATIONS: usize = 50;

/// Builds the state at `t0` from the system's initial configuration, at rest.
pub fn initial_state<S: Equations + ?Sized>(
    sys: &S,
    t0: f64,
    settings: &Settings,
) -> Result<GaState, EngineError> {
    let q = sys.initial_coordinates()?;
    initial_state_from(sys, t0, settings, q, DVector::zeros(sys.n()))
}

/// Builds the state at `t0` from coordinates `q` (assembled here if they do not meet the joints
/// yet) and velocities `v` (which must meet them: [`super::given_start`]).
pub fn initial_state_from<S: Equations + ?Sized>(
    sys: &S,
    t0: f64,
    settings: &Settings,
    mut q: DVector<f64>,
    v: DVector<f64>,
) -> Result<GaState, EngineError> {
    let (n, m) = (sys.n(), sys.m());
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
    let h = if settings.adaptive {
        settings.max_step.min(1e-3)
    } else {
        settings.max_step
    };
    // the scene's loads and motions start at t0: a jump from none, met as the first step meets it
    let w = super::generalized_alpha::jump_scaling(settings.rho_inf, h);
    let (qdd, lambda) = consistent_accelerations(sys, &q, &v, t0, w)?;
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
    check_rows_rank(sys, gm, &(0..gm.nrows()).collect::<Vec<_>>(), t)
}

/// Refuses redundant rows: `gm` (the system's rows `rows`) must have full row rank.
pub(super) fn check_rows_rank<S: Equations + ?Sized>(
    sys: &S,
    gm: &DMatrix<f64>,
    rows: &[usize],
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
            sys.joints_of_rows(&weak.iter().map(|&i| rows[i]).collect::<Vec<_>>())
                .join(", ")
        ),
    })
}

/// Solves [[S, Gᵀ], [G, 0]] [q''; c_m λ] = [-c_m r(q, q', 0); -bias] with S = c_m M + c_c C +
/// d K as `w` says: the mass matrix alone (the accelerations the equations give) or the
/// iteration matrix of the first step ([`meet_jump`] says why); dense or sparse by the system's
/// size ([`LinearSolver::Auto`]).
pub fn consistent_accelerations<S: Equations + ?Sized>(
    sys: &S,
    q: &DVector<f64>,
    v: &DVector<f64>,
    t: f64,
    w: Scaling,
) -> Result<(DVector<f64>, DVector<f64>), EngineError> {
    let (n, m) = (sys.n(), sys.m());
    let mut r = DVector::zeros(n);
    sys.body_residual(q, v, &DVector::zeros(n), t, &mut r);
    let mut bias = DVector::zeros(m);
    sys.accel_bias(q, v, t, &mut bias);
    let mut x = DVector::zeros(n + m);
    x.rows_mut(0, n).copy_from(&(-w.cm * r));
    x.rows_mut(n, m).copy_from(&(-bias));
    let mut matrix = IterationMatrix::new(sys, LinearSolver::Auto);
    let (zero_n, zero_m) = (DVector::zeros(n), DVector::zeros(m));
    let at = Point {
        q,
        v,
        a: &zero_n,
        lambda: &zero_m,
        t,
    };
    let solved = matrix.factorize(sys, &at, w)
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
    Ok((x.rows(0, n).into_owned(), x.rows(n, m) / w.cm))
}

/// What a jump of the applied forces or motions changes at a state: the bodies' residual
/// r(q, q', q'', t) (without the reactions) and the constraints' acceleration bias.
#[derive(Debug, Clone)]
pub struct Equated {
    r: DVector<f64>,
    bias: DVector<f64>,
}

impl Equated {
    /// The equations' values at the state's (q, q', q'') at time `t`.
    pub fn at<S: Equations + ?Sized>(sys: &S, st: &GaState, t: f64) -> Equated {
        let mut r = DVector::zeros(sys.n());
        sys.body_residual(&st.q, &st.v, &st.qdd, t, &mut r);
        let mut bias = DVector::zeros(sys.m());
        sys.accel_bias(&st.q, &st.v, t, &mut bias);
        Equated { r, bias }
    }
}

/// Meets a jump of the applied forces or motions at `st` (the equations were `before`, and are
/// those at `t_after`) before a step of about `h`: the accelerations, the algorithmic ones and
/// the multipliers change by the solution of [[S, Gᵀ], [G, 0]] [Δq''; c_m Δλ] = [−c_m Δr;
/// −Δbias], with S the iteration matrix of the step to come (`w`: c_m M + c_c C + d K), not the
/// mass matrix.
///
/// Why not the mass matrix (the consistent accelerations): a jump strikes every mode of a
/// flexible body, each with an amplitude A near its share of the static deflection, and M⁻¹
/// gives it the acceleration ω²A. Generalized-α fed h²a = (ωh)²A at ωh ≫ 1 overshoots by that
/// factor: its velocity grows to about (ωh)² A/h in the steps after (a scalar mode struck at
/// ωh = 300 peaks at 99 × its energy at ρ∞ = 0.7, 9 × at 0.9), and holds it for tens of steps
/// while ρ∞ damps it. C3's elastic crank at a fixed 4e-3 s held 13 % of the drive's work more
/// than it was given after the torque's cut-off, 58 % at 1e-2 s. Through S a mode the step
/// resolves (ωh ≪ 1) takes the same acceleration to O((ωh)²), which keeps the scheme's order,
/// and one it does not takes at most A/(c h²) (c = d/(c_m h²)): the scheme then starts inside
/// the range it damps, and no mode gains energy at any ωh or ρ∞ (scalar modes, ωh 0.1 to 1e4,
/// ρ∞ 0 to 0.99). Only the jump is solved for: what did not jump keeps its accelerations, the
/// algorithmic one's lag included.
pub fn meet_jump<S: Equations + ?Sized>(
    sys: &S,
    st: &mut GaState,
    before: &Equated,
    t_after: f64,
    h: f64,
    w: Scaling,
) -> Result<(), EngineError> {
    let (n, m) = (sys.n(), sys.m());
    let after = Equated::at(sys, st, t_after);
    let mut x = DVector::zeros(n + m);
    for i in 0..n {
        x[i] = -w.cm * (after.r[i] - before.r[i]);
    }
    for k in 0..m {
        x[n + k] = -(after.bias[k] - before.bias[k]);
    }
    let mut matrix = IterationMatrix::new(sys, LinearSolver::Auto);
    let at = Point {
        t: t_after,
        ..st.point()
    };
    let solved = matrix.factorize(sys, &at, w)
        && matrix.solve_mut(&mut x)
        && x.iter().all(|v| v.is_finite());
    if !solved {
        return Err(EngineError::SingularMatrix { t: st.t, h });
    }
    let jump = x.rows(0, n);
    st.qdd += jump;
    st.acc += jump;
    st.lambda.axpy(1.0 / w.cm, &x.rows(n, m).into_owned(), 1.0);
    Ok(())
}
