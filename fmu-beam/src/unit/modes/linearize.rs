//! The linearized equations M x'' + C x' + K x = 0 on the free motions x = N y (N spans the
//! null space of G), at rest or in the frame co-rotating at Ω about the world origin.
//!
//! Tangents by central differences of the system's own residual r(q, q', q'') + G(q)ᵀλ, along
//! the free motions only: the analytic tangents of [`Equations::tangent_blocks`] are block-
//! diagonal approximations for Newton (they leave out the coupling between bodies and the
//! joints' λ-Hessian), which at speed carry the centrifugal tension through the welds and the
//! hub. Along a free motion a rigid motion deforms nothing, so its difference is exact up to
//! the loads' rounding: rigid-body modes keep their zero (see `eigen`).
//!
//! The systems are invariant to turning about the world z axis (the planar one as its
//! `Turning` says; the spatial one with positions turned and quaternions multiplied on the
//! left, an orthogonal map): with q*(t) the steady state turned by Ωt and δq = T(Ωt) x
//! (T the turn, [`Spin`], J = dT/d(Ωt) at 0),
//! δq' = T(x' + ΩJx), δq'' = T(x'' + 2ΩJx' + Ω²J²x), so in the co-rotating frame
//! M̃ = M, C̃ = C + 2ΩMJ, K̃ = K + ΩCJ + Ω²MJ², constant in time (Coriolis and centrifugal terms;
//! the stiffening is in K through the deformed state's multipliers and axial strain).

use crate::error::EngineError;
use crate::mechanics::multibody::equations::Equations;
use crate::mechanics::Mechanics;
use nalgebra::{DMatrix, DVector};

/// The linearization on the free motions: reduced M, C, K (r × r) and the elastic mask of the
/// free motions' basis (to find the rigid ones).
#[derive(Debug, Clone)]
pub struct Linear {
    /// Reduced mass Nᵀ M N.
    pub m: DMatrix<f64>,
    /// Reduced damping and gyroscopic matrix Nᵀ C̃ N.
    pub c: DMatrix<f64>,
    /// Reduced stiffness Nᵀ K̃ N.
    pub k: DMatrix<f64>,
    /// The free motions that deform no beam, in the coordinates y of the reduced matrices
    /// (r × p, orthonormal columns).
    pub rigid: DMatrix<f64>,
    /// N (n × r, orthonormal columns): a free motion y is δq = N y on the system's coordinates.
    pub basis: DMatrix<f64>,
}

/// How the coordinates turn with the whole system about the world z axis: each body's
/// position pair (x, y), its planar angle (additive), its quaternion (left product with the
/// turn about z); elastic coordinates, in the body frame, do not turn.
#[derive(Debug, Clone, Default)]
pub struct Spin {
    /// Index in q of each body's position x (y follows).
    pub pairs: Vec<usize>,
    /// Index in q of each planar body's angle.
    pub angles: Vec<usize>,
    /// Index in q of each spatial body's quaternion e0 (e1, e2, e3 follow).
    pub quaternions: Vec<usize>,
}

impl Spin {
    /// The turning coordinates of a planar or spatial system.
    pub fn of(sys: &Mechanics) -> Spin {
        match sys {
            Mechanics::Planar(s) => Spin {
                pairs: s.offsets.clone(),
                angles: s.offsets.iter().map(|o| o + 2).collect(),
                quaternions: Vec::new(),
            },
            Mechanics::Spatial(s, _) => Spin {
                pairs: s.offsets.clone(),
                angles: Vec::new(),
                quaternions: s.offsets.iter().map(|o| o + 3).collect(),
            },
        }
    }

    /// J x, the linear part of the turn's generator: (x, y) → (-y, x); a quaternion p →
    /// ½ (0, e_z) ⊗ p = ½ (-e3, -e2, e1, e0); zero elsewhere.
    fn turn(&self, x: &DVector<f64>) -> DVector<f64> {
        let mut out = DVector::zeros(x.len());
        for &p in &self.pairs {
            out[p] = -x[p + 1];
            out[p + 1] = x[p];
        }
        for &e in &self.quaternions {
            out[e] = -0.5 * x[e + 3];
            out[e + 1] = -0.5 * x[e + 2];
            out[e + 2] = 0.5 * x[e + 1];
            out[e + 3] = 0.5 * x[e];
        }
        out
    }

    /// The steady rates and accelerations at q spinning at Ω about the world z axis: q' = ΩJq
    /// (and Ω for a planar angle), q'' = Ω²J²q; the deformation is still.
    fn rates(&self, q: &DVector<f64>, omega: f64) -> (DVector<f64>, DVector<f64>) {
        let jq = self.turn(q);
        let a = self.turn(&jq) * (omega * omega);
        let mut v = jq * omega;
        for &i in &self.angles {
            v[i] = omega;
        }
        (v, a)
    }
}

/// r(q, v, a, 0) + G(q)ᵀλ.
fn residual<E: Equations>(
    sys: &E,
    q: &DVector<f64>,
    v: &DVector<f64>,
    a: &DVector<f64>,
    lambda: &DVector<f64>,
) -> DVector<f64> {
    let mut r = DVector::zeros(sys.n());
    sys.body_residual(q, v, a, 0.0, &mut r);
    let mut gm = DMatrix::zeros(sys.m(), sys.n());
    sys.constraint_jacobian(q, 0.0, &mut gm);
    r + gm.transpose() * lambda
}

/// Step of the central differences in q: 1e-6 of the system's length (rounding of the
/// residual's parts against the truncation of the frame angles' sines, both near 1e-11).
fn step_q<E: Equations>(sys: &E) -> f64 {
    1e-6 * sys.length_scale().max(1e-3)
}

/// 8 equal steps of speed from rest to `omega`.
pub fn ramp(omega: f64) -> Vec<f64> {
    (1..=8).map(|s| omega * s as f64 / 8.0).collect()
}

/// The coordinates and multipliers of the steady state spinning about the origin (the hub's
/// world frame) at the last of `speeds`, from (q0, λ0): Newton on r(q, v(q), a(q)) + Gᵀλ = 0,
/// g(q, 0) = 0, its q-columns by central differences, at each of `speeds` in turn (from rest,
/// [`ramp`]).
pub fn steady_state<E: Equations>(
    sys: &E,
    spin: &Spin,
    q0: &DVector<f64>,
    lambda0: &DVector<f64>,
    speeds: &[f64],
) -> Result<(DVector<f64>, DVector<f64>), EngineError> {
    let omega = speeds.last().copied().unwrap_or(0.0);
    let (n, m) = (sys.n(), sys.m());
    let (mut q, mut lambda) = (q0.clone(), lambda0.clone());
    let h = step_q(sys);
    let scale = sys.length_scale().max(1e-3);
    for &w in speeds {
        let f = |q: &DVector<f64>, lambda: &DVector<f64>| {
            let (v, a) = spin.rates(q, w);
            residual(sys, q, &v, &a, lambda)
        };
        let mut converged = false;
        let mut last = f64::INFINITY;
        for _ in 0..40 {
            let mut gm = DMatrix::zeros(m, n);
            sys.constraint_jacobian(&q, 0.0, &mut gm);
            let mut g = DVector::zeros(m);
            sys.constraints(&q, 0.0, &mut g);
            let r = f(&q, &lambda);
            let mut jac = DMatrix::zeros(n + m, n + m);
            for k in 0..n {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[k] += h;
                qm[k] -= h;
                let col = (f(&qp, &lambda) - f(&qm, &lambda)) / (2.0 * h);
                jac.view_mut((0, k), (n, 1)).copy_from(&col);
            }
            jac.view_mut((0, n), (n, m)).copy_from(&gm.transpose());
            jac.view_mut((n, 0), (m, n)).copy_from(&gm);
            let mut rhs = DVector::zeros(n + m);
            rhs.rows_mut(0, n).copy_from(&(-r));
            rhs.rows_mut(n, m).copy_from(&(-g));
            let dz = jac
                .full_piv_lu()
                .solve(&rhs)
                .ok_or_else(|| EngineError::Modes {
                    message: format!(
                        "no steady state at {w} rad/s: the equilibrium's Jacobian is singular \
                     (a free mechanism without stiffness in the rotating frame?)"
                    ),
                })?;
            q += dz.rows(0, n);
            lambda += dz.rows(n, m);
            let step = dz.rows(0, n).amax();
            if step <= 1e-10 * scale {
                converged = true;
                break;
            }
            if !step.is_finite() || (step > 10.0 * last && step > scale) {
                break;
            }
            last = step;
        }
        if !converged {
            return Err(EngineError::Modes {
                message: format!(
                    "no steady state found at {w} rad/s (of {omega}): Newton did not converge \
                     (a beam spun near or past its stability limit, or needing geometric \
                     stiffening: `geometric_stiffening = true` or substructures)"
                ),
            });
        }
    }
    Ok((q, lambda))
}

/// The linearization at (q, λ), at rest (`omega` = 0) or about the steady state spinning at
/// `omega`, reduced to the free motions.
pub fn corotating<E: Equations>(
    sys: &E,
    spin: &Spin,
    q: &DVector<f64>,
    lambda: &DVector<f64>,
    omega: f64,
) -> Result<Linear, EngineError> {
    let n = sys.n();
    let (v0, a0) = spin.rates(q, omega);
    let mut gm = DMatrix::zeros(sys.m(), n);
    sys.constraint_jacobian(q, 0.0, &mut gm);
    let basis = null_space(&gm, n);
    let r = basis.ncols();
    let mut mm = DMatrix::zeros(n, n);
    sys.mass_matrix(q, &mut mm);
    let h = step_q(sys);
    let hv = 1e-6 * v0.amax().max(1.0);
    let dq = |d: &DVector<f64>| {
        (residual(sys, &(q + d * h), &v0, &a0, lambda)
            - residual(sys, &(q - d * h), &v0, &a0, lambda))
            / (2.0 * h)
    };
    let dv = |d: &DVector<f64>| {
        (residual(sys, q, &(&v0 + d * hv), &a0, lambda)
            - residual(sys, q, &(&v0 - d * hv), &a0, lambda))
            / (2.0 * hv)
    };
    let mut kn = DMatrix::zeros(n, r);
    let mut cn = DMatrix::zeros(n, r);
    for k in 0..r {
        let d: DVector<f64> = basis.column(k).into();
        kn.set_column(k, &dq(&d));
        let mut c = dv(&d);
        let mut kcol = DVector::zeros(n);
        if omega != 0.0 {
            let jd = spin.turn(&d);
            // C̃ = C + 2ΩMJ, K̃ = K + ΩCJ + Ω²MJ²
            c += &mm * &jd * (2.0 * omega);
            kcol += dv(&jd) * omega + &mm * spin.turn(&jd) * (omega * omega);
        }
        cn.set_column(k, &c);
        let kk = kn.column(k) + kcol;
        kn.set_column(k, &kk);
    }
    let bt = basis.transpose();
    let m = &bt * &mm * &basis;
    let elastic: Vec<bool> = {
        let mut e = vec![true; n];
        for i in sys.frame_coordinates() {
            e[i] = false;
        }
        e
    };
    // free motions that move no elastic coordinate: the null space of [G; E] in y = Nᵀ x
    let mut rows: Vec<usize> = (0..n).filter(|&i| elastic[i]).collect();
    rows.sort_unstable();
    let e_on_free = DMatrix::from_fn(rows.len(), r, |i, j| basis[(rows[i], j)]);
    let rigid = null_space(&e_on_free, r);
    Ok(Linear {
        m: (&m + m.transpose()) * 0.5,
        c: &bt * cn,
        k: &bt * kn,
        rigid,
        basis,
    })
}

/// Orthonormal basis of the null space of A (rows × n), n × (n - rank).
pub fn null_space(a: &DMatrix<f64>, n: usize) -> DMatrix<f64> {
    if a.nrows() == 0 || n == 0 {
        return DMatrix::identity(n, n);
    }
    // complete the row space with the SVD of the square matrix [A; 0] (or AᵀA-sized rows)
    let rows = a.nrows().max(n);
    let mut sq = DMatrix::zeros(rows, n);
    sq.view_mut((0, 0), (a.nrows(), n)).copy_from(a);
    let svd = sq.svd(false, true);
    let vt = svd.v_t.expect("v_t requested");
    let smax = svd.singular_values.amax().max(1e-300);
    let cols: Vec<_> = (0..svd.singular_values.len())
        .filter(|&k| svd.singular_values[k] <= 1e-10 * smax)
        .map(|k| vt.row(k).transpose())
        .collect();
    if cols.is_empty() {
        return DMatrix::zeros(n, 0);
    }
    DMatrix::from_columns(&cols)
}
