//! The scene file: what a user writes (TOML, read with serde), and its validation.
//!
//! A scene names its beams, the joints that hold them, the solver settings and the default
//! experiment. Unknown keys are refused by serde (`deny_unknown_fields`); every value rule is
//! checked in `validate`, whose errors name the field and the rule.
//!
//! Over 600 lines on purpose: the format's spec structs, whose doc comments are the generated scene
//! reference, read in one place.

mod accuracy;
pub mod files;
mod joint_start;
mod laws;
mod limits;
pub mod matrix_file;
mod number;
pub use number::Short;
mod paths;
mod placement;
mod planar;
pub mod rules;
mod size;
pub use size::TABLE_PARAMETER_ROWS;
mod space;
mod validate;
pub mod xyz;

use serde::{Deserialize, Serialize};
use std::path::Path;

pub use accuracy::AccuracySpec;

pub use paths::{part_path, part_paths};
pub(crate) use placement::show_length;
pub use placement::{JointGap, GAP_TOLERANCE};
pub use size::Size;
pub use space::SPATIAL_EFFECTS;
pub use validate::{SceneError, MAX_STEP, MIN_STEP};

/// The default number of space dimensions of a scene.
fn two() -> u8 {
    2
}

/// A scene file: the beams, bodies, joints and loads of one FMU, its solver settings, default
/// experiment and effects.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Model name: the FMU's modelName and modelIdentifier.
    pub name: String,
    /// Free text: the FMU's description and the first line of its documentation.
    #[serde(default)]
    pub description: String,
    /// 2 (default): a planar scene in the world x–y plane; 3: a spatial scene (3D beams,
    /// frames and joints, vectors with 3 components).
    #[serde(default = "two")]
    pub dimensions: u8,
    /// Which beam element a 3D scene runs with: `auto` (the planar element when the scene's
    /// motion stays in the world x–y plane: exact, and faster) or `spatial` (always the 3D
    /// element).
    #[serde(default)]
    pub formulation: Formulation,
    /// The gravity field.
    #[serde(default)]
    pub world: World,
    /// Integrator settings.
    #[serde(default)]
    pub solver: SolverSpec,
    /// The FMU's DefaultExperiment.
    #[serde(default)]
    pub experiment: ExperimentSpec,
    /// The flexible beams (at least one).
    #[serde(default, rename = "beam")]
    pub beams: Vec<BeamSpec>,
    /// The rigid bodies.
    #[serde(default, rename = "body")]
    pub bodies: Vec<RigidBodySpec>,
    /// The joints between frames, with their drives.
    #[serde(default, rename = "joint")]
    pub joints: Vec<JointSpec>,
    /// Point forces and torques on frames.
    #[serde(default, rename = "load")]
    pub loads: Vec<LoadSpec>,
    /// What to simulate: `"scene"` (default: every term, geometric stiffening where a beam
    /// asks for it), `"all"` (every effect, geometric stiffening on every flexible beam),
    /// `"auto"` (the generator decides from the scene, `fmu-harness explain` says why), or a
    /// list of effect names: gravity, flexibility, axial, quadratic_velocity,
    /// geometric_stiffening, rayleigh_damping.
    #[serde(default)]
    pub effects: EffectsSpec,
    /// The accuracy these settings were tuned for (`fmu-harness explain` states it); absent:
    /// no statement.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<AccuracySpec>,
}

/// The scene's `effects`: a mode (`"scene"`, `"all"`, `"auto"`) or the list of effects to
/// simulate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(untagged)]
pub enum EffectsSpec {
    /// `"scene"` (every term, geometric stiffening where a beam asks for it), `"all"` (every
    /// effect, geometric stiffening included) or `"auto"` (the generator decides).
    Mode(String),
    /// The effects to simulate, by name; those not listed are off.
    List(Vec<String>),
}

impl Default for EffectsSpec {
    fn default() -> Self {
        EffectsSpec::Mode("scene".into())
    }
}

/// Which element a 3D scene runs with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum Formulation {
    /// The planar element when the motion is planar, else the spatial one.
    #[default]
    Auto,
    /// Always the spatial element.
    Spatial,
}

/// The world: the fixed frame every position, angle and direction is given in (origin
/// `[0, 0, 0]`, right-handed axes x, y, z; a planar scene is its x–y plane, angles about z
/// counter-clockwise from x; the joint frame `world` is this origin with these axes), and its
/// gravity field.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct World {
    /// Gravity (world axes): `[gx, gy]` or `[gx, gy, gz]`; it says which way is down
    /// (`[0, -9.81]`: along -y); no field, no gravity terms.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m/s^2")))]
    #[cfg_attr(feature = "schema", schemars(schema_with = "xyz::schema::point"))]
    #[serde(default, with = "xyz::point")]
    pub gravity: [f64; 3],
}

/// Integrator settings (generalized-α with Newton iterations); each is also a tunable FMU
/// parameter `solver.<field>`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// Local error control on (true) or a fixed internal step of `max_step` (false).
    #[serde(default = "default_adaptive")]
    pub adaptive: bool,
    /// Relative tolerance of the error control and of the Newton iteration, on each coordinate
    /// against tol × (|q| + the system's length; 1 rad for angles). The local error is estimated
    /// from the positions, so a vibration whose amplitude is below it is left to `rho_inf`'s
    /// damping rather than resolved; with `rho_inf` < 1, so is a mode the step does not resolve
    /// (ω h well above 1): an estimate that refuses a step is filtered by the scheme's damping.
    /// At a fixed step it bounds only Newton's error: set it below the accuracy asked of the
    /// outputs.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "1")))]
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Largest internal step; the fixed step when `adaptive = false`.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "s")))]
    #[serde(default = "default_max_step")]
    pub max_step: f64,
    /// Spectral radius at infinity of generalized-alpha: 1 = no numerical damping.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "1")))]
    #[serde(default = "default_rho_inf")]
    pub rho_inf: f64,
    /// The work budget of one communication step, in work units (Newton iterations times
    /// unknowns plus 32, plus iteration matrices times the entries the matrix stores / 4:
    /// unknowns² when dense) before the step ends in fmi2Discard with the reason, the last good
    /// state kept. The default, 30 000 000, is seconds of work on any shipped scene; a master
    /// that takes long communication steps of a fine fixed step raises it.
    #[serde(default = "default_step_budget")]
    pub step_budget: u64,
}

fn default_adaptive() -> bool {
    true
}
fn default_tolerance() -> f64 {
    1e-6
}
fn default_max_step() -> f64 {
    1e-2
}
fn default_rho_inf() -> f64 {
    0.9
}
fn default_step_budget() -> u64 {
    DEFAULT_STEP_BUDGET
}

/// The default `solver.step_budget`, in work units: 2–4 s of work on any shipped scene
/// (`integrator::work_units` says what a unit is and what it was measured to cost).
pub const DEFAULT_STEP_BUDGET: u64 = 30_000_000;

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec {
            adaptive: default_adaptive(),
            tolerance: default_tolerance(),
            max_step: default_max_step(),
            rho_inf: default_rho_inf(),
            step_budget: default_step_budget(),
        }
    }
}

/// The DefaultExperiment written into modelDescription.xml (what a master runs by default).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct ExperimentSpec {
    /// Start time.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "s")))]
    #[serde(default)]
    pub start_time: f64,
    /// Stop time.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "s")))]
    #[serde(default = "default_stop_time")]
    pub stop_time: f64,
    /// Communication step (a suggestion: the master chooses its own).
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "s")))]
    #[serde(default = "default_step_size")]
    pub step_size: f64,
}

fn default_stop_time() -> f64 {
    1.0
}
fn default_step_size() -> f64 {
    1e-3
}

impl Default for ExperimentSpec {
    fn default() -> Self {
        ExperimentSpec {
            start_time: 0.0,
            stop_time: default_stop_time(),
            step_size: default_step_size(),
        }
    }
}

/// A flexible beam: Euler–Bernoulli finite elements in one floating frame (planar paper §3), or
/// in substructures; planar, or 3D in a scene with `dimensions = 3`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct BeamSpec {
    /// Beam name: the prefix of its variables (`<beam>.tip.x`) and of its frames `<beam>.a`
    /// (root flange) and `<beam>.b` (tip flange).
    pub name: String,
    /// Undeformed length.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m")))]
    pub length: f64,
    /// Number of finite elements N of a single-frame beam.
    #[serde(default)]
    pub elements: Option<usize>,
    /// Number of substructures k (planar paper §3.4): k floating frames welded tip to root,
    /// for large deformation.
    #[serde(default)]
    pub substructures: Option<usize>,
    /// Elements in each substructure (with `substructures`).
    #[serde(default)]
    pub elements_per_substructure: Option<usize>,
    /// A rigid bar instead of a flexible beam (same mass and inertia, no deformation).
    #[serde(default)]
    pub rigid: bool,
    /// Adds the geometric stiffness of the axial force (nonlinear strain u' + v'^2/2; in 3D
    /// u' + (v'^2 + w'^2)/2, both bending planes).
    #[serde(default)]
    pub geometric_stiffening: bool,
    /// Modal truncation: keep the lowest `modes` modes of each frame's deformation.
    #[serde(default)]
    pub modes: Option<usize>,
    /// Reference frame of the deformation field (planar paper §3.3): `tangent` at flange a,
    /// or `pinned` through both ends.
    #[serde(default)]
    pub frame: FrameKind,
    /// The material.
    pub material: MaterialSpec,
    /// The cross-section: constants given directly, or a shape with its dimensions. Required,
    /// except for a beam from a matrix file.
    #[serde(default)]
    pub section: SectionSpec,
    /// Rayleigh damping of the deformation.
    #[serde(default)]
    pub rayleigh: RayleighSpec,
    /// World position of flange a in the undeformed initial configuration.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m")))]
    #[cfg_attr(feature = "schema", schemars(schema_with = "xyz::schema::point"))]
    #[serde(default, with = "xyz::point")]
    pub position: [f64; 3],
    /// World angle of the beam axis about z in the initial configuration (planar scenes, and
    /// the default axis of a 3D beam: in the x–y plane).
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "rad")))]
    #[serde(default)]
    pub angle: f64,
    /// 3D: world direction of the beam axis (local x) at t = 0 (default: from `angle`).
    #[cfg_attr(feature = "schema", schemars(schema_with = "xyz::schema::direction"))]
    #[serde(
        default,
        with = "xyz::direction",
        skip_serializing_if = "Option::is_none"
    )]
    pub axis: Option<[f64; 3]>,
    /// 3D: world direction of the section's local z axis at t = 0, normal to `axis`
    /// (default: world z). Bending in the local x–y plane uses `Iz`, in x–z `Iy`.
    #[cfg_attr(feature = "schema", schemars(schema_with = "xyz::schema::direction"))]
    #[serde(
        default,
        with = "xyz::direction",
        skip_serializing_if = "Option::is_none"
    )]
    pub normal: Option<[f64; 3]>,
    /// 3D: `full` inertia, or `frozen` (3D paper §6: constant mass matrix, no
    /// quadratic-velocity update; the fast variant).
    #[serde(default)]
    pub inertia: InertiaSpec,
    /// 3D: a one-element beam whose 12 × 12 mass and stiffness come from this file, relative
    /// to the scene file (format: `fmu-beam/src/scene/matrix_file.rs`); the FMU carries its text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix_file: Option<String>,
    /// 3D: the matrix file's text itself, in the same format. Loading the scene (and so the
    /// packager) fills it from `matrix_file`, so that a packaged scene carries its matrices and a unit
    /// reads no other file; a scene may also give the text here instead of a `matrix_file`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix_text: Option<String>,
    /// The initial deformed state.
    #[serde(default)]
    pub initial: InitialSpec,
    /// The outputs to offer, by their name after `<beam>.` (empty: all, and the shape). Planar:
    /// tip.deflection, tip.x, tip.y, tip.phi, mid.deflection; 3D: tip.x, tip.y, tip.z,
    /// tip.deflection_y, tip.deflection_z, tip.twist; both: shape (`<beam>.shape.*`, `.axis.*`).
    #[serde(default)]
    pub outputs: Vec<String>,
    /// Points of the deformed centre line offered as `<beam>.shape.x[i]`, `.y[i]` (3D: `.z[i]`),
    /// equally spaced from flange a to flange b; absent: at the nodes; 0: no shape outputs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape_points: Option<usize>,
}

/// Most shape points a beam may ask for (`shape_points`).
pub const MAX_POINTS: usize = 1000;

/// The name in a beam's `outputs` list that offers its shape outputs (the points of its
/// deformed centre line and the axis its deflections are measured from).
pub const SHAPE_OUTPUT: &str = "shape";

/// The outputs a beam can offer, by their name after `<beam>.`.
pub const BEAM_OUTPUTS: [&str; 5] = [
    "tip.deflection",
    "tip.x",
    "tip.y",
    "tip.phi",
    "mid.deflection",
];

/// The outputs a 3D beam offers, by their name after `<beam>.`.
pub const BEAM_OUTPUTS_3D: [&str; 6] = [
    "tip.x",
    "tip.y",
    "tip.z",
    "tip.deflection_y",
    "tip.deflection_z",
    "tip.twist",
];

/// The names a planar beam's `outputs` list may hold: [`BEAM_OUTPUTS`] and [`SHAPE_OUTPUT`].
pub const BEAM_OUTPUT_NAMES: [&str; 6] = [
    "tip.deflection",
    "tip.x",
    "tip.y",
    "tip.phi",
    "mid.deflection",
    SHAPE_OUTPUT,
];

/// The names a 3D beam's `outputs` list may hold: [`BEAM_OUTPUTS_3D`] and [`SHAPE_OUTPUT`].
pub const BEAM_OUTPUT_NAMES_3D: [&str; 7] = [
    "tip.x",
    "tip.y",
    "tip.z",
    "tip.deflection_y",
    "tip.deflection_z",
    "tip.twist",
    SHAPE_OUTPUT,
];

/// Inertia model of a 3D beam.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum InertiaSpec {
    /// The full inertia of the 3D paper.
    #[default]
    Full,
    /// Constant mass matrix, no quadratic-velocity update (3D paper §6).
    Frozen,
}

/// Reference frame conventions of the planar paper §3.3.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum FrameKind {
    /// Frame tangent to the beam at flange a: root deformation (u, v, slope) is zero.
    #[default]
    Tangent,
    /// Frame through both ends: root (u, v) and tip v are zero.
    Pinned,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
/// The beam's material (isotropic, linear elastic).
pub struct MaterialSpec {
    /// Density.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "kg/m^3")))]
    pub rho: f64,
    /// Young's modulus.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "Pa")))]
    #[serde(rename = "E")]
    pub e: f64,
    /// Shear modulus (torsion); used by 3D beams only, required by a flexible one.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "Pa")))]
    #[serde(rename = "G", default)]
    pub g: Option<f64>,
}

/// A cross-section: its constants given directly (planar: `A` and `J`; 3D: `A`, `Iy`, `Iz`,
/// `It`), or a `shape` with its dimensions (`a`, `b`, `d`, `t`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct SectionSpec {
    /// Area, given directly.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m^2")))]
    #[serde(rename = "A", default)]
    pub area: Option<f64>,
    /// Second moment of area for in-plane bending, given directly (planar scenes).
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m^4")))]
    #[serde(rename = "J", default, skip_serializing_if = "Option::is_none")]
    pub second_moment: Option<f64>,
    /// 3D, given directly: second moment I_y = ∫z² dA (bending in the local x–z plane).
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m^4")))]
    #[serde(rename = "Iy", default, skip_serializing_if = "Option::is_none")]
    pub iy: Option<f64>,
    /// 3D, given directly: second moment I_z = ∫y² dA (bending in the local x–y plane).
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m^4")))]
    #[serde(rename = "Iz", default, skip_serializing_if = "Option::is_none")]
    pub iz: Option<f64>,
    /// 3D, given directly: Saint-Venant torsion constant.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m^4")))]
    #[serde(rename = "It", default, skip_serializing_if = "Option::is_none")]
    pub torsion_constant: Option<f64>,
    /// `rectangle`, `circle`, `hollow_rectangle`, `hollow_circle`.
    #[serde(default)]
    pub shape: Option<String>,
    /// Height of a rectangle (in the plane of bending; 3D: along the local y axis).
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m")))]
    #[serde(default)]
    pub a: Option<f64>,
    /// Width of a rectangle (3D: along the local z axis).
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m")))]
    #[serde(default)]
    pub b: Option<f64>,
    /// Outer diameter of a circle.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m")))]
    #[serde(default)]
    pub d: Option<f64>,
    /// Wall thickness of a hollow shape.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m")))]
    #[serde(default)]
    pub t: Option<f64>,
}

/// Rayleigh damping of the deformation, D = alpha M_ff + beta K_ff.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct RayleighSpec {
    /// Mass-proportional coefficient.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "1/s")))]
    #[serde(default)]
    pub alpha: f64,
    /// Stiffness-proportional coefficient.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "s")))]
    #[serde(default)]
    pub beta: f64,
}

/// Initial deformed state of a beam, at rest (planar element, single frame, tangent frame).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// Transverse tip displacement of the static shape under a tip force (tangent frame).
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m")))]
    #[serde(default)]
    pub tip_displacement: f64,
}

/// A rigid body (planar, or 3D with its frame parallel to the world's at t = 0).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct RigidBodySpec {
    /// Body name: the prefix of its variables (`<body>.x`) and frames (`<body>.origin`).
    pub name: String,
    /// Mass; zero is allowed when joints fix every coordinate of the body.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "kg")))]
    pub mass: f64,
    /// Moment of inertia about the centre of mass: a number (about z) or, in 3D, the
    /// principal moments `[Ixx, Iyy, Izz]` along the body axes.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "kg m^2")))]
    #[cfg_attr(feature = "schema", schemars(schema_with = "xyz::schema::about_z"))]
    #[serde(default, with = "xyz::about_z")]
    pub inertia: [f64; 3],
    /// Centre of mass in the body frame.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m")))]
    #[cfg_attr(feature = "schema", schemars(schema_with = "xyz::schema::point"))]
    #[serde(default, with = "xyz::point")]
    pub com: [f64; 3],
    /// World position of the body frame at t = 0.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "m")))]
    #[cfg_attr(feature = "schema", schemars(schema_with = "xyz::schema::point"))]
    #[serde(default, with = "xyz::point")]
    pub position: [f64; 3],
    /// World angle of the body frame about z at t = 0.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "rad")))]
    #[serde(default)]
    pub angle: f64,
    /// Named frames: `name = [x, y]` or `[x, y, z]`, positions in the body frame (m), joined
    /// or loaded as `<body>.<name>`; `origin` and `com` always exist.
    #[serde(default)]
    pub frames: std::collections::BTreeMap<String, Point>,
}

/// A joint between two frames: `world`, `<beam>.a`, `<beam>.b`, `<body>.<frame>`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct JointSpec {
    /// Joint name: the prefix of its variables (`<joint>.angle`, `<joint>.drive.torque`).
    pub name: String,
    /// The kind of joint.
    #[serde(rename = "type")]
    pub kind: JointKind,
    /// The two frames the joint connects: `world`, `<beam>.a`, `<beam>.b`, `<body>.<frame>`;
    /// a prismatic joint slides along the x axis of the first, turned by `axis_angle`.
    #[cfg_attr(feature = "schema", schemars(schema_with = "xyz::schema::pair"))]
    #[serde(with = "xyz::pair")]
    pub frames: [String; 2],
    /// Planar prismatic joint: angle of the sliding axis from the first frame's x axis.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "rad")))]
    #[serde(default)]
    pub axis_angle: f64,
    /// 3D: world direction, at t = 0, of a revolute joint's rotation axis or a prismatic
    /// joint's sliding axis (default: world z for a revolute joint, the first frame's x axis
    /// turned by `axis_angle` about z for a prismatic one).
    #[cfg_attr(feature = "schema", schemars(schema_with = "xyz::schema::direction"))]
    #[serde(
        default,
        with = "xyz::direction",
        skip_serializing_if = "Option::is_none"
    )]
    pub axis: Option<[f64; 3]>,
    /// A drive of the joint's coordinate (revolute and prismatic joints).
    #[serde(default)]
    pub drive: Option<DriveSpec>,
    /// The joint's coordinate and rate at the start (revolute and prismatic joints without a
    /// motion drive): the bodies are placed to meet them, and move at the speed given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial: Option<JointInitialSpec>,
    /// The two frames may be apart at t = 0: the unit moves the parts together at
    /// initialization (only their frames, never deforming a beam) and logs which part it moved
    /// and by how much. Without it, frames further apart than 1e-6 of the longest beam are
    /// refused (rule `joint_gap`), since a placement error would go unnoticed.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub assemble: bool,
}

/// A joint's start: its coordinate and its rate (each optional). Another joint's coordinate
/// stays where the bodies are placed and its rate at 0, as far as the joints and the values
/// given allow (in a closed loop the others follow); values they cannot all meet are refused.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct JointInitialSpec {
    /// The joint coordinate at the start, as `<joint>.angle` (revolute, rad) or
    /// `<joint>.position` (prismatic, m) reads it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<f64>,
    /// Joint angular speed (revolute, rad/s) or sliding velocity (prismatic, m/s) at the start.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed: Option<f64>,
}

/// How a joint constrains its two frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// Rigid connection: position and angle of the two frames coincide.
    Weld,
    /// Same position, free relative rotation.
    Revolute,
    /// Same angle, free sliding along an axis.
    Prismatic,
    /// 3D: same position, free rotation about any axis.
    Spherical,
}

/// What drives a revolute or prismatic joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct DriveSpec {
    /// `motion` (the joint coordinate follows the law), or `effort` (a torque, or a force for a
    /// prismatic joint, acts across the joint). A motion drive's law gives the coordinate
    /// (rad or m), an effort drive's the torque (N m) or force (N).
    pub kind: DriveKind,
    /// The law and its parameters, written beside `kind` (`law`, `value`, …).
    #[serde(flatten)]
    pub law: LawSpec,
}

/// What a drive's law sets: the joint coordinate, or the effort across the joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum DriveKind {
    /// The joint coordinate follows the law.
    Motion,
    /// A torque or force acts across the joint.
    Effort,
}

/// A scalar function of time: a drive's law, or a load's scale (`law` and its parameters).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct LawSpec {
    /// `constant`, `exponential` (value (1 - exp(-t/time_constant))), `spin_up` (planar paper
    /// eq. (18) with `omega` and `ramp_time`), `table` (piecewise linear), `input` (an FMU input).
    pub law: String,
    /// The value of `constant`, the final value of `exponential`, the start value of `input`
    /// (unit of what the law drives: rad or m, N m or N; a load's scale is a factor).
    #[serde(default)]
    pub value: Option<f64>,
    /// Time constant of `exponential`.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "s")))]
    #[serde(default)]
    pub time_constant: Option<f64>,
    /// The law is zero after this time.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "s")))]
    #[serde(default)]
    pub until: Option<f64>,
    /// Final angular speed of `spin_up` (a motion drive of a revolute joint).
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "rad/s")))]
    #[serde(default)]
    pub omega: Option<f64>,
    /// Duration of the `spin_up` ramp.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "s")))]
    #[serde(default)]
    pub ramp_time: Option<f64>,
    /// Rows [t, value] of `table` (t in s, increasing), interpolated linearly and held after
    /// the last row.
    #[serde(default)]
    pub table: Option<Vec<[f64; 2]>>,
}

/// A point force (world axes) and torque on a frame, constant or FMU inputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Load name: the prefix of its inputs and outputs (`<load>.fx`, `<load>.ax`).
    pub name: String,
    /// The frame it acts on: `<beam>.a`, `<beam>.b` or `<body>.<frame>`.
    pub frame: String,
    /// Force (world axes): `[fx, fy]` or `[fx, fy, fz]`.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "N")))]
    #[cfg_attr(feature = "schema", schemars(schema_with = "xyz::schema::point"))]
    #[serde(default, with = "xyz::point")]
    pub force: [f64; 3],
    /// Torque: a number (about z) or, in 3D, `[tx, ty, tz]` (world axes).
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "N m")))]
    #[cfg_attr(feature = "schema", schemars(schema_with = "xyz::schema::about_z"))]
    #[serde(default, with = "xyz::about_z")]
    pub torque: [f64; 3],
    /// Offer `<load>.fx`, `<load>.fy`, `<load>.torque` (3D: `.fz`, `.tx`, `.ty`, `.tz`) as FMU
    /// inputs (start: the values above).
    #[serde(default)]
    pub input: bool,
    /// The force and torque are scaled by this time law (e.g. a slow ramp); not with `input`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<LawSpec>,
}

/// A point in a body frame: `[x, y]` or `[x, y, z]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(transparent)]
pub struct Point(
    #[cfg_attr(feature = "schema", schemars(schema_with = "xyz::schema::point"))]
    #[serde(with = "xyz::point")]
    pub [f64; 3],
);

impl Scene {
    /// Parses and validates scene text; `origin` (a file name) prefixes every message.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Scene, SceneError> {
        let scene = Scene::parse(text, origin)?;
        scene.validate(origin)?;
        Ok(scene)
    }

    /// Parses scene text of at most [`files::MAX_SCENE_BYTES`]; a refusal says where (line,
    /// column) and what the parser expected, never the text around it.
    fn parse(text: &str, origin: &str) -> Result<Scene, SceneError> {
        let scene = Scene::parse_text(text, origin)?;
        let ck = validate::Checker { origin };
        // the number of components written is gone from the spec structs: read it again (not
        // for a scene of too many parts, which validation refuses at once)
        if scene.is_3d() && limits::parts(&ck, &scene).is_ok() {
            let table: toml::Table = toml::from_str(text).unwrap_or_default();
            scene.check_components(&ck, &table)?;
        }
        Ok(scene)
    }

    /// The text as a scene (the spec structs), nothing checked beyond its shape.
    fn parse_text(text: &str, origin: &str) -> Result<Scene, SceneError> {
        if text.len() as u64 > files::MAX_SCENE_BYTES {
            return Err(SceneError::Io {
                origin: origin.to_string(),
                message: files::FileRefusal::TooLarge {
                    cap: files::MAX_SCENE_BYTES,
                }
                .to_string(),
            });
        }
        toml::from_str(text).map_err(|e| {
            let at = match e.span() {
                Some(span) => {
                    let start = span.start.min(text.len());
                    let before = text.get(..start).unwrap_or("");
                    let line = before.matches('\n').count() + 1;
                    let line_start = before.rfind('\n').map_or(0, |k| k + 1);
                    let column = before.get(line_start..).map_or(0, |l| l.chars().count()) + 1;
                    format!(" at line {line}, column {column}")
                }
                None => String::new(),
            };
            SceneError::Parse {
                origin: origin.to_string(),
                message: format!(
                    "TOML parse error{at}: {}",
                    limits::abbreviate(e.message().trim_end(), 300)
                ),
            }
        })
    }

    /// Reads, parses and validates a scene file; a beam's `matrix_file` is read into its
    /// `matrix_text`, unless the text is there already. Each file is read only if it is a
    /// regular file within its cap ([`files::MAX_SCENE_BYTES`],
    /// [`files::MAX_MATRIX_FILE_BYTES`]); a matrix file must lie below the scene file's
    /// directory ([`Scene::from_toml_in`]).
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let origin = path.display().to_string();
        let text =
            files::read_capped(path, files::MAX_SCENE_BYTES).map_err(|e| SceneError::Io {
                origin: origin.clone(),
                message: e.to_string(),
            })?;
        let dir = path.parent().unwrap_or(Path::new("."));
        Scene::from_toml_in(&text, &origin, dir)
    }

    /// Parses and validates scene text whose beams' `matrix_file`s are read below `dir` (each
    /// into its `matrix_text`, unless the text is there already) by the one reader of the files
    /// a scene names, [`files::read_below`]: every entry point (`Scene::load`, the command
    /// line, the Python package's `from_toml` and `from_dict`) reads them here.
    pub fn from_toml_in(text: &str, origin: &str, dir: &Path) -> Result<Scene, SceneError> {
        let mut scene = Scene::parse(text, origin)?;
        // no file is read for a scene of too many beams (each may name one)
        limits::parts(&validate::Checker { origin }, &scene)?;
        let names: Vec<String> = scene.beams.iter().map(|b| b.name.clone()).collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        for (i, b) in scene.beams.iter_mut().enumerate() {
            // a packaged scene carries the text already
            if let (Some(file), None) = (&b.matrix_file, &b.matrix_text) {
                let refuse = |e: files::FileRefusal| SceneError::File {
                    origin: origin.to_string(),
                    field: format!("{}.matrix_file", part_path("beam", i, &names)),
                    file: limits::abbreviate(&format!("{file:?}"), 200),
                    rule: e.to_string(),
                };
                let text =
                    files::read_below(dir, file, files::MAX_MATRIX_FILE_BYTES).map_err(refuse)?;
                b.matrix_text = Some(text);
            }
        }
        scene.validate(origin)?;
        Ok(scene)
    }

    /// A 3D scene (`dimensions = 3`)?
    pub fn is_3d(&self) -> bool {
        self.dimensions == 3
    }

    /// The canonical TOML text of this scene (what the packager writes into the FMU).
    pub fn to_toml_string(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }

    /// Elements per floating frame and number of frames of a (validated) beam.
    pub fn beam_layout(beam: &BeamSpec) -> (usize, usize) {
        match beam.substructures {
            Some(k) => (beam.elements_per_substructure.unwrap_or(1), k),
            None => (beam.elements.unwrap_or(1), 1),
        }
    }

    /// The beam named `name`.
    pub fn beam(&self, name: &str) -> Option<&BeamSpec> {
        self.beams.iter().find(|b| b.name == name)
    }

    /// The outputs of a beam, resolved (an empty list means all).
    pub fn beam_outputs(&self, beam: &BeamSpec) -> Vec<&'static str> {
        let all: &[&'static str] = if self.is_3d() {
            &BEAM_OUTPUTS_3D
        } else {
            &BEAM_OUTPUTS
        };
        all.iter()
            .copied()
            .filter(|o| beam.outputs.is_empty() || beam.outputs.iter().any(|x| x == o))
            .collect()
    }
}
