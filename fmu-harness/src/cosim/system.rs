//! The system file of `fmu-harness cosim` (TOML, serde with `deny_unknown_fields`): units,
//! connections, experiment, communication step, coupling algorithm, input extrapolation,
//! rollback. [`System::load`] parses and checks it; every error names the file and the field.
//!
//! Over 600 lines only by its unit tests (130); the format and its checks read best together.

use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer};
use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum SystemError {
    #[error(transparent)]
    File(#[from] crate::input_file::InputFileError),
    #[error("{}: {message}", .path.display())]
    Parse { path: PathBuf, message: String },
    #[error("{}: field `{field}`: {message}", .path.display())]
    Invalid {
        path: PathBuf,
        field: String,
        message: String,
    },
}

/// Bytes of a system file: 16 MiB.
pub const MAX_SYSTEM_FILE_BYTES: u64 = 16 * 1024 * 1024;
/// Units of one system: 256. Each is an FMU extracted and a library loaded; the shipped
/// examples couple 2 or 3, co-simulations of a machine a few dozen.
pub const MAX_UNITS: usize = 256;
/// Bytes the units' FMUs of one system may expand to, all together: 2 GiB (four FMUs at the
/// master's limit for one, [`crate::slave::MAX_EXTRACTED_BYTES`]; ours expand to 4 MB).
pub const MAX_SYSTEM_EXTRACTED_BYTES: u64 = 2 * 1024 * 1024 * 1024;

/// Where the TOML is wrong and why, without the source line toml's own message quotes, and
/// without the value serde's `invalid type: string "…", expected …` quotes (only its kind is
/// kept); the reason is cut at 200 characters.
fn parse_message(text: &str, e: &toml::de::Error) -> String {
    let message = e.message().trim_end();
    let unquoted = ["invalid type: ", "invalid value: "]
        .iter()
        .find_map(|head| {
            let rest = message.strip_prefix(head)?;
            let (found, expected) = rest.split_once(", expected ")?;
            let kind = found.split_whitespace().next().unwrap_or("value");
            Some(format!("{head}{kind}, expected {expected}"))
        })
        .unwrap_or_else(|| message.to_string());
    let mut why: String = unquoted.chars().take(200).collect();
    if unquoted.chars().count() > 200 {
        why.push('…');
    }
    match e.span() {
        Some(span) => {
            let (line, column) = crate::input_file::line_column(text, span.start);
            format!("line {line}, column {column}: {why}")
        }
        None => why,
    }
}

/// The whole system file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct System {
    #[serde(default)]
    pub start_time: f64,
    pub stop_time: f64,
    pub step: StepSpec,
    #[serde(default)]
    pub algorithm: Algorithm,
    /// Gauss–Seidel order of the units (names); default: the order of `[[unit]]`.
    #[serde(default)]
    pub order: Vec<String>,
    #[serde(default)]
    pub extrapolation: Extrapolation,
    #[serde(default)]
    pub rollback: Option<RollbackSpec>,
    /// Columns of the CSV, `<unit>.<variable>`; empty = every output of every unit.
    #[serde(default)]
    pub outputs: Vec<String>,
    #[serde(rename = "unit")]
    pub units: Vec<UnitSpec>,
    #[serde(default)]
    pub connections: Vec<ConnectionSpec>,
    /// Mechanical joints between units, coupled by their interface forces (`cosim::joint`).
    #[serde(default, rename = "joint")]
    pub joints: Vec<JointSpec>,
    #[serde(default)]
    pub coupling: CouplingSpec,
}

/// A mechanical joint between two units: the frames `<unit>.<prefix>` of both carry an input
/// load (inputs `<prefix>.fx`, `.fy` (, `.fz`)) and offer their motion (outputs `<prefix>.x`,
/// `.y` (, `.z`) and `<prefix>.ax`, `.ay` (, `.az`)). The first gets the joint force λ, the
/// second −λ; λ makes the two positions agree at every communication point.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpec {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: JointKind,
    pub frames: [String; 2],
}

/// What a joint holds together.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// A planar pin: positions x, y agree, forces fx, fy.
    Revolute,
    /// A 3D ball joint: positions x, y, z agree, forces fx, fy, fz.
    Spherical,
}

impl JointKind {
    /// The world axes the joint holds: the suffixes of its force inputs, positions and
    /// accelerations.
    pub fn axes(self) -> &'static [(&'static str, &'static str, &'static str)] {
        match self {
            JointKind::Revolute => &[("fx", "x", "ax"), ("fy", "y", "ay")],
            JointKind::Spherical => &[("fx", "x", "ax"), ("fy", "y", "ay"), ("fz", "z", "az")],
        }
    }
}

/// The iteration of the joint forces in each communication step.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CouplingSpec {
    /// Largest |position mismatch| of any joint at the end of a step (m).
    #[serde(default = "default_joint_tolerance")]
    pub tolerance: f64,
    /// Iterations (each one step of every unit) before the step is refused (and halved).
    #[serde(default = "default_joint_iterations")]
    pub max_iterations: u32,
}

fn default_joint_tolerance() -> f64 {
    1e-9
}
fn default_joint_iterations() -> u32 {
    10
}

impl Default for CouplingSpec {
    fn default() -> Self {
        CouplingSpec {
            tolerance: default_joint_tolerance(),
            max_iterations: default_joint_iterations(),
        }
    }
}

/// Communication step: `size` fixed, or (with `variable`) the first step of the step-size
/// control on the extrapolation error of the coupling signals.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepSpec {
    pub size: f64,
    #[serde(default)]
    pub variable: Option<VariableStep>,
}

#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariableStep {
    pub min: f64,
    pub max: f64,
    /// Per signal: |y(t+h) − extrapolated y(t+h)| ≤ abs_tolerance + tolerance·|y(t+h)|.
    pub tolerance: f64,
    #[serde(default)]
    pub abs_tolerance: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Algorithm {
    /// Every unit steps from the values at t (order irrelevant).
    #[default]
    Jacobi,
    /// Units step in `order`; a unit gets the t + h outputs of the units before it.
    GaussSeidel,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Extrapolation {
    /// Inputs held constant over a step.
    #[default]
    None,
    /// Polynomial of order 1 through the last two communication points (order 2: three), handed
    /// over with fmi2SetRealInputDerivatives to units whose canInterpolateInputs is true.
    Linear,
    Quadratic,
}

impl Extrapolation {
    pub fn order(self) -> usize {
        match self {
            Extrapolation::None => 0,
            Extrapolation::Linear => 1,
            Extrapolation::Quadratic => 2,
        }
    }
}

/// Retry a step with half the step from the FMU states saved at its start.
impl Default for RollbackSpec {
    fn default() -> Self {
        RollbackSpec {
            max_halvings: default_max_halvings(),
            on_discard: true,
            checks: Vec::new(),
        }
    }
}

/// Retry a step with half the step from the FMU states saved at its start.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RollbackSpec {
    /// Halvings of one step before the run is given up.
    #[serde(default = "default_max_halvings")]
    pub max_halvings: u32,
    /// Retry when a unit returns fmi2Discard from fmi2DoStep.
    #[serde(default = "default_true")]
    pub on_discard: bool,
    #[serde(default, rename = "check")]
    pub checks: Vec<CheckSpec>,
}

fn default_max_halvings() -> u32 {
    10
}
fn default_true() -> bool {
    true
}

/// An output that must stay within bounds at the end of every step, else the step is retried.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckSpec {
    /// `<unit>.<variable>`.
    pub variable: String,
    #[serde(default)]
    pub min: Option<f64>,
    #[serde(default)]
    pub max: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnitSpec {
    /// Unit name, no `.` in it: `<unit>.<variable>` names its variables.
    pub name: String,
    /// The FMU, relative to the system file.
    pub fmu: PathBuf,
    /// Start values of parameters (or inputs), set before initialization.
    #[serde(default)]
    pub start: BTreeMap<String, StartValue>,
}

#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum StartValue {
    Boolean(bool),
    Integer(i64),
    Real(f64),
}

/// `"a.x -> b.u"`, or `{ from = "a.x", to = "b.u", factor = -1.0, extrapolation = "none" }`
/// (u = factor·x; `extrapolation` overrides the system's for this connection).
#[derive(Debug, Clone, PartialEq)]
pub struct ConnectionSpec {
    pub from: String,
    pub to: String,
    pub factor: f64,
    pub extrapolation: Option<Extrapolation>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConnectionTable {
    from: String,
    to: String,
    #[serde(default = "one")]
    factor: f64,
    #[serde(default)]
    extrapolation: Option<Extrapolation>,
}

fn one() -> f64 {
    1.0
}

impl<'de> Deserialize<'de> for ConnectionSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = ConnectionSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(r#""<unit>.<output> -> <unit>.<input>" or { from, to, factor }"#)
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<ConnectionSpec, E> {
                let (from, to) = s.split_once("->").ok_or_else(|| {
                    E::custom(format!(
                        "connection `{s}`: expected \"<unit>.<output> -> <unit>.<input>\""
                    ))
                })?;
                Ok(ConnectionSpec {
                    from: from.trim().to_string(),
                    to: to.trim().to_string(),
                    factor: 1.0,
                    extrapolation: None,
                })
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<ConnectionSpec, A::Error> {
                let t = ConnectionTable::deserialize(de::value::MapAccessDeserializer::new(map))?;
                Ok(ConnectionSpec {
                    from: t.from,
                    to: t.to,
                    factor: t.factor,
                    extrapolation: t.extrapolation,
                })
            }
        }
        d.deserialize_any(V)
    }
}

/// Splits `<unit>.<variable>` at the first dot.
pub fn split_name(full: &str) -> Option<(&str, &str)> {
    full.split_once('.')
        .filter(|(u, v)| !u.is_empty() && !v.is_empty())
}

impl System {
    /// Reads, parses and checks a system file.
    pub fn load(path: &Path) -> Result<System, SystemError> {
        let text = crate::input_file::read_text(path, "a system file", MAX_SYSTEM_FILE_BYTES)?;
        System::from_toml_str(&text, path)
    }

    /// Parses and checks system text; `path` names the file in errors.
    pub fn from_toml_str(text: &str, path: &Path) -> Result<System, SystemError> {
        let system: System = toml::from_str(text).map_err(|e| SystemError::Parse {
            path: path.to_path_buf(),
            message: parse_message(text, &e),
        })?;
        system.check(path)?;
        Ok(system)
    }

    /// Value rules that serde cannot express.
    fn check(&self, path: &Path) -> Result<(), SystemError> {
        let bad = |field: &str, message: String| SystemError::Invalid {
            path: path.to_path_buf(),
            field: field.to_string(),
            message,
        };
        if !(self.start_time.is_finite() && self.stop_time.is_finite())
            || self.stop_time <= self.start_time
        {
            return Err(bad(
                "stop_time",
                format!(
                    "= {}: must be finite and after start_time = {}",
                    self.stop_time, self.start_time
                ),
            ));
        }
        let positive = |field: &str, v: f64| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(bad(field, format!("= {v}: must be positive and finite")))
            }
        };
        positive("step.size", self.step.size)?;
        let steps = ((self.stop_time - self.start_time) / self.step.size).ceil();
        let limit = crate::simulate::MAX_COMMUNICATION_STEPS;
        if self.step.variable.is_none() && (steps.is_nan() || steps > limit) {
            return Err(bad(
                "step.size",
                format!(
                    "= {:e}: {steps:.3e} communication steps from start_time to stop_time; \
                     the master takes at most {limit:e}",
                    self.step.size
                ),
            ));
        }
        if let Some(v) = &self.step.variable {
            positive("step.variable.min", v.min)?;
            positive("step.variable.max", v.max)?;
            positive("step.variable.tolerance", v.tolerance)?;
            if !(v.abs_tolerance >= 0.0 && v.abs_tolerance.is_finite()) {
                return Err(bad(
                    "step.variable.abs_tolerance",
                    format!("= {}: must be non-negative", v.abs_tolerance),
                ));
            }
            // the controller never steps below `min`: the count's worst case, bounded as the
            // fixed step's count is
            let worst = ((self.stop_time - self.start_time) / v.min).ceil();
            if worst.is_nan() || worst > limit {
                return Err(bad(
                    "step.variable.min",
                    format!(
                        "= {:e}: up to {worst:.3e} communication steps from start_time to \
                         stop_time; the master takes at most {limit:e}",
                        v.min
                    ),
                ));
            }
            if !(v.min <= self.step.size && self.step.size <= v.max) {
                return Err(bad(
                    "step.size",
                    format!(
                        "= {}: the first step must lie in [step.variable.min, step.variable.max] = [{}, {}]",
                        self.step.size, v.min, v.max
                    ),
                ));
            }
        }
        if self.units.is_empty() {
            return Err(bad("unit", "at least one [[unit]] is needed".into()));
        }
        if self.units.len() > MAX_UNITS {
            return Err(bad(
                "unit",
                format!(
                    "{} [[unit]] entries: a system has at most {MAX_UNITS}",
                    self.units.len()
                ),
            ));
        }
        for (i, u) in self.units.iter().enumerate() {
            if u.name.is_empty() || u.name.contains('.') {
                return Err(bad(
                    &format!("unit[{i}].name"),
                    format!("= \"{}\": must be non-empty and without `.`", u.name),
                ));
            }
            if self.units[..i].iter().any(|o| o.name == u.name) {
                return Err(bad(
                    &format!("unit[{i}].name"),
                    format!("= \"{}\": two units have this name", u.name),
                ));
            }
        }
        let unit_of = |field: &str, full: &str| -> Result<(), SystemError> {
            let (u, _) = split_name(full)
                .ok_or_else(|| bad(field, format!("= \"{full}\": expected <unit>.<variable>")))?;
            if self.units.iter().any(|x| x.name == u) {
                Ok(())
            } else {
                Err(bad(
                    field,
                    format!(
                        "= \"{full}\": no unit named `{u}` (units: {})",
                        self.unit_names()
                    ),
                ))
            }
        };
        for (i, c) in self.connections.iter().enumerate() {
            unit_of(&format!("connections[{i}].from"), &c.from)?;
            unit_of(&format!("connections[{i}].to"), &c.to)?;
            if !c.factor.is_finite() {
                return Err(bad(
                    &format!("connections[{i}].factor"),
                    format!("= {}: must be finite", c.factor),
                ));
            }
            if let Some(j) = self.connections[..i].iter().position(|o| o.to == c.to) {
                return Err(bad(
                    &format!("connections[{i}].to"),
                    format!("= \"{}\": already set by connections[{j}]", c.to),
                ));
            }
        }
        for (i, o) in self.outputs.iter().enumerate() {
            unit_of(&format!("outputs[{i}]"), o)?;
        }
        if !self.order.is_empty() {
            let mut sorted: Vec<&str> = self.order.iter().map(String::as_str).collect();
            sorted.sort_unstable();
            let mut names: Vec<&str> = self.units.iter().map(|u| u.name.as_str()).collect();
            names.sort_unstable();
            if sorted != names {
                return Err(bad(
                    "order",
                    format!(
                        "= {:?}: must name every unit exactly once (units: {})",
                        self.order,
                        self.unit_names()
                    ),
                ));
            }
        }
        for (i, j) in self.joints.iter().enumerate() {
            for (k, f) in j.frames.iter().enumerate() {
                unit_of(&format!("joint[{i}].frames[{k}]"), f)?;
            }
            let units = j.frames.each_ref().map(|f| split_name(f).map(|x| x.0));
            if units[0] == units[1] {
                return Err(bad(
                    &format!("joint[{i}].frames"),
                    "must name frames of two different units".into(),
                ));
            }
            if self.joints[..i].iter().any(|o| o.name == j.name) {
                return Err(bad(
                    &format!("joint[{i}].name"),
                    format!("= \"{}\": two joints have this name", j.name),
                ));
            }
        }
        if !self.joints.is_empty() && self.step.variable.is_some() {
            return Err(bad(
                "step.variable",
                "joints are coupled with a fixed communication step (they land on the units' \
                 events by themselves); remove `variable`"
                    .into(),
            ));
        }
        if !(self.coupling.tolerance > 0.0 && self.coupling.tolerance.is_finite()) {
            return Err(bad(
                "coupling.tolerance",
                format!("= {}: must be positive and finite", self.coupling.tolerance),
            ));
        }
        if self.coupling.max_iterations == 0 {
            return Err(bad(
                "coupling.max_iterations",
                "= 0: must be at least 1".into(),
            ));
        }
        if let Some(r) = &self.rollback {
            for (i, c) in r.checks.iter().enumerate() {
                let field = format!("rollback.check[{i}]");
                unit_of(&format!("{field}.variable"), &c.variable)?;
                if c.min.is_none() && c.max.is_none() {
                    return Err(bad(&field, "needs `min`, `max` or both".into()));
                }
            }
        }
        Ok(())
    }

    fn unit_names(&self) -> String {
        self.units
            .iter()
            .map(|u| u.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Unit indices in stepping order.
    pub fn stepping_order(&self) -> Vec<usize> {
        if self.order.is_empty() {
            (0..self.units.len()).collect()
        } else {
            self.order
                .iter()
                .map(|n| self.units.iter().position(|u| &u.name == n).unwrap_or(0))
                .collect()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const OK: &str = r#"
stop_time = 1.0
step = { size = 1e-2 }
algorithm = "gauss-seidel"
order = ["b", "a"]
extrapolation = "linear"
connections = ["a.x -> b.u", { from = "b.y", to = "a.u", factor = -1.0, extrapolation = "none" }]
[[unit]]
name = "a"
fmu = "a.fmu"
start = { k = 2.0, n = 3, on = true }
[[unit]]
name = "b"
fmu = "b.fmu"
[rollback]
max_halvings = 4
check = [{ variable = "a.e", max = 1.0 }]
"#;

    fn parse(text: &str) -> Result<System, SystemError> {
        System::from_toml_str(text, Path::new("sys.toml"))
    }

    #[test]
    fn a_full_system_file_is_read() {
        let s = parse(OK).unwrap();
        assert_eq!(s.algorithm, Algorithm::GaussSeidel);
        assert_eq!(s.stepping_order(), [1, 0]);
        assert_eq!(s.extrapolation, Extrapolation::Linear);
        assert_eq!(s.connections[0].factor, 1.0);
        assert_eq!(
            (s.connections[1].from.as_str(), s.connections[1].factor),
            ("b.y", -1.0)
        );
        assert_eq!(s.connections[1].extrapolation, Some(Extrapolation::None));
        assert_eq!(s.connections[0].extrapolation, None);
        assert_eq!(s.units[0].start["k"], StartValue::Real(2.0));
        assert_eq!(s.units[0].start["n"], StartValue::Integer(3));
        assert_eq!(s.rollback.as_ref().unwrap().max_halvings, 4);
        assert!(s.rollback.as_ref().unwrap().on_discard);
    }

    #[test]
    fn joints_are_read_and_checked() {
        let joint = "[[joint]]\nname = \"pin\"\ntype = \"revolute\"\nframes = [\"a.p\", \"b.p\"]\n";
        let s = parse(&format!("{OK}{joint}[coupling]\ntolerance = 1e-8\n")).unwrap();
        assert_eq!(s.joints[0].kind, JointKind::Revolute);
        assert_eq!(s.joints[0].frames, ["a.p".to_string(), "b.p".to_string()]);
        assert_eq!(s.coupling.tolerance, 1e-8);
        assert_eq!(s.coupling.max_iterations, 10);
        let cases = [
            (
                joint.replace("b.p", "a.q"),
                "field `joint[0].frames`: must name frames of two different units",
            ),
            (
                joint.replace("b.p", "c.p"),
                "field `joint[0].frames[1]`: = \"c.p\": no unit named `c`",
            ),
            (
                joint.replace("revolute", "hinge"),
                "unknown variant `hinge`",
            ),
            (
                format!("{joint}[coupling]\nmax_iterations = 0\n"),
                "field `coupling.max_iterations`",
            ),
        ];
        for (extra, expected) in cases {
            let e = parse(&format!("{OK}{extra}")).unwrap_err().to_string();
            assert!(e.contains(expected), "expected `{expected}` in: {e}");
        }
        let variable = OK.replace(
            "size = 1e-2 }",
            "size = 1e-2, variable = { min = 1e-3, max = 1e-1, tolerance = 1e-3 } }",
        );
        let e = parse(&format!("{variable}{joint}"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("field `step.variable`"), "{e}");
    }

    #[test]
    fn errors_name_the_file_and_the_field() {
        let cases = [
            (
                OK.replace("max_halvings", "max_halving"),
                "unknown field `max_halving`",
            ),
            (
                OK.replace("a.x -> b.u", "a.x => b.u"),
                "expected \"<unit>.<output> -> <unit>.<input>\"",
            ),
            (
                OK.replace("a.x -> b.u", "c.x -> b.u"),
                "field `connections[0].from`: = \"c.x\": no unit named `c`",
            ),
            (
                OK.replace("\"b.y\"", "\"b.y\", gain = 2"),
                "unknown field `gain`",
            ),
            (OK.replace("[\"b\", \"a\"]", "[\"b\"]"), "field `order`"),
            (
                OK.replace("size = 1e-2", "size = -1"),
                "field `step.size`: = -1: must be positive",
            ),
            (
                OK.replace("max = 1.0", "bound = 1.0"),
                "unknown field `bound`",
            ),
            (
                OK.replace("\"gauss-seidel\"", "\"newton\""),
                "unknown variant `newton`",
            ),
            (
                OK.replace("name = \"b\"", "name = \"a\""),
                "field `unit[1].name`",
            ),
        ];
        for (text, expected) in cases {
            let e = parse(&text).unwrap_err().to_string();
            assert!(e.starts_with("sys.toml: "), "{e}");
            assert!(e.contains(expected), "expected `{expected}` in: {e}");
        }
    }
}
