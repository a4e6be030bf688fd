//! The master treats an FMI 3.0 FMU as untrusted as a 2.0 one (`hostile_fmus.rs`, issue 47
//! item 5): a 3.0 model description whose binary is missing from its platform tuple folder (or
//! lies in 2.0's), an instantiationToken that is not the unit's, an fmiVersion the master does
//! not run, a missing instantiationToken, value references shared between variables, absurd or
//! unreadable array dimensions, a binary without the fmi3 entry points and malformed XML: each
//! refused with a message that says what, without quoting what could not be read, no panic, no
//! extraction folder left behind.

use crate::common;
use common::hostile::*;
use common::*;
use std::path::Path;

const MD3: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="m" instantiationToken="{0}">
  <CoSimulation modelIdentifier="m"/>
  <DefaultExperiment startTime="0" stopTime="1" stepSize="0.1"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent"/>
    <Float64 name="u" valueReference="1" causality="input" start="0"/>
    <Float64 name="y" valueReference="2" causality="output"><Dimension start="3"/></Float64>
  </ModelVariables>
</fmiModelDescription>"#;

/// An FMU of `md` with `binary` at `entry` (none when empty).
fn fmu3(dir: &Path, name: &str, md: &str, entry: &str, binary: &[u8]) -> std::path::PathBuf {
    let fmu = dir.join(name);
    let mut entries = vec![("modelDescription.xml", md.as_bytes(), false)];
    if !entry.is_empty() {
        entries.push((entry, binary, false));
    }
    fmu_of(&fmu, &entries);
    fmu
}

#[test]
fn a_missing_binary_is_named_in_the_platform_tuple_folder() {
    let dir = scratch("hostile3_missing_binary");
    let engine = std::fs::read(fmu_harness::package::default_binary().expect("release engine"))
        .expect("the release engine is readable");
    // no binary at all, and the engine in FMI 2.0's folder only
    for (name, entry) in [("none.fmu", ""), ("v2_folder.fmu", "binaries/linux64/m.so")] {
        let fmu = fmu3(&dir, name, MD3, entry, &engine);
        let run = simulate(&dir, &fmu, &[], QUICK);
        refused(&run, &["binaries/x86_64-linux/m.so", "is not in the FMU"]);
    }
}

#[test]
fn a_binary_without_the_fmi3_entry_points_is_refused_before_loading() {
    let dir = scratch("hostile3_no_exports");
    let libm =
        std::fs::read("/lib/x86_64-linux-gnu/libm.so.6").expect("libm, as on every glibc Linux");
    let fmu = fmu3(&dir, "libm.fmu", MD3, "binaries/x86_64-linux/m.so", &libm);
    let run = simulate(&dir, &fmu, &[], QUICK);
    refused(
        &run,
        &[
            "binaries/x86_64-linux/m.so",
            "does not export fmi3InstantiateCoSimulation",
        ],
    );
}

#[test]
fn an_instantiation_token_that_is_not_the_units_is_refused_by_the_unit() {
    let dir = scratch("hostile3_token");
    let c1 = c1_fmu_of(&dir, 3);
    let bad = dir.join("token.fmu");
    with_description(&c1, &bad, |md| {
        let at = md.find("instantiationToken=\"").expect("a token") + 20;
        let end = at + md[at..].find('"').expect("closed");
        format!(
            "{}{{00000000-0000-0000-0000-000000000000}}{}",
            &md[..at],
            &md[end..]
        )
    });
    let run = simulate(&dir, &bad, &[], QUICK);
    refused(
        &run,
        &[
            "fmi3InstantiateCoSimulation returned NULL",
            "instantiationToken",
        ],
    );
    // and the untouched unit runs
    let run = simulate(&dir, &c1, &["--stop", "0.01"], QUICK);
    assert!(run.status.success(), "{}", run.stderr);
}

#[test]
fn an_fmi_version_the_master_does_not_run_is_refused_without_quoting_it() {
    let dir = scratch("hostile3_version");
    for (version, words) in [
        ("1.0", &["fmiVersion 1.0 is neither 2.0 nor 3.0"][..]),
        ("4.0", &["fmiVersion 4.0 is neither 2.0 nor 3.0"]),
        (
            "root:x:0:0:SECRET",
            &["its fmiVersion is neither 2.0 nor 3.0"],
        ),
    ] {
        let md = MD3.replace("fmiVersion=\"3.0\"", &format!("fmiVersion=\"{version}\""));
        let run = simulate(&dir, &md_fmu(&dir, "version.fmu", &md), &[], QUICK);
        refused(&run, words);
        assert!(!run.stderr.contains("root:x"), "{}", run.stderr);
    }
    let md = MD3.replace("fmiVersion=\"3.0\" ", "");
    let run = simulate(&dir, &md_fmu(&dir, "none.fmu", &md), &[], QUICK);
    refused(&run, &["has no fmiVersion"]);
    let md = MD3.replace("instantiationToken=", "guid=");
    let run = simulate(&dir, &md_fmu(&dir, "guid.fmu", &md), &[], QUICK);
    refused(&run, &["no instantiationToken"]);
}

#[test]
fn shared_value_references_and_absurd_arrays_are_refused() {
    let dir = scratch("hostile3_variables");
    // FMI 3.0: one value reference, one variable, whatever the types
    let shared = MD3.replace(
        "<Float64 name=\"u\" valueReference=\"1\"",
        "<Int32 name=\"n\" valueReference=\"2\"/>\n    <Float64 name=\"u\" valueReference=\"1\"",
    );
    let run = simulate(&dir, &md_fmu(&dir, "shared.fmu", &shared), &[], QUICK);
    refused(
        &run,
        &["valueReference 2", "`y`", "`n`", "names one variable"],
    );
    let huge = MD3.replace(
        "<Dimension start=\"3\"/>",
        "<Dimension start=\"100000\"/><Dimension start=\"100000000\"/>",
    );
    let run = simulate(&dir, &md_fmu(&dir, "huge.fmu", &huge), &[], QUICK);
    refused(&run, &["array `y` has more than 10000000 elements"]);
    let overflow = MD3.replace(
        "<Dimension start=\"3\"/>",
        "<Dimension start=\"18446744073709551615\"/><Dimension start=\"3\"/>",
    );
    let run = simulate(&dir, &md_fmu(&dir, "overflow.fmu", &overflow), &[], QUICK);
    refused(&run, &["array `y` has more than"]);
    let structural = MD3.replace(
        "<Dimension start=\"3\"/>",
        "<Dimension valueReference=\"1\"/>",
    );
    let run = simulate(
        &dir,
        &md_fmu(&dir, "structural.fmu", &structural),
        &[],
        QUICK,
    );
    refused(&run, &["array `y`", "structural parameter"]);
    let secret = "root:x:0:0:SECRET";
    let bad = MD3.replace(
        "<Dimension start=\"3\"/>",
        &format!("<Dimension start=\"{secret}\"/>"),
    );
    let run = simulate(&dir, &md_fmu(&dir, "bad.fmu", &bad), &[], QUICK);
    refused(&run, &["array `y`", "not a whole number"]);
    assert!(!run.stderr.contains("root:x"), "{}", run.stderr);
}

#[test]
fn a_malformed_fmi3_description_is_located_not_quoted() {
    let dir = scratch("hostile3_xml");
    let secret = "root:x:0:0:SECRET";
    let md = MD3.replace(
        "<Dimension start=\"3\"/></Float64>",
        &format!("<Dimension start=\"3\"/></{secret}>"),
    );
    let run = simulate(&dir, &md_fmu(&dir, "xml.fmu", &md), &[], QUICK);
    refused(&run, &["line 8", "the end tag `</Float64>`"]);
    assert!(!run.stderr.contains("root:x"), "{}", run.stderr);
}
