//! The value rules of a scene, as one table: the validator (`validate.rs`, `space.rs`) refuses
//! a scene only through a [`Rule`] of [`RULES`], whose text is the message's rule; the packager
//! writes the same table into the scene reference (`docs/scene-reference.md`) and, where a rule
//! has a JSON-Schema form ([`Schema`]), into the scene schema. A test refuses one scene per rule
//! (`tests/refused_scenes.toml`) and checks the rule's code and field; so the page lists what the
//! validator does, no more and no less.
//!
//! Over 600 lines on purpose: one entry per rule, the table the generated reference lists, kept as
//! one table.

/// Which scenes a rule applies to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dims {
    /// Planar and 3D scenes.
    Any,
    /// Planar scenes (`dimensions = 2`).
    Planar,
    /// 3D scenes (`dimensions = 3`).
    Spatial,
}

/// How a rule reads in JSON Schema, where it has a form there (draft-07 keywords on the rule's
/// fields; in a scene of one kind only, under `if dimensions = 3`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Schema {
    /// Not expressed in the schema (it needs other fields' values, or arithmetic).
    None,
    /// `exclusiveMinimum`.
    Above(f64),
    /// `minimum`.
    AtLeast(f64),
    /// `maximum`.
    AtMost(f64),
    /// `exclusiveMaximum`.
    Below(f64),
    /// `minimum` and `maximum`.
    Within(f64, f64),
    /// `enum` of strings (on a string, or on an array's items).
    OneOf(&'static [&'static str]),
    /// `enum` of integers.
    OneOfIntegers(&'static [i64]),
    /// An identifier (`pattern`) other than these names (`not enum`); on a table's keys for a
    /// field `<name>`.
    Identifier(&'static [&'static str]),
    /// `not enum`: any value but these.
    NoneOf(&'static [&'static str]),
    /// The field must be absent.
    Absent,
    /// The field must be absent when the sibling field (`type`) has this value.
    AbsentWhen(&'static str, &'static str),
    /// The field is present, with at least this many items.
    Required(usize),
    /// `minItems`.
    MinItems(usize),
    /// `uniqueItems` on the array.
    Unique,
    /// The beam's layout: `elements`, or `substructures` with `elements_per_substructure`.
    BeamLayout,
    /// The parameters each time law needs.
    LawParameters,
}

/// One rule of the validator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rule {
    /// Stable name, used by the reference and the tests.
    pub code: &'static str,
    /// The fields it checks: `beam[].length` (`[]`: any index, `<name>`: any key; `*`: any
    /// number of the scene).
    pub fields: &'static [&'static str],
    /// The message's rule (some messages add the values that decided it).
    pub text: &'static str,
    /// The scenes it applies to: planar, 3D or both.
    pub dims: Dims,
    /// Its JSON-Schema form, if it has one.
    pub schema: Schema,
}

const fn rule(
    code: &'static str,
    fields: &'static [&'static str],
    text: &'static str,
    dims: Dims,
    schema: Schema,
) -> Rule {
    Rule {
        code,
        fields,
        text,
        dims,
        schema,
    }
}

use Dims::{Any, Planar, Spatial};

/// The time laws of drives and load scales.
pub const LAWS: [&str; 5] = ["constant", "exponential", "spin_up", "table", "input"];
/// The section shapes.
pub const SHAPES: [&str; 4] = ["rectangle", "circle", "hollow_rectangle", "hollow_circle"];
/// The effects a list may name, with what each one is.
pub const EFFECTS: [(&str, &str); 6] = [
    ("gravity", "the gravity field of world.gravity"),
    (
        "flexibility",
        "deformation of the beams (off: every beam is a rigid bar)",
    ),
    (
        "axial",
        "axial deformation of the beams (off: inextensible)",
    ),
    (
        "quadratic_velocity",
        "centrifugal and Coriolis terms of the beams' deformation",
    ),
    (
        "geometric_stiffening",
        "the geometric stiffness of the beams that ask for it (`geometric_stiffening = true`)",
    ),
    ("rayleigh_damping", "Rayleigh damping of the beams"),
];

/// The effects a scene can list ([`EFFECTS`], by name).
pub const EFFECT_NAMES: [&str; 6] = [
    "gravity",
    "flexibility",
    "axial",
    "quadratic_velocity",
    "geometric_stiffening",
    "rayleigh_damping",
];
/// Names that a beam, body, joint or load cannot take (they start other variables' names).
pub const RESERVED_NAMES: [&str; 3] = ["world", "solver", "energy"];
/// Which parameters each law needs.
pub const LAW_PARAMETERS: [(&str, &[&str]); 4] = [
    ("constant", &["value"]),
    ("exponential", &["value", "time_constant"]),
    ("spin_up", &["omega", "ramp_time"]),
    ("table", &["table"]),
];

/// Longest name of the scene, a beam, a body, a joint, a load or a body's frame (characters):
/// names become FMI variable names (`<beam>.shape.x[12]`) and the scene's name the file name of
/// the unit's binary (`<name>.so`, at most 255 bytes on Linux), which a master must open.
pub const MAX_NAME_LENGTH: usize = 64;
/// Longest `description` (characters): a line or a paragraph of modelDescription.xml.
pub const MAX_DESCRIPTION_LENGTH: usize = 1000;
/// Most beams of a scene.
pub const MAX_BEAMS: usize = 100;
/// Most rigid bodies, joints and loads of a scene (each).
pub const MAX_PARTS: usize = 1000;
/// Most rows of a `table` law.
pub const MAX_TABLE_ROWS: usize = 10_000;
/// Most elements of one beam, however split: `elements`, or `substructures` ×
/// `elements_per_substructure`.
pub const MAX_BEAM_ELEMENTS: usize = 2000;
/// Most memory a unit may need for its matrices (bytes, [`crate::scene::Size::memory`]): 1 GiB,
/// about 8000 unknowns n + m with a dense iteration matrix.
pub const MAX_UNIT_MEMORY: u64 = 1 << 30;
/// Most FMU variables of a unit ([`crate::scene::Size::variables`]): a modelDescription.xml of
/// some 10 MB, which masters still read in a moment.
pub const MAX_VARIABLES: u64 = 20_000;

const IDENTIFIER: &str = "must be an identifier (letters, digits, _; not starting with a digit)";
const ONLY_3D: &str = "is for 3D scenes (dimensions = 3)";
const PLANE: &str =
    "a planar scene lies in the world x–y plane (z = 0); write dimensions = 3 for a 3D scene";

pub(crate) const FINITE: Rule = rule(
    "finite",
    &["*"],
    "must be a finite number",
    Any,
    Schema::None,
);
/// A [`RANGES`] rule.
pub(crate) const GRAVITY_RANGE: Rule = rule(
    "gravity_range",
    &["world.gravity[]"],
    "must be at most 1e4 m/s² in magnitude (1000 g)",
    Any,
    Schema::Within(-1e4, 1e4),
);
/// A [`RANGES`] rule.
pub(crate) const LENGTH_RANGE: Rule = rule(
    "length_range",
    &[
        "beam[].length",
        "beam[].position[]",
        "beam[].section.a",
        "beam[].section.b",
        "beam[].section.d",
        "beam[].section.t",
        "beam[].initial.tip_displacement",
        "body[].position[]",
        "body[].com[]",
        "body[].frames.<name>[]",
    ],
    "must be at most 1e4 m in magnitude (10 km)",
    Any,
    Schema::Within(-1e4, 1e4),
);
/// A [`RANGES`] rule.
pub(crate) const MODULUS_RANGE: Rule = rule(
    "modulus_range",
    &["beam[].material.E", "beam[].material.G"],
    "must be at most 1e16 Pa (50 000 times steel's: room for a stiff stand-in for a rigid beam)",
    Any,
    Schema::Within(-1e16, 1e16),
);
/// A [`RANGES`] rule.
pub(crate) const DENSITY_RANGE: Rule = rule(
    "density_range",
    &["beam[].material.rho"],
    "must be at most 1e7 kg/m³ (400 times osmium's: room for masses smeared along a beam)",
    Any,
    Schema::Within(-1e7, 1e7),
);
/// A [`RANGES`] rule.
pub(crate) const AREA_RANGE: Rule = rule(
    "area_range",
    &["beam[].section.A"],
    "must be at most 1e8 m² in magnitude (a section within a square whose side is the largest length, 1e4 m)",
    Any,
    Schema::Within(-1e8, 1e8),
);
/// A [`RANGES`] rule.
pub(crate) const SECOND_MOMENT_RANGE: Rule = rule(
    "second_moment_range",
    &[
        "beam[].section.J",
        "beam[].section.Iy",
        "beam[].section.Iz",
        "beam[].section.It",
    ],
    "must be at most 1e16 m⁴ in magnitude (above a section within a square whose side is the largest length, 1e4 m: its polar moment is 1.7e15 m⁴)",
    Any,
    Schema::Within(-1e16, 1e16),
);
/// A [`RANGES`] rule.
pub(crate) const RAYLEIGH_ALPHA_RANGE: Rule = rule(
    "rayleigh_alpha_range",
    &["beam[].rayleigh.alpha"],
    "must be at most 1e9 1/s in magnitude (the deformation's velocity decays at the rate alpha: a decay faster than the smallest internal step, 1e-9 s, is one no step resolves)",
    Any,
    Schema::Within(-1e9, 1e9),
);
/// A [`RANGES`] rule.
pub(crate) const RAYLEIGH_BETA_RANGE: Rule = rule(
    "rayleigh_beta_range",
    &["beam[].rayleigh.beta"],
    "must be at most 1e9 s in magnitude (beta = viscosity / modulus is the retardation time of a Kelvin-Voigt solid: a deformation that relaxes only after the longest run a scene may ask for, 1e9 s, describes no beam)",
    Any,
    Schema::Within(-1e9, 1e9),
);
/// A [`RANGES`] rule.
pub(crate) const MASS_RANGE: Rule = rule(
    "mass_range",
    &["body[].mass"],
    "must be at most 1e9 kg",
    Any,
    Schema::Within(-1e9, 1e9),
);
/// A [`RANGES`] rule.
pub(crate) const INERTIA_RANGE: Rule = rule(
    "inertia_range",
    &["body[].inertia[]"],
    "must be at most 1e12 kg·m²",
    Any,
    Schema::Within(-1e12, 1e12),
);
/// A [`RANGES`] rule.
pub(crate) const LOAD_RANGE: Rule = rule(
    "load_range",
    &["load[].force[]", "load[].torque[]"],
    "must be at most 1e12 N (a torque: N·m) in magnitude",
    Any,
    Schema::Within(-1e12, 1e12),
);
/// A [`RANGES`] rule.
pub(crate) const LAW_VALUE_RANGE: Rule = rule(
    "law_value_range",
    &[
        "joint[].drive.value",
        "joint[].drive.omega",
        "joint[].drive.table[][1]",
        "load[].scale.value",
        "load[].scale.table[][1]",
    ],
    "must be at most 1e12 in magnitude, in the unit of what the law drives or scales",
    Any,
    Schema::Within(-1e12, 1e12),
);
/// A [`RANGES`] rule.
pub(crate) const TIME_RANGE: Rule = rule(
    "time_range",
    &[
        "experiment.start_time",
        "experiment.stop_time",
        "joint[].drive.time_constant",
        "joint[].drive.ramp_time",
        "joint[].drive.until",
        "joint[].drive.table[][0]",
        "load[].scale.time_constant",
        "load[].scale.ramp_time",
        "load[].scale.until",
        "load[].scale.table[][0]",
    ],
    "must be at most 1e9 s in magnitude (32 years)",
    Any,
    Schema::Within(-1e9, 1e9),
);
/// The physical ranges, with each rule's bound: every number of these fields lies within
/// ±bound, far beyond any machine's figure. A larger value describes no machine and only makes
/// the integrator take steps without end (gravity of 1e9 m/s² and an effort drive of −9.2e18
/// N·m kept `Stepper::advance` busy for minutes). A test checks each rule's text and schema
/// against its bound.
pub const RANGES: &[(Rule, f64)] = &[
    (GRAVITY_RANGE, 1e4),
    (LENGTH_RANGE, 1e4),
    (MODULUS_RANGE, 1e16),
    (DENSITY_RANGE, 1e7),
    (AREA_RANGE, 1e8),
    (SECOND_MOMENT_RANGE, 1e16),
    (RAYLEIGH_ALPHA_RANGE, 1e9),
    (RAYLEIGH_BETA_RANGE, 1e9),
    (MASS_RANGE, 1e9),
    (INERTIA_RANGE, 1e12),
    (LOAD_RANGE, 1e12),
    (LAW_VALUE_RANGE, 1e12),
    (TIME_RANGE, 1e9),
];

/// The least bound of [`RANGES`]: a number within it is within every range.
pub const LEAST_RANGE: f64 = least_bound(RANGES);

const fn least_bound(ranges: &[(Rule, f64)]) -> f64 {
    let mut least = f64::INFINITY;
    let mut k = 0;
    while k < ranges.len() {
        if ranges[k].1 < least {
            least = ranges[k].1;
        }
        k += 1;
    }
    least
}

/// The range rule and bound of the quantity at `field`, if it has one.
pub fn range_of(field: &str) -> Option<&'static (Rule, f64)> {
    RANGES
        .iter()
        .find(|(r, _)| r.fields.iter().any(|p| field_matches(p, field)))
}

pub(crate) const POSITIVE: Rule = rule(
    "positive",
    &[
        "solver.tolerance",
        "solver.max_step",
        "experiment.step_size",
        "accuracy.target",
        "beam[].length",
        "beam[].material.rho",
        "beam[].material.E",
        "beam[].material.G",
        "beam[].section.A",
        "beam[].section.J",
        "beam[].section.Iy",
        "beam[].section.Iz",
        "beam[].section.It",
        "beam[].section.a",
        "beam[].section.b",
        "beam[].section.d",
        "beam[].section.t",
        "joint[].drive.time_constant",
        "joint[].drive.ramp_time",
        "load[].scale.time_constant",
        "load[].scale.ramp_time",
    ],
    "must be positive",
    Any,
    Schema::Above(0.0),
);
pub(crate) const NON_NEGATIVE: Rule = rule(
    "non_negative",
    &[
        "accuracy.estimate",
        "beam[].rayleigh.alpha",
        "beam[].rayleigh.beta",
        "body[].mass",
        "body[].inertia[]",
        "joint[].drive.until",
        "load[].scale.until",
    ],
    "must not be negative",
    Any,
    Schema::AtLeast(0.0),
);
pub(crate) const SCENE_NAME: Rule = rule(
    "name",
    &["name", "beam[].name"],
    IDENTIFIER,
    Any,
    Schema::Identifier(&[]),
);
pub(crate) const NAME_LENGTH: Rule = rule(
    "name_length",
    &[
        "name",
        "beam[].name",
        "body[].name",
        "joint[].name",
        "load[].name",
        "body[].frames.<name>",
    ],
    "must be at most 64 characters (names become FMI variable names, the scene's name the binary's file name)",
    Any,
    Schema::None,
);
pub(crate) const DESCRIPTION_LENGTH: Rule = rule(
    "description_length",
    &["description"],
    "must be at most 1000 characters",
    Any,
    Schema::None,
);
pub(crate) const PARTS_MAX: Rule = rule(
    "parts_max",
    &["beam", "body", "joint", "load"],
    "a scene has at most 100 beams and 1000 each of bodies, joints and loads",
    Any,
    Schema::None,
);
pub(crate) const TABLE_ROWS_MAX: Rule = rule(
    "table_rows_max",
    &["joint[].drive.table", "load[].scale.table"],
    "a table has at most 10000 rows",
    Any,
    Schema::None,
);
pub(crate) const BEAM_ELEMENTS_MAX: Rule = rule(
    "beam_elements_max",
    &["beam[].substructures"],
    "substructures × elements_per_substructure must be at most 2000 (the elements of one beam)",
    Any,
    Schema::None,
);
pub(crate) const UNIT_MEMORY: Rule = rule(
    "unit_memory",
    &["beam"],
    "the unit's matrices must fit in 1 GiB (1073741824 bytes; fewer elements or substructures)",
    Any,
    Schema::None,
);
pub(crate) const VARIABLES_MAX: Rule = rule(
    "variables_max",
    &["beam"],
    "the unit must have at most 20000 FMU variables (fewer shape points, beams or parts)",
    Any,
    Schema::None,
);
pub(crate) const DIMENSIONS: Rule = rule(
    "dimensions",
    &["dimensions"],
    "must be 2 (planar) or 3 (spatial)",
    Any,
    Schema::OneOfIntegers(&[2, 3]),
);
/// The smallest `solver.tolerance`: about 450 machine epsilons. The error estimate is a third
/// divided difference of four positions, each known to a machine epsilon of its size: about 8 ε
/// of rounding. Below this the estimate is that rounding, and 5e-324 had every step Discarded
/// ("last correction inf").
pub const MIN_TOLERANCE: f64 = 1e-13;
/// Its text quotes [`MIN_TOLERANCE`] (a test checks it).
pub(crate) const TOLERANCE_FLOOR: Rule = rule(
    "tolerance_floor",
    &["solver.tolerance"],
    "must be at least 1e-13 (450 machine epsilons: below it the error estimate, a third difference of positions known to a machine epsilon, is rounding)",
    Any,
    Schema::AtLeast(MIN_TOLERANCE),
);
/// The smallest `beam[].material.rho` (kg/m³).
pub const MIN_DENSITY: f64 = 0.1;
/// Its text quotes [`MIN_DENSITY`] (a test checks it).
pub(crate) const DENSITY_FLOOR: Rule = rule(
    "density_floor",
    &["beam[].material.rho"],
    "must be at least 0.1 kg/m³ (no solid is lighter: graphene aerogel is 0.16 kg/m³; rho = 1e-300 left the beam a mass matrix of denormals)",
    Any,
    Schema::AtLeast(MIN_DENSITY),
);
/// XML 1.0 (§2.2, `Char`) holds tab, line feed, carriage return and the characters from U+0020
/// on, but not U+FFFE and U+FFFF (surrogates cannot occur in Rust text).
pub fn xml_char(c: char) -> bool {
    matches!(c, '\t' | '\n' | '\r') || (c >= ' ' && c != '\u{FFFE}' && c != '\u{FFFF}')
}
pub(crate) const XML_TEXT: Rule = rule(
    "xml_text",
    &["description"],
    "must hold only characters XML 1.0 allows: no control characters but tab, line feed and carriage return, no U+FFFE or U+FFFF (the text goes into modelDescription.xml)",
    Any,
    Schema::None,
);
pub(crate) const TOLERANCE_BELOW_ONE: Rule = rule(
    "tolerance_below_one",
    &["solver.tolerance"],
    "must be below 1",
    Any,
    Schema::Below(1.0),
);
pub(crate) const ACCURACY_TARGET: Rule = rule(
    "accuracy_target",
    &["accuracy.target"],
    "must be below 1 (an error relative to the output's largest magnitude)",
    Any,
    Schema::Below(1.0),
);
pub(crate) const ACCURACY_ESTIMATE: Rule = rule(
    "accuracy_estimate",
    &["accuracy.estimate"],
    "must be at most accuracy.target (settings tuned for a target meet it)",
    Any,
    Schema::None,
);
pub(crate) const ACCURACY_OUTPUT: Rule = rule(
    "accuracy_output",
    &["accuracy.output"],
    "must name an output of the unit, <part>.<output>, where <part> is a beam, body, joint or load of the scene",
    Any,
    Schema::None,
);
/// Its text quotes [`super::validate::MIN_STEP`] (a test checks it).
pub(crate) const MIN_STEP: Rule = rule(
    "min_step",
    &["solver.max_step"],
    "must be at least 1e-9 s (a smaller step makes no progress)",
    Any,
    Schema::AtLeast(super::validate::MIN_STEP),
);
/// Its text quotes [`super::validate::MAX_STEP`] (a test checks it).
pub(crate) const MAX_STEP: Rule = rule(
    "max_step",
    &["solver.max_step"],
    "must be at most 1 s (a longer step resolves no motion of a flexible multibody scene)",
    Any,
    Schema::AtMost(super::validate::MAX_STEP),
);
/// Its text quotes [`super::validate::MAX_STEP_BUDGET`].
pub(crate) const STEP_BUDGET: Rule = rule(
    "step_budget",
    &["solver.step_budget"],
    "must lie in [1, 300000000] (work units of one communication step: ten times the default, about a minute of work at most)",
    Any,
    Schema::Within(1.0, 300000000.0),
);
pub(crate) const RHO_INF: Rule = rule(
    "rho_inf",
    &["solver.rho_inf"],
    "must lie in [0, 1]",
    Any,
    Schema::Within(0.0, 1.0),
);
pub(crate) const STOP_AFTER_START: Rule = rule(
    "stop_after_start",
    &["experiment.stop_time"],
    "must be after experiment.start_time",
    Any,
    Schema::None,
);
pub(crate) const A_BEAM: Rule = rule(
    "a_beam",
    &["beam"],
    "a scene needs at least one [[beam]]",
    Any,
    Schema::Required(1),
);
pub(crate) const BEAM_NAMES_UNIQUE: Rule = rule(
    "beam_names_unique",
    &["beam[].name"],
    "beam names must be unique",
    Any,
    Schema::None,
);
pub(crate) const PART_NAME: Rule = rule(
    "part_name",
    &["beam[].name", "body[].name", "joint[].name", "load[].name"],
    "must be an identifier (letters, digits, _; not starting with a digit) other than world, solver, energy",
    Any,
    Schema::Identifier(&RESERVED_NAMES),
);
pub(crate) const NAMES_UNIQUE: Rule = rule(
    "names_unique",
    &["beam[].name", "body[].name", "joint[].name", "load[].name"],
    "names of beams, bodies, joints and loads must be unique",
    Any,
    Schema::None,
);
pub(crate) const JOINT_FRAME: Rule = rule(
    "joint_frame",
    &["joint[].frames[]"],
    "must be `world`, `<beam>.a`, `<beam>.b` or `<body>.<frame>` of this scene",
    Any,
    Schema::None,
);
pub(crate) const JOINT_FRAMES_DIFFER: Rule = rule(
    "joint_frames_differ",
    &["joint[].frames"],
    "a joint connects two different frames",
    Any,
    Schema::Unique,
);
/// Its text quotes [`super::placement::GAP_TOLERANCE`] (a test checks it).
pub(crate) const JOINT_GAP: Rule = rule(
    "joint_gap",
    &["joint[].frames"],
    "the joint's two frames must meet at t = 0 (a prismatic joint's: on its sliding axis), \
     within 1e-6 of the longest beam's length: place the parts so that they do, or write \
     `assemble = true` on the joint to have the unit move them together at initialization \
     (it logs what it moved)",
    Any,
    Schema::None,
);
pub(crate) const WELD_NO_DRIVE: Rule = rule(
    "weld_no_drive",
    &["joint[].drive"],
    "a weld joint has no motion to drive",
    Any,
    Schema::AbsentWhen("type", "weld"),
);
pub(crate) const MOTION_CONTINUOUS: Rule = rule(
    "motion_continuous",
    &["joint[].drive.law"],
    "a motion drive needs a law with a continuous start (constant, spin_up, table, input)",
    Any,
    Schema::None,
);
pub(crate) const JOINT_INITIAL_KIND: Rule = rule(
    "joint_initial_kind",
    &["joint[].initial"],
    "only a revolute or prismatic joint has a coordinate to start from",
    Any,
    Schema::None,
);
pub(crate) const JOINT_INITIAL_MOTION: Rule = rule(
    "joint_initial_motion",
    &["joint[].initial"],
    "a joint with a motion drive starts where its law does: give no initial position or speed",
    Any,
    Schema::None,
);
pub(crate) const LOAD_FRAME: Rule = rule(
    "load_frame",
    &["load[].frame"],
    "must be `<beam>.a`, `<beam>.b` or `<body>.<frame>` of this scene",
    Any,
    Schema::None,
);
pub(crate) const LOAD_ON_BODY: Rule = rule(
    "load_on_body",
    &["load[].frame"],
    "a load acts on a body",
    Any,
    Schema::NoneOf(&["world"]),
);
pub(crate) const SCALE_NOT_INPUT: Rule = rule(
    "scale_not_input",
    &["load[].scale"],
    "an input load, or an input law, cannot scale a load (use input = true)",
    Any,
    Schema::None,
);
pub(crate) const EFFECTS_MODE: Rule = rule(
    "effects_mode",
    &["effects"],
    "must be \"scene\", \"all\", \"auto\" or a list of effects",
    Any,
    Schema::OneOf(&["scene", "all", "auto"]),
);
pub(crate) const EFFECT_KNOWN: Rule = rule(
    "effect_known",
    &["effects[]"],
    "is not an effect; the effects are gravity, flexibility, axial, quadratic_velocity, geometric_stiffening, rayleigh_damping",
    Any,
    Schema::OneOf(&EFFECT_NAMES),
);
pub(crate) const EFFECT_ONCE: Rule = rule(
    "effect_once",
    &["effects[]"],
    "is listed twice",
    Any,
    Schema::Unique,
);
pub(crate) const DEFORMED_NEEDS_FLEXIBILITY: Rule = rule(
    "deformed_needs_flexibility",
    &["beam[].initial.tip_displacement"],
    "needs the effect \"flexibility\" (a rigid beam cannot start deformed)",
    Any,
    Schema::None,
);
pub(crate) const STIFFENING_NEEDS_AXIAL: Rule = rule(
    "stiffening_needs_axial",
    &["effects"],
    "a beam that asks for geometric stiffening needs the effect \"axial\" in the list (the 3D element always has it)",
    Any,
    Schema::None,
);
pub(crate) const AT_LEAST_ONE: Rule = rule(
    "at_least_one",
    &[
        "beam[].elements",
        "beam[].substructures",
        "beam[].elements_per_substructure",
    ],
    "must be at least 1",
    Any,
    Schema::AtLeast(1.0),
);
pub(crate) const ELEMENTS_MAX: Rule = rule(
    "elements_max",
    &["beam[].elements", "beam[].elements_per_substructure"],
    "must be at most 2000",
    Any,
    Schema::AtMost(2000.0),
);
pub(crate) const SUBSTRUCTURES_MAX: Rule = rule(
    "substructures_max",
    &["beam[].substructures"],
    "must be at most 500",
    Any,
    Schema::AtMost(500.0),
);
pub(crate) const LAYOUT_MISSING: Rule = rule(
    "layout_missing",
    &["beam[].elements"],
    "give `elements`, or `substructures` with `elements_per_substructure`",
    Any,
    Schema::BeamLayout,
);
pub(crate) const LAYOUT_PER_SUBSTRUCTURE: Rule = rule(
    "layout_per_substructure",
    &["beam[].elements_per_substructure"],
    "is required with `substructures`",
    Any,
    Schema::BeamLayout,
);
pub(crate) const LAYOUT_EITHER: Rule = rule(
    "layout_either",
    &["beam[].elements"],
    "give either `elements` (one frame) or `substructures` with `elements_per_substructure`",
    Any,
    Schema::BeamLayout,
);
pub(crate) const DEFORMED_SINGLE_FRAME: Rule = rule(
    "deformed_single_frame",
    &["beam[].initial.tip_displacement"],
    "is only available for single-frame beams (`elements`)",
    Any,
    Schema::None,
);
pub(crate) const RIGID_PLAIN: Rule = rule(
    "rigid_plain",
    &["beam[].rigid"],
    "a rigid beam has no substructures, stiffening or initial deformation",
    Any,
    Schema::None,
);
pub(crate) const MODES_RANGE: Rule = rule(
    "modes_range",
    &["beam[].modes"],
    "must lie between 1 and the deformation coordinates of a frame of a flexible beam (3 per element)",
    Any,
    Schema::AtLeast(1.0),
);
pub(crate) const SECTION_MISSING: Rule = rule(
    "section_missing",
    &["beam[].section"],
    "give `A` and `J`, or a `shape` (rectangle, circle, hollow_rectangle, hollow_circle) with its dimensions",
    Planar,
    Schema::None,
);
pub(crate) const SECTION_MISSING_3D: Rule = rule(
    "section_missing_3d",
    &["beam[].section"],
    "give `A`, `Iy`, `Iz` and `It`, or a `shape` (rectangle, circle, hollow_rectangle, hollow_circle) with its dimensions",
    Spatial,
    Schema::None,
);
pub(crate) const SECTION_VALUE_MISSING: Rule = rule(
    "section_value_missing",
    &[
        "beam[].section.A",
        "beam[].section.J",
        "beam[].section.Iy",
        "beam[].section.Iz",
        "beam[].section.It",
        "beam[].section.a",
        "beam[].section.b",
        "beam[].section.d",
        "beam[].section.t",
    ],
    "is required for this section",
    Any,
    Schema::None,
);
pub(crate) const SECTION_3D_CONSTANTS: Rule = rule(
    "section_3d_constants",
    &[
        "beam[].section.Iy",
        "beam[].section.Iz",
        "beam[].section.It",
    ],
    "is for 3D scenes (dimensions = 3); a planar section has A and J",
    Planar,
    Schema::Absent,
);
pub(crate) const SECTION_PLANAR_J: Rule = rule(
    "section_planar_j",
    &["beam[].section.J"],
    "is the planar second moment; a 3D section gives Iy, Iz and It",
    Spatial,
    Schema::Absent,
);
pub(crate) const SHAPE_DIMENSION_UNUSED: Rule = rule(
    "shape_dimension_unused",
    &[
        "beam[].section.a",
        "beam[].section.b",
        "beam[].section.d",
        "beam[].section.t",
    ],
    "belongs to a `shape`; with the section constants given it is not used",
    Any,
    Schema::None,
);
pub(crate) const CONSTANT_FROM_SHAPE: Rule = rule(
    "constant_from_shape",
    &[
        "beam[].section.A",
        "beam[].section.J",
        "beam[].section.Iy",
        "beam[].section.Iz",
        "beam[].section.It",
    ],
    "is computed from the `shape`; give either the shape or A and J",
    Any,
    Schema::None,
);
pub(crate) const NOT_OF_RECTANGLE: Rule = rule(
    "not_of_rectangle",
    &["beam[].section.d"],
    "is not a dimension of a rectangle",
    Any,
    Schema::None,
);
pub(crate) const NOT_OF_CIRCLE: Rule = rule(
    "not_of_circle",
    &["beam[].section.a", "beam[].section.b"],
    "is not a dimension of a circle",
    Any,
    Schema::None,
);
pub(crate) const HOLLOW_ONLY: Rule = rule(
    "hollow_only",
    &["beam[].section.t"],
    "is for hollow shapes",
    Any,
    Schema::None,
);
pub(crate) const WALL_OF_RECTANGLE: Rule = rule(
    "wall_of_rectangle",
    &["beam[].section.t"],
    "must be less than half of min(a, b)",
    Any,
    Schema::None,
);
pub(crate) const WALL_OF_CIRCLE: Rule = rule(
    "wall_of_circle",
    &["beam[].section.t"],
    "must be less than half of d",
    Any,
    Schema::None,
);
pub(crate) const SHAPE: Rule = rule(
    "shape",
    &["beam[].section.shape"],
    "must be one of rectangle, circle, hollow_rectangle, hollow_circle",
    Any,
    Schema::OneOf(&SHAPES),
);
pub(crate) const DEFORMATION_SMALL: Rule = rule(
    "deformation_small",
    &["beam[].initial.tip_displacement"],
    "must be small against the length (at most half of it)",
    Any,
    Schema::None,
);
pub(crate) const DEFORMED_TANGENT: Rule = rule(
    "deformed_tangent",
    &["beam[].initial.tip_displacement"],
    "needs frame = \"tangent\" (a pinned frame holds the tip on its axis)",
    Any,
    Schema::None,
);
pub(crate) const BEAM_OUTPUT: Rule = rule(
    "beam_output",
    &["beam[].outputs[]"],
    "must be one of tip.deflection, tip.x, tip.y, tip.phi, mid.deflection, shape",
    Planar,
    Schema::OneOf(&super::BEAM_OUTPUT_NAMES),
);
pub(crate) const BEAM_OUTPUT_3D: Rule = rule(
    "beam_output_3d",
    &["beam[].outputs[]"],
    "must be one of tip.x, tip.y, tip.z, tip.deflection_y, tip.deflection_z, tip.twist, shape",
    Spatial,
    Schema::OneOf(&super::BEAM_OUTPUT_NAMES_3D),
);
pub(crate) const SHAPE_POINTS: Rule = rule(
    "shape_points",
    &["beam[].shape_points"],
    "must be 0 (no shape outputs) or 2 to 1000 (points from flange a to flange b)",
    Any,
    Schema::AtMost(1000.0),
);
pub(crate) const BODY_INERTIA_3D: Rule = rule(
    "body_inertia_3d",
    &["body[].inertia"],
    "a 3D body with mass needs inertia = [Ixx, Iyy, Izz] (principal, body axes), each positive",
    Spatial,
    Schema::None,
);
pub(crate) const FRAME_NAME: Rule = rule(
    "frame_name",
    &["body[].frames.<name>"],
    "frame names are identifiers other than a and b",
    Any,
    Schema::Identifier(&["a", "b"]),
);
pub(crate) const LAW_PARAMETER: Rule = rule(
    "law_parameter",
    &[
        "joint[].drive.value",
        "joint[].drive.time_constant",
        "joint[].drive.omega",
        "joint[].drive.ramp_time",
        "joint[].drive.table",
        "load[].scale.value",
        "load[].scale.time_constant",
        "load[].scale.omega",
        "load[].scale.ramp_time",
        "load[].scale.table",
    ],
    "is required by law",
    Any,
    Schema::LawParameters,
);
pub(crate) const TABLE_ROWS: Rule = rule(
    "table_rows",
    &["joint[].drive.table", "load[].scale.table"],
    "needs at least two rows [t, value]",
    Any,
    Schema::MinItems(2),
);
pub(crate) const TABLE_TIMES: Rule = rule(
    "table_times",
    &["joint[].drive.table[][]", "load[].scale.table[][]"],
    "times must increase",
    Any,
    Schema::None,
);
pub(crate) const LAW: Rule = rule(
    "law",
    &["joint[].drive.law", "load[].scale.law"],
    "must be one of constant, exponential, spin_up, table, input",
    Any,
    Schema::OneOf(&LAWS),
);
pub(crate) const ONLY_3D_FIELD: Rule = rule(
    "only_3d_field",
    &[
        "beam[].axis",
        "beam[].normal",
        "beam[].matrix_file",
        "joint[].axis",
    ],
    ONLY_3D,
    Planar,
    Schema::Absent,
);
pub(crate) const SPATIAL_FORMULATION: Rule = rule(
    "spatial_formulation",
    &["formulation"],
    ONLY_3D,
    Planar,
    Schema::NoneOf(&["spatial"]),
);
pub(crate) const FROZEN_INERTIA: Rule = rule(
    "frozen_inertia",
    &["beam[].inertia"],
    ONLY_3D,
    Planar,
    Schema::NoneOf(&["frozen"]),
);
pub(crate) const SPHERICAL: Rule = rule(
    "spherical",
    &["joint[].type"],
    ONLY_3D,
    Planar,
    Schema::NoneOf(&["spherical"]),
);
pub(crate) const IN_PLANE: Rule = rule(
    "in_plane",
    &[
        "world.gravity[2]",
        "beam[].position[2]",
        "body[].position[2]",
        "body[].com[2]",
        "body[].frames.<name>[2]",
        "load[].force[2]",
    ],
    PLANE,
    Planar,
    Schema::None,
);
pub(crate) const SPATIAL_VECTOR: Rule = rule(
    "spatial_vector",
    &[
        "world.gravity",
        "beam[].position",
        "body[].position",
        "body[].com",
        "body[].frames.<name>",
        "load[].force",
    ],
    "a 3D scene's points and forces have 3 components [x, y, z] ([x, y] is the planar form)",
    Spatial,
    Schema::None,
);
pub(crate) const PLANAR_INERTIA: Rule = rule(
    "planar_inertia",
    &["body[].inertia[0]", "body[].inertia[1]"],
    "a planar body has one moment of inertia (about z): give a number",
    Planar,
    Schema::None,
);
pub(crate) const PLANAR_TORQUE: Rule = rule(
    "planar_torque",
    &["load[].torque[0]", "load[].torque[1]"],
    "a planar torque acts about z: give a number",
    Planar,
    Schema::None,
);
pub(crate) const DIRECTION: Rule = rule(
    "direction",
    &["beam[].axis", "beam[].normal", "joint[].axis"],
    "must be a non-zero direction",
    Spatial,
    Schema::None,
);
pub(crate) const NORMAL_TO_AXIS: Rule = rule(
    "normal_to_axis",
    &["beam[].normal"],
    "must be normal to the beam axis (it is the section's local z axis)",
    Spatial,
    Schema::None,
);
pub(crate) const NORMAL_REQUIRED: Rule = rule(
    "normal_required",
    &["beam[].normal"],
    "is required when the beam axis leaves the x–y plane (the default is world z)",
    Spatial,
    Schema::None,
);
pub(crate) const SHEAR_MODULUS: Rule = rule(
    "shear_modulus",
    &["beam[].material.G"],
    "a flexible 3D beam needs its shear modulus (torsion)",
    Spatial,
    Schema::None,
);
pub(crate) const PLANAR_ELEMENT_ONLY: Rule = rule(
    "planar_element_only",
    &["beam[].modes", "beam[].initial.tip_displacement"],
    "is available with the planar element only, and this scene runs with the 3D element",
    Spatial,
    Schema::None,
);
pub(crate) const MATRIX_FILE: Rule = rule(
    "matrix_file",
    &["beam[].matrix_file"],
    "is not a valid matrix file (symmetric 12 x 12 mass and stiffness, see the format)",
    Spatial,
    Schema::None,
);
pub(crate) const MATRIX_ONE_ELEMENT: Rule = rule(
    "matrix_one_element",
    &["beam[].matrix_file"],
    "a matrix-file beam is one flexible element: write elements = 1, no substructures, not rigid",
    Spatial,
    Schema::None,
);
pub(crate) const MATRIX_LENGTH: Rule = rule(
    "matrix_length",
    &["beam[].length"],
    "must equal the matrix file's length",
    Spatial,
    Schema::None,
);
pub(crate) const SPHERICAL_NO_DRIVE: Rule = rule(
    "spherical_no_drive",
    &["joint[].drive"],
    "a spherical joint has no single coordinate to drive",
    Spatial,
    Schema::AbsentWhen("type", "spherical"),
);
pub(crate) const SPATIAL_EFFECTS: Rule = rule(
    "spatial_effects",
    &["effects[]"],
    "with the 3D element, the effects that can be switched are gravity, flexibility, geometric_stiffening, rayleigh_damping",
    Spatial,
    Schema::None,
);

/// Every rule, in the order the reference lists them.
pub const RULES: &[Rule] = &[
    FINITE,
    GRAVITY_RANGE,
    LENGTH_RANGE,
    MODULUS_RANGE,
    DENSITY_RANGE,
    AREA_RANGE,
    SECOND_MOMENT_RANGE,
    RAYLEIGH_ALPHA_RANGE,
    RAYLEIGH_BETA_RANGE,
    MASS_RANGE,
    INERTIA_RANGE,
    LOAD_RANGE,
    LAW_VALUE_RANGE,
    TIME_RANGE,
    POSITIVE,
    NON_NEGATIVE,
    SCENE_NAME,
    NAME_LENGTH,
    DESCRIPTION_LENGTH,
    XML_TEXT,
    PARTS_MAX,
    DIMENSIONS,
    SPATIAL_FORMULATION,
    EFFECTS_MODE,
    EFFECT_KNOWN,
    EFFECT_ONCE,
    STIFFENING_NEEDS_AXIAL,
    SPATIAL_EFFECTS,
    IN_PLANE,
    SPATIAL_VECTOR,
    TOLERANCE_BELOW_ONE,
    TOLERANCE_FLOOR,
    DENSITY_FLOOR,
    ACCURACY_TARGET,
    ACCURACY_ESTIMATE,
    ACCURACY_OUTPUT,
    MIN_STEP,
    MAX_STEP,
    STEP_BUDGET,
    RHO_INF,
    STOP_AFTER_START,
    A_BEAM,
    PART_NAME,
    BEAM_NAMES_UNIQUE,
    NAMES_UNIQUE,
    AT_LEAST_ONE,
    ELEMENTS_MAX,
    SUBSTRUCTURES_MAX,
    BEAM_ELEMENTS_MAX,
    UNIT_MEMORY,
    VARIABLES_MAX,
    LAYOUT_MISSING,
    LAYOUT_PER_SUBSTRUCTURE,
    LAYOUT_EITHER,
    RIGID_PLAIN,
    MODES_RANGE,
    PLANAR_ELEMENT_ONLY,
    ONLY_3D_FIELD,
    FROZEN_INERTIA,
    DIRECTION,
    NORMAL_TO_AXIS,
    NORMAL_REQUIRED,
    SHEAR_MODULUS,
    MATRIX_FILE,
    MATRIX_ONE_ELEMENT,
    MATRIX_LENGTH,
    SECTION_MISSING,
    SECTION_MISSING_3D,
    SECTION_VALUE_MISSING,
    SECTION_3D_CONSTANTS,
    SECTION_PLANAR_J,
    SHAPE,
    SHAPE_DIMENSION_UNUSED,
    CONSTANT_FROM_SHAPE,
    NOT_OF_RECTANGLE,
    NOT_OF_CIRCLE,
    HOLLOW_ONLY,
    WALL_OF_RECTANGLE,
    WALL_OF_CIRCLE,
    DEFORMATION_SMALL,
    DEFORMED_TANGENT,
    DEFORMED_SINGLE_FRAME,
    DEFORMED_NEEDS_FLEXIBILITY,
    BEAM_OUTPUT,
    BEAM_OUTPUT_3D,
    SHAPE_POINTS,
    BODY_INERTIA_3D,
    PLANAR_INERTIA,
    FRAME_NAME,
    JOINT_FRAME,
    JOINT_FRAMES_DIFFER,
    JOINT_GAP,
    SPHERICAL,
    WELD_NO_DRIVE,
    SPHERICAL_NO_DRIVE,
    MOTION_CONTINUOUS,
    JOINT_INITIAL_KIND,
    JOINT_INITIAL_MOTION,
    LAW,
    LAW_PARAMETER,
    TABLE_ROWS,
    TABLE_ROWS_MAX,
    TABLE_TIMES,
    LOAD_FRAME,
    LOAD_ON_BODY,
    SCALE_NOT_INPUT,
    PLANAR_TORQUE,
];

/// The rule of this code.
pub fn find(code: &str) -> Option<&'static Rule> {
    RULES.iter().find(|r| r.code == code)
}

/// Does a field of a message (`beam[2].section.A`, `beam "arm".section.A`) match a pattern of a
/// rule (`beam[].section.A`)? `[]` matches any index, or a part's name in quotes after a space
/// (how messages name a beam, body, joint or load that has one); `<name>` any key, `*` anything.
pub fn field_matches(pattern: &str, field: &str) -> bool {
    if pattern == "*" {
        return true;
    }
    let (p, f) = (pattern.as_bytes(), field.as_bytes());
    let (mut i, mut j) = (0, 0);
    while i < p.len() {
        if p[i..].starts_with(b"[]") && f.get(j..).is_some_and(|r| r.starts_with(b" \"")) {
            j += 2;
            let start = j;
            while j < f.len() && (f[j].is_ascii_alphanumeric() || f[j] == b'_') {
                j += 1;
            }
            if j == start || j >= f.len() || f[j] != b'"' {
                return false;
            }
            i += 2;
            j += 1;
        } else if p[i..].starts_with(b"[]") {
            if j >= f.len() || f[j] != b'[' {
                return false;
            }
            j += 1;
            let start = j;
            while j < f.len() && f[j].is_ascii_digit() {
                j += 1;
            }
            if j == start || j >= f.len() || f[j] != b']' {
                return false;
            }
            i += 2;
            j += 1;
        } else if p[i..].starts_with(b"<name>") {
            let start = j;
            while j < f.len() && (f[j].is_ascii_alphanumeric() || f[j] == b'_') {
                j += 1;
            }
            if j == start {
                return false;
            }
            i += 6;
        } else {
            if j >= f.len() || f[j] != p[i] {
                return false;
            }
            i += 1;
            j += 1;
        }
    }
    j == f.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_unique_and_every_rule_is_listed_once() {
        for (k, r) in RULES.iter().enumerate() {
            assert!(
                RULES[..k].iter().all(|o| o.code != r.code),
                "code {} twice",
                r.code
            );
        }
    }

    #[test]
    fn the_tables_quote_the_engine_constants() {
        let effects: Vec<&str> = EFFECTS.iter().map(|(n, _)| *n).collect();
        assert_eq!(effects, EFFECT_NAMES);
        assert!(EFFECT_KNOWN.text.ends_with(&EFFECT_NAMES.join(", ")));
        assert!(MIN_STEP
            .text
            .contains(&format!("{:e} s", super::super::validate::MIN_STEP)));
        assert!(TOLERANCE_FLOOR
            .text
            .contains(&format!("at least {MIN_TOLERANCE:e} (")));
        assert!(DENSITY_FLOOR
            .text
            .contains(&format!("at least {MIN_DENSITY} kg/m³")));
        assert!(STEP_BUDGET
            .text
            .contains(&format!("[1, {}]", super::super::validate::MAX_STEP_BUDGET)));
        assert!(LAW.text.ends_with(&LAWS.join(", ")));
        assert!(SHAPE.text.ends_with(&SHAPES.join(", ")));
        assert!(BEAM_OUTPUT
            .text
            .ends_with(&super::super::BEAM_OUTPUT_NAMES.join(", ")));
        assert!(BEAM_OUTPUT_3D
            .text
            .ends_with(&super::super::BEAM_OUTPUT_NAMES_3D.join(", ")));
        assert!(SHAPE_POINTS
            .text
            .contains(&format!("2 to {}", super::super::MAX_POINTS)));
        assert!(SPATIAL_EFFECTS
            .text
            .ends_with(&super::super::SPATIAL_EFFECTS.join(", ")));
        assert!(PART_NAME.text.ends_with(&RESERVED_NAMES.join(", ")));
        let quotes = |r: &Rule, n: &str| assert!(r.text.contains(n), "{}: {n}", r.code);
        quotes(
            &NAME_LENGTH,
            &format!("at most {MAX_NAME_LENGTH} characters"),
        );
        quotes(
            &DESCRIPTION_LENGTH,
            &format!("at most {MAX_DESCRIPTION_LENGTH} characters"),
        );
        quotes(&PARTS_MAX, &format!("at most {MAX_BEAMS} beams"));
        quotes(&PARTS_MAX, &format!("{MAX_PARTS} each"));
        quotes(&TABLE_ROWS_MAX, &format!("at most {MAX_TABLE_ROWS} rows"));
        quotes(&BEAM_ELEMENTS_MAX, &format!("at most {MAX_BEAM_ELEMENTS}"));
        quotes(&UNIT_MEMORY, &format!("({MAX_UNIT_MEMORY} bytes"));
        quotes(&VARIABLES_MAX, &format!("at most {MAX_VARIABLES} FMU"));
        quotes(
            &JOINT_GAP,
            &format!("within {:e} of", super::super::placement::GAP_TOLERANCE),
        );
    }

    #[test]
    fn each_range_rule_quotes_its_bound_in_its_text_and_schema() {
        for (rule, bound) in RANGES {
            assert!(
                rule.text.contains(&format!("at most {bound:e}")),
                "{}: {}",
                rule.code,
                rule.text
            );
            assert_eq!(rule.schema, Schema::Within(-bound, *bound), "{}", rule.code);
            assert!(RULES.contains(rule), "{}", rule.code);
        }
        assert_eq!(range_of("world.gravity[1]").map(|r| r.1), Some(1e4));
        assert_eq!(range_of("body[3].frames.tip[0]").map(|r| r.1), Some(1e4));
        assert_eq!(
            range_of("joint[0].drive.table[2][0]").map(|r| r.0.code),
            Some("time_range")
        );
        assert_eq!(range_of("solver.rho_inf"), None);
        assert_eq!(LEAST_RANGE, 1e4);
        assert!(RANGES.iter().all(|(_, bound)| *bound >= LEAST_RANGE));
    }

    #[test]
    fn field_patterns_match_indices_and_names() {
        assert!(field_matches("beam[].length", "beam[12].length"));
        assert!(!field_matches("beam[].length", "beam[].length"));
        assert!(!field_matches("beam[].length", "beam[0].lengths"));
        assert!(field_matches(
            "body[].frames.<name>[2]",
            "body[1].frames.tip[2]"
        ));
        assert!(!field_matches(
            "body[].frames.<name>[2]",
            "body[1].frames.tip[1]"
        ));
        assert!(field_matches(
            "joint[].drive.table[][]",
            "joint[0].drive.table[3][0]"
        ));
        assert!(field_matches("*", "anything"));
        assert!(field_matches(
            "joint[].frames[]",
            "joint \"elbow\".frames[0]"
        ));
        assert!(field_matches("beam[].length", "beam \"arm_2\".length"));
        assert!(!field_matches("beam[].length", "beam \"\".length"));
        assert!(!field_matches("beam[].length", "beam \"arm.length"));
    }
}
