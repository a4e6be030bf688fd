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
        let mut iterations = 0;
        // corrections since the matrix was factorized, and refactorizations within this step
        let (mut k, mut refreshed) = (0, 0);
        let tol = self.settings.tolerance;
        let floor_of = |noise: f64| ROUNDING.max(NOISE_BAND * noise * f64::EPSILON) / tol;
        let mut floor = floor_of(self.memory.noise);
        // Newton's error bound: κ of the tolerance, and at most the tolerance's share of the
        // step's own increment, so that it cannot pile up over many small steps (summed over a
        // run it stays below tol × the path the coordinates travel)
        let increment = self.norm((&q - &st.q).iter(), &q);
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
            let dq = self.rhs.rows(0, n);
            q += dq;
            v.axpy(gamma_p, &dq, 1.0);
            qdd.axpy(beta_p, &dq, 1.0);
            for k in 0..m {
                lambda[k] += self.rhs[n + k] / d;
            }
            if !dq.iter().all(|x| x.is_finite()) || !q.iter().all(|x| x.is_finite()) {
                self.forget();
                return Err(Failure::NonFinite);
            }
            norm = self.norm(dq.iter(), &q);
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
                    let mut acc = (&st.qdd * c.alpha_f - &st.acc * c.alpha_m
                        + &qdd * (1.0 - c.alpha_f))
                        / (1.0 - c.alpha_m);
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
