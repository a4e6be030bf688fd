//! Generalized-α for index-3 constrained mechanical systems, with Newton iterations on the
//! position correction, scaling of the iteration matrix, and local error control.
//!
//! # References
//! - J. Chung, G. M. Hulbert (1993), A time integration algorithm for structural dynamics with
//!   improved numerical dissipation: the generalized-α method. J. Appl. Mech. 60, 371–375.
//! - M. Arnold, O. Brüls (2007), Convergence of the generalized-α scheme for constrained
//!   mechanical systems. Multibody Syst. Dyn. 18, 185–202.
//! - M. Géradin, A. Cardona (2001), Flexible Multibody Dynamics, §11 (error estimate
//!   h²(β - 1/6)(a_{n+1} - a_n)).

use super::{Settings, Stats};
use crate::error::EngineError;
use crate::multibody::{CoordinateKind, Equations};
use nalgebra::{DMatrix, DVector, Dyn, LU};

/// The integration state at a step boundary.
#[derive(Debug, Clone, PartialEq)]
pub struct GaState {
    pub t: f64,
    /// Proposed size of the next internal step (adaptive mode).
    pub h: f64,
    pub q: DVector<f64>,
    pub v: DVector<f64>,
    /// Algorithmic acceleration a of the generalized-α scheme.
    pub acc: DVector<f64>,
    /// True acceleration q''.
    pub qdd: DVector<f64>,
    pub lambda: DVector<f64>,
    /// Work done by drives and loads since the start (J), trapezoidal in time.
    pub work: f64,
}

/// Coefficients of the scheme for a spectral radius at infinity ρ∞.
#[derive(Debug, Clone, Copy)]
struct Coefficients {
    alpha_m: f64,
    alpha_f: f64,
    gamma: f64,
    beta: f64,
}

impl Coefficients {
    fn new(rho_inf: f64) -> Coefficients {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        Coefficients {
            alpha_m,
            alpha_f,
            gamma,
            beta,
        }
    }
}

const MAX_NEWTON: usize = 8;
/// Absolute part of the error weights, as a fraction of the system's length (or of 1 rad):
/// a coordinate's local error must stay below tol × (|q_i| + ERROR_SCALE × scale_i).
const ERROR_SCALE: f64 = 1.0;
/// Newton stops when its correction is this fraction of the tolerance.
const NEWTON_KAPPA: f64 = 0.01;
/// Largest growth of the step size from one step to the next.
const MAX_GROWTH: f64 = 5.0;
/// A proposed growth of the step size up to this factor keeps the step size, and with it the
/// factorized iteration matrix (hysteresis).
const KEEP_STEP: f64 = 1.2;
/// Step sizes within this relative difference share an iteration matrix (equal substeps of a
/// fixed-step run differ by rounding).
const SAME_STEP: f64 = 1e-9;

/// The factor on the step size after an accepted step whose controller proposes `grow`.
fn step_factor(grow: f64) -> f64 {
    let grow = grow.clamp(0.2, MAX_GROWTH);
    if (1.0..=KEEP_STEP).contains(&grow) {
        1.0
    } else {
        grow
    }
}

/// The integrator with its workspace. The factorized iteration matrix is reused across
/// Newton iterations and internal steps of one communication step, while it converges well.
#[derive(Debug, Clone)]
pub struct Stepper {
    pub settings: Settings,
    /// Error weight scale of each coordinate (length for translations, 1 for angles).
    scale: DVector<f64>,
    /// Coordinates of massless bodies.
    algebraic: Vec<usize>,
    lu: Option<LU<f64, Dyn, Dyn>>,
    lu_h: f64,
    // workspace
    mm: DMatrix<f64>,
    kt: DMatrix<f64>,
    ct: DMatrix<f64>,
    gm: DMatrix<f64>,
    jac: DMatrix<f64>,
    r: DVector<f64>,
    g: DVector<f64>,
    rhs: DVector<f64>,
}

/// Why one attempt at a step failed.
enum Failure {
    /// Newton did not converge (with this last correction norm).
    Newton {
        iterations: usize,
        correction: f64,
        fresh: bool,
    },
    Singular,
    NonFinite,
}

impl Stepper {
    pub fn new<S: Equations + ?Sized>(sys: &S, settings: Settings) -> Stepper {
        let (n, m) = (sys.n(), sys.m());
        let mut scale = DVector::zeros(n);
        for (k, kind) in sys.coordinate_kinds().into_iter().enumerate() {
            // a body without mass has algebraic coordinates, fixed by the joints: its
            // "acceleration" carries no error information and stays out of the norm
            scale[k] = match kind {
                CoordinateKind::Algebraic => f64::INFINITY,
                CoordinateKind::Angle => 1.0,
                CoordinateKind::Length => sys.length_scale(),
            };
        }
        scale *= ERROR_SCALE;
        let algebraic = (0..n).filter(|&k| scale[k].is_infinite()).collect();
        Stepper {
            settings,
            scale,
            algebraic,
            lu: None,
            lu_h: 0.0,
            mm: DMatrix::zeros(n, n),
            kt: DMatrix::zeros(n, n),
            ct: DMatrix::zeros(n, n),
            gm: DMatrix::zeros(m, n),
            jac: DMatrix::zeros(n + m, n + m),
            r: DVector::zeros(n),
            g: DVector::zeros(m),
            rhs: DVector::zeros(n + m),
        }
    }

    /// Weighted RMS norm of a position-like vector against the tolerance.
    fn norm<'a>(&self, dq: impl Iterator<Item = &'a f64>, q: &DVector<f64>) -> f64 {
        let tol = self.settings.tolerance;
        let n = q.len().max(1) as f64;
        let s: f64 = dq
            .zip(q.iter())
            .zip(self.scale.iter())
            .map(|((d, x), sc)| {
                let w = tol * (x.abs() + sc);
                (d / w) * (d / w)
            })
            .sum();
        (s / n).sqrt()
    }

    /// Integrates `st` to exactly `t_end`, in internal steps.
    pub fn step_to<S: Equations + ?Sized>(
        &mut self,
        sys: &S,
        st: &mut GaState,
        stats: &mut Stats,
        t_end: f64,
    ) -> Result<(), EngineError> {
        // The factorization is not part of the FMU state: start each communication step afresh
        // so that a restored state continues bit for bit.
        self.lu = None;
        let set = self.settings;
        let h_min = 1e-12 * t_end.abs().max(1.0);
        let mut h_try = if set.adaptive {
            st.h.min(set.max_step)
        } else {
            set.max_step
        };
        let breakpoints = sys.breakpoints();
        while st.t < t_end {
            // land on the end of the communication step, or on a jump of a drive law before it
            let target = breakpoints
                .iter()
                .copied()
                .find(|&b| b > st.t * (1.0 + 1e-14) + 1e-14 && b <= t_end)
                .unwrap_or(t_end);
            let remaining = target - st.t;
            // a leftover of rounding (the sum of substeps falls short by an ulp) is no step
            if remaining <= 1e-12 * target.abs().max(1.0) {
                st.t = target;
                continue;
            }
            let mut h = h_try.min(set.max_step);
            if !set.adaptive {
                // equal substeps that land on t_end
                let k = (remaining / set.max_step * (1.0 - 1e-9)).ceil().max(1.0);
                h = h.min(remaining / k);
            } else if h >= remaining {
                h = remaining;
            } else if h > 0.5 * remaining {
                h = 0.5 * remaining;
            }
            let last = h >= remaining * (1.0 - 1e-9);
            if last {
                h = remaining;
            }
            let t_new = if last { target } else { st.t + h };
            if t_new <= st.t {
                // a step that rounds away would loop forever
                return Err(EngineError::StepTooSmall {
                    t: st.t,
                    h,
                    h_min,
                    tolerance: set.tolerance,
                });
            }
            match self.attempt(sys, st, stats, h, t_new) {
                Ok((new, err)) => {
                    if set.adaptive && err > 1.0 {
                        stats.rejected += 1;
                        h_try = h * (0.9 * err.powf(-1.0 / 3.0)).clamp(0.2, 1.0);
                    } else {
                        // the power at the step's start, as the limit from inside the step (a drive law
                        // that stops at t_n acts no more in (t_n, t_n+1])
                        let p0 = sys.power(&st.q, &st.v, &st.lambda, st.t + 1e-9 * h);
                        let p1 = sys.power(&new.q, &new.v, &new.lambda, t_new);
                        *st = new;
                        st.work += 0.5 * h * (p0 + p1);
                        st.t = t_new;
                        stats.steps += 1;
                        if last && breakpoints.contains(&target) {
                            restart(sys, st)?;
                        }
                        if set.adaptive {
                            let grow = if err > 0.0 {
                                0.9 * err.powf(-1.0 / 3.0)
                            } else {
                                MAX_GROWTH
                            };
                            h_try = h * step_factor(grow);
                            // keep the proposal when the step was cut short to land
                            if !last {
                                st.h = h_try;
                            }
                        }
                        continue;
                    }
                }
                Err(Failure::NonFinite) => {
                    stats.rejected += 1;
                    h_try = h * 0.25;
                    if h_try < h_min {
                        return Err(EngineError::NonFinite { t: st.t });
                    }
                }
                Err(Failure::Singular) => {
                    stats.rejected += 1;
                    h_try = h * 0.25;
                    if h_try < h_min {
                        return Err(EngineError::SingularMatrix { t: st.t, h });
                    }
                }
                Err(Failure::Newton {
                    iterations,
                    correction,
                    fresh,
                }) => {
                    if !fresh {
                        // retry once with a new iteration matrix at the same step
                        continue;
                    }
                    stats.rejected += 1;
                    h_try = h * 0.25;
                    if h_try < h_min {
                        return Err(EngineError::NewtonNotConverged {
                            t: st.t,
                            h,
                            iterations,
                            correction,
                        });
                    }
                }
            }
            if h_try < h_min {
                return Err(EngineError::StepTooSmall {
                    t: st.t,
                    h: h_try,
                    h_min,
                    tolerance: set.tolerance,
                });
            }
        }
        Ok(())
    }

    /// Builds and factorizes the scaled iteration matrix at the current iterate.
    #[allow(clippy::too_many_arguments)]
    fn factorize<S: Equations + ?Sized>(
        &mut self,
        sys: &S,
        q: &DVector<f64>,
        v: &DVector<f64>,
        qdd: &DVector<f64>,
        lambda: &DVector<f64>,
        t: f64,
        h: f64,
        c: &Coefficients,
        stats: &mut Stats,
    ) -> bool {
        let (n, m) = (sys.n(), sys.m());
        let d = c.beta * h * h;
        let beta_p = (1.0 - c.alpha_m) / (d * (1.0 - c.alpha_f));
        let gamma_p = c.gamma / (c.beta * h);
        sys.mass_matrix(q, &mut self.mm);
        sys.tangents(q, v, qdd, lambda, t, &mut self.kt, &mut self.ct);
        sys.constraint_jacobian(q, t, &mut self.gm);
        let (cm, cc) = (beta_p * d, gamma_p * d);
        for j in 0..n {
            for i in 0..n {
                self.jac[(i, j)] =
                    self.kt[(i, j)] * d + self.mm[(i, j)] * cm + self.ct[(i, j)] * cc;
            }
            for k in 0..m {
                self.jac[(n + k, j)] = self.gm[(k, j)];
                self.jac[(j, n + k)] = self.gm[(k, j)];
            }
        }
        self.jac.view_mut((n, n), (m, m)).fill(0.0);
        stats.jacobians += 1;
        let lu = self.jac.clone().lu();
        if !lu.is_invertible() {
            self.lu = None;
            return false;
        }
        self.lu = Some(lu);
        self.lu_h = h;
        true
    }

    /// One step of size h from `st`; returns the new state and the local error norm.
    fn attempt<S: Equations + ?Sized>(
        &mut self,
        sys: &S,
        st: &GaState,
        stats: &mut Stats,
        h: f64,
        t_new: f64,
    ) -> Result<(GaState, f64), Failure> {
        let c = Coefficients::new(self.settings.rho_inf);
        let (n, m) = (sys.n(), sys.m());
        let d = c.beta * h * h;
        let beta_p = (1.0 - c.alpha_m) / (d * (1.0 - c.alpha_f));
        let gamma_p = c.gamma / (c.beta * h);
        if self.lu.is_some() && (h - self.lu_h).abs() > SAME_STEP * h {
            self.lu = None;
        }
        // predictor: q''_{n+1} = q''_n
        let mut qdd = st.qdd.clone();
        let acc_new = (&st.qdd * c.alpha_f - &st.acc * c.alpha_m + &qdd * (1.0 - c.alpha_f))
            / (1.0 - c.alpha_m);
        let mut v = &st.v + &st.acc * (h * (1.0 - c.gamma)) + &acc_new * (h * c.gamma);
        let mut q = &st.q + &st.v * h + &st.acc * (h * h * (0.5 - c.beta)) + &acc_new * d;
        let mut lambda = st.lambda.clone();
        let mut fresh = false;
        let mut prev = f64::INFINITY;
        let mut norm = f64::INFINITY;
        for it in 0..MAX_NEWTON {
            if self.lu.is_none() {
                if !self.factorize(sys, &q, &v, &qdd, &lambda, t_new, h, &c, stats) {
                    return Err(Failure::Singular);
                }
                fresh = true;
            }
            sys.body_residual(&q, &v, &qdd, t_new, &mut self.r);
            sys.constraints_and_jacobian(&q, t_new, &mut self.g, &mut self.gm);
            self.r.gemv_tr(1.0, &self.gm, &lambda, 1.0);
            for i in 0..n {
                self.rhs[i] = -d * self.r[i];
            }
            for k in 0..m {
                self.rhs[n + k] = -self.g[k];
            }
            let lu = self.lu.as_ref().ok_or(Failure::Singular)?;
            if !lu.solve_mut(&mut self.rhs) {
                return Err(Failure::Singular);
            }
            stats.newton_iterations += 1;
            let dq = self.rhs.rows(0, n);
            q += dq;
            v.axpy(gamma_p, &dq, 1.0);
            qdd.axpy(beta_p, &dq, 1.0);
            for k in 0..m {
                lambda[k] += self.rhs[n + k] / d;
            }
            if !dq.iter().all(|x| x.is_finite()) || !q.iter().all(|x| x.is_finite()) {
                self.lu = None;
                return Err(Failure::NonFinite);
            }
            norm = self.norm(dq.iter(), &q);
            let rate = norm / prev;
            let converged = norm <= NEWTON_KAPPA
                || (it > 0 && rate < 1.0 && norm * rate / (1.0 - rate) <= NEWTON_KAPPA);
            if converged {
                let mut acc = (&st.qdd * c.alpha_f - &st.acc * c.alpha_m
                    + &qdd * (1.0 - c.alpha_f))
                    / (1.0 - c.alpha_m);
                // coordinates of massless bodies are algebraic: their accelerations enter no
                // equation, and the scheme's recurrence would let them grow without bound
                for &k in &self.algebraic {
                    acc[k] = 0.0;
                    qdd[k] = 0.0;
                }
                let err = (c.beta - 1.0 / 6.0).abs() * h * h;
                let err = self.norm(((&acc - &st.acc) * err).iter(), &q);
                if rate > 0.5 && it > 0 {
                    self.lu = None; // slow: refresh for the next step
                }
                return Ok((
                    GaState {
                        t: st.t,
                        h: st.h,
                        q,
                        v,
                        acc,
                        qdd,
                        lambda,
                        work: st.work,
                    },
                    err,
                ));
            }
            if it > 0 && rate >= 1.0 {
                break;
            }
            prev = norm;
        }
        self.lu = None;
        Err(Failure::Newton {
            iterations: MAX_NEWTON,
            correction: norm,
            fresh,
        })
    }
}

/// Restarts the scheme at a jump of a drive law: the accelerations and multipliers become those
/// of the equations just after the jump, so that the algorithmic acceleration carries no memory
/// of the forces before it (without this the error order drops to one at the jump).
fn restart<S: Equations + ?Sized>(sys: &S, st: &mut GaState) -> Result<(), EngineError> {
    let after = st.t * (1.0 + 1e-13) + 1e-13;
    let (qdd, lambda) = super::initial::consistent_accelerations(sys, &st.q, &st.v, after)?;
    st.acc = qdd.clone();
    st.qdd = qdd;
    st.lambda = lambda;
    Ok(())
}
