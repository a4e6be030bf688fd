//! What the master reads of an FMU's `modelDescription.xml` ([`ModelDescription::parse`]): the
//! FMI version, the model identifier, GUID (FMI 3.0's instantiationToken), capability flags,
//! variables and default experiment (the file the packager writes is
//! [`crate::model_description`]'s).
//!
//! FMI 2.0 declares each variable as a `ScalarVariable` with a type element inside; FMI 3.0 as
//! a type element (`Float64`, `Int32`, ...) of its own, an array with `Dimension` children.
//! The master moves Float64, Int32 and Boolean values of FMI 3.0 (2.0's Real, Integer and
//! Boolean); a variable of another 3.0 type is kept as [`VarType::Other`], to be named in an
//! error if it is used.

use super::extract::shown;
use super::{FmuRefused, SlaveError};
use crate::input_file::line_column;
use crate::platform::FmiVersion;
use quick_xml::events::{BytesStart, Event};
use std::collections::HashMap;
use std::path::Path;

/// Bytes of a `modelIdentifier`: 251, so that `<modelIdentifier>.dll` fits a file name of 255
/// bytes (NAME_MAX of Linux and most file systems).
pub const MAX_MODEL_IDENTIFIER_BYTES: usize = 251;

/// Why `id` cannot name a binary: it must be a C identifier ([A-Za-z_][A-Za-z0-9_]*, FMI 2.0
/// §2.2.1 asks the C function prefix to be one) of at most [`MAX_MODEL_IDENTIFIER_BYTES`].
fn identifier_problem(id: &str) -> Option<&'static str> {
    let mut chars = id.chars();
    match chars.next() {
        None => Some("is empty"),
        _ if id.len() > MAX_MODEL_IDENTIFIER_BYTES => Some("is too long"),
        Some(c) if !(c.is_ascii_alphabetic() || c == '_') => {
            Some("does not start with a letter or `_`")
        }
        _ if !chars.all(|c| c.is_ascii_alphanumeric() || c == '_') => {
            Some("holds a character other than a letter, digit or `_`")
        }
        _ => None,
    }
}

/// What the XML parser expected, in words of our own: the parser's own messages quote the
/// document (a tag's name, an attribute's text), and the document is not to be echoed.
fn expected(e: &quick_xml::Error) -> String {
    use quick_xml::errors::{IllFormedError, SyntaxError};
    use quick_xml::Error;
    match e {
        Error::Syntax(s) => match s {
            SyntaxError::InvalidBangMarkup => "a comment, CDATA or DOCTYPE after `<!`".into(),
            SyntaxError::UnclosedPIOrXmlDecl => "`?>` closing a declaration".into(),
            SyntaxError::UnclosedComment => "`-->` closing a comment".into(),
            SyntaxError::UnclosedDoctype => "`>` closing the DOCTYPE".into(),
            SyntaxError::UnclosedCData => "`]]>` closing a CDATA section".into(),
            SyntaxError::UnclosedTag => "`>` closing a tag".into(),
        },
        Error::IllFormed(f) => match f {
            IllFormedError::MissingEndTag(name) => format!("an end tag `</{}>`", shown(name)),
            IllFormedError::MismatchedEndTag { expected, .. } => {
                format!("the end tag `</{}>`", shown(expected))
            }
            IllFormedError::UnmatchedEndTag(_) => "no end tag here (nothing is open)".into(),
            IllFormedError::DoubleHyphenInComment => "no `--` inside a comment".into(),
            _ => "a well-formed XML declaration or DOCTYPE".into(),
        },
        Error::InvalidAttr(_) => "attributes as name=\"value\", each name once".into(),
        Error::Encoding(_) => "text in UTF-8".into(),
        Error::Escape(_) => "a known entity or character reference after `&`".into(),
        Error::Io(_) | Error::Namespace(_) => "well-formed XML".into(),
    }
}

/// Base type of a variable: FMI 2.0's names; FMI 3.0's Float64 is `Real`, Int32 `Integer`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
    String,
    /// FMI 2.0's Enumeration (read as an Integer).
    Enumeration,
    /// An FMI 3.0 type the master does not move (Float32, Int64, Enumeration, Binary, Clock,
    /// ...), by its element name.
    Other(&'static str),
}

impl VarType {
    /// The type as the model description of `version` names it.
    pub fn name(self, version: FmiVersion) -> &'static str {
        match (version, self) {
            (FmiVersion::V2, VarType::Real) => "Real",
            (FmiVersion::V2, VarType::Integer) => "Integer",
            (FmiVersion::V3, VarType::Real) => "Float64",
            (FmiVersion::V3, VarType::Integer) => "Int32",
            (_, VarType::Boolean) => "Boolean",
            (_, VarType::String) => "String",
            (_, VarType::Enumeration) => "Enumeration",
            (_, VarType::Other(name)) => name,
        }
    }

    /// Whether the master reads and records it as a number.
    pub fn is_numeric(self) -> bool {
        !matches!(self, VarType::String | VarType::Other(_))
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
    Independent,
    /// FMI 3.0: a parameter that sets the size of arrays.
    StructuralParameter,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    pub name: String,
    pub value_reference: u32,
    pub var_type: VarType,
    pub causality: Causality,
    /// An FMI 3.0 array's dimensions (row-major); empty for a scalar.
    pub dimensions: Vec<usize>,
}

impl Variable {
    /// How many values a get or set of it moves: 1 for a scalar.
    pub fn value_count(&self) -> usize {
        self.dimensions.iter().product()
    }

    pub fn is_scalar(&self) -> bool {
        self.dimensions.is_empty()
    }

    /// Its values' column names: its name for a scalar; for an array each element's, as FMI
    /// 2.0 names the scalars of an array (`x[1]`, ..., `m[1,2]`), in row-major order.
    pub fn columns(&self) -> Vec<String> {
        if self.is_scalar() {
            return vec![self.name.clone()];
        }
        let mut index = vec![1usize; self.dimensions.len()];
        let mut names = Vec::with_capacity(self.value_count());
        for _ in 0..self.value_count() {
            let i: Vec<String> = index.iter().map(usize::to_string).collect();
            names.push(format!("{}[{}]", self.name, i.join(",")));
            for d in (0..index.len()).rev() {
                if index[d] < self.dimensions[d] {
                    index[d] += 1;
                    break;
                }
                index[d] = 1;
            }
        }
        names
    }
}

/// The `DefaultExperiment` element; each attribute optional.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DefaultExperiment {
    pub start_time: Option<f64>,
    pub stop_time: Option<f64>,
    pub tolerance: Option<f64>,
    pub step_size: Option<f64>,
}

/// The elements of an FMI 3.0 variable, by name: the type the master moves it as.
const TYPES3: [(&str, VarType); 15] = [
    ("Float64", VarType::Real),
    ("Int32", VarType::Integer),
    ("Boolean", VarType::Boolean),
    ("String", VarType::String),
    ("Float32", VarType::Other("Float32")),
    ("Int8", VarType::Other("Int8")),
    ("UInt8", VarType::Other("UInt8")),
    ("Int16", VarType::Other("Int16")),
    ("UInt16", VarType::Other("UInt16")),
    ("UInt32", VarType::Other("UInt32")),
    ("Int64", VarType::Other("Int64")),
    ("UInt64", VarType::Other("UInt64")),
    ("Enumeration", VarType::Other("Enumeration")),
    ("Binary", VarType::Other("Binary")),
    ("Clock", VarType::Other("Clock")),
];

/// Elements of one array variable at the most (FMI 3.0 dimensions multiplied): 1e7, 80 MB of
/// Float64 values for one get. A larger product is refused as absurd.
pub const MAX_ARRAY_ELEMENTS: usize = 10_000_000;

/// The attribute of the root element that holds the FMU's identity.
fn token_name(version: FmiVersion) -> &'static str {
    match version {
        FmiVersion::V2 => "guid",
        FmiVersion::V3 => "instantiationToken",
    }
}

/// The version of the `fmiVersion` attribute: `2.0`, or `3.0` and its minor versions (`3.1`).
fn version_of(text: &str) -> Option<FmiVersion> {
    let text = text.trim();
    if text == "2.0" {
        Some(FmiVersion::V2)
    } else if text == "3.0"
        || text.starts_with("3.") && text[2..].bytes().all(|b| b.is_ascii_digit() || b == b'.')
    {
        Some(FmiVersion::V3)
    } else {
        None
    }
}

/// What the master needs from `modelDescription.xml`.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelDescription {
    /// 2.0 or 3.0, from `fmiVersion`.
    pub fmi_version: FmiVersion,
    pub model_identifier: String,
    pub guid: String,
    pub can_get_and_set_fmu_state: bool,
    pub can_interpolate_inputs: bool,
    pub provides_directional_derivative: bool,
    pub variables: Vec<Variable>,
    pub default_experiment: DefaultExperiment,
    /// The number of values of each array variable (FMI 3.0), by value reference.
    array_lengths: HashMap<u32, usize>,
}

impl ModelDescription {
    /// Parses the XML text; `origin` names the file in errors.
    pub fn parse(xml: &str, origin: &Path) -> Result<Self, SlaveError> {
        let fail = |message: String| SlaveError::ModelDescription {
            path: origin.to_path_buf(),
            message,
        };
        let mut reader = quick_xml::Reader::from_str(xml);
        let mut md = ModelDescription {
            fmi_version: FmiVersion::V2,
            model_identifier: String::new(),
            guid: String::new(),
            can_get_and_set_fmu_state: false,
            can_interpolate_inputs: false,
            provides_directional_derivative: false,
            variables: Vec::new(),
            default_experiment: DefaultExperiment::default(),
            array_lengths: HashMap::new(),
        };
        // whether the root element named a version the master runs; read before any variable
        let mut versioned = false;
        let mut token: Option<String> = None;
        // FMI 2.0: the ScalarVariable being read (name, vr, causality), until its type element;
        // FMI 3.0: the variable being read, until its end tag (its Dimension children)
        let mut pending: Option<(String, u32, Causality)> = None;
        let mut pending3: Option<Variable> = None;
        let mut in_model_variables = false;
        loop {
            let event = reader.read_event().map_err(|e| {
                let (line, column) = line_column(xml, reader.error_position() as usize);
                SlaveError::from(FmuRefused::XmlSyntax {
                    path: origin.to_path_buf(),
                    line,
                    column,
                    expected: expected(&e),
                })
            })?;
            let (e, empty) = match &event {
                Event::Start(e) => (e, false),
                Event::Empty(e) => (e, true),
                Event::End(e) => {
                    match e.name().as_ref() {
                        b"ModelVariables" => in_model_variables = false,
                        b"ScalarVariable" => {
                            if let Some((name, ..)) = pending.take() {
                                return Err(fail(format!(
                                    "variable `{}` has no type element",
                                    shown(&name)
                                )));
                            }
                        }
                        tag if pending3
                            .as_ref()
                            .is_some_and(|v| v.var_type.name(FmiVersion::V3).as_bytes() == tag) =>
                        {
                            let v = pending3.take().expect("checked");
                            md.push3(v, origin)?;
                        }
                        _ => {}
                    }
                    continue;
                }
                Event::Eof => break,
                _ => continue,
            };
            let attr = |key: &str| attribute(e, key).map_err(&fail);
            let v3 = md.fmi_version == FmiVersion::V3;
            match e.name().as_ref() {
                b"fmiModelDescription" => {
                    if let Some(text) = attr("fmiVersion")? {
                        md.fmi_version = version_of(&text).ok_or_else(|| {
                            let plain = text.len() <= 10
                                && text.bytes().all(|b| b.is_ascii_digit() || b == b'.');
                            let said = if plain {
                                format!("fmiVersion {text}")
                            } else {
                                "its fmiVersion".to_string()
                            };
                            fail(format!(
                                "{said} is neither 2.0 nor 3.0: the master runs FMI 2.0 and \
                                 3.0 co-simulation FMUs"
                            ))
                        })?;
                        versioned = true;
                    }
                    // missing: refused at the end, after the document's syntax
                    token = attr(token_name(md.fmi_version))?;
                }
                b"CoSimulation" => {
                    let id = attr("modelIdentifier")?
                        .ok_or_else(|| fail("CoSimulation has no modelIdentifier".into()))?;
                    if let Some(reason) = identifier_problem(&id) {
                        return Err(SlaveError::from(FmuRefused::ModelIdentifier {
                            path: origin.to_path_buf(),
                            shown: shown(&id),
                            bytes: id.len(),
                            limit: MAX_MODEL_IDENTIFIER_BYTES,
                            reason,
                        }));
                    }
                    md.model_identifier = id;
                    let flag = |v2: &str, v3_name: &str| -> Result<bool, SlaveError> {
                        Ok(attr(if v3 { v3_name } else { v2 })?.as_deref() == Some("true"))
                    };
                    md.can_get_and_set_fmu_state =
                        flag("canGetAndSetFMUstate", "canGetAndSetFMUState")?;
                    // FMI 3.0 has no input derivatives: its inputs are held over a step
                    md.can_interpolate_inputs = !v3 && flag("canInterpolateInputs", "")?;
                    md.provides_directional_derivative = flag(
                        "providesDirectionalDerivative",
                        "providesDirectionalDerivatives",
                    )?;
                }
                b"DefaultExperiment" => {
                    let num = |key: &str| -> Result<Option<f64>, SlaveError> {
                        attr(key)?
                            .map(|v| {
                                v.trim().parse::<f64>().map_err(|_| {
                                    fail(format!("DefaultExperiment {key} is not a number"))
                                })
                            })
                            .transpose()
                    };
                    md.default_experiment = DefaultExperiment {
                        start_time: num("startTime")?,
                        stop_time: num("stopTime")?,
                        tolerance: num("tolerance")?,
                        step_size: num("stepSize")?,
                    };
                }
                b"ModelVariables" => in_model_variables = !empty,
                b"ScalarVariable" if in_model_variables && !v3 => {
                    let (name, vr, causality) = header(e, &fail)?;
                    if empty {
                        return Err(fail(format!(
                            "variable `{}` has no type element",
                            shown(&name)
                        )));
                    }
                    pending = Some((name, vr, causality));
                }
                tag @ (b"Real" | b"Integer" | b"Boolean" | b"String" | b"Enumeration") if !v3 => {
                    if let Some((name, value_reference, causality)) = pending.take() {
                        let var_type = match tag {
                            b"Real" => VarType::Real,
                            b"Integer" => VarType::Integer,
                            b"Boolean" => VarType::Boolean,
                            b"String" => VarType::String,
                            _ => VarType::Enumeration,
                        };
                        md.variables.push(Variable {
                            name,
                            value_reference,
                            var_type,
                            causality,
                            dimensions: Vec::new(),
                        });
                    }
                }
                b"Dimension" if pending3.is_some() => {
                    let v = pending3.as_mut().expect("checked");
                    let name = shown(&v.name);
                    let Some(start) = attr("start")? else {
                        return Err(fail(format!(
                            "array `{name}`: a dimension set by a structural parameter; the \
                             master reads arrays of fixed size only"
                        )));
                    };
                    let n = start.trim().parse::<usize>().map_err(|_| {
                        fail(format!(
                            "array `{name}`: a Dimension's start is not a whole number"
                        ))
                    })?;
                    v.dimensions.push(n);
                }
                tag if v3 && in_model_variables && pending3.is_none() => {
                    let Some(&(_, var_type)) = TYPES3.iter().find(|(n, _)| n.as_bytes() == tag)
                    else {
                        continue;
                    };
                    let (name, value_reference, causality) = header(e, &fail)?;
                    let v = Variable {
                        name,
                        value_reference,
                        var_type,
                        causality,
                        dimensions: Vec::new(),
                    };
                    if empty {
                        md.push3(v, origin)?;
                    } else {
                        pending3 = Some(v);
                    }
                }
                _ => {}
            }
        }
        if !versioned {
            return Err(fail(
                "fmiModelDescription has no fmiVersion (2.0 or 3.0)".into(),
            ));
        }
        md.guid = token.ok_or_else(|| fail(format!("no {}", token_name(md.fmi_version))))?;
        if md.model_identifier.is_empty() {
            return Err(fail(
                "no CoSimulation element: not a co-simulation FMU".into(),
            ));
        }
        check_value_references(&md.variables, md.fmi_version, origin)?;
        Ok(md)
    }

    /// Adds an FMI 3.0 variable, read to its end tag.
    fn push3(&mut self, v: Variable, origin: &Path) -> Result<(), SlaveError> {
        if !v.is_scalar() {
            let len = v
                .dimensions
                .iter()
                .try_fold(1usize, |n, &d| n.checked_mul(d))
                .filter(|&n| n <= MAX_ARRAY_ELEMENTS);
            let Some(len) = len else {
                return Err(SlaveError::ModelDescription {
                    path: origin.to_path_buf(),
                    message: format!(
                        "array `{}` has more than {MAX_ARRAY_ELEMENTS} elements",
                        shown(&v.name)
                    ),
                });
            };
            self.array_lengths.insert(v.value_reference, len);
        }
        self.variables.push(v);
        Ok(())
    }

    /// How many values a get or set of the variables `vrs` moves (an FMI 3.0 array's elements;
    /// a reference the model description does not declare counts one).
    pub fn values_of(&self, vrs: &[u32]) -> usize {
        vrs.iter()
            .map(|vr| self.array_lengths.get(vr).copied().unwrap_or(1))
            .sum()
    }

    pub fn variable(&self, name: &str) -> Result<&Variable, SlaveError> {
        self.variables
            .iter()
            .find(|v| v.name == name)
            .ok_or_else(|| SlaveError::UnknownVariable { name: name.into() })
    }

    pub fn outputs(&self) -> impl Iterator<Item = &Variable> {
        self.variables
            .iter()
            .filter(|v| v.causality == Causality::Output)
    }
}

/// A variable's name, value reference and causality (both versions' attributes).
fn header(
    e: &BytesStart,
    fail: &impl Fn(String) -> SlaveError,
) -> Result<(String, u32, Causality), SlaveError> {
    let attr = |key: &str| attribute(e, key).map_err(fail);
    let name = attr("name")?.ok_or_else(|| fail("a variable has no name".into()))?;
    let vr = attr("valueReference")?
        .and_then(|v| v.trim().parse::<u32>().ok())
        .ok_or_else(|| {
            fail(format!(
                "variable `{}`: valueReference is not an integer in [0, 2^32)",
                shown(&name)
            ))
        })?;
    let causality = match attr("causality")?.as_deref().unwrap_or("local") {
        "parameter" => Causality::Parameter,
        "calculatedParameter" => Causality::CalculatedParameter,
        "structuralParameter" => Causality::StructuralParameter,
        "input" => Causality::Input,
        "output" => Causality::Output,
        "local" => Causality::Local,
        "independent" => Causality::Independent,
        _ => {
            return Err(fail(format!(
                "variable `{}`: causality is none of parameter, calculatedParameter, \
                 structuralParameter, input, output, local, independent",
                shown(&name)
            )))
        }
    };
    Ok((name, vr, causality))
}

/// FMI 2.0: two variables of one base type (Integer and Enumeration count as one) may share a
/// value reference only as aliases (FMI 2.0 §2.2.7), and an alias set has at most one start
/// value: at most one of them is an input or a parameter, and an input is aliased to nothing
/// (it would move another variable the master did not set). FMI 3.0: a value reference names
/// one variable (§2.4.7; aliases are `Alias` elements of it). Any other sharing is refused,
/// naming both variables.
fn check_value_references(
    variables: &[Variable],
    version: FmiVersion,
    origin: &Path,
) -> Result<(), SlaveError> {
    let class = |t: VarType| match t {
        VarType::Integer | VarType::Enumeration => "Integer",
        t => t.name(version),
    };
    let settable = |c: Causality| matches!(c, Causality::Input | Causality::Parameter);
    // (class, vr) → the first variable with it and the settable one of the set, if any.
    let mut seen: HashMap<(&str, u32), (usize, Option<usize>)> = HashMap::new();
    for (i, v) in variables.iter().enumerate() {
        // FMI 3.0: one space of value references for all types
        let space = if version == FmiVersion::V3 {
            "any"
        } else {
            class(v.var_type)
        };
        let key = (space, v.value_reference);
        match seen.get_mut(&key) {
            None => {
                seen.insert(key, (i, settable(v.causality).then_some(i)));
            }
            Some((first, _)) if version == FmiVersion::V3 => {
                return Err(SlaveError::from(FmuRefused::DuplicateValueReference {
                    path: origin.to_path_buf(),
                    vr: v.value_reference,
                    kind: v.var_type.name(version),
                    first: shown(&variables[*first].name),
                    second: shown(&v.name),
                    rule: "in FMI 3.0 a value reference names one variable",
                }));
            }
            Some((first, setter)) => {
                let other = match (*setter, settable(v.causality)) {
                    (Some(s), true) => Some(s),
                    _ if v.causality == Causality::Input => Some(*first),
                    _ if variables[*first].causality == Causality::Input => Some(*first),
                    (None, true) => {
                        *setter = Some(i);
                        None
                    }
                    _ => None,
                };
                if let Some(o) = other {
                    return Err(SlaveError::from(FmuRefused::DuplicateValueReference {
                        path: origin.to_path_buf(),
                        vr: v.value_reference,
                        kind: key.0,
                        first: shown(&variables[o].name),
                        second: shown(&v.name),
                        rule: "aliases may share one only if at most one of them is an input \
                               or a parameter, and an input has none",
                    }));
                }
            }
        }
    }
    Ok(())
}

fn attribute(e: &BytesStart, key: &str) -> Result<Option<String>, String> {
    match e.try_get_attribute(key) {
        Ok(Some(a)) => a
            .unescape_value()
            .map(|v| Some(v.into_owned()))
            .map_err(|_| {
                format!("attribute {key}: an unknown entity or a bad character reference")
            }),
        Ok(None) => Ok(None),
        Err(_) => Err(format!(
            "attribute {key}: not written as {key}=\"value\", once"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const XML: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="m" guid="{g&amp;1}">
  <CoSimulation modelIdentifier="m_id" canGetAndSetFMUstate="true"/>
  <DefaultExperiment startTime="0.5" stopTime="2" stepSize="1e-3"/>
  <ModelVariables>
    <ScalarVariable name="k" valueReference="3" causality="parameter"><Real start="1"/></ScalarVariable>
    <ScalarVariable name="n" valueReference="7"><Integer/></ScalarVariable>
    <ScalarVariable name="y" valueReference="0" causality="output"><Real/></ScalarVariable>
  </ModelVariables>
</fmiModelDescription>"#;

    #[test]
    fn model_description_gives_identifier_guid_variables_and_experiment() {
        let md = ModelDescription::parse(XML, Path::new("x.fmu")).unwrap();
        assert_eq!(md.model_identifier, "m_id");
        assert_eq!(md.guid, "{g&1}");
        assert!(md.can_get_and_set_fmu_state && !md.can_interpolate_inputs);
        assert_eq!(md.variables.len(), 3);
        let n = md.variable("n").unwrap();
        assert_eq!(
            (n.value_reference, n.var_type, n.causality),
            (7, VarType::Integer, Causality::Local)
        );
        assert_eq!(
            md.outputs().map(|v| v.name.as_str()).collect::<Vec<_>>(),
            ["y"]
        );
        let de = md.default_experiment;
        assert_eq!(
            (de.start_time, de.stop_time, de.step_size, de.tolerance),
            (Some(0.5), Some(2.0), Some(1e-3), None)
        );
    }

    #[test]
    fn a_model_exchange_only_description_is_refused() {
        let xml = XML.replace("CoSimulation", "ModelExchange");
        let e = ModelDescription::parse(&xml, Path::new("x.fmu")).unwrap_err();
        assert!(e.to_string().contains("no CoSimulation element"), "{e}");
    }
}
