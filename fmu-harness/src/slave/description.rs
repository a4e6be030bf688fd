//! What the master reads of an FMU's `modelDescription.xml` ([`ModelDescription::parse`]): the
//! model identifier, GUID, capability flags, scalar variables and default experiment (the file
//! the packager writes is [`crate::model_description`]'s).

use super::extract::shown;
use super::{FmuRefused, SlaveError};
use crate::input_file::line_column;
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

/// Base type of a scalar variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
    String,
    Enumeration,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
    Independent,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    pub name: String,
    pub value_reference: u32,
    pub var_type: VarType,
    pub causality: Causality,
}

/// The `DefaultExperiment` element; each attribute optional.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DefaultExperiment {
    pub start_time: Option<f64>,
    pub stop_time: Option<f64>,
    pub tolerance: Option<f64>,
    pub step_size: Option<f64>,
}

/// What the master needs from `modelDescription.xml`.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelDescription {
    pub model_identifier: String,
    pub guid: String,
    pub can_get_and_set_fmu_state: bool,
    pub can_interpolate_inputs: bool,
    pub provides_directional_derivative: bool,
    pub variables: Vec<Variable>,
    pub default_experiment: DefaultExperiment,
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
            model_identifier: String::new(),
            guid: String::new(),
            can_get_and_set_fmu_state: false,
            can_interpolate_inputs: false,
            provides_directional_derivative: false,
            variables: Vec::new(),
            default_experiment: DefaultExperiment::default(),
        };
        // The ScalarVariable being read: (name, vr, causality), until its type element.
        let mut pending: Option<(String, u32, Causality)> = None;
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
                        _ => {}
                    }
                    continue;
                }
                Event::Eof => break,
                _ => continue,
            };
            let attr = |key: &str| attribute(e, key).map_err(&fail);
            match e.name().as_ref() {
                b"fmiModelDescription" => {
                    md.guid = attr("guid")?.ok_or_else(|| fail("no guid".into()))?;
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
                    md.can_get_and_set_fmu_state =
                        attr("canGetAndSetFMUstate")?.as_deref() == Some("true");
                    md.can_interpolate_inputs =
                        attr("canInterpolateInputs")?.as_deref() == Some("true");
                    md.provides_directional_derivative =
                        attr("providesDirectionalDerivative")?.as_deref() == Some("true");
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
                b"ScalarVariable" if in_model_variables => {
                    let name =
                        attr("name")?.ok_or_else(|| fail("a variable has no name".into()))?;
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
                        "input" => Causality::Input,
                        "output" => Causality::Output,
                        "local" => Causality::Local,
                        "independent" => Causality::Independent,
                        _ => {
                            return Err(fail(format!(
                                "variable `{}`: causality is none of parameter, \
                                 calculatedParameter, input, output, local, independent",
                                shown(&name)
                            )))
                        }
                    };
                    if empty {
                        return Err(fail(format!(
                            "variable `{}` has no type element",
                            shown(&name)
                        )));
                    }
                    pending = Some((name, vr, causality));
                }
                tag @ (b"Real" | b"Integer" | b"Boolean" | b"String" | b"Enumeration") => {
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
                        });
                    }
                }
                _ => {}
            }
        }
        if md.model_identifier.is_empty() {
            return Err(fail(
                "no CoSimulation element: not a co-simulation FMU".into(),
            ));
        }
        check_value_references(&md.variables, origin)?;
        Ok(md)
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

/// Two variables of one base type (Integer and Enumeration count as one) may share a value
/// reference only as aliases (FMI 2.0 §2.2.7), and an alias set has at most one start value:
/// at most one of them is an input or a parameter, and an input is aliased to nothing (it
/// would move another variable the master did not set). Any other sharing is refused, naming
/// both variables.
fn check_value_references(variables: &[Variable], origin: &Path) -> Result<(), SlaveError> {
    let class = |t: VarType| match t {
        VarType::Real => "Real",
        VarType::Integer | VarType::Enumeration => "Integer",
        VarType::Boolean => "Boolean",
        VarType::String => "String",
    };
    let settable = |c: Causality| matches!(c, Causality::Input | Causality::Parameter);
    // (class, vr) → the first variable with it and the settable one of the set, if any.
    let mut seen: HashMap<(&str, u32), (usize, Option<usize>)> = HashMap::new();
    for (i, v) in variables.iter().enumerate() {
        let key = (class(v.var_type), v.value_reference);
        match seen.get_mut(&key) {
            None => {
                seen.insert(key, (i, settable(v.causality).then_some(i)));
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
