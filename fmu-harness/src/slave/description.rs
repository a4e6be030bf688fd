//! What the master reads of an FMU's `modelDescription.xml` ([`ModelDescription::parse`]): the
//! model identifier, GUID, capability flags, scalar variables and default experiment (the file
//! the packager writes is [`crate::model_description`]'s).

use super::SlaveError;
use quick_xml::events::{BytesStart, Event};
use std::path::Path;

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
            let event = reader
                .read_event()
                .map_err(|e| fail(format!("at byte {}: {e}", reader.buffer_position())))?;
            let (e, empty) = match &event {
                Event::Start(e) => (e, false),
                Event::Empty(e) => (e, true),
                Event::End(e) => {
                    match e.name().as_ref() {
                        b"ModelVariables" => in_model_variables = false,
                        b"ScalarVariable" => {
                            if let Some((name, ..)) = pending.take() {
                                return Err(fail(format!("variable `{name}` has no type element")));
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
                    md.model_identifier = attr("modelIdentifier")?
                        .ok_or_else(|| fail("CoSimulation has no modelIdentifier".into()))?;
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
                                    fail(format!("DefaultExperiment {key}=\"{v}\" is not a number"))
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
                        .ok_or_else(|| fail(format!("variable `{name}`: bad valueReference")))?;
                    let causality = match attr("causality")?.as_deref().unwrap_or("local") {
                        "parameter" => Causality::Parameter,
                        "calculatedParameter" => Causality::CalculatedParameter,
                        "input" => Causality::Input,
                        "output" => Causality::Output,
                        "local" => Causality::Local,
                        "independent" => Causality::Independent,
                        other => {
                            return Err(fail(format!(
                                "variable `{name}`: unknown causality `{other}`"
                            )))
                        }
                    };
                    if empty {
                        return Err(fail(format!("variable `{name}` has no type element")));
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

fn attribute(e: &BytesStart, key: &str) -> Result<Option<String>, String> {
    match e.try_get_attribute(key) {
        Ok(Some(a)) => a
            .unescape_value()
            .map(|v| Some(v.into_owned()))
            .map_err(|err| format!("attribute {key}: {err}")),
        Ok(None) => Ok(None),
        Err(err) => Err(format!("attribute {key}: {err}")),
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
