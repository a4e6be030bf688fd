//! The variable table of a scene: the single source of the engine's get/set and of the
//! ModelVariables, UnitDefinitions and ModelStructure that the packager writes.

use crate::scene::Scene;
use crate::unit::effects::Effects;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
}

impl VarType {
    pub fn as_str(self) -> &'static str {
        match self {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
}

impl Causality {
    pub fn as_str(self) -> &'static str {
        match self {
            Causality::Parameter => "parameter",
            Causality::CalculatedParameter => "calculatedParameter",
            Causality::Input => "input",
            Causality::Output => "output",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variability {
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

impl Variability {
    pub fn as_str(self) -> &'static str {
        match self {
            Variability::Fixed => "fixed",
            Variability::Tunable => "tunable",
            Variability::Discrete => "discrete",
            Variability::Continuous => "continuous",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Initial {
    Exact,
    Calculated,
}

impl Initial {
    pub fn as_str(self) -> &'static str {
        match self {
            Initial::Exact => "exact",
            Initial::Calculated => "calculated",
        }
    }
}

/// What a parameter changes in the scene before the model is built (or, when tunable, in the
/// running solver).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamTarget {
    GravityX,
    GravityY,
    GravityZ,
    SolverAdaptive,
    SolverTolerance,
    SolverMaxStep,
    SolverRhoInf,
    BeamLength(usize),
    BeamRho(usize),
    BeamE(usize),
    BeamG(usize),
    BeamArea(usize),
    BeamSecondMoment(usize),
    BeamIy(usize),
    BeamIz(usize),
    BeamTorsion(usize),
    BeamRayleighAlpha(usize),
    BeamRayleighBeta(usize),
    BeamTipDisplacement(usize),
    /// A parameter of a joint's drive law.
    DriveValue(usize),
    DriveOmega(usize),
    DriveRampTime(usize),
    DriveTimeConstant(usize),
    DriveUntil(usize),
}

/// What an output or calculated parameter reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind {
    /// Transverse displacement of flange b from the root frame's axis, in the root frame (m).
    TipDeflection(usize),
    TipX(usize),
    TipY(usize),
    TipPhi(usize),
    /// 3D: world z of flange b; its displacement along the root frame's y and z axes from the
    /// root axis (m); its rotation about the beam axis relative to the root (rad).
    TipZ(usize),
    TipDeflectionY(usize),
    TipDeflectionZ(usize),
    TipTwist(usize),
    /// Transverse displacement at mid-span from the root axis (tangent) or the chord (pinned).
    MidDeflection(usize),
    /// Joint coordinate, its rate, and the effort of its drive (scene joint index).
    JointCoordinate(usize),
    JointRate(usize),
    JointEffort(usize),
    /// The reaction of a motion drive reading an input (scene joint index), consistent with
    /// the state and the inputs as set now: depends directly on the input's acceleration.
    DriveReaction(usize),
    /// World coordinate `axis` (0 x, 1 y, 2 z) of shape point `point` (from 0) of scene beam
    /// `beam` ([`crate::unit::shape`]).
    Shape {
        beam: usize,
        point: usize,
        axis: usize,
    },
    /// World component `axis` of the unit direction the deflections of scene beam `usize` are
    /// measured from.
    BeamAxis(usize, usize),
    /// World coordinate `axis` of the second frame of scene joint `joint` (where a revolute,
    /// spherical or weld joint is; the sliding frame of a prismatic joint).
    JointPosition {
        joint: usize,
        axis: usize,
    },
    /// 3D: entry (row, column) of the rotation matrix of a rigid body (body → world: column j
    /// is body axis j in world components).
    BodyRotation {
        body: usize,
        row: usize,
        col: usize,
    },
    /// Pose of a rigid body (scene body index).
    BodyX(usize),
    BodyY(usize),
    BodyZ(usize),
    BodyPhi(usize),
    /// Work done by drives and loads since the start (J).
    EnergyWork,
    /// Calculated section constants of a beam whose section is a shape.
    SectionArea(usize),
    SectionSecondMoment(usize),
    EnergyKinetic,
    EnergyStrain,
    EnergyPotential,
    EnergyTotal,
    SolverSteps,
    SolverNewtonIterations,
    SolverJacobians,
    SolverRejectedSteps,
    SolverSplitSteps,
    /// Largest |g_k(q, t)| over the joint equations (m or rad): the constraint drift.
    ConstraintResidual,
    /// A kinematic quantity of the frame of input load `usize` (scene load index).
    LoadFrame(usize, crate::unit::interface::FrameQuantity),
    /// Time of the next jump of a drive or load law after the current time (f64::MAX if none).
    NextEventTime,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Binding {
    Parameter(ParamTarget),
    Output(OutputKind),
    /// FMU input in this slot of `multibody::system::input_slots`.
    Input(usize),
    /// The first or second time derivative (`order` 1 or 2) of the motion input in `slot`, as
    /// an input of its own: the same value fmi2SetRealInputDerivatives sets.
    InputDerivative {
        slot: usize,
        order: u8,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    pub name: String,
    pub vr: u32,
    pub ty: VarType,
    pub causality: Causality,
    pub variability: Variability,
    pub initial: Option<Initial>,
    pub unit: Option<&'static str>,
    pub description: String,
    /// Start value of parameters (Booleans as 0/1).
    pub start: Option<f64>,
    pub binding: Binding,
    /// Of an output: the inputs (value references) it depends on directly, for ModelStructure
    /// ([`crate::unit::interface::dependencies`]); empty otherwise.
    pub dependencies: Vec<u32>,
}

/// A unit in SI base-unit exponents, for UnitDefinitions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnitDef {
    pub name: &'static str,
    pub kg: i32,
    pub m: i32,
    pub s: i32,
    pub rad: i32,
}

const fn unit(name: &'static str, kg: i32, m: i32, s: i32, rad: i32) -> UnitDef {
    UnitDef {
        name,
        kg,
        m,
        s,
        rad,
    }
}

/// Every unit a variable may use.
pub const UNITS: &[UnitDef] = &[
    unit("m", 0, 1, 0, 0),
    unit("rad", 0, 0, 0, 1),
    unit("s", 0, 0, 1, 0),
    unit("m/s", 0, 1, -1, 0),
    unit("rad/s", 0, 0, -1, 1),
    unit("m/s2", 0, 1, -2, 0),
    unit("rad/s2", 0, 0, -2, 1),
    unit("kg/m3", 1, -3, 0, 0),
    unit("Pa", 1, -1, -2, 0),
    unit("m2", 0, 2, 0, 0),
    unit("m4", 0, 4, 0, 0),
    unit("N", 1, 1, -2, 0),
    unit("N.m", 1, 2, -2, 0),
    unit("J", 1, 2, -2, 0),
    unit("1/s", 0, 0, -1, 0),
];

/// All variables of a scene, in value-reference order (vr = index; unique over all types).
#[derive(Debug, Clone, PartialEq)]
pub struct VariableTable {
    pub variables: Vec<Variable>,
}

impl VariableTable {
    /// The table of a scene with the effects it resolves to.
    pub fn build(scene: &Scene) -> VariableTable {
        VariableTable::build_with(scene, &crate::unit::effects::resolve(scene).effects)
    }

    /// The table of a scene computing `effects`: only the variables of effects that are on
    /// (no gravity parameters without gravity, no stiffness, damping or deflection of a rigid
    /// beam, no damping parameters without damping).
    pub fn build_with(scene: &Scene, effects: &Effects) -> VariableTable {
        let mut t = Builder { vars: Vec::new() };
        use Binding::{Output as O, Parameter as P};
        use Causality as C;
        use OutputKind as K;
        use ParamTarget as T;
        use Variability as V;
        let real_param = |t: &mut Builder, name: String, target, unit, v: f64, var, desc: &str| {
            t.push(
                name,
                VarType::Real,
                C::Parameter,
                var,
                Some(unit),
                desc,
                Some(v),
                P(target),
            );
        };
        let g = scene.world.gravity;
        if effects.gravity {
            real_param(
                &mut t,
                "world.gravity.x".into(),
                T::GravityX,
                "m/s2",
                g[0],
                V::Fixed,
                "Gravity, world x",
            );
            real_param(
                &mut t,
                "world.gravity.y".into(),
                T::GravityY,
                "m/s2",
                g[1],
                V::Fixed,
                "Gravity, world y",
            );
            if scene.is_3d() {
                real_param(
                    &mut t,
                    "world.gravity.z".into(),
                    T::GravityZ,
                    "m/s2",
                    g[2],
                    V::Fixed,
                    "Gravity, world z",
                );
            }
        }
        let s = &scene.solver;
        t.push(
            "solver.adaptive".into(),
            VarType::Boolean,
            C::Parameter,
            V::Tunable,
            None,
            "Local error control (true) or a fixed internal step of solver.max_step (false)",
            Some(if s.adaptive { 1.0 } else { 0.0 }),
            P(T::SolverAdaptive),
        );
        real_param(
            &mut t,
            "solver.tolerance".into(),
            T::SolverTolerance,
            "1",
            s.tolerance,
            V::Tunable,
            "Relative tolerance of the error control and of the Newton iteration",
        );
        real_param(
            &mut t,
            "solver.max_step".into(),
            T::SolverMaxStep,
            "s",
            s.max_step,
            V::Tunable,
            "Largest internal step; the fixed step when solver.adaptive is false",
        );
        real_param(
            &mut t,
            "solver.rho_inf".into(),
            T::SolverRhoInf,
            "1",
            s.rho_inf,
            V::Tunable,
            "Generalized-alpha spectral radius at infinity (1: no numerical damping)",
        );
        for (i, (b, fx)) in scene.beams.iter().zip(&effects.beams).enumerate() {
            let n = &b.name;
            real_param(
                &mut t,
                format!("{n}.length"),
                T::BeamLength(i),
                "m",
                b.length,
                V::Fixed,
                "Undeformed length",
            );
            real_param(
                &mut t,
                format!("{n}.rho"),
                T::BeamRho(i),
                "kg/m3",
                b.material.rho,
                V::Fixed,
                "Density",
            );
            let matrices = b.matrix_text.is_some();
            if !fx.rigid && !matrices {
                real_param(
                    &mut t,
                    format!("{n}.E"),
                    T::BeamE(i),
                    "Pa",
                    b.material.e,
                    V::Fixed,
                    "Young's modulus",
                );
            }
            if scene.is_3d() {
                spatial_section_params(&mut t, b, i, fx.rigid);
            } else if b.section.shape.is_none() {
                real_param(
                    &mut t,
                    format!("{n}.A"),
                    T::BeamArea(i),
                    "m2",
                    b.section.area.unwrap_or(0.0),
                    V::Fixed,
                    "Section area",
                );
                real_param(
                    &mut t,
                    format!("{n}.J"),
                    T::BeamSecondMoment(i),
                    "m4",
                    b.section.second_moment.unwrap_or(0.0),
                    V::Fixed,
                    "Second moment of area, in-plane bending",
                );
            } else {
                t.push(
                    format!("{n}.A"),
                    VarType::Real,
                    C::CalculatedParameter,
                    V::Fixed,
                    Some("m2"),
                    "Section area, from the section shape",
                    None,
                    O(K::SectionArea(i)),
                );
                t.push(
                    format!("{n}.J"),
                    VarType::Real,
                    C::CalculatedParameter,
                    V::Fixed,
                    Some("m4"),
                    "Second moment of area, from the section shape",
                    None,
                    O(K::SectionSecondMoment(i)),
                );
            }
            if fx.rigid {
                continue;
            }
            if fx.options.damping {
                real_param(
                    &mut t,
                    format!("{n}.rayleigh.alpha"),
                    T::BeamRayleighAlpha(i),
                    "1/s",
                    b.rayleigh.alpha,
                    V::Fixed,
                    "Rayleigh damping, mass-proportional",
                );
                real_param(
                    &mut t,
                    format!("{n}.rayleigh.beta"),
                    T::BeamRayleighBeta(i),
                    "s",
                    b.rayleigh.beta,
                    V::Fixed,
                    "Rayleigh damping, stiffness-proportional",
                );
            }
            if scene.is_3d() {
                continue;
            }
            real_param(
                &mut t,
                format!("{n}.initial.tip_displacement"),
                T::BeamTipDisplacement(i),
                "m",
                b.initial.tip_displacement,
                V::Fixed,
                "Initial static transverse tip displacement",
            );
        }
        for (i, j) in scene.joints.iter().enumerate() {
            let Some(d) = &j.drive else { continue };
            let unit = match (j.kind, d.kind) {
                (crate::scene::JointKind::Prismatic, crate::scene::DriveKind::Motion) => "m",
                (crate::scene::JointKind::Prismatic, crate::scene::DriveKind::Effort) => "N",
                (_, crate::scene::DriveKind::Motion) => "rad",
                (_, crate::scene::DriveKind::Effort) => "N.m",
            };
            let law = &d.law;
            let n = &j.name;
            if law.law != "input" {
                if let Some(v) = law.value {
                    real_param(
                        &mut t,
                        format!("{n}.drive.value"),
                        T::DriveValue(i),
                        unit,
                        v,
                        V::Fixed,
                        "Drive law: value or amplitude",
                    );
                }
            }
            if let Some(v) = law.omega {
                real_param(
                    &mut t,
                    format!("{n}.drive.omega"),
                    T::DriveOmega(i),
                    "rad/s",
                    v,
                    V::Fixed,
                    "Spin-up law: final angular speed",
                );
            }
            if let Some(v) = law.ramp_time {
                real_param(
                    &mut t,
                    format!("{n}.drive.ramp_time"),
                    T::DriveRampTime(i),
                    "s",
                    v,
                    V::Fixed,
                    "Spin-up law: duration T of the ramp",
                );
            }
            if let Some(v) = law.time_constant {
                real_param(
                    &mut t,
                    format!("{n}.drive.time_constant"),
                    T::DriveTimeConstant(i),
                    "s",
                    v,
                    V::Fixed,
                    "Exponential law: time constant",
                );
            }
            if let Some(v) = law.until {
                real_param(
                    &mut t,
                    format!("{n}.drive.until"),
                    T::DriveUntil(i),
                    "s",
                    v,
                    V::Fixed,
                    "The drive law is zero after this time",
                );
            }
        }
        for (slot, input) in crate::mechanics::multibody::system::input_slots(scene)
            .into_iter()
            .enumerate()
        {
            t.push(
                input.name.clone(),
                VarType::Real,
                C::Input,
                V::Continuous,
                Some(input.unit),
                &input.description,
                Some(input.start),
                Binding::Input(slot),
            );
            motion_interface(&mut t, scene, slot, &input.name);
        }
        for (i, (b, fx)) in scene.beams.iter().zip(&effects.beams).enumerate() {
            for o in scene.beam_outputs(b) {
                if fx.rigid && (o.contains("deflection") || o == "tip.twist") {
                    continue; // a rigid beam does not deflect
                }
                let (kind, unit, desc) = match o {
                    "tip.deflection" => (
                        K::TipDeflection(i),
                        "m",
                        "Transverse displacement of flange b from the tangent at flange a",
                    ),
                    "tip.x" => (K::TipX(i), "m", "World x of flange b"),
                    "tip.y" => (K::TipY(i), "m", "World y of flange b"),
                    "tip.z" => (K::TipZ(i), "m", "World z of flange b"),
                    "tip.deflection_y" => (K::TipDeflectionY(i), "m",
                        "Displacement of flange b along the root frame's y axis, from the root axis"),
                    "tip.deflection_z" => (K::TipDeflectionZ(i), "m",
                        "Displacement of flange b along the root frame's z axis, from the root axis"),
                    "tip.twist" => (K::TipTwist(i), "rad",
                        "Rotation of flange b about the beam axis, relative to the root frame"),
                    "mid.deflection" => (K::MidDeflection(i), "m",
                        "Transverse displacement at mid-span from the root axis (the chord for a pinned frame)"),
                    _ => (K::TipPhi(i), "rad", "World rotation of flange b"),
                };
                t.output(
                    format!("{}.{o}", b.name),
                    VarType::Real,
                    Some(unit),
                    desc,
                    kind,
                );
            }
        }
        let xyz: &[&str] = if scene.is_3d() {
            &["x", "y", "z"]
        } else {
            &["x", "y"]
        };
        for (i, (b, fx)) in scene.beams.iter().zip(&effects.beams).enumerate() {
            let points = crate::unit::shape::stations(b, fx.rigid).len();
            if points == 0 {
                continue;
            }
            for (axis, c) in xyz.iter().enumerate() {
                for point in 0..points {
                    t.output(
                        format!("{}.shape.{c}[{}]", b.name, point + 1),
                        VarType::Real,
                        Some("m"),
                        &format!(
                            "World {c} of point {} of {points} of the deformed centre line, equally \
                             spaced from flange a to flange b along the undeformed axis",
                            point + 1
                        ),
                        K::Shape {
                            beam: i,
                            point,
                            axis,
                        },
                    );
                }
            }
            for (axis, c) in xyz.iter().enumerate() {
                t.output(
                    format!("{}.axis.{c}", b.name),
                    VarType::Real,
                    None,
                    &format!(
                        "World {c} of the unit direction the deflections are measured from (the \
                         root frame's axis; for a planar pinned frame the chord)"
                    ),
                    K::BeamAxis(i, axis),
                );
            }
        }
        for (i, j) in scene.joints.iter().enumerate() {
            for (axis, c) in xyz.iter().enumerate() {
                t.output(
                    format!("{}.{c}", j.name),
                    VarType::Real,
                    Some("m"),
                    &format!(
                        "World {c} of the joint's second frame (where a revolute, spherical or \
                         weld joint is; the sliding frame of a prismatic joint)"
                    ),
                    K::JointPosition { joint: i, axis },
                );
            }
        }
        for (i, j) in scene.joints.iter().enumerate() {
            let n = &j.name;
            match j.kind {
                crate::scene::JointKind::Revolute => {
                    t.output(
                        format!("{n}.angle"),
                        VarType::Real,
                        Some("rad"),
                        "Joint angle, frame 1 relative to frame 0",
                        K::JointCoordinate(i),
                    );
                    t.output(
                        format!("{n}.speed"),
                        VarType::Real,
                        Some("rad/s"),
                        "Joint angular speed",
                        K::JointRate(i),
                    );
                    t.output(format!("{n}.torque"), VarType::Real, Some("N.m"),
                        "Torque of the joint's drive on frame 1 (the reaction of a motion drive; 0 without drive)", K::JointEffort(i));
                }
                crate::scene::JointKind::Prismatic => {
                    t.output(
                        format!("{n}.position"),
                        VarType::Real,
                        Some("m"),
                        "Position of frame 1 along the axis of frame 0",
                        K::JointCoordinate(i),
                    );
                    t.output(
                        format!("{n}.velocity"),
                        VarType::Real,
                        Some("m/s"),
                        "Sliding velocity",
                        K::JointRate(i),
                    );
                    t.output(format!("{n}.force"), VarType::Real, Some("N"),
                        "Force of the joint's drive on frame 1 along the axis (the reaction of a motion drive; 0 without drive)", K::JointEffort(i));
                }
                crate::scene::JointKind::Weld | crate::scene::JointKind::Spherical => {}
            }
        }
        for (i, b) in scene.bodies.iter().enumerate() {
            let n = &b.name;
            t.output(
                format!("{n}.x"),
                VarType::Real,
                Some("m"),
                "World x of the body frame",
                K::BodyX(i),
            );
            t.output(
                format!("{n}.y"),
                VarType::Real,
                Some("m"),
                "World y of the body frame",
                K::BodyY(i),
            );
            if scene.is_3d() {
                t.output(
                    format!("{n}.z"),
                    VarType::Real,
                    Some("m"),
                    "World z of the body frame",
                    K::BodyZ(i),
                );
                for row in 0..3 {
                    for col in 0..3 {
                        t.output(
                            format!("{n}.R[{},{}]", row + 1, col + 1),
                            VarType::Real,
                            None,
                            &format!(
                                "Rotation of the body frame: world {} component of body axis {}",
                                xyz[row], xyz[col]
                            ),
                            K::BodyRotation { body: i, row, col },
                        );
                    }
                }
                continue;
            }
            t.output(
                format!("{n}.phi"),
                VarType::Real,
                Some("rad"),
                "World angle of the body frame",
                K::BodyPhi(i),
            );
        }
        for (name, kind, desc) in [
            (
                "energy.work",
                K::EnergyWork,
                "Work done by drives and loads since the start",
            ),
            ("energy.kinetic", K::EnergyKinetic, "Kinetic energy"),
            ("energy.strain", K::EnergyStrain, "Strain energy"),
            (
                "energy.potential",
                K::EnergyPotential,
                "Potential energy of gravity",
            ),
            (
                "energy.total",
                K::EnergyTotal,
                "Kinetic + strain + potential energy",
            ),
        ] {
            let strain = kind == K::EnergyStrain && effects.beams.iter().all(|b| b.rigid);
            if strain || (kind == K::EnergyPotential && !effects.gravity) {
                continue; // no deformation, or no gravity field
            }
            t.output(name.into(), VarType::Real, Some("J"), desc, kind);
        }
        t.output(
            "solver.constraint_residual".into(),
            VarType::Real,
            None,
            "Largest residual of the joint equations |g(q, t)| (m or rad) at the end of the last internal step: the constraint drift",
            K::ConstraintResidual,
        );
        for (name, kind, desc) in [
            (
                "solver.steps",
                K::SolverSteps,
                "Accepted internal steps since initialization",
            ),
            (
                "solver.newton_iterations",
                K::SolverNewtonIterations,
                "Newton iterations since initialization",
            ),
            (
                "solver.jacobians",
                K::SolverJacobians,
                "Iteration-matrix factorizations since initialization",
            ),
            (
                "solver.rejected_steps",
                K::SolverRejectedSteps,
                "Rejected internal steps since initialization",
            ),
            (
                "solver.split_steps",
                K::SolverSplitSteps,
                "Fixed steps cut shorter than solver.max_step since initialization (to land on a \
                 drive law's jump or on a communication point of a unit with inputs, or after a \
                 failed Newton iteration); 0 with error control",
            ),
        ] {
            t.output(name.into(), VarType::Integer, None, desc, kind);
        }
        t.push(
            "solver.next_event_time".into(),
            VarType::Real,
            C::Output,
            V::Discrete,
            Some("s"),
            "Time of the next jump of a drive or load law after the current time, where the unit \
             lands and restarts (a master coupling units mechanically lands there too); \
             1.7976931348623157e308 when none",
            None,
            O(K::NextEventTime),
        );
        // the frames of input loads: what a master joining this unit mechanically reads
        for (i, l) in scene.loads.iter().enumerate().filter(|(_, l)| l.input) {
            for (suffix, what, unit, desc) in
                crate::unit::interface::frame_outputs(if scene.is_3d() { 3 } else { 2 })
            {
                t.output(
                    format!("{}.{suffix}", l.name),
                    VarType::Real,
                    Some(unit),
                    desc,
                    K::LoadFrame(i, what),
                );
            }
        }
        let deps = crate::unit::interface::dependencies(scene, &t.vars);
        for (v, d) in t.vars.iter_mut().zip(deps) {
            v.dependencies = d;
        }
        VariableTable { variables: t.vars }
    }

    pub fn get(&self, vr: u32) -> Option<&Variable> {
        self.variables.get(vr as usize)
    }

    pub fn by_name(&self, name: &str) -> Option<&Variable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// The units used by at least one variable, in [`UNITS`] order.
    pub fn units(&self) -> Vec<UnitDef> {
        UNITS
            .iter()
            .copied()
            .filter(|u| self.variables.iter().any(|v| v.unit == Some(u.name)))
            .collect()
    }
}

/// The shear modulus and the section constants given directly of a 3D beam (a section from a
/// shape or a matrix file has none to set).
fn spatial_section_params(t: &mut Builder, b: &crate::scene::BeamSpec, i: usize, rigid: bool) {
    use ParamTarget as T;
    let n = &b.name;
    let mut param = |name: &str, target, unit, v: f64, desc: &str| {
        t.push(
            format!("{n}.{name}"),
            VarType::Real,
            Causality::Parameter,
            Variability::Fixed,
            Some(unit),
            desc,
            Some(v),
            Binding::Parameter(target),
        );
    };
    if b.matrix_text.is_some() {
        return;
    }
    if !rigid {
        param(
            "G",
            T::BeamG(i),
            "Pa",
            b.material.g.unwrap_or(0.0),
            "Shear modulus",
        );
    }
    let s = &b.section;
    if s.shape.is_some() {
        return;
    }
    param(
        "A",
        T::BeamArea(i),
        "m2",
        s.area.unwrap_or(0.0),
        "Section area",
    );
    if rigid {
        return;
    }
    for (name, target, value, desc) in [
        (
            "Iy",
            T::BeamIy(i),
            s.iy,
            "Second moment of area Iy (bending in the local x-z plane)",
        ),
        (
            "Iz",
            T::BeamIz(i),
            s.iz,
            "Second moment of area Iz (bending in the local x-y plane)",
        ),
        (
            "It",
            T::BeamTorsion(i),
            s.torsion_constant,
            "Saint-Venant torsion constant",
        ),
    ] {
        param(name, target, "m4", value.unwrap_or(0.0), desc);
    }
}

struct Builder {
    vars: Vec<Variable>,
}

impl Builder {
    fn push(
        &mut self,
        name: String,
        ty: VarType,
        causality: Causality,
        variability: Variability,
        unit: Option<&'static str>,
        description: &str,
        start: Option<f64>,
        binding: Binding,
    ) {
        let initial = match causality {
            Causality::Parameter => Some(Initial::Exact),
            Causality::CalculatedParameter | Causality::Output => Some(Initial::Calculated),
            Causality::Input => None,
        };
        let unit = unit.filter(|u| *u != "1");
        self.vars.push(Variable {
            name,
            vr: self.vars.len() as u32,
            ty,
            causality,
            variability,
            initial,
            unit,
            description: description.to_string(),
            start,
            binding,
            dependencies: Vec::new(),
        });
    }

    fn output(
        &mut self,
        name: String,
        ty: VarType,
        unit: Option<&'static str>,
        desc: &str,
        kind: OutputKind,
    ) {
        let variability = if ty == VarType::Real {
            Variability::Continuous
        } else {
            Variability::Discrete
        };
        self.push(
            name,
            ty,
            Causality::Output,
            variability,
            unit,
            desc,
            None,
            Binding::Output(kind),
        );
    }
}

/// The motion interface of a motion drive reading input `slot` (named `name`): its rate and
/// acceleration as inputs of their own, and its reaction consistent with them, so that a master
/// coupling in motion causality reads the interface's effective inertia as
/// d(reaction)/d(acceleration) (fmi2GetDirectionalDerivative). Nothing for other inputs.
fn motion_interface(t: &mut Builder, scene: &Scene, slot: usize, name: &str) {
    use crate::scene::{DriveKind, JointKind};
    let Some((j, joint)) = scene.joints.iter().enumerate().find(|(_, j)| {
        j.drive
            .as_ref()
            .is_some_and(|d| d.kind == DriveKind::Motion && d.law.law == "input")
            && name.starts_with(&format!("{}.drive.", j.name))
    }) else {
        return;
    };
    let n = &joint.name;
    let (rate, units, effort) = if joint.kind == JointKind::Prismatic {
        ("velocity", ["m/s", "m/s2", "N"], "force")
    } else {
        ("speed", ["rad/s", "rad/s2", "N.m"], "torque")
    };
    for (order, what, unit) in [(1u8, rate, units[0]), (2, "acceleration", units[1])] {
        t.push(
            format!("{n}.drive.{what}"),
            VarType::Real,
            Causality::Input,
            Variability::Continuous,
            Some(unit),
            &format!(
                "Drive of joint {n}: the prescribed motion's {what}, the time derivative of \
                 order {order} of {name} over the next step (the value fmi2SetRealInputDerivatives \
                 sets; setting {name} resets it to 0, so set it after {name})"
            ),
            Some(0.0),
            Binding::InputDerivative { slot, order },
        );
    }
    t.output(
        format!("{n}.drive.reaction"),
        VarType::Real,
        Some(units[2]),
        &format!(
            "Reaction {effort} of the drive of joint {n} on frame 1, consistent with the state and \
             the inputs as set now (direct feedthrough of {n}.drive.acceleration: its derivative \
             is the interface's effective inertia); {n}.{effort} is the last step's"
        ),
        OutputKind::DriveReaction(j),
    );
}
