//! The eigenproblem of the linearized equations: rigid-body modes counted and taken out
//! exactly, then K φ = ω² M φ (symmetric, at rest without damping) or the quadratic problem
//! (s² M + s C + K) φ = 0 in state-space form, [0 I; -M⁻¹K -M⁻¹C], by nalgebra's real Schur
//! form (gyroscopic or damped).

use super::linearize::{null_space, Linear};
use crate::error::EngineError;
use nalgebra::{Complex, DMatrix, DVector};
use std::f64::consts::TAU;

/// One oscillating mode of a linearization.
#[derive(Debug, Clone)]
pub struct RawMode {
    /// Natural frequency (Hz): |s|/2π, the undamped ω/2π without damping.
    pub natural: f64,
    /// Damped natural frequency |Im s|/2π (Hz); `natural` at rest without damping.
    pub damped: f64,
    /// Damping ratio −Re s/|s| (0 from the symmetric problem).
    pub ratio: f64,
    /// The motion on the free motions' coordinates y of [`Linear`]: real part, imaginary part
    /// (zero from the symmetric problem).
    pub shape: (DVector<f64>, DVector<f64>),
}

/// The modes of one linearization.
#[derive(Debug, Clone, Default)]
pub struct Solved {
    /// Frequencies (Hz, ascending): ω/2π at rest, |Im s|/2π from the state space.
    pub frequencies: Vec<f64>,
    /// The oscillating modes, by ascending natural frequency, with their shapes.
    pub modes: Vec<RawMode>,
    /// Rigid-body modes taken out.
    pub rigid: usize,
    /// Modes without oscillation (real eigenvalue pairs: overdamped or diverging; or
    /// negative ω²).
    pub non_oscillating: usize,
}

/// ω² below this share of the largest in the rigid motions' block (and below 1e-9 s⁻²) is no
/// stiffness: the differences there are exact up to the loads' rounding, near 1e-10 of them.
const RIGID_SHARE: f64 = 1e-6;

fn singular(what: &str) -> EngineError {
    EngineError::InitialState {
        message: format!("the mass matrix is not positive definite on the {what}"),
    }
}

/// L⁻¹ of the Cholesky factor of a (symmetric positive definite) matrix.
fn inverse_factor(m: &DMatrix<f64>, what: &str) -> Result<DMatrix<f64>, EngineError> {
    let chol = m.clone().cholesky().ok_or_else(|| singular(what))?;
    chol.l().try_inverse().ok_or_else(|| singular(what))
}

/// Eigen-solves `lin`: by the state space when `state_space` (gyroscopic or damped), else the
/// symmetric problem without C. Without `damping` (C only gyroscopic, the eigenvalues
/// imaginary) a mode's ratio is 0 and its natural frequency |Im s|/2π, not the rounding of
/// Re s.
pub fn solve(lin: &Linear, state_space: bool, damping: bool) -> Result<Solved, EngineError> {
    let r = lin.m.nrows();
    if r == 0 {
        return Ok(Solved::default());
    }
    let ksym = (&lin.k + lin.k.transpose()) * 0.5;
    // the rigid motions without stiffness
    let p = &lin.rigid;
    let zero_modes = if p.ncols() > 0 {
        let mp = p.transpose() * &lin.m * p;
        let kp = p.transpose() * &ksym * p;
        let li = inverse_factor(&((&mp + mp.transpose()) * 0.5), "rigid motions")?;
        let a = &li * kp * li.transpose();
        let eig = ((&a + a.transpose()) * 0.5).symmetric_eigen();
        let largest = eig.eigenvalues.amax();
        let limit = (RIGID_SHARE * largest).max(1e-9);
        let cols: Vec<_> = (0..eig.eigenvalues.len())
            .filter(|&k| eig.eigenvalues[k].abs() <= limit)
            .map(|k| p * li.transpose() * eig.eigenvectors.column(k))
            .collect();
        if cols.is_empty() {
            DMatrix::zeros(r, 0)
        } else {
            DMatrix::from_columns(&cols)
        }
    } else {
        DMatrix::zeros(r, 0)
    };
    let rigid = zero_modes.ncols();
    // the M-orthogonal complement: invariant under M⁻¹K when K Z = 0
    let w = if rigid > 0 {
        null_space(&(zero_modes.transpose() * &lin.m), r)
    } else {
        DMatrix::identity(r, r)
    };
    let wt = w.transpose();
    let m = &wt * &lin.m * &w;
    let m = (&m + m.transpose()) * 0.5;
    let k = &wt * &ksym * &w;
    let mut out = Solved {
        rigid,
        ..Solved::default()
    };
    if w.ncols() == 0 {
        return Ok(out);
    }
    let li = inverse_factor(&m, "free motions")?;
    if !state_space {
        let a = &li * k * li.transpose();
        let eig = ((&a + a.transpose()) * 0.5).symmetric_eigen();
        let back = &w * li.transpose();
        for (j, &l) in eig.eigenvalues.iter().enumerate() {
            if l > 0.0 {
                let f = l.sqrt() / TAU;
                out.frequencies.push(f);
                let y = &back * eig.eigenvectors.column(j);
                out.modes.push(RawMode {
                    natural: f,
                    damped: f,
                    ratio: 0.0,
                    shape: (y, DVector::zeros(r)),
                });
            } else {
                out.non_oscillating += 1;
            }
        }
        out.frequencies.sort_by(f64::total_cmp);
        out.modes.sort_by(|a, b| a.natural.total_cmp(&b.natural));
        return Ok(out);
    }
    let kfull = &wt * &lin.k * &w;
    let c = &wt * &lin.c * &w;
    let minv = li.transpose() * &li;
    let s = w.ncols();
    // the state (x, x'/ω) with ω² = ‖M⁻¹K‖: the same eigenvalues, but a norm near ω (or
    // ‖M⁻¹C‖) instead of ω², and rounding scales with the norm
    let stiffness = -&minv * kfull;
    let omega = stiffness.norm().sqrt().max(1e-300);
    let mut a = DMatrix::zeros(2 * s, 2 * s);
    a.view_mut((0, s), (s, s)).fill_diagonal(omega);
    a.view_mut((s, 0), (s, s)).copy_from(&(stiffness / omega));
    a.view_mut((s, s), (s, s)).copy_from(&(-&minv * c));
    let (values, vectors) = state_space_eigen(&a)?;
    let size = a.norm();
    let mut real = 0;
    for (j, z) in values.iter().enumerate() {
        if !oscillates(*z, size) {
            real += 1;
        } else if z.im > 0.0 {
            let v = vectors.column(j);
            let re = DVector::from_fn(s, |i, _| v[i].re);
            let im = DVector::from_fn(s, |i, _| v[i].im);
            let (natural, ratio) = if damping {
                (z.norm() / TAU, -z.re / z.norm())
            } else {
                (z.im / TAU, 0.0)
            };
            out.modes.push(RawMode {
                natural,
                damped: z.im / TAU,
                ratio,
                shape: (&w * re, &w * im),
            });
        }
    }
    out.non_oscillating = real / 2;
    out.modes.sort_by(|a, b| a.natural.total_cmp(&b.natural));
    out.frequencies = out.modes.iter().map(|m| m.damped).collect();
    out.frequencies.sort_by(f64::total_cmp);
    Ok(out)
}

/// Is the eigenvalue z of a real state-space matrix of Frobenius norm `size` one of an
/// oscillating pair? Not when its imaginary part lies within what rounding can split a double
/// real root into: a perturbation ε‖A‖ parts a double root s by ±√(ε‖A‖|s|). The overdamped
/// roots of stiffness-proportional damping gather near −1/β, and the Schur form splits them
/// into pairs (listed before as modes near 1e-6 Hz with damping ratio 1): measured on a
/// clamped 3D beam with β = 4e-3 and 2e-2 s, 16 to 64 elements, |Im s| up to 2.8e-4 s⁻¹
/// against a split of 0.25 s⁻¹ or more, while its first mode's |Im s| is 13 s⁻¹.
fn oscillates(z: Complex<f64>, size: f64) -> bool {
    z.im.abs() > (f64::EPSILON * size * z.norm()).sqrt()
}

/// Eigenvalues and eigenvectors (columns).
type Eigen = (Vec<Complex<f64>>, DMatrix<Complex<f64>>);

/// Eigenvalues and eigenvectors (columns) of a real square matrix, by faer's Schur form.
fn state_space_eigen(a: &DMatrix<f64>) -> Result<Eigen, EngineError> {
    let n = a.nrows();
    let m = faer::Mat::<f64>::from_fn(n, n, |i, j| a[(i, j)]);
    let evd = m.eigen().map_err(|e| EngineError::Modes {
        message: format!("the state-space eigenproblem ({n} × {n}) did not converge: {e:?}"),
    })?;
    let s = evd.S().column_vector();
    let u = evd.U();
    let values = (0..n).map(|i| Complex::new(s[i].re, s[i].im)).collect();
    let vectors = DMatrix::from_fn(n, n, |i, j| Complex::new(u[(i, j)].re, u[(i, j)].im));
    Ok((values, vectors))
}
