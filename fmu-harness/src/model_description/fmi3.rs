//! modelDescription.xml of FMI 3.0 (issue 47): the template
//! `modelDescription-templates/fmi3-cosimulation.xml` filled from the same variable table as
//! FMI 2.0's, through the unit's FMI 3.0 layout ([`Layout3`]): each beam's shape points as one
//! Float64 array per axis with its `<Dimension>`, every other variable a scalar under its 2.0
//! value reference, the independent variable `time` after them. ModelStructure names variables
//! by value reference (3.0), not by index (2.0).

use super::{default_experiment, start_text, unit, unit_definitions, Xml};
use crate::error::HarnessError;
use crate::log_categories::LOG_CATEGORIES;
use crate::template::{fill, Fill};
use fmu_beam::Scene;
use fmu_beam::{Causality, Declared, Initial, Layout3, VarType, Variable, VariableTable, UNITS};

/// The FMI 3.0 co-simulation skeleton, compiled in.
pub const TEMPLATE: &str =
    include_str!("../../../modelDescription-templates/fmi3-cosimulation.xml");

/// The whole FMI 3.0 modelDescription.xml; `token` (the instantiationToken, the GUID) may be
/// empty (the text it is computed from).
pub fn render(scene: &Scene, table: &VariableTable, token: &str) -> Result<String, HarnessError> {
    super::check_units(scene, table)?;
    let layout = Layout3::of(table);
    // the table's units and the second of `time`, in the order of UNITS
    let used = table.units();
    let units: Vec<_> = UNITS
        .iter()
        .copied()
        .filter(|u| u.name == "s" || used.contains(u))
        .collect();
    let units = unit_definitions(&units)?;
    let categories = log_categories()?;
    let experiment = default_experiment(&scene.experiment, scene.solver.tolerance)?;
    let variables = model_variables(table, &layout)?;
    let structure = model_structure(table, &layout)?;
    fill(
        TEMPLATE,
        &[
            ("MODEL_NAME", Fill::Text(&scene.name)),
            ("MODEL_IDENTIFIER", Fill::Text(&scene.name)),
            ("GUID", Fill::Text(token)),
            ("DESCRIPTION", Fill::Text(&scene.description)),
            ("GENERATION_TOOL", Fill::Text(&super::generation_tool())),
            ("UNIT_DEFINITIONS", Fill::Xml(&units)),
            ("LOG_CATEGORIES", Fill::Xml(&categories)),
            ("DEFAULT_EXPERIMENT", Fill::Xml(&experiment)),
            ("MODEL_VARIABLES", Fill::Xml(&variables)),
            ("MODEL_STRUCTURE", Fill::Xml(&structure)),
        ],
    )
}

/// The unit's log categories, their statuses named as FMI 3.0 names them.
fn log_categories() -> Result<String, HarnessError> {
    let mut x = Xml::new();
    x.start("LogCategories", &[])?;
    for (name, description) in LOG_CATEGORIES {
        let description = statuses3(description);
        x.empty("Category", &[("name", name), ("description", &description)])?;
    }
    x.end("LogCategories")?;
    x.finish()
}

/// A text with FMI 2.0's status names (fmi2OK ... fmi2Fatal) as FMI 3.0's; other names of
/// functions stay (a derivative input's text names fmi2SetRealInputDerivatives, which FMI 3.0
/// does not have: there, the derivative is its own input).
fn statuses3(text: &str) -> String {
    ["OK", "Warning", "Discard", "Error", "Fatal"]
        .iter()
        .fold(text.to_string(), |t, s| {
            t.replace(&format!("fmi2{s}"), &format!("fmi3{s}"))
        })
}

/// The element name of a variable type in FMI 3.0.
fn element(ty: VarType) -> &'static str {
    match ty {
        VarType::Real => "Float64",
        VarType::Integer => "Int32",
        VarType::Boolean => "Boolean",
    }
}

/// The table's variable that an FMI 3.0 variable's attributes come from (an array's first
/// element); none for `time`.
fn first(table: &VariableTable, d: Declared) -> Option<&Variable> {
    match d {
        Declared::Time => None,
        d => table.get(d.elements().start),
    }
}

fn model_variables(table: &VariableTable, layout: &Layout3) -> Result<String, HarnessError> {
    let mut x = Xml::new();
    x.start("ModelVariables", &[])?;
    for v3 in &layout.variables {
        let vr = v3.vr.to_string();
        let Some(v) = first(table, v3.declared) else {
            x.empty(
                "Float64",
                &[
                    ("name", "time"),
                    ("valueReference", &vr),
                    ("description", "Simulation time"),
                    ("causality", "independent"),
                    ("variability", "continuous"),
                    ("unit", "s"),
                ],
            )?;
            continue;
        };
        let n = v3.declared.values();
        let description = match v3.declared {
            Declared::Array { .. } => array_description(&v.description, n),
            _ => v.description.clone(),
        };
        let description = statuses3(&description);
        let mut attrs = vec![
            ("name", v3.name.as_str()),
            ("valueReference", vr.as_str()),
            ("description", description.as_str()),
            ("causality", v.causality.as_str()),
            ("variability", v.variability.as_str()),
        ];
        if let Some(initial) = v.initial {
            attrs.push(("initial", initial.as_str()));
        }
        if let Some(u) = unit(v) {
            attrs.push(("unit", u));
        }
        let start = start_text(v);
        if let Some(s) = &start {
            attrs.push(("start", s.as_str()));
        }
        match v3.declared {
            Declared::Array { .. } => {
                x.start(element(v.ty), &attrs)?;
                x.empty("Dimension", &[("start", &n.to_string())])?;
                x.end(element(v.ty))?;
            }
            _ => x.empty(element(v.ty), &attrs)?,
        }
    }
    x.end("ModelVariables")?;
    x.finish()
}

/// An array's description from its first element's ("World x of point 1 of 11 of ...").
fn array_description(first: &str, n: usize) -> String {
    match first.split_once(" of point 1 of ") {
        Some((head, tail)) => {
            let tail = tail.split_once(" of ").map_or(tail, |(_, t)| t);
            format!("{head} of the {n} points of {tail}")
        }
        None => first.to_string(),
    }
}

/// Outputs (each with the inputs it depends on directly, by value reference; an array on the
/// union of its elements') and InitialUnknowns (outputs and calculated parameters).
fn model_structure(table: &VariableTable, layout: &Layout3) -> Result<String, HarnessError> {
    let mut x = Xml::new();
    x.start("ModelStructure", &[])?;
    let of = |pred: &dyn Fn(&Variable) -> bool| -> Vec<(u32, Declared)> {
        layout
            .variables
            .iter()
            .filter(|v3| first(table, v3.declared).is_some_and(pred))
            .map(|v3| (v3.vr, v3.declared))
            .collect()
    };
    for (vr, d) in of(&|v| v.causality == Causality::Output) {
        let mut deps: Vec<u32> = d
            .elements()
            .filter_map(|e| table.get(e))
            .flat_map(|v| v.dependencies.iter().copied())
            .collect();
        deps.sort_unstable();
        deps.dedup();
        let deps: Vec<String> = deps.iter().map(u32::to_string).collect();
        x.empty(
            "Output",
            &[
                ("valueReference", &vr.to_string()),
                ("dependencies", &deps.join(" ")),
            ],
        )?;
    }
    for (vr, _) in of(&|v| {
        (v.causality == Causality::Output && v.initial == Some(Initial::Calculated))
            || v.causality == Causality::CalculatedParameter
    }) {
        x.empty("InitialUnknown", &[("valueReference", &vr.to_string())])?;
    }
    x.end("ModelStructure")?;
    x.finish()
}
