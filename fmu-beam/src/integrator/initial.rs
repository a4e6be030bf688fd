//! Consistent initial conditions: assemble the mechanism (g(q) = 0), then solve for the
//! accelerations and multipliers that the equations of motion give at rest.

use super::iteration_matrix::{IterationMatrix, LinearSolver, Scaling};
use super::{GaState, Settings};
use crate::error::EngineError;
use crate::mechanics::multibody::{Equations, JacobianRows, Point};
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
    if m > 0 {
        check_rank(sys, &q, t0)?;
        let frames = sys.frame_coordinates();
        // dense only if the bodies' own placement does not meet the joints (O(m n))
        let mut gm = DMatrix::zeros(0, 0);
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
            if gm.shape() != (m, n) {
                gm = DMatrix::zeros(m, n);
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

/// Refuses redundant joints: G must have full row rank. Proven cheaply where it can be
/// ([`peels_to_full_rank`], linear in the bodies); otherwise the SVD of the dense G decides and
/// names the joints.
fn check_rank<S: Equations + ?Sized>(sys: &S, q: &DVector<f64>, t: f64) -> Result<(), EngineError> {
    let mut rows = sys.jacobian_pattern();
    sys.jacobian_rows(q, t, &mut rows);
    if peels_to_full_rank(&sys.body_ranges(), &sys.row_bodies(), &rows) {
        return Ok(());
    }
    let mut gm = DMatrix::zeros(sys.m(), sys.n());
    rows.to_dense(&mut gm);
    check_rows_rank(sys, &gm, &(0..gm.nrows()).collect::<Vec<_>>(), t)
}

/// How far above round-off (relative to ‖G‖_F) the smallest singular value of each peeled
/// block must lie for [`peels_to_full_rank`] to call G full rank: far above the SVD's 1e-10, so
/// that near-redundant joints go to the SVD.
const PEEL_MARGIN: f64 = 1e-6;

/// True when G has full row rank by peeling: the rows that still touch a body, restricted to that
/// body's columns, with full row rank (the smallest singular value above [`PEEL_MARGIN`] ‖G‖_F)
/// are independent of every other row (no other row has an entry there), so they are set aside,
/// body after body, until none is left. A chain or tree of bodies peels from its leaves, in
/// small SVDs of one body's rows; a loop that does not peel, or a block near rank deficiency,
/// gives false and the dense SVD decides.
fn peels_to_full_rank(
    ranges: &[std::ops::Range<usize>],
    row_bodies: &[[Option<usize>; 2]],
    rows: &JacobianRows,
) -> bool {
    let m = row_bodies.len();
    let norm = rows.values().iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut of_body: Vec<Vec<usize>> = vec![Vec::new(); ranges.len()];
    for (row, bodies) in row_bodies.iter().enumerate() {
        let mut b: Vec<usize> = bodies.iter().flatten().copied().collect();
        b.dedup();
        if b.is_empty() {
            // a row on the world alone: zero, or a constant, never a rank
            return false;
        }
        for body in b {
            of_body[body].push(row);
        }
    }
    let mut left = vec![true; m];
    let mut remaining = m;
    let mut queue: Vec<usize> = (0..ranges.len()).rev().collect();
    let mut queued = vec![true; ranges.len()];
    while let Some(b) = queue.pop() {
        queued[b] = false;
        let live: Vec<usize> = of_body[b].iter().copied().filter(|&r| left[r]).collect();
        let cols = &ranges[b];
        if live.is_empty() || live.len() > cols.len() {
            continue;
        }
        let mut block = DMatrix::zeros(live.len(), cols.len());
        for (i, &r) in live.iter().enumerate() {
            match rows.row_over(r, cols) {
                Some(v) => block.row_mut(i).copy_from_slice(v),
                None => return false,
            }
        }
        let sv = block.transpose().svd(false, false).singular_values;
        if sv.len() < live.len() || sv.min() <= PEEL_MARGIN * norm {
            continue;
        }
        for &r in &live {
            left[r] = false;
            remaining -= 1;
            for other in row_bodies[r].iter().flatten() {
                if !queued[*other] {
                    queued[*other] = true;
                    queue.push(*other);
                }
            }
        }
    }
    remaining == 0
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

#[cfg(test)]
mod tests {
    use super::peels_to_full_rank;
    use crate::mechanics::multibody::JacobianRows;
    use std::ops::Range;

    /// A chain of `k` bodies of 3 coordinates: body 0 pinned to the world (2 rows), each next
    /// one welded to the one before (3 rows: its coordinates minus the other's), and `extra`
    /// rows appended.
    fn chain(k: usize, extra: &[([Option<usize>; 2], [f64; 6])]) -> bool {
        let ranges: Vec<Range<usize>> = (0..k).map(|b| 3 * b..3 * b + 3).collect();
        let mut rows: Vec<([Option<usize>; 2], [f64; 6])> = vec![
            ([Some(0), None], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            ([Some(0), None], [0.0, 1.0, 0.0, 0.0, 0.0, 0.0]),
        ];
        for b in 1..k {
            for c in 0..3 {
                let mut v = [0.0; 6];
                v[c] = -1.0;
                v[3 + c] = 1.0;
                rows.push(([Some(b - 1), Some(b)], v));
            }
        }
        rows.extend_from_slice(extra);
        let bodies: Vec<[Option<usize>; 2]> = rows.iter().map(|r| r.0).collect();
        let mut g = JacobianRows::new(3 * k, &ranges, &bodies);
        for (i, (b, v)) in rows.iter().enumerate() {
            for (s, body) in b.iter().flatten().enumerate() {
                for c in 0..3 {
                    g.add(i, ranges[*body].start + c, v[3 * s + c]);
                }
            }
        }
        peels_to_full_rank(&ranges, &bodies, &g)
    }

    #[test]
    fn a_chain_of_welds_peels_and_a_redundant_or_looped_row_does_not() {
        assert!(chain(1, &[]));
        assert!(chain(50, &[]));
        // a second pin of body 0's x: the same motion twice
        let again = ([Some(0), None], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert!(!chain(50, &[again]));
        // the last body's angle fixed to the world closes a loop through it: full rank, but
        // no body's rows peel (4 on the last body's 3 columns), so the SVD decides
        let angle = ([Some(49), None], [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
        assert!(!chain(50, &[angle]));
        // nearly redundant (1e-9 of the other): left to the SVD
        let near = ([Some(0), None], [1.0, 1e-9, 0.0, 0.0, 0.0, 0.0]);
        assert!(!chain(5, &[near]));
    }
}
