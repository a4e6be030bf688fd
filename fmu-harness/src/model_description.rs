//! modelDescription.xml of a scene: the template in `modelDescription-templates/` filled from
//! the scene and its variable table (the single source of ModelVariables and ModelStructure).

use crate::error::HarnessError;
use crate::log_categories::LOG_CATEGORIES;
use crate::template::{escape_attribute, fill, Fill};
use fmu_beam::scene::ExperimentSpec;
use fmu_beam::Scene;
use fmu_beam::{Causality, Initial, UnitDef, VarType, Variable, VariableTable};
use quick_xml::events::attributes::Attribute;
use quick_xml::events::{BytesEnd, BytesStart, Event};
use quick_xml::name::QName;
use quick_xml::Writer;
use std::borrow::Cow;

pub mod fmi3;

/// The FMI 2.0 co-simulation skeleton, compiled in so the harness binary is self-contained.
pub const TEMPLATE: &str = include_str!("../../modelDescription-templates/fmi2-cosimulation.xml");

/// The `generationTool` attribute.
pub fn generation_tool() -> String {
    format!("fmu-harness {}", env!("CARGO_PKG_VERSION"))
}

/// The whole modelDescription.xml; `guid` may be empty (the text the GUID is computed from).
pub fn render(scene: &Scene, table: &VariableTable, guid: &str) -> Result<String, HarnessError> {
    let tool = generation_tool();
    check_units(scene, table)?;
    let units = unit_definitions(&table.units())?;
    let categories = log_categories()?;
    let experiment = default_experiment(&scene.experiment, scene.solver.tolerance)?;
    let variables = model_variables(table)?;
    let structure = model_structure(table)?;
    fill(
        TEMPLATE,
        &[
            ("MODEL_NAME", Fill::Text(&scene.name)),
            ("MODEL_IDENTIFIER", Fill::Text(&scene.name)),
            ("GUID", Fill::Text(guid)),
            ("DESCRIPTION", Fill::Text(&scene.description)),
            ("GENERATION_TOOL", Fill::Text(&tool)),
            ("UNIT_DEFINITIONS", Fill::Xml(&units)),
            ("LOG_CATEGORIES", Fill::Xml(&categories)),
            ("DEFAULT_EXPERIMENT", Fill::Xml(&experiment)),
            ("MODEL_VARIABLES", Fill::Xml(&variables)),
            ("MODEL_STRUCTURE", Fill::Xml(&structure)),
        ],
    )
}

/// Refuses a variable whose unit is not one of [`fmu_beam::UNITS`].
fn check_units(scene: &Scene, table: &VariableTable) -> Result<(), HarnessError> {
    let defined = table.units();
    for v in &table.variables {
        if let Some(unit) = v.unit.filter(|u| !defined.iter().any(|d| d.name == *u)) {
            return Err(HarnessError::UndefinedUnit {
                scene: scene.name.clone(),
                variable: v.name.clone(),
                unit: unit.to_string(),
            });
        }
    }
    Ok(())
}

/// A real number as its shortest round-trip decimal text (`{:?}`-style), in exponent form when
/// that reads better (|x| ≥ 1e6 or < 1e-4): `0.01`, `2700.0`, `7.2e10`, `1e-8`.
pub fn format_real(x: f64) -> String {
    if x.is_nan() {
        return "NaN".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "INF".into() } else { "-INF".into() };
    }
    let a = x.abs();
    if a != 0.0 && !(1e-4..1e6).contains(&a) {
        format!("{x:e}")
    } else {
        format!("{x:?}")
    }
}

/// `<UnitDefinitions>` with each unit's SI base-unit exponents (zero exponents left out).
pub fn unit_definitions(units: &[UnitDef]) -> Result<String, HarnessError> {
    if units.is_empty() {
        return Ok(String::new());
    }
    let mut x = Xml::new();
    x.start("UnitDefinitions", &[])?;
    for u in units {
        x.start("Unit", &[("name", u.name)])?;
        let exps: Vec<(&str, String)> = [("kg", u.kg), ("m", u.m), ("s", u.s), ("rad", u.rad)]
            .into_iter()
            .filter(|&(_, e)| e != 0)
            .map(|(n, e)| (n, e.to_string()))
            .collect();
        let attrs: Vec<(&str, &str)> = exps.iter().map(|(n, e)| (*n, e.as_str())).collect();
        x.empty("BaseUnit", &attrs)?;
        x.end("Unit")?;
    }
    x.end("UnitDefinitions")?;
    x.finish()
}

pub fn log_categories() -> Result<String, HarnessError> {
    let mut x = Xml::new();
    x.start("LogCategories", &[])?;
    for (name, description) in LOG_CATEGORIES {
        x.empty("Category", &[("name", name), ("description", description)])?;
    }
    x.end("LogCategories")?;
    x.finish()
}

/// `<DefaultExperiment>`: the scene's times and communication step, and its solver tolerance,
/// so that a master which passes the DefaultExperiment's tolerance to fmi2SetupExperiment runs
/// the unit at the scene's (issue 31).
pub fn default_experiment(e: &ExperimentSpec, tolerance: f64) -> Result<String, HarnessError> {
    let (t0, t1, tol, h) = (
        format_real(e.start_time),
        format_real(e.stop_time),
        format_real(tolerance),
        format_real(e.step_size),
    );
    let mut x = Xml::new();
    x.empty(
        "DefaultExperiment",
        &[
            ("startTime", &t0),
            ("stopTime", &t1),
            ("tolerance", &tol),
            ("stepSize", &h),
        ],
    )?;
    x.finish()
}

/// The variables in value-reference order; a variable's ModelStructure index is its position.
fn ordered(table: &VariableTable) -> Vec<&Variable> {
    let mut v: Vec<&Variable> = table.variables.iter().collect();
    v.sort_by_key(|v| v.vr);
    v
}

/// A variable's start value as the XML writes it (also in the FMU's documentation).
pub fn start_text(v: &Variable) -> Option<String> {
    v.start.map(|s| match v.ty {
        VarType::Real => format_real(s),
        VarType::Integer => format!("{}", s.round() as i64),
        VarType::Boolean => (if s != 0.0 { "true" } else { "false" }).to_string(),
    })
}

/// A variable's unit as the XML declares it (Real variables only).
pub fn unit(v: &Variable) -> Option<&'static str> {
    match v.ty {
        VarType::Real => v.unit,
        _ => None,
    }
}

pub fn model_variables(table: &VariableTable) -> Result<String, HarnessError> {
    let mut x = Xml::new();
    x.start("ModelVariables", &[])?;
    for v in ordered(table) {
        let vr = v.vr.to_string();
        let mut attrs = vec![
            ("name", v.name.as_str()),
            ("valueReference", vr.as_str()),
            ("description", v.description.as_str()),
            ("causality", v.causality.as_str()),
            ("variability", v.variability.as_str()),
        ];
        if let Some(initial) = v.initial {
            attrs.push(("initial", initial.as_str()));
        }
        x.start("ScalarVariable", &attrs)?;
        let start = start_text(v);
        let mut type_attrs = Vec::new();
        if let Some(unit) = unit(v) {
            type_attrs.push(("unit", unit));
        }
        if let Some(s) = &start {
            type_attrs.push(("start", s.as_str()));
        }
        x.empty(v.ty.as_str(), &type_attrs)?;
        x.end("ScalarVariable")?;
    }
    x.end("ModelVariables")?;
    x.finish()
}

/// Outputs and InitialUnknowns (outputs and calculated parameters).
///
/// Each output lists the inputs it depends on directly (`Variable::dependencies`, from
/// `VariableTable`'s dependencies): the accelerations of input loads' frames on the force
/// inputs, an input effort drive's effort on its input, the constraint residual on the motion
/// inputs; every other output on none (`dependencies=""`). InitialUnknowns never carry it.
pub fn model_structure(table: &VariableTable) -> Result<String, HarnessError> {
    let vars = ordered(table);
    let position = |vr: u32| vars.iter().position(|v| v.vr == vr).map(|i| i + 1);
    let indices = |pred: &dyn Fn(&Variable) -> bool| -> Vec<usize> {
        vars.iter()
            .enumerate()
            .filter(|(_, v)| pred(v))
            .map(|(i, _)| i)
            .collect()
    };
    let outputs = indices(&|v| v.causality == Causality::Output);
    let initial_unknowns = indices(&|v| {
        (v.causality == Causality::Output && v.initial == Some(Initial::Calculated))
            || v.causality == Causality::CalculatedParameter
    });
    let mut x = Xml::new();
    x.start("ModelStructure", &[])?;
    if !outputs.is_empty() {
        x.start("Outputs", &[])?;
        for &i in &outputs {
            let deps: Vec<String> = vars[i]
                .dependencies
                .iter()
                .filter_map(|&vr| position(vr))
                .map(|p| p.to_string())
                .collect();
            let index = (i + 1).to_string();
            x.empty(
                "Unknown",
                &[("index", &index), ("dependencies", &deps.join(" "))],
            )?;
        }
        x.end("Outputs")?;
    }
    if !initial_unknowns.is_empty() {
        x.start("InitialUnknowns", &[])?;
        for &i in &initial_unknowns {
            x.empty("Unknown", &[("index", &(i + 1).to_string())])?;
        }
        x.end("InitialUnknowns")?;
    }
    x.end("ModelStructure")?;
    x.finish()
}

/// An indenting XML writer over a byte buffer; attribute values escaped by [`escape_attribute`].
struct Xml {
    w: Writer<Vec<u8>>,
}

impl Xml {
    fn new() -> Xml {
        Xml {
            w: Writer::new_with_indent(Vec::new(), b' ', 2),
        }
    }

    fn element<'a>(name: &'a str, attrs: &[(&str, &str)]) -> BytesStart<'a> {
        let mut e = BytesStart::new(name);
        for (k, v) in attrs {
            e.push_attribute(Attribute {
                key: QName(k.as_bytes()),
                value: Cow::Owned(escape_attribute(v).into_bytes()),
            });
        }
        e
    }

    fn write(&mut self, ev: Event) -> Result<(), HarnessError> {
        self.w.write_event(ev).map_err(|e| HarnessError::Template {
            message: format!("writing XML: {e}"),
        })
    }

    fn start(&mut self, name: &str, attrs: &[(&str, &str)]) -> Result<(), HarnessError> {
        self.write(Event::Start(Self::element(name, attrs)))
    }

    fn empty(&mut self, name: &str, attrs: &[(&str, &str)]) -> Result<(), HarnessError> {
        self.write(Event::Empty(Self::element(name, attrs)))
    }

    fn end(&mut self, name: &str) -> Result<(), HarnessError> {
        self.write(Event::End(BytesEnd::new(name)))
    }

    fn finish(self) -> Result<String, HarnessError> {
        String::from_utf8(self.w.into_inner()).map_err(|e| HarnessError::Template {
            message: format!("XML is not UTF-8: {e}"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_round_trip_in_short_form() {
        for (x, s) in [
            (0.01, "0.01"),
            (2700.0, "2700.0"),
            (72e9, "7.2e10"),
            (1e-8, "1e-8"),
            (5e-4, "0.0005"),
            (0.0, "0.0"),
            (-2.5, "-2.5"),
            (8.333333333333334e-10, "8.333333333333334e-10"),
        ] {
            assert_eq!(format_real(x), s);
            assert_eq!(s.parse::<f64>().unwrap(), x);
        }
    }

    fn small_scene() -> Scene {
        Scene::from_toml_str(
            "name = \"t\"\n[[beam]]\nname = \"b\"\nlength = 1.0\nelements = 2\n\
             material = { rho = 1.0, E = 1.0 }\nsection = { A = 1.0, J = 1.0 }\n",
            "inline",
        )
        .unwrap()
    }

    #[test]
    fn each_output_lists_exactly_the_inputs_it_depends_on() {
        let table = VariableTable::build(&small_scene());
        let outputs = table
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .count();
        let s = model_structure(&table).unwrap();
        assert_eq!(s.matches("dependencies=\"\"").count(), outputs, "{s}");

        // an input load: the accelerations of its frame depend on its three inputs (1-based
        // indices of the ordered variables), every other output on none
        let text = "name = \"t\"\n[[beam]]\nname = \"b\"\nlength = 1.0\nelements = 2\n\
                    material = { rho = 1.0, E = 1.0 }\nsection = { A = 1.0, J = 1.0 }\n\
                    [[joint]]\nname = \"j\"\ntype = \"revolute\"\nframes = [\"world\", \"b.a\"]\n\
                    [[load]]\nname = \"tip\"\nframe = \"b.b\"\ninput = true\n";
        let table = VariableTable::build(&Scene::from_toml_str(text, "inline").unwrap());
        let index = |name: &str| table.by_name(name).unwrap().vr + 1;
        let deps = format!(
            "{} {} {}",
            index("tip.fx"),
            index("tip.fy"),
            index("tip.torque")
        );
        let s = model_structure(&table).unwrap();
        for out in ["tip.ax", "tip.ay", "tip.alpha"] {
            let line = format!(
                "<Unknown index=\"{}\" dependencies=\"{deps}\"/>",
                index(out)
            );
            assert!(s.contains(&line), "{line} in {s}");
        }
        let outputs = table
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .count();
        assert_eq!(s.matches("dependencies=\"\"").count(), outputs - 3, "{s}");
    }

    #[test]
    fn template_has_every_placeholder_filled() {
        let scene = Scene::from_toml_str(
            "name = \"t\"\ndescription = \"a < b & \\\"c\\\"\"\n[[beam]]\nname = \"b\"\nlength = 1.0\n\
             elements = 2\nmaterial = { rho = 1.0, E = 1.0 }\nsection = { A = 1.0, J = 1.0 }\n",
            "inline",
        )
        .unwrap();
        let table = VariableTable::build(&scene);
        let md = render(&scene, &table, "{guid}").unwrap();
        assert!(!md.contains("{{"), "{md}");
        assert!(
            md.contains("description=\"a &lt; b &amp; &quot;c&quot;\""),
            "{md}"
        );
        assert!(md.contains("guid=\"{guid}\""));
        assert!(
            md.contains("<BaseUnit kg=\"1\" m=\"-1\" s=\"-2\"/>"),
            "{md}"
        );
    }
}
