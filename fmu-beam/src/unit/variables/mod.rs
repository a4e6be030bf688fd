//! The variable table of a scene: the single source of the engine's get/set and of the
//! ModelVariables, UnitDefinitions and ModelStructure that the packager writes.

mod arrays;
mod build;

pub use arrays::{Declared, Layout3, Variable3};

use crate::scene::Scene;
use crate::unit::effects::Effects;

/// The FMI type of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VarType {
    /// fmi2Real: every physical quantity.
    Real,
    /// fmi2Integer: the solver's counters.
    Integer,
    /// fmi2Boolean: switches such as `solver.adaptive`.
    Boolean,
}

impl VarType {
    /// The element name in modelDescription.xml (`Real`, `Integer`, `Boolean`).
    pub fn as_str(self) -> &'static str {
        match self {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
        }
    }
}

/// The FMI causality of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// Set by the user before (fixed) or between (tunable) steps.
    Parameter,
    /// Computed from parameters.
    CalculatedParameter,
    /// Set by the master at communication points.
    Input,
    /// Read by the master at communication points.
    Output,
}

impl Causality {
    /// The attribute value in modelDescription.xml (`parameter`, `input`, ...).
    pub fn as_str(self) -> &'static str {
        match self {
            Causality::Parameter => "parameter",
            Causality::CalculatedParameter => "calculatedParameter",
            Causality::Input => "input",
            Causality::Output => "output",
        }
    }
}

/// The FMI `variability` attribute of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variability {
    /// A parameter set before fmi2ExitInitializationMode only.
    Fixed,
    /// A parameter a master may change between communication steps.
    Tunable,
    /// Changes only at events (the unit's counters and flags).
    Discrete,
    /// Changes continuously in time.
    Continuous,
}

impl Variability {
    /// The attribute value in modelDescription.xml.
    pub fn as_str(self) -> &'static str {
        match self {
            Variability::Fixed => "fixed",
            Variability::Tunable => "tunable",
            Variability::Discrete => "discrete",
            Variability::Continuous => "continuous",
        }
    }
}

/// The FMI `initial` attribute of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Initial {
    /// Its start value is the value (parameters).
    Exact,
    /// Computed by the unit (outputs, calculated parameters).
    Calculated,
}

impl Initial {
    /// The attribute value in modelDescription.xml (`exact`, `calculated`).
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
    /// `solver.step_budget`.
    SolverStepBudget,
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
    /// The mass of a rigid body (scene body index).
    BodyMass(usize),
    /// A principal moment of inertia of a rigid body about its centre of mass: (body, axis),
    /// axis 2 (about z) in a planar scene.
    BodyInertia(usize, usize),
    /// A coordinate (body, axis) of a rigid body's centre of mass in its body frame.
    BodyCom(usize, usize),
    /// A world component (load, axis) of a load's force, of a load that is not an input.
    LoadForce(usize, usize),
    /// A world component (load, axis) of a load's torque (axis 2 only in a planar scene).
    LoadTorque(usize, usize),
    /// A parameter of a time law: a joint's drive law or a load's scale.
    Law(LawOf, LawParam),
    /// The coordinate of scene joint `usize` at the start (`joint.initial.position`).
    JointInitialPosition(usize),
    /// The rate of scene joint `usize` at the start (`joint.initial.speed`).
    JointInitialSpeed(usize),
}

/// Whose time law a [`ParamTarget::Law`] parameter sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LawOf {
    /// The drive law of scene joint `usize`.
    Drive(usize),
    /// The scale law of scene load `usize`.
    LoadScale(usize),
}

/// Which number of a time law a [`ParamTarget::Law`] parameter sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LawParam {
    /// `value`: a constant's value, an exponential's final value.
    Value,
    /// `omega`: a spin-up's final angular speed.
    Omega,
    /// `ramp_time`: a spin-up's ramp duration.
    RampTime,
    /// `time_constant`: an exponential's time constant.
    TimeConstant,
    /// `until`: the law is zero after it.
    Until,
    /// The time of row `usize` (from 0) of a `table`.
    TableTime(usize),
    /// The value of row `usize` (from 0) of a `table`.
    TableValue(usize),
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

/// What a variable reads or writes in the engine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Binding {
    /// A parameter, written into the scene (or the running solver) as the target says.
    Parameter(ParamTarget),
    /// An output, computed from the state at the communication point.
    Output(OutputKind),
    /// FMU input in this slot of `from_scene::input_slots`.
    Input(usize),
    /// The first or second time derivative (`order` 1 or 2) of the motion input in `slot`, as
    /// an input of its own: the same value fmi2SetRealInputDerivatives sets.
    InputDerivative {
        /// The motion input's slot.
        slot: usize,
        /// 1 (rate) or 2 (acceleration).
        order: u8,
    },
}

/// One variable of the unit, as modelDescription.xml declares it and the engine serves it.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// Structured name (`crank.tip.y`, `solver.tolerance`).
    pub name: String,
    /// Value reference: the variable's index in the table.
    pub vr: u32,
    /// FMI type.
    pub ty: VarType,
    /// FMI causality.
    pub causality: Causality,
    /// FMI variability (fixed, tunable, discrete, continuous).
    pub variability: Variability,
    /// FMI `initial`, where the standard asks for one.
    pub initial: Option<Initial>,
    /// A name of [`UNITS`], or none (dimensionless, counters, Booleans).
    pub unit: Option<&'static str>,
    /// What it is, for the XML and the FMU's documentation.
    pub description: String,
    /// Start value of parameters (Booleans as 0/1).
    pub start: Option<f64>,
    /// What it reads or writes in the engine.
    pub binding: Binding,
    /// Of an output: the inputs (value references) it depends on directly, for ModelStructure
    /// (`unit::interface::dependencies`); empty otherwise.
    pub dependencies: Vec<u32>,
}

/// A unit in SI base-unit exponents, for UnitDefinitions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnitDef {
    /// The unit's name as variables use it (`m/s2`, `N.m`).
    pub name: &'static str,
    /// Exponent of kilogram.
    pub kg: i32,
    /// Exponent of metre.
    pub m: i32,
    /// Exponent of second.
    pub s: i32,
    /// Exponent of radian.
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
    unit("kg", 1, 0, 0, 0),
    unit("kg.m2", 1, 2, 0, 0),
];

/// All variables of a scene, in value-reference order (vr = index; unique over all types).
#[derive(Debug, Clone, PartialEq)]
pub struct VariableTable {
    /// The variables, indexed by value reference.
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
        let mut vars = build::variables(scene, effects);
        let deps = crate::unit::interface::dependencies(scene, &vars);
        for (v, d) in vars.iter_mut().zip(deps) {
            v.dependencies = d;
        }
        VariableTable { variables: vars }
    }

    /// The variable of value reference `vr`.
    pub fn get(&self, vr: u32) -> Option<&Variable> {
        self.variables.get(vr as usize)
    }

    /// The variable named `name`.
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
