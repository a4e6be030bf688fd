//! One generalized-α step of the [`Stepper`]: the predictor, Newton iterations on the
//! factorized iteration matrix (refreshed when convergence is slow, its solves turned with the
//! bodies' rotation since the matrix's point), and the verdict that accepts the step or says
//! why not.

use super::*;

impl Stepper {
    /// Builds and factorizes the scaled iteration matrix at a point, for a step h.
    pub(super) fn factorize<S: Equations + ?Sized>(
        &mut self,
        sys: &S,
        at: &Point,
        h: f64,
        c: &Coefficients,
    ) -> bool {
        self.matrix.factorize(sys, at, c.scaling(h))
    }

    /// Solves for the Newton correction at iterate `q` in `rhs`. Where the bodies have turned
    /// since the matrix was factorized, by angles δ_b, the matrix is used as if turned by the
    /// middle of their range ([`Turning`]): a matrix of a spinning or swinging system stays a
    /// good one over many steps, and no body's mismatch exceeds what it was unturned.
    pub(super) fn solve_turned(&mut self, q: &DVector<f64>) -> bool {
        let (Some(delta), Some(turning)) = (self.turned(q), &self.turning) else {
            return self.matrix.solve_mut(&mut self.rhs);
        };
        turn_pairs(&mut self.rhs, &turning.pairs, -delta);
        let solved = self.matrix.solve_mut(&mut self.rhs);
        turn_pairs(&mut self.rhs, &turning.pairs, delta);
        solved
    }

    /// The angle δ by which the matrix is used as turned at iterate `q` (the middle of the
    /// range of the bodies' turns since it was factorized), where it is not zero.
    pub(super) fn turned(&self, q: &DVector<f64>) -> Option<f64> {
        let (Some(turning), Some(p)) = (&self.turning, &self.memory.point) else {
            return None;
        };
        let (lo, hi) = turning
            .angles
            .iter()
            .map(|&k| q[k] - p.q[k])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| {
                (lo.min(d), hi.max(d))
            });
        // no bodies: ∞ - ∞, not finite
        let delta = 0.5 * (lo + hi);
        (delta != 0.0 && delta.is_finite()).then_some(delta)
    }

    /// One step of size h from `st`; returns the new state and the local error norm.
    /// Whether evaluating the iteration matrix again at the current iterate costs less than
    /// the corrections the current one still needs at its measured rate: a factorization
    /// counts its work units ([`IterationMatrix::factorization_units`]) in iterations
    /// ([`super::super::ITERATION_OVERHEAD`] plus one per unknown), and the new matrix
    /// [`AFTER_REFRESH`] corrections.
    fn refresh_pays(&self, norm: f64, kappa: f64, unknowns: usize) -> bool {
        let iteration = (unknowns as u64 + super::super::ITERATION_OVERHEAD) as f64;
        let factorization = self.matrix.factorization_units() as f64 / iteration;
        self.memory
            .contraction
            .remaining(norm, kappa)
            .is_some_and(|left| left > AFTER_REFRESH + factorization)
    }

    pub(super) fn attempt<S: Equations + ?Sized>(
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
        if self
            .memory
            .point
            .as_ref()
            .is_some_and(|p| (h - p.h).abs() > SAME_STEP * h)
        {
            self.forget();
        }
        // a restored state: the same factors, at the same point
        if !self.matrix.is_factored() {
            if let Some(p) = self.memory.point.take() {
                let at = Point {
                    q: &p.q,
                    v: &p.v,
                    a: &p.qdd,
                    lambda: &p.lambda,
                    t: p.t,
                };
                if !self.factorize(sys, &at, p.h, &c) {
                    self.forget();
                    return Err(Failure::Singular);
                }
                self.memory.point = Some(p);
            }
        }
        // predictor: q''_{n+1} = q''_n; element by element, the operations of
        // a_{n+1} = (α_f q''_n - α_m a_n + (1 - α_f) q''_{n+1}) / (1 - α_m),
        // v = v_n + h (1 - γ) a_n + h γ a_{n+1}, q = q_n + h v_n + h² (1/2 - β) a_n + d a_{n+1}
        // in the order the vector expressions took them, without their temporaries
        let mut qdd = st.qdd.clone();
        let mut v = st.v.clone();
        let mut q = st.q.clone();
        let (v_acc, v_new) = (h * (1.0 - c.gamma), h * c.gamma);
        let q_acc = h * h * (0.5 - c.beta);
        {
            // slices of one length: no bounds check in the loop
            let (q0, v0) = (&st.q.as_slice()[..n], &st.v.as_slice()[..n]);
            let (a0, qdd0) = (&st.acc.as_slice()[..n], &st.qdd.as_slice()[..n]);
            let (q1, v1) = (&mut q.as_mut_slice()[..n], &mut v.as_mut_slice()[..n]);
            for i in 0..n {
                // q''_{n+1} = q''_n here
                let acc_new = next_acc(&c, qdd0[i], a0[i], qdd0[i]);
                v1[i] = v0[i] + a0[i] * v_acc + acc_new * v_new;
                q1[i] = q0[i] + v0[i] * h + a0[i] * q_acc + acc_new * d;
            }
        }
        let mut lambda = st.lambda.clone();
        let mut fresh = false;
        let mut prev = f64::INFINITY;
        let mut norm = f64::INFINITY;
        let mut iterations = 0;
        // corrections since the matrix was factorized, and refactorizations within this step
        let (mut k, mut refreshed) = (0, 0);
        let tol = self.settings.tolerance;
        let floor_of = |noise: f64| ROUNDING.max(NOISE_BAND * noise * f64::EPSILON) / tol;
        let mut floor = floor_of(self.memory.noise);
        // Newton's error bound: κ of the tolerance, and at most the tolerance's share of the
        // step's own increment, so that it cannot pile up over many small steps (summed over a
        // run it stays below tol × the path the coordinates travel)
        let increment = self.norm(
            q.as_slice().iter().zip(st.q.as_slice()).map(|(a, b)| a - b),
            &q,
        );
        let kappa = KAPPA.min(INCREMENT_SHARE * self.settings.tolerance * increment);
        for it in 0..MAX_NEWTON {
            if !self.matrix.is_factored() {
                let at = Point {
                    q: &q,
                    v: &v,
                    a: &qdd,
                    lambda: &lambda,
                    t: t_new,
                };
                if !self.factorize(sys, &at, h, &c) {
                    self.forget();
                    return Err(Failure::Singular);
                }
                stats.jacobians += 1;
                // a new matrix: its point, and a rate not yet measured (the grid, the
                // controller and the noise level are the run's, not the matrix's)
                self.memory.point = Some(MatrixPoint {
                    q: q.clone(),
                    v: v.clone(),
                    qdd: qdd.clone(),
                    lambda: lambda.clone(),
                    t: t_new,
                    h,
                });
                self.memory.contraction.fresh();
                fresh = true;
                k = 0;
                prev = f64::INFINITY;
            }
            sys.body_residual(&q, &v, &qdd, t_new, &mut self.r);
            sys.constraints_and_rows(&q, t_new, &mut self.g, &mut self.gm);
            self.gm.add_transpose_times(&lambda, &mut self.r);
            for i in 0..n {
                self.rhs[i] = -d * self.r[i];
            }
            for k in 0..m {
                self.rhs[n + k] = -self.g[k];
            }
            if !self.solve_turned(&q) {
                self.forget();
                return Err(Failure::Singular);
            }
            stats.newton_iterations += 1;
            iterations += 1;
            // on slices, not through nalgebra's strided iterators (every iteration); the
            // operations of q += Δq, q' += γ' Δq, q'' += β' Δq
            let (dq, dl) = self.rhs.as_slice().split_at(n);
            {
                let (q1, v1) = (&mut q.as_mut_slice()[..n], &mut v.as_mut_slice()[..n]);
                let qdd1 = &mut qdd.as_mut_slice()[..n];
                for i in 0..n {
                    q1[i] += dq[i];
                    v1[i] += gamma_p * dq[i];
                    qdd1[i] += beta_p * dq[i];
                }
            }
            for (l, x) in lambda.as_mut_slice().iter_mut().zip(&dl[..m]) {
                *l += x / d;
            }
            if !dq.iter().all(|x| x.is_finite()) || !q.as_slice().iter().all(|x| x.is_finite()) {
                self.forget();
                return Err(Failure::NonFinite);
            }
            norm = self.norm(dq.iter().copied(), &q);
            let ratio = norm / prev;
            let size = norm * tol / f64::EPSILON;
            if fresh
                && k >= 1
                && size <= NOISE_CEILING
                && (ratio > NOISE_STAGNANT || (ratio > NOISE_RATIO && size <= NOISE_SMALL))
            {
                self.memory.noise = size;
                floor = floor_of(self.memory.noise);
            }
            let verdict = self.memory.contraction.judge(
                k,
                norm,
                prev,
                floor,
                MAX_NEWTON - 1 - it,
                kappa,
                fresh,
            );
            k += 1;
            match verdict {
                Verdict::Converged => {
                    let mut acc = qdd.clone();
                    let (a0, qdd0) = (&st.acc.as_slice()[..n], &st.qdd.as_slice()[..n]);
                    for (i, a) in acc.as_mut_slice()[..n].iter_mut().enumerate() {
                        *a = next_acc(&c, qdd0[i], a0[i], *a);
                    }
                    // coordinates of massless bodies are algebraic: their accelerations enter
                    // no equation, and the scheme's recurrence would let them grow without bound
                    for &k in &self.algebraic {
                        acc[k] = 0.0;
                        qdd[k] = 0.0;
                    }
                    let err = if self.settings.adaptive {
                        self.error_norm(st, t_new, &q, &c)
                    } else {
                        0.0
                    };
                    let stale = if self.turning.is_some() {
                        STALE_TURNED
                    } else {
                        STALE
                    };
                    if self.memory.contraction.slow(stale) {
                        self.forget(); // slow: a new matrix for the next step
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
                Verdict::Continue => {
                    prev = norm;
                    // a matrix that contracts slowly (it was evaluated at a predictor far from
                    // the solution, or steps ago) is evaluated again at the current iterate,
                    // close to the solution: Newton's own quadratic convergence; so is one
                    // evaluated for this step, at its predictor, whose remaining corrections
                    // cost more than a new one (a matrix kept from earlier steps is judged by
                    // its rate: `STALE`)
                    let pays = || fresh && self.refresh_pays(norm, kappa, n + m);
                    if k > 2
                        && refreshed < MAX_REFRESH
                        && (self.memory.contraction.stalls() || pays())
                    {
                        self.matrix.forget();
                        refreshed += 1;
                    }
                }
                Verdict::Diverging => break,
            }
        }
        self.forget();
        Err(Failure::Newton {
            iterations,
            correction: norm,
            fresh,
        })
    }
}

/// The algorithmic acceleration a_{n+1} = (α_f q''_n - α_m a_n + (1 - α_f) q''_{n+1}) / (1 - α_m)
/// of one coordinate, its operations in the order of the vector expression it replaces.
fn next_acc(c: &Coefficients, qdd_old: f64, acc_old: f64, qdd_new: f64) -> f64 {
    (qdd_old * c.alpha_f - acc_old * c.alpha_m + qdd_new * (1.0 - c.alpha_f)) / (1.0 - c.alpha_m)
}
