//! The variable table is the single source of ModelVariables: every variable of the table
//! appears exactly once in modelDescription.xml, with its value reference, causality and
//! variability, and ModelStructure lists every output.

use crate::common;
use common::*;
use fmu_beam::{Causality, VariableTable};

#[test]
fn every_table_variable_appears_exactly_once() {
    let dir = scratch("model_variables");
    let engine = fake_engine(&dir, b"engine");
    let out = dir.join("c1.fmu");
    assert!(package(&c1_path(), &out, &engine).status.success());
    let md = read_entry(&out, "modelDescription.xml");
    let table = VariableTable::build(&fmu_beam::Scene::load(&c1_path()).unwrap());
    assert!(!table.variables.is_empty());
    assert_eq!(
        md.matches("<ScalarVariable ").count(),
        table.variables.len()
    );
    for v in &table.variables {
        let head = format!(
            "<ScalarVariable name=\"{}\" valueReference=\"{}\"",
            v.name, v.vr
        );
        assert_eq!(md.matches(&head).count(), 1, "{head}");
        let line = md.lines().find(|l| l.contains(&head)).unwrap();
        assert!(
            line.contains(&format!("causality=\"{}\"", v.causality.as_str())),
            "{line}"
        );
        assert!(
            line.contains(&format!("variability=\"{}\"", v.variability.as_str())),
            "{line}"
        );
    }
    let outputs = table
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .count();
    let structure = &md[md.find("<Outputs>").unwrap()..md.find("</Outputs>").unwrap()];
    assert_eq!(structure.matches("<Unknown ").count(), outputs);
    for u in table.units() {
        assert_eq!(
            md.matches(&format!("<Unit name=\"{}\">", u.name)).count(),
            1
        );
    }
}
