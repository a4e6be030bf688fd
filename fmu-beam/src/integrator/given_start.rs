//! A start where joints are given their coordinate or rate (a scene's `joint.initial`, issue
//! 31): the bodies are placed, and set moving, to meet the joints and the values given, moving
//! only the bodies' frames (a beam is not deformed to meet them), and keeping the other joints'
//! coordinates where the scene placed them, their rates at 0, as far as the joints allow.
//!
//! Both are least-squares problems with hard rows (the joints, the values given) and soft rows
//! (the other joints' coordinates): the least-norm solution x_p of the hard rows H x = h, then
//! the step a within their null space (P = I − H⁺H) that best meets the soft rows S x = s:
//! x = x_p + P a, a the least-norm solution of S P a = s − S x_p.

use super::initial::check_rows_rank;
use crate::error::EngineError;
use crate::mechanics::multibody::Equations;
use nalgebra::{DMatrix, DVector};

/// Iterations of the placement before it is refused.
const PLACEMENT_ITERATIONS: usize = 50;

/// A joint coordinate's start: its row in the twin system (the coordinate less a constant: a
/// motion drive's row), whether the row must be 0 (the coordinate given) or is free (kept
/// where placed, as far as the hard rows allow), and the rate given, or `None` where it is
/// free (at rest, as far as the hard rows allow).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoordinateStart {
    /// The row of `twin`: the joint coordinate less the value given (or any constant).
    pub row: usize,
    /// The row must be 0: the coordinate is given.
    pub held: bool,
    /// The rate given (rad/s or m/s).
    pub speed: Option<f64>,
}

/// The coordinates and velocities at `t0` of `twin`, the system with one more row per joint
/// coordinate of `starts` (each the coordinate itself): its other rows, and the coordinates and
/// rates given, hold; the coordinates and rates not given stay as placed and at rest as far as
/// those allow. Refused when the values given contradict the joints or each other.
pub fn given_start<S: Equations + ?Sized>(
    twin: &S,
    t0: f64,
    starts: &[CoordinateStart],
) -> Result<(DVector<f64>, DVector<f64>), EngineError> {
    let (n, m) = (twin.n(), twin.m());
    let frames = twin.frame_coordinates();
    let mut q = twin.initial_coordinates()?;
    let mut g = DVector::zeros(m);
    let mut gm = DMatrix::zeros(m, n);
    twin.constraint_jacobian(&q, t0, &mut gm);
    // only the rows that must hold are checked for redundancy
    let hard: Vec<usize> = (0..m)
        .filter(|r| starts.iter().all(|s| s.row != *r || s.held))
        .collect();
    check_rows_rank(twin, &gm.select_rows(hard.iter()), &hard, t0)?;
    twin.constraints(&q, t0, &mut g);
    let placed = g.clone();
    // what each row should be: 0 (a joint, a coordinate given), or as placed
    let mut target = DVector::zeros(m);
    for s in starts.iter().filter(|s| !s.held) {
        target[s.row] = placed[s.row];
    }
    let soft: Vec<usize> = starts.iter().filter(|s| !s.held).map(|s| s.row).collect();
    let tol = 1e-12 * twin.length_scale().max(1.0);
    let mut iterations = 0;
    loop {
        twin.constraints(&q, t0, &mut g);
        let r = &g - &target;
        let residual = hard.iter().map(|&i| r[i].abs()).fold(0.0, f64::max);
        twin.constraint_jacobian(&q, t0, &mut gm);
        let columns = |rows: &[usize]| {
            DMatrix::from_fn(rows.len(), frames.len(), |i, j| gm[(rows[i], frames[j])])
        };
        let step = split_least_squares(
            &columns(&hard),
            &-DVector::from_iterator(hard.len(), hard.iter().map(|&i| r[i])),
            &columns(&soft),
            &-DVector::from_iterator(soft.len(), soft.iter().map(|&i| r[i])),
        );
        let small = step
            .as_ref()
            .is_some_and(|d| d.amax() <= 1e-12 * twin.length_scale().max(1.0));
        if residual <= tol && (small || iterations >= PLACEMENT_ITERATIONS) {
            break;
        }
        let Some(step) = step.filter(|_| iterations < PLACEMENT_ITERATIONS && residual.is_finite())
        else {
            let rows: Vec<usize> = hard.iter().copied().filter(|&i| r[i].abs() > tol).collect();
            return Err(EngineError::Assembly {
                t: t0,
                residual,
                joints: twin.joints_of_rows(&rows).join(", "),
                tolerance: tol,
                iterations,
            });
        };
        for (j, &k) in frames.iter().enumerate() {
            q[k] += step[j];
        }
        iterations += 1;
    }
    // the rates: the joints' rows at 0 (time-independent rows), the rates given
    let mut rate = DVector::zeros(m);
    let speeds: Vec<usize> = starts
        .iter()
        .filter(|s| s.speed.is_some())
        .map(|s| s.row)
        .collect();
    for s in starts {
        rate[s.row] = s.speed.unwrap_or(0.0);
    }
    let must: Vec<usize> = (0..m)
        .filter(|r| starts.iter().all(|s| s.row != *r) || speeds.contains(r))
        .collect();
    let free: Vec<usize> = starts
        .iter()
        .filter(|s| s.speed.is_none())
        .map(|s| s.row)
        .collect();
    twin.constraint_jacobian(&q, t0, &mut gm);
    let columns = |rows: &[usize]| {
        DMatrix::from_fn(rows.len(), frames.len(), |i, j| gm[(rows[i], frames[j])])
    };
    let (hm, hr) = (
        columns(&must),
        DVector::from_iterator(must.len(), must.iter().map(|&i| rate[i])),
    );
    let vf = split_least_squares(&hm, &hr, &columns(&free), &DVector::zeros(free.len()));
    let scale = 1e-9 * (1.0 + hr.amax());
    let (vf, off) = match vf {
        Some(vf) => {
            let off = &hm * &vf - &hr;
            (vf, off)
        }
        None => (DVector::zeros(frames.len()), -hr.clone()),
    };
    if off.amax() > scale || !vf.iter().all(|x| x.is_finite()) {
        let rows: Vec<usize> = (0..must.len())
            .filter(|&i| off[i].abs() > scale)
            .map(|i| must[i])
            .collect();
        return Err(EngineError::InitialState {
            message: format!(
                "the initial speeds given cannot all hold: joint(s) {} stay off by up to {:.3e}; \
                 give fewer, or speeds the joints allow",
                twin.joints_of_rows(&rows).join(", "),
                off.amax()
            ),
        });
    }
    let mut v = DVector::zeros(n);
    for (j, &k) in frames.iter().enumerate() {
        v[k] = vf[j];
    }
    Ok((q, v))
}

/// x = x_p + P a: x_p the least-norm solution of H x = h, P = I − H⁺H the projection on the
/// null space of H, a the least-norm solution of S P a = s − S x_p. `None` if an SVD fails.
fn split_least_squares(
    h: &DMatrix<f64>,
    hv: &DVector<f64>,
    s: &DMatrix<f64>,
    sv: &DVector<f64>,
) -> Option<DVector<f64>> {
    let n = h.ncols();
    const EPS: f64 = 1e-12;
    let (xp, p) = if h.nrows() == 0 {
        (DVector::zeros(n), DMatrix::identity(n, n))
    } else {
        let pinv = h.clone().pseudo_inverse(EPS).ok()?;
        (&pinv * hv, DMatrix::identity(n, n) - &pinv * h)
    };
    if s.nrows() == 0 {
        return Some(xp);
    }
    let sp = s * &p;
    let a = sp.svd(true, true).solve(&(sv - s * &xp), EPS).ok()?;
    Some(xp + p * a)
}
