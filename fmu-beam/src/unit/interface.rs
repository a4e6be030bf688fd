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

mod feedthrough;

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
    let slots = crate::mechanics::from_scene::input_slots(scene);
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
        Mechanics::Planar(s) => s.joints.iter().filter_map(|j| j.drive.as_ref()).collect(),
        Mechanics::Spatial(s, _) => s.joints.iter().filter_map(|j| j.drive.as_ref()).collect(),
    };
    for d in drives {
        if let (crate::mechanics::DriveKind::Motion, Law::Input(slot)) = (d.kind, &d.law.law) {
            if let Some(m) = motion.get_mut(*slot) {
                *m = true;
            }
        }
    }
    motion
}

/// The scene's `[accuracy]` statement (empty without one), or why it cannot be made: its
/// `output` is not a Real output of the unit (the scene's own validation sees only that it
/// names a part).
pub fn explain_accuracy(scene: &Scene, table: &VariableTable) -> Result<String, String> {
    let Some(a) = &scene.accuracy else {
        return Ok(String::new());
    };
    let outputs: Vec<&str> = table
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Output && v.ty == VarType::Real)
        .map(|v| v.name.as_str())
        .collect();
    if outputs.contains(&a.output.as_str()) {
        return Ok(a.statement(scene));
    }
    const SHOWN: usize = 12;
    let more = if outputs.len() > SHOWN { ", ..." } else { "" };
    Err(format!(
        "accuracy.output = {:?} is not a Real output of the unit; its outputs: {}{more}",
        a.output,
        outputs[..outputs.len().min(SHOWN)].join(", ")
    ))
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
