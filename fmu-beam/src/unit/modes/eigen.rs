//! The eigenproblem of the linearized equations: rigid-body modes counted and taken out
//! exactly, then K φ = ω² M φ (symmetric, at rest without damping) or the quadratic problem
//! (s² M + s C + K) φ = 0 in state-space form, [0 I; -M⁻¹K -M⁻¹C], by nalgebra's real Schur
//! form (gyroscopic or damped).

use super::linearize::{null_space, Linear};
use super::DampedMode;
use crate::error::EngineError;
use nalgebra::DMatrix;
use std::f64::consts::TAU;

/// The modes of one linearization.
#[derive(Debug, Clone, Default)]
pub struct Solved {
    /// Frequencies (Hz, ascending): ω/2π at rest, |Im s|/2π from the state space.
    pub frequencies: Vec<f64>,
    /// Damped frequency and ratio of each oscillating eigenvalue pair (state space only).
    pub damped: Vec<DampedMode>,
    /// Rigid-body modes taken out.
    pub rigid: usize,
    /// Modes without oscillation (real eigenvalues, or negative ω²).
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
/// symmetric problem without C.
pub fn solve(lin: &Linear, state_space: bool) -> Result<Solved, EngineError> {
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
        for &l in eig.eigenvalues.iter() {
            if l > 0.0 {
                out.frequencies.push(l.sqrt() / TAU);
            } else {
                out.non_oscillating += 1;
            }
        }
        out.frequencies.sort_by(f64::total_cmp);
        return Ok(out);
    }
    let kfull = &wt * &lin.k * &w;
    let c = &wt * &lin.c * &w;
    let minv = li.transpose() * &li;
    let s = w.ncols();
    let mut a = DMatrix::zeros(2 * s, 2 * s);
    a.view_mut((0, s), (s, s)).fill_with_identity();
    a.view_mut((s, 0), (s, s)).copy_from(&(-&minv * kfull));
    a.view_mut((s, s), (s, s)).copy_from(&(-&minv * c));
    let eig = a.complex_eigenvalues();
    let mut real = 0;
    for z in eig.iter() {
        let size = z.norm();
        if z.im.abs() <= 1e-9 * size {
            real += 1;
        } else if z.im > 0.0 {
            out.damped.push(DampedMode {
                frequency: z.im / TAU,
                damping_ratio: -z.re / size,
            });
        }
    }
    out.non_oscillating = real / 2;
    out.damped
        .sort_by(|a, b| a.frequency.total_cmp(&b.frequency));
    out.frequencies = out.damped.iter().map(|d| d.frequency).collect();
    Ok(out)
}
