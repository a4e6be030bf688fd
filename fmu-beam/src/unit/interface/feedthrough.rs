//! The unit's feedthrough: the consistent accelerations at the current state and inputs (what
//! the frames of input loads and a motion drive's reaction read), and
//! fmi2GetDirectionalDerivative, exact, from the factorized [[M, Gᵀ], [G, 0]].

use super::*;
use crate::mechanics::DriveKind;

impl Feedthrough {
    /// Factorizes the matrix at (q, t) unless it already is.
    fn factorize(&mut self, sys: &Mechanics, st: &GaState) -> Result<(), EngineError> {
        if matches!(&self.matrix_at, Some((t, q)) if *t == st.t && *q == st.q) {
            return Ok(());
        }
        let (n, m) = (sys.n(), sys.m());
        let mut mm = DMatrix::zeros(n, n);
        sys.mass_matrix(&st.q, &mut mm);
        let mut gm = DMatrix::zeros(m, n);
        sys.constraint_jacobian(&st.q, st.t, &mut gm);
        let mut a = DMatrix::zeros(n + m, n + m);
        a.view_mut((0, 0), (n, n)).copy_from(&mm);
        a.view_mut((0, n), (n, m)).copy_from(&gm.transpose());
        a.view_mut((n, 0), (m, n)).copy_from(&gm);
        let lu = a.lu();
        if !lu.is_invertible() {
            self.matrix_at = None;
            return Err(EngineError::FeedthroughSingular { t: st.t });
        }
        self.lu = Some(lu);
        self.matrix_at = Some((st.t, st.q.clone()));
        Ok(())
    }

    /// Solves the factorized matrix for right-hand sides (n + m); non-finite → singular.
    fn solve(&self, rhs: &DVector<f64>, t: f64) -> Result<DVector<f64>, EngineError> {
        self.lu
            .as_ref()
            .and_then(|lu| lu.solve(rhs))
            .filter(|x| x.iter().all(|v| v.is_finite()))
            .ok_or(EngineError::FeedthroughSingular { t })
    }

    /// q'' consistent with the state and the inputs as set now, just after the current time
    /// (at a jump of a law, the accelerations the unit continues with, as its restart there).
    fn accelerations(&mut self, sys: &mut Mechanics, st: &GaState) -> Result<(), EngineError> {
        let te = just_after(st.t);
        // inputs hold their set values at the current point
        for u in sys.inputs_mut().iter_mut() {
            u.t0 = te;
        }
        let key_matches = matches!(&self.accel_at,
            Some((t, q, v, u)) if *t == st.t && *q == st.q && *v == st.v && u == sys.inputs());
        if key_matches {
            return Ok(());
        }
        self.factorize(sys, st)?;
        let (n, m) = (sys.n(), sys.m());
        let mut r = DVector::zeros(n);
        sys.body_residual(&st.q, &st.v, &DVector::zeros(n), te, &mut r);
        let mut bias = DVector::zeros(m);
        sys.accel_bias(&st.q, &st.v, te, &mut bias);
        let mut rhs = DVector::zeros(n + m);
        rhs.rows_mut(0, n).copy_from(&(-r));
        rhs.rows_mut(n, m).copy_from(&(-bias));
        let x = self.solve(&rhs, st.t)?;
        self.qdd = x.rows(0, n).into_owned();
        self.lambda = x.rows(n, m).into_owned();
        self.accel_at = Some((st.t, st.q.clone(), st.v.clone(), sys.inputs().to_vec()));
        Ok(())
    }

    /// The value of a frame output of scene load `load`.
    pub fn frame_output(
        &mut self,
        sys: &mut Mechanics,
        st: &GaState,
        scene: &Scene,
        load: usize,
        what: FrameQuantity,
    ) -> Result<f64, EngineError> {
        if what.is_acceleration() {
            self.accelerations(sys, st)?;
        }
        let f = load_frame(sys, scene, load);
        Ok(frame_value(sys, st, &self.qdd, f, what))
    }

    /// The reaction of the motion drive of system joint `j`, consistent with the state and the
    /// inputs as set now (the multiplier of the acceleration-level solve, not the last step's).
    pub fn drive_reaction(
        &mut self,
        sys: &mut Mechanics,
        st: &GaState,
        j: usize,
    ) -> Result<f64, EngineError> {
        self.accelerations(sys, st)?;
        Ok(joint_effort(sys, j, &self.lambda, just_after(st.t)))
    }

    /// Σ_j ∂y_i/∂u_j dv_j for each unknown y_i (references checked by [`check_references`]).
    #[allow(clippy::too_many_arguments)]
    pub fn directional_derivative(
        &mut self,
        sys: &mut Mechanics,
        st: &GaState,
        scene: &Scene,
        table: &VariableTable,
        joint_index: &[usize],
        unknowns: &[u32],
        knowns: &[u32],
        dv: &[f64],
    ) -> Result<Vec<f64>, EngineError> {
        let te = just_after(st.t);
        for u in sys.inputs_mut().iter_mut() {
            u.t0 = te;
        }
        // the input slot a known sets by value (a rate or acceleration input sets none: only the
        // acceleration solve below reads those)
        let slot = |vr: u32| match table.get(vr).map(|v| v.binding) {
            Some(Binding::Input(s)) => Some(s),
            _ => None,
        };
        let needs_accel = unknowns.iter().any(|&vr| {
            matches!(
                table.get(vr).map(|v| v.binding),
                Some(Binding::Output(OutputKind::LoadFrame(_, q))) if q.is_acceleration()
            ) || matches!(
                table.get(vr).map(|v| v.binding),
                Some(Binding::Output(OutputKind::DriveReaction(_)))
            )
        });
        // ∂q'', ∂λ along dv
        let (n, m) = (sys.n(), sys.m());
        let mut dqdd = DVector::zeros(n);
        let mut dlambda = DVector::zeros(m);
        if needs_accel {
            let mut rhs = DVector::zeros(n + m);
            for (&vr, &d) in knowns.iter().zip(dv) {
                if d == 0.0 {
                    continue;
                }
                match table.get(vr).map(|v| v.binding) {
                    Some(Binding::Input(s)) => {
                        for (k, x) in input_force(sys, st, te, s) {
                            rhs[k] += x * d;
                        }
                    }
                    Some(Binding::InputDerivative { slot: s, order: 2 }) => {
                        for (row, law) in motion_rows(sys) {
                            if law.law == Law::Input(s) {
                                // g'' = G q'' + bias_q − law'': the row's right side is +law''
                                rhs[n + row] += law.eval(te, &second(sys, s, te)).2 * d;
                            }
                        }
                    }
                    // the rate does not act at the communication point: the state's velocity does
                    _ => {}
                }
            }
            self.factorize(sys, st)?;
            let x = self.solve(&rhs, st.t)?;
            dqdd = x.rows(0, n).into_owned();
            dlambda = x.rows(n, m).into_owned();
        }
        let unit = |s: usize| InputValue::unit(sys.inputs().len(), s, st.t);
        let mut out = Vec::with_capacity(unknowns.len());
        for &vr in unknowns {
            let kind = match table.get(vr).map(|v| v.binding) {
                Some(Binding::Output(kind)) => kind,
                _ => unreachable!("checked: unknowns are outputs"),
            };
            let d = match kind {
                OutputKind::LoadFrame(l, what) if what.is_acceleration() => {
                    let f = load_frame(sys, scene, l);
                    jacobian_times(sys, st, f, &dqdd, what)
                }
                OutputKind::JointEffort(j) => {
                    // an effort drive reading an input: effort = law(u), linear
                    let drive = drive_of(sys, joint_index[j]);
                    knowns
                        .iter()
                        .zip(dv)
                        .map(|(&vr, &d)| match drive {
                            Some((DriveKind::Effort, law)) => match slot(vr) {
                                Some(s) if law.law == Law::Input(s) => {
                                    law.eval(st.t, &unit(s)).0 * d
                                }
                                _ => 0.0,
                            },
                            _ => 0.0,
                        })
                        .sum()
                }
                OutputKind::ConstraintResidual => {
                    residual_derivative(sys, st, knowns, dv, slot, &unit)
                }
                // linear in λ (a motion drive's effort is −λ of its row)
                OutputKind::DriveReaction(j) => joint_effort(sys, joint_index[j], &dlambda, te),
                _ => 0.0,
            };
            out.push(d);
        }
        Ok(out)
    }
}

/// The drive kind and law of system joint `j`.
pub(super) fn drive_of(
    sys: &Mechanics,
    j: usize,
) -> Option<(DriveKind, &crate::mechanics::multibody::law::TimeLaw)> {
    let d = match sys {
        Mechanics::Planar(s) => s.joints[j].drive.as_ref(),
        Mechanics::Spatial(s, _) => s.joints[j].drive.as_ref(),
    };
    d.map(|d| (d.kind, &d.law))
}

/// One-sided directional derivative of max_k |g_k| (the constraint residual output): g depends
/// on the motion inputs u through the drive rows g = s(q) − law(u).
pub(super) fn residual_derivative(
    sys: &Mechanics,
    st: &GaState,
    knowns: &[u32],
    dv: &[f64],
    slot: impl Fn(u32) -> Option<usize>,
    unit: &impl Fn(usize) -> Vec<InputValue>,
) -> f64 {
    let m = sys.m();
    if m == 0 {
        return 0.0;
    }
    let mut g = DVector::zeros(m);
    sys.constraints(&st.q, st.t, &mut g);
    let mut dg: DVector<f64> = DVector::zeros(m);
    for (row, law) in motion_rows(sys) {
        for (&vr, &d) in knowns.iter().zip(dv) {
            if let Some(s) = slot(vr).filter(|&s| law.law == Law::Input(s)) {
                dg[row] -= law.eval(st.t, &unit(s)).0 * d;
            }
        }
    }
    let gmax = g.amax();
    (0..m)
        .filter(|&k| g[k].abs() == gmax)
        .map(|k| {
            if g[k] == 0.0 {
                dg[k].abs()
            } else {
                g[k].signum() * dg[k]
            }
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The constraint row and law of each motion drive (the drive's row is its joint's last).
pub(super) fn motion_rows(
    sys: &Mechanics,
) -> Vec<(usize, &crate::mechanics::multibody::law::TimeLaw)> {
    let joints = match sys {
        Mechanics::Planar(s) => s.joints.len(),
        Mechanics::Spatial(s, _) => s.joints.len(),
    };
    (0..joints)
        .filter_map(|j| {
            let Some((DriveKind::Motion, law)) = drive_of(sys, j) else {
                return None;
            };
            let row = match sys {
                Mechanics::Planar(s) => {
                    let jt = &s.joints[j];
                    jt.row
                        + crate::mechanics::multibody::joint::Joint::rows_count(
                            jt.kind,
                            jt.drive.as_ref(),
                        )
                        - 1
                }
                Mechanics::Spatial(s, _) => s.joint_row(j) + s.joints[j].len() - 1,
            };
            Some((row, law))
        })
        .collect()
}

/// Inputs with a unit second derivative in slot `s` at t and nothing else: a law reading the
/// slot returns its coefficient on the input's acceleration as its own second derivative.
pub(super) fn second(sys: &Mechanics, s: usize, t: f64) -> Vec<InputValue> {
    let mut u = vec![InputValue::default(); sys.inputs().len()];
    u[s] = InputValue {
        value: 0.0,
        der1: 0.0,
        der2: 1.0,
        t0: t,
    };
    u
}

/// The effort of system joint `j`'s drive with multipliers `lambda` (a motion drive's: −λ of
/// its row).
pub(super) fn joint_effort(sys: &Mechanics, j: usize, lambda: &DVector<f64>, t: f64) -> f64 {
    match sys {
        Mechanics::Planar(s) => s.joint_effort(j, lambda, t),
        Mechanics::Spatial(s, _) => s.joint_effort(j, lambda, t),
    }
}

/// ∂Q/∂u of one input slot at time t, as (coordinate, value) pairs.
pub(super) fn input_force(sys: &Mechanics, st: &GaState, t: f64, slot: usize) -> Vec<(usize, f64)> {
    match sys {
        Mechanics::Planar(s) => s.input_force(&st.q, &st.v, t, slot),
        Mechanics::Spatial(s, _) => s.input_force(&st.q, t, slot),
    }
}

/// A time just after t, as the integrator restarts at a jump of a law
/// (`generalized_alpha::restart`): a law that stops at t acts no more.
pub(super) fn just_after(t: f64) -> f64 {
    t * (1.0 + 1e-13) + 1e-13
}

/// The system frame of scene load `load` (an input load: its frame is the load's).
pub(super) fn load_frame(sys: &Mechanics, scene: &Scene, load: usize) -> usize {
    let name = &scene.loads[load].name;
    match sys {
        Mechanics::Planar(s) => {
            s.loads
                .iter()
                .find(|l| &l.name == name)
                .expect("scene load in the system")
                .frame
        }
        Mechanics::Spatial(s, _) => {
            let first = format!("{name}.fx");
            s.loads
                .iter()
                .find(|l| l.name == first || &l.name == name)
                .expect("scene load in the system")
                .frame
        }
    }
}

/// J_F a for frame f: the translation (or rotation) part picked by `what` (the acceleration
/// without its velocity-dependent bias).
pub(super) fn jacobian_times(
    sys: &Mechanics,
    st: &GaState,
    f: usize,
    a: &DVector<f64>,
    what: FrameQuantity,
) -> f64 {
    use FrameQuantity as Q;
    match sys {
        Mechanics::Planar(s) => {
            let fs = s.frame_state(f, &st.q, None);
            let Some(b) = fs.body else { return 0.0 };
            let (w, c) = match what {
                Q::Acceleration(i) | Q::Velocity(i) | Q::Position(i) if i < 2 => {
                    (Vector2::ith(i, 1.0), 0.0)
                }
                Q::AngularAcceleration(2) | Q::AngularVelocity(2) | Q::Angle => {
                    (Vector2::zeros(), 1.0)
                }
                _ => return 0.0, // out of the plane
            };
            fs.jacobian_dot(w, c, s.body_coords(b, a))
        }
        Mechanics::Spatial(s, _) => {
            let (_, cols) = s.frame_jacobian(f, &st.q);
            cols.iter()
                .map(|(k, dx, dth)| match what {
                    Q::Acceleration(i) | Q::Velocity(i) | Q::Position(i) => dx[i] * a[*k],
                    Q::AngularAcceleration(i) | Q::AngularVelocity(i) => dth[i] * a[*k],
                    Q::Angle => 0.0,
                })
                .sum()
        }
    }
}

/// The value of a frame quantity at the current state, with accelerations `qdd`.
pub(super) fn frame_value(
    sys: &Mechanics,
    st: &GaState,
    qdd: &DVector<f64>,
    f: usize,
    what: FrameQuantity,
) -> f64 {
    use FrameQuantity as Q;
    let (q, v) = (&st.q, &st.v);
    match sys {
        Mechanics::Planar(s) => {
            let fs = s.frame_state(f, q, Some(v));
            // a planar model: nothing leaves the plane, rotations are about z
            match what {
                Q::Position(i) if i < 2 => fs.p[i],
                Q::Angle => fs.phi,
                Q::Velocity(i) if i < 2 => fs.pd[i],
                Q::AngularVelocity(2) => fs.phid,
                Q::Acceleration(i) if i < 2 && fs.body.is_some() => {
                    jacobian_times(sys, st, f, qdd, what) + fs.bias_p[i]
                }
                Q::AngularAcceleration(2) => jacobian_times(sys, st, f, qdd, what),
                _ => 0.0,
            }
        }
        Mechanics::Spatial(s, _) => match what {
            Q::Position(i) => s.frame_pose(f, q).0[i],
            Q::Angle => 0.0,
            Q::Velocity(_) | Q::AngularVelocity(_) => jacobian_times(sys, st, f, v, what),
            Q::Acceleration(i) => {
                jacobian_times(sys, st, f, qdd, what) + spatial_translation_bias(s, f, q, v)[i]
            }
            Q::AngularAcceleration(i) => {
                jacobian_times(sys, st, f, qdd, what) + spatial_rotation_bias(s, f, q, v)[i]
            }
        },
    }
}

/// d²x/dt² at q'' = 0 of a 3D frame's position: x(q) = R + A(p)(s0 + S_p q_f) is a polynomial
/// of degree 3 in q, so its central second difference along q' is exact (for any step).
pub(super) fn spatial_translation_bias(
    s: &crate::mechanics::multibody3d::System3,
    f: usize,
    q: &DVector<f64>,
    v: &DVector<f64>,
) -> Vector3<f64> {
    let vmax = v.amax();
    if vmax == 0.0 {
        return Vector3::zeros();
    }
    let e = 1.0 / vmax;
    let x0 = s.frame_pose(f, q).0;
    let xp = s.frame_pose(f, &(q + v * e)).0;
    let xn = s.frame_pose(f, &(q - v * e)).0;
    (xp - x0 * 2.0 + xn) / (e * e)
}

/// (d/dt J_ω) q' of a 3D frame: the central difference of J_ω(q + ε q') q' (relative error
/// about ε² = 1e-8 of the term; documented in the FMU).
pub(super) fn spatial_rotation_bias(
    s: &crate::mechanics::multibody3d::System3,
    f: usize,
    q: &DVector<f64>,
    v: &DVector<f64>,
) -> Vector3<f64> {
    let vmax = v.amax();
    if vmax == 0.0 {
        return Vector3::zeros();
    }
    let e = 1e-4 / vmax;
    let omega = |qq: &DVector<f64>| -> Vector3<f64> {
        let (_, cols) = s.frame_jacobian(f, qq);
        cols.iter().map(|(k, _, dth)| dth * v[*k]).sum()
    };
    (omega(&(q + v * e)) - omega(&(q - v * e))) / (2.0 * e)
}
