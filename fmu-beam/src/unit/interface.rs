//! Direct feedthrough at a mechanical interface, for masters that join units mechanically:
//! the kinematics of each frame that carries an input load (outputs `<load>.x … .ax .ay
//! .alpha`), accelerations consistent with the inputs as set now, the exact partial
//! derivatives of outputs with respect to inputs (fmi2GetDirectionalDerivative) and the inputs
//! each output depends on directly (ModelStructure).
//!
//! At a communication point the state (q, q', t) is fixed; what an input set now changes at
//! once is the acceleration: [[M, Gᵀ], [G, 0]] [q''; λ] = [Q(q, q', t, u); −bias(q, q', t)]
//! with Q linear in the force inputs (input loads, effort drives). So ∂q''/∂u_j solves the same
//! matrix with ∂Q/∂u_j ([`System::input_force`], [`System3::input_force`]) on the right, and a
//! frame's acceleration J_F q'' + bias_F has ∂/∂u_j = J_F ∂q''/∂u_j: the column j of the
//! interface mobility. The matrix is factorized once per state and reused (`Feedthrough`).
//!
//! What the inputs are at a communication point: their values as set (the derivatives given by
//! fmi2SetRealInputDerivatives only shape them inside the next step), the motion inputs'
//! derivatives as the prescribed rates (a motion drive's bias uses its second derivative).
//!
//! The derivatives involve no finite differences. The values do in one place each in 3D: the
//! velocity-dependent part of a frame's angular acceleration is a central difference along q'
//! (relative error about 1e-8 of that part), and the joints' acceleration bias is the 3D
//! system's own second difference; the FMU's documentation says so ([`explain`]). A frame's
//! translation bias is exact: the position is a polynomial of degree 3 in q, whose central
//! second difference along q' is exact.
//!
//! # References
//! - Gu, B., Asada, H. H. (2004): Co-simulation of algebraically coupled dynamic subsystems
//!   without disclosure of proprietary subsystem models. J. Dyn. Syst. Meas. Control 126(1).
//! - Arnold, M., Günther, M. (2001): Preconditioned dynamic iteration for coupled
//!   differential-algebraic systems. BIT 41(1): the contractivity of co-simulation depends on
//!   the direct feedthrough ∂y/∂u between units.

use crate::error::EngineError;
use crate::integrator::GaState;
use crate::mechanics::multibody::equations::Equations;
use crate::mechanics::multibody::law::{InputValue, Law};
use crate::mechanics::Mechanics;
use crate::scene::{DriveKind, Scene};
use crate::unit::variables::{Binding, Causality, OutputKind, VarType, Variable, VariableTable};
use nalgebra::{DMatrix, DVector, Dyn, Vector2, Vector3, LU};

/// A kinematic quantity of a frame, world axes (`usize`: axis 0, 1, 2 = x, y, z).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameQuantity {
    Position(usize),
    /// Planar: the frame's world angle.
    Angle,
    Velocity(usize),
    /// Planar: axis 2 (about z).
    AngularVelocity(usize),
    Acceleration(usize),
    AngularAcceleration(usize),
}

impl FrameQuantity {
    /// Depends directly on the force inputs (an acceleration) rather than on the state alone.
    pub fn is_acceleration(self) -> bool {
        matches!(
            self,
            FrameQuantity::Acceleration(_) | FrameQuantity::AngularAcceleration(_)
        )
    }
}

/// The outputs of the frame of an input load: (name suffix, quantity, unit, description).
pub fn frame_outputs(
    dimensions: usize,
) -> Vec<(&'static str, FrameQuantity, &'static str, &'static str)> {
    use FrameQuantity as Q;
    const ACC: &str = "Acceleration of the load's frame, world axes, consistent with the \
                       inputs as set now (direct feedthrough of the force inputs)";
    const ALPHA: &str = "Angular acceleration of the load's frame, world axes, consistent with \
                         the inputs as set now (direct feedthrough of the force inputs)";
    if dimensions == 3 {
        let xyz = ["x", "y", "z"];
        let mut v = Vec::new();
        let names: [[&str; 3]; 5] = [
            xyz,
            ["vx", "vy", "vz"],
            ["wx", "wy", "wz"],
            ["ax", "ay", "az"],
            ["alphax", "alphay", "alphaz"],
        ];
        for (row, n) in names.iter().enumerate() {
            for (i, name) in n.iter().enumerate() {
                v.push(match row {
                    0 => (
                        *name,
                        Q::Position(i),
                        "m",
                        "World position of the load's frame",
                    ),
                    1 => (*name, Q::Velocity(i), "m/s", "Velocity of the load's frame"),
                    2 => (
                        *name,
                        Q::AngularVelocity(i),
                        "rad/s",
                        "Angular velocity of the load's frame, world axes",
                    ),
                    3 => (*name, Q::Acceleration(i), "m/s2", ACC),
                    _ => (*name, Q::AngularAcceleration(i), "rad/s2", ALPHA),
                });
            }
        }
        return v;
    }
    vec![
        ("x", Q::Position(0), "m", "World x of the load's frame"),
        ("y", Q::Position(1), "m", "World y of the load's frame"),
        ("phi", Q::Angle, "rad", "World angle of the load's frame"),
        (
            "vx",
            Q::Velocity(0),
            "m/s",
            "Velocity of the load's frame, x",
        ),
        (
            "vy",
            Q::Velocity(1),
            "m/s",
            "Velocity of the load's frame, y",
        ),
        (
            "omega",
            Q::AngularVelocity(2),
            "rad/s",
            "Angular velocity of the load's frame",
        ),
        ("ax", Q::Acceleration(0), "m/s2", ACC),
        ("ay", Q::Acceleration(1), "m/s2", ACC),
        ("alpha", Q::AngularAcceleration(2), "rad/s2", ALPHA),
    ]
}

/// The owner (beam or body name) of a scene frame name; `None` for the world.
fn owner(frame: &str) -> Option<&str> {
    (frame != "world").then(|| frame.split_once('.').map_or(frame, |(o, _)| o))
}

/// The inputs each variable depends on directly (value references), structurally: the
/// acceleration of an input load's frame on every force input (input load, effort drive) that
/// acts on a body joined to it by joints (not through the world); an effort drive's effort on
/// its own input; the constraint residual on the motion inputs (g = s(q) − u). Everything else
/// is a function of the state alone. Empty for non-outputs.
pub fn dependencies(scene: &Scene, vars: &[Variable]) -> Vec<Vec<u32>> {
    // connected components of the owners, joined by joints that do not touch the world
    let mut names: Vec<&str> = scene.beams.iter().map(|b| b.name.as_str()).collect();
    names.extend(scene.bodies.iter().map(|b| b.name.as_str()));
    let index = |n: &str| names.iter().position(|x| *x == n);
    let mut parent: Vec<usize> = (0..names.len()).collect();
    fn root(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    for j in &scene.joints {
        if let (Some(a), Some(b)) = (
            owner(&j.frames[0]).and_then(index),
            owner(&j.frames[1]).and_then(index),
        ) {
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            parent[ra] = rb;
        }
    }
    let mut component = |frame: &str| owner(frame).and_then(index).map(|i| root(&mut parent, i));
    // each input: (vr, components it acts on, what it is)
    #[derive(PartialEq)]
    enum Acts {
        /// A force: a load or an effort drive.
        Force,
        /// A motion input's value (its rate acts on nothing at a communication point).
        Motion,
        MotionRate,
        /// A motion input's acceleration: acts on the accelerations as a force does.
        MotionAcceleration,
    }
    let slots = crate::mechanics::multibody::system::input_slots(scene);
    let mut inputs: Vec<(u32, Vec<usize>, Acts)> = Vec::new();
    for v in vars {
        let (slot, order) = match v.binding {
            Binding::Input(slot) => (slot, 0),
            Binding::InputDerivative { slot, order } => (slot, order),
            _ => continue,
        };
        let name = &slots[slot].name;
        let mut acts = Vec::new();
        let mut what = Acts::Force;
        for j in &scene.joints {
            let Some(d) = &j.drive else { continue };
            if d.law.law == "input" && name.starts_with(&format!("{}.drive.", j.name)) {
                if d.kind == DriveKind::Motion {
                    what = [Acts::Motion, Acts::MotionRate, Acts::MotionAcceleration]
                        .into_iter()
                        .nth(order as usize)
                        .expect("order 0, 1 or 2");
                }
                acts.extend(j.frames.iter().filter_map(|f| component(f)));
            }
        }
        for l in scene.loads.iter().filter(|l| l.input) {
            if name.starts_with(&format!("{}.", l.name)) {
                acts.extend(component(&l.frame));
            }
        }
        inputs.push((v.vr, acts, what));
    }
    // the inputs that move the accelerations of component c at once
    let accelerating = |c: Option<usize>| -> Vec<u32> {
        inputs
            .iter()
            .filter(|(_, acts, what)| {
                matches!(what, Acts::Force | Acts::MotionAcceleration)
                    && c.is_some_and(|c| acts.contains(&c))
            })
            .map(|x| x.0)
            .collect()
    };
    vars.iter()
        .map(|v| {
            if v.causality != Causality::Output {
                return Vec::new();
            }
            match v.binding {
                Binding::Output(OutputKind::LoadFrame(l, q)) if q.is_acceleration() => {
                    accelerating(component(&scene.loads[l].frame))
                }
                Binding::Output(OutputKind::DriveReaction(j)) => {
                    let frames = &scene.joints[j].frames;
                    accelerating(component(&frames[1]).or_else(|| component(&frames[0])))
                }
                Binding::Output(OutputKind::JointEffort(j)) => {
                    let jt = &scene.joints[j];
                    match &jt.drive {
                        Some(d) if d.kind == DriveKind::Effort && d.law.law == "input" => {
                            let prefix = format!("{}.drive.", jt.name);
                            vars.iter()
                                .filter(|x| {
                                    matches!(x.binding, Binding::Input(_))
                                        && x.name.starts_with(&prefix)
                                })
                                .map(|x| x.vr)
                                .collect()
                        }
                        _ => Vec::new(),
                    }
                }
                Binding::Output(OutputKind::ConstraintResidual) => inputs
                    .iter()
                    .filter(|x| x.2 == Acts::Motion)
                    .map(|x| x.0)
                    .collect(),
                _ => Vec::new(),
            }
        })
        .collect()
}

/// The inputs' values and first two derivatives at `t` of the polynomials a step applied
/// (3 per input, as `Engine`'s applied inputs): what the step ended with.
pub fn inputs_ended(sys: &Mechanics, t: f64) -> Vec<f64> {
    sys.inputs()
        .iter()
        .flat_map(|u| {
            let dt = t - u.t0;
            [
                u.value + u.der1 * dt + 0.5 * u.der2 * dt * dt,
                u.der1 + u.der2 * dt,
                u.der2,
            ]
        })
        .collect()
}

/// Whether the inputs as set for the next step (value, der1, der2 at its start, 3 per input)
/// differ in any part from what the last step ended with ([`inputs_ended`]): where none does,
/// the inputs go on as the unit extrapolated them, and its steps need not land on the
/// communication point.
pub fn inputs_changed(ended: &[f64], next: &[f64]) -> bool {
    ended.len() != next.len() || ended.iter().zip(next).any(|(&a, &b)| differ(a, b))
}

/// Two input parts differ beyond rounding.
fn differ(a: f64, b: f64) -> bool {
    (a - b).abs() > 1e-10 * a.abs().max(b.abs())
}

/// Whether the inputs as set for the next step (value, der1, der2 at its start, 3 per input)
/// jump from what the last step ended with ([`inputs_ended`]): a force input whose value
/// jumps, or a motion input whose value, rate or acceleration jumps. Then the integrator
/// restarts from consistent accelerations. A force input continuous in value whose derivatives
/// change (a kink, as a master's piecewise-linear interface force makes) is no jump: restarting
/// there would reset the generalized-α algorithmic accelerations every step and cost the
/// scheme its second order (measured on the coupled slider-crank).
pub fn inputs_jump(ended: &[f64], next: &[f64], sys: &Mechanics) -> bool {
    if ended.len() != next.len() {
        return true;
    }
    let motion = motion_slots(sys);
    (0..next.len() / 3).any(|k| {
        let parts = if motion[k] { 3 } else { 1 };
        (0..parts).any(|p| differ(ended[3 * k + p], next[3 * k + p]))
    })
}

/// Per input slot: read by a motion drive.
fn motion_slots(sys: &Mechanics) -> Vec<bool> {
    let mut motion = vec![false; sys.inputs().len()];
    let drives: Vec<&crate::mechanics::multibody::joint::Drive> = match sys {
        Mechanics::Planar(s, _) => s.joints.iter().filter_map(|j| j.drive.as_ref()).collect(),
        Mechanics::Spatial(s, _) => s.joints.iter().filter_map(|j| j.drive.as_ref()).collect(),
    };
    for d in drives {
        if let (DriveKind::Motion, Law::Input(slot)) = (d.kind, &d.law.law) {
            if let Some(m) = motion.get_mut(*slot) {
                *m = true;
            }
        }
    }
    motion
}

/// What the unit's FMU documentation says about its direct feedthrough and derivatives.
pub fn explain(scene: &Scene, table: &VariableTable) -> String {
    let mut t = String::from(
        "fmi2GetDirectionalDerivative gives exact partial derivatives of outputs with respect to \
         inputs at the current communication point (providesDirectionalDerivative = true): with the \
         state (q, q') fixed, the force inputs enter the accelerations linearly through \
         [[M, G^T], [G, 0]] [q''; lambda] = [Q; -bias], which the unit factorizes and solves with \
         each input's generalized force on the right: the derivatives involve no finite \
         differences. Unknowns must be Real outputs and knowns Real inputs; any other reference is \
         refused with fmi2Error and a message naming it.\n\n",
    );
    let feeds: Vec<String> = table
        .variables
        .iter()
        .filter(|v| !v.dependencies.is_empty())
        .map(|v| {
            let deps: Vec<&str> = v
                .dependencies
                .iter()
                .filter_map(|&d| table.get(d).map(|x| x.name.as_str()))
                .collect();
            format!("  {} <- {}", v.name, deps.join(", "))
        })
        .collect();
    if feeds.is_empty() {
        t.push_str("No output depends directly on an input (ModelStructure: dependencies=\"\").\n");
    } else {
        t.push_str(
            "Outputs that depend directly on inputs (ModelStructure lists exactly these; every \
             other output is a function of the state alone):\n",
        );
        t.push_str(&feeds.join("\n"));
        t.push('\n');
    }
    if scene.loads.iter().any(|l| l.input) {
        t.push_str(
            "\nThe frame of each input load offers its position, velocity and acceleration \
             (<load>.x ... .ax ... .alpha): the accelerations are consistent with the inputs as \
             set now (their values; a motion input's derivatives give its prescribed rate and \
             acceleration), so d(<load>.ax)/d(<load>.fx) is the frame's mobility.",
        );
        if scene.is_3d() {
            t.push_str(
                " In 3D two velocity-dependent terms of the acceleration values are differences \
                 along q': the joints' acceleration bias (second differences of the constraints, \
                 the integrator's own) and the frame's angular-acceleration bias (a central \
                 difference of its angular velocity, relative error about 1e-8 of that term); the \
                 frame's translation bias is exact, and the derivatives involve no differences.",
            );
        }
        t.push('\n');
    }
    let motion_inputs = scene.joints.iter().any(|j| {
        j.drive
            .as_ref()
            .is_some_and(|d| d.kind == DriveKind::Motion && d.law.law == "input")
    });
    if motion_inputs {
        t.push_str(
            "\nEach motion drive reading an input offers its prescribed motion's rate and \
             acceleration as inputs of their own (<joint>.drive.speed or .velocity, \
             <joint>.drive.acceleration: the values fmi2SetRealInputDerivatives sets; setting the \
             motion's value resets them, and within one fmi2SetReal call values are set first) \
             and its reaction <joint>.drive.reaction consistent with the state and the inputs as \
             set now: d(<joint>.drive.reaction)/d(<joint>.drive.acceleration) is the interface's \
             effective inertia (mass), what a master coupling in motion causality needs. \
             <joint>.torque or .force stays the reaction of the last step.\n",
        );
    }
    t.push_str(
        "\nsolver.next_event_time is the next time where a drive or load law jumps (the unit \
         lands there and restarts its integrator); a master joining units mechanically lands \
         there too. An input whose value jumps between steps restarts the integrator; one that \
         only changes its derivatives (a ramp that continues the last one) does not. While the \
         inputs go on as the last step extrapolated them (held, or left alone), the unit steps \
         past communication points and interpolates its outputs there, so that its run does not \
         depend on how the master cuts time; after a point where the master changed them, its \
         steps land on the next one, and an input changed while the unit is past the point has \
         its last step redone to land there.\n",
    );
    t
}

/// The first jump of a drive or load law after `t` (as `Stepper::step_to` finds the breakpoints
/// it lands on), f64::MAX when none.
pub fn next_event_time(sys: &Mechanics, t: f64) -> f64 {
    sys.breakpoints()
        .into_iter()
        .find(|&b| b > t * (1.0 + 1e-14) + 1e-14)
        .unwrap_or(f64::MAX)
}

/// Refuses a directional-derivative request whose references are not (Real) outputs and inputs.
pub fn check_references(
    table: &VariableTable,
    unknowns: &[u32],
    knowns: &[u32],
) -> Result<(), EngineError> {
    let check = |vr: u32, role: &'static str, want: Causality| {
        let refuse = |name: Option<String>, reason: String| EngineError::DirectionalDerivative {
            vr,
            role,
            name,
            reason,
        };
        let Some(v) = table.get(vr) else {
            return Err(refuse(None, "no variable has this value reference".into()));
        };
        if v.causality != want || v.ty != VarType::Real {
            return Err(refuse(
                Some(v.name.clone()),
                format!(
                    "it is a {} {} variable; {role}s must be Real {} variables",
                    v.ty.as_str(),
                    v.causality.as_str(),
                    want.as_str()
                ),
            ));
        }
        Ok(())
    };
    for &vr in unknowns {
        check(vr, "unknown", Causality::Output)?;
    }
    for &vr in knowns {
        check(vr, "known", Causality::Input)?;
    }
    Ok(())
}

/// The state and inputs that consistent accelerations belong to: (t, q, q', inputs).
type AccelKey = (f64, DVector<f64>, DVector<f64>, Vec<InputValue>);

/// The consistent accelerations at the current state and inputs, with the factorized matrix
/// [[M, Gᵀ], [G, 0]] kept for the derivatives; recomputed when the state or inputs change.
#[derive(Debug, Clone, Default)]
pub struct Feedthrough {
    /// (t, q) of the factorization.
    matrix_at: Option<(f64, DVector<f64>)>,
    lu: Option<LU<f64, Dyn, Dyn>>,
    /// (t, q, q', inputs) of `qdd`.
    accel_at: Option<AccelKey>,
    qdd: DVector<f64>,
    /// The multipliers that go with `qdd`.
    lambda: DVector<f64>,
}

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
fn drive_of(
    sys: &Mechanics,
    j: usize,
) -> Option<(DriveKind, &crate::mechanics::multibody::law::TimeLaw)> {
    let d = match sys {
        Mechanics::Planar(s, _) => s.joints[j].drive.as_ref(),
        Mechanics::Spatial(s, _) => s.joints[j].drive.as_ref(),
    };
    d.map(|d| (d.kind, &d.law))
}

/// One-sided directional derivative of max_k |g_k| (the constraint residual output): g depends
/// on the motion inputs u through the drive rows g = s(q) − law(u).
fn residual_derivative(
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
fn motion_rows(sys: &Mechanics) -> Vec<(usize, &crate::mechanics::multibody::law::TimeLaw)> {
    let joints = match sys {
        Mechanics::Planar(s, _) => s.joints.len(),
        Mechanics::Spatial(s, _) => s.joints.len(),
    };
    (0..joints)
        .filter_map(|j| {
            let Some((DriveKind::Motion, law)) = drive_of(sys, j) else {
                return None;
            };
            let row = match sys {
                Mechanics::Planar(s, _) => {
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
fn second(sys: &Mechanics, s: usize, t: f64) -> Vec<InputValue> {
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
fn joint_effort(sys: &Mechanics, j: usize, lambda: &DVector<f64>, t: f64) -> f64 {
    match sys {
        Mechanics::Planar(s, _) => s.joint_effort(j, lambda, t),
        Mechanics::Spatial(s, _) => s.joint_effort(j, lambda, t),
    }
}

/// ∂Q/∂u of one input slot at time t, as (coordinate, value) pairs.
fn input_force(sys: &Mechanics, st: &GaState, t: f64, slot: usize) -> Vec<(usize, f64)> {
    match sys {
        Mechanics::Planar(s, _) => s.input_force(&st.q, &st.v, t, slot),
        Mechanics::Spatial(s, _) => s.input_force(&st.q, t, slot),
    }
}

/// A time just after t, as the integrator restarts at a jump of a law
/// (`generalized_alpha::restart`): a law that stops at t acts no more.
fn just_after(t: f64) -> f64 {
    t * (1.0 + 1e-13) + 1e-13
}

/// The system frame of scene load `load` (an input load: its frame is the load's).
fn load_frame(sys: &Mechanics, scene: &Scene, load: usize) -> usize {
    let name = &scene.loads[load].name;
    match sys {
        Mechanics::Planar(s, _) => {
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
fn jacobian_times(
    sys: &Mechanics,
    st: &GaState,
    f: usize,
    a: &DVector<f64>,
    what: FrameQuantity,
) -> f64 {
    use FrameQuantity as Q;
    match sys {
        Mechanics::Planar(s, _) => {
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
fn frame_value(
    sys: &Mechanics,
    st: &GaState,
    qdd: &DVector<f64>,
    f: usize,
    what: FrameQuantity,
) -> f64 {
    use FrameQuantity as Q;
    let (q, v) = (&st.q, &st.v);
    match sys {
        Mechanics::Planar(s, _) => {
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
fn spatial_translation_bias(
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
fn spatial_rotation_bias(
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
