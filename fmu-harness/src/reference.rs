//! `fmu-harness reference`: the scene reference (`docs/scene-reference.md`), every field of every
//! table of a scene file with its type, unit, default, allowed values, the scenes it belongs to
//! and the validator's rules on it. It is written from the same sources as the scene schema:
//! the serde structs through schemars (types, defaults, doc comments, `x-unit`) and the rule table
//! `fmu_beam::scene::rules::RULES`; a test compares the committed page with this text.

use crate::schema;
use fmu_beam::scene::rules::{self, Dims, Rule, Schema};
use serde_json::Value;
use std::fmt::Write;

/// The file the reference is committed as, relative to the repository.
pub const FILE_NAME: &str = "docs/scene-reference.md";

/// One table of a scene file (`[solver]`, `[[beam]]`, `[beam.section]`...).
#[derive(Debug, Clone)]
pub struct Table {
    /// The table's path in the rules' notation: `""` (the top level), `solver`, `beam[]`,
    /// `beam[].section`.
    pub path: String,
    /// How the table is written in TOML: `[solver]`, `[[beam]]`, `[beam.section]`.
    pub heading: String,
    pub description: String,
    pub fields: Vec<Field>,
}

/// One key of a table.
#[derive(Debug, Clone)]
pub struct Field {
    pub key: String,
    /// The field's path in the rules' notation (`beam[].section.A`).
    pub path: String,
    /// Its schema (a `$ref` followed: the definition's keywords under the property's own).
    pub schema: Value,
    pub required: bool,
    /// A table of its own (listed as a [`Table`]).
    pub table: bool,
}

/// The definition a node names (`$ref`, or `allOf: [{$ref}]`), or the node itself.
fn target<'a>(root: &'a Value, node: &'a Value) -> &'a Value {
    let r = node.get("$ref").or_else(|| {
        node.get("allOf")
            .and_then(Value::as_array)
            .filter(|a| a.len() == 1)
            .and_then(|a| a[0].get("$ref"))
    });
    match r.and_then(Value::as_str) {
        Some(r) => root.pointer(r.trim_start_matches('#')).unwrap_or(node),
        None => node,
    }
}

/// A property's schema with the definition it names merged under it (the property's
/// description and default win).
fn merged(root: &Value, node: &Value) -> Value {
    let def = target(root, node);
    let mut out = def.clone();
    if let (Value::Object(o), Value::Object(n)) = (&mut out, node) {
        for (k, v) in n {
            if k != "$ref" && k != "allOf" {
                o.insert(k.clone(), v.clone());
            }
        }
    }
    out
}

fn is_struct(v: &Value) -> bool {
    v.get("properties").is_some()
}

/// Every table of a scene, in the order of the structs' fields (depth first), from the
/// schema of the scene structs (after [`schema::raw`] and its tidying).
pub fn tables(root: &Value) -> Vec<Table> {
    let mut out = Vec::new();
    walk(root, root, "", "", "", &mut out);
    out
}

fn walk(root: &Value, def: &Value, path: &str, toml: &str, heading: &str, out: &mut Vec<Table>) {
    let required: Vec<&str> = def
        .get("required")
        .and_then(Value::as_array)
        .map(|a| a.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    let mut table = Table {
        path: path.to_string(),
        heading: heading.to_string(),
        description: def
            .get("description")
            .and_then(Value::as_str)
            .unwrap_or("")
            .to_string(),
        fields: Vec::new(),
    };
    let mut children = Vec::new();
    let join = |a: &str, b: &str| match a {
        "" => b.to_string(),
        _ => format!("{a}.{b}"),
    };
    for (key, node) in def
        .get("properties")
        .and_then(Value::as_object)
        .into_iter()
        .flatten()
    {
        let schema = merged(root, node);
        let items = schema.get("items").map(|i| target(root, i));
        let (sub, array) = match items {
            Some(i) if is_struct(i) => (Some(i.clone()), true),
            _ if is_struct(&schema) => (Some(schema.clone()), false),
            _ => (None, false),
        };
        let field_path = join(path, key);
        table.fields.push(Field {
            key: key.clone(),
            path: field_path.clone(),
            schema: schema.clone(),
            required: required.contains(&key.as_str()),
            table: sub.is_some(),
        });
        if let Some(sub) = sub {
            let toml_path = join(toml, key);
            let (p, h) = match array {
                true => (format!("{field_path}[]"), format!("[[{toml_path}]]")),
                false => (field_path, format!("[{toml_path}]")),
            };
            let mut sub = sub;
            let own = target(root, node.get("items").unwrap_or(node)).get("description");
            if let (Value::Object(o), Some(d)) = (&mut sub, own.or(node.get("description"))) {
                // the struct's own description says what the table is
                o.insert("description".into(), d.clone());
            }
            children.push((sub, p, toml_path, h));
        }
    }
    out.push(table);
    for (sub, p, t, h) in children {
        walk(root, &sub, &p, &t, &h, out);
    }
}

/// A rule's field pattern reduced to the field it is written under: array items (`[]`, `[2]`)
/// and map keys (`.<name>`) belong to their field.
fn base_of(pattern: &str) -> &str {
    let mut p = pattern;
    loop {
        let before = p;
        p = p.trim_end_matches(".<name>");
        if p.ends_with(']') {
            if let Some(k) = p.rfind('[') {
                p = &p[..k];
            }
        }
        if p == before {
            return p;
        }
    }
}

/// The rules that check a field (`beam[].section.A`), in the table's order; the rule on
/// every number (`*`) is stated once, not per field.
pub fn rules_of(path: &str) -> Vec<&'static Rule> {
    rules::RULES
        .iter()
        .filter(|r| r.fields.iter().any(|f| *f != "*" && base_of(f) == path))
        .collect()
}

/// Which scenes a field belongs to: a rule that wants it absent from planar scenes makes it
/// 3D only, and the other way round.
pub fn scenes_of(path: &str) -> &'static str {
    let absent_in = |dims: Dims| {
        rules_of(path)
            .iter()
            .any(|r| r.dims == dims && r.schema == Schema::Absent)
    };
    match (absent_in(Dims::Planar), absent_in(Dims::Spatial)) {
        (true, false) => "3D",
        (false, true) => "planar",
        _ => "both",
    }
}

/// `planar: ` / `3D: ` before a rule of one kind of scene.
pub fn dims_tag(d: Dims) -> &'static str {
    match d {
        Dims::Any => "",
        Dims::Planar => "planar: ",
        Dims::Spatial => "3D: ",
    }
}

fn number(x: &Value) -> String {
    match x.as_f64() {
        Some(f) if f == f.trunc() && f.abs() < 1e6 => format!("{}", f as i64),
        Some(f) if f.abs() < 1e-3 || f.abs() >= 1e6 => format!("{f:e}"),
        Some(f) => format!("{f}"),
        None => x.to_string(),
    }
}

/// A value as TOML would write it (numbers shortest, arrays inline).
fn toml_value(v: &Value) -> String {
    match v {
        Value::String(s) => format!("\"{s}\""),
        Value::Number(_) => number(v),
        Value::Array(a) => format!(
            "[{}]",
            a.iter().map(toml_value).collect::<Vec<_>>().join(", ")
        ),
        Value::Object(o) if o.is_empty() => "{}".into(),
        Value::Object(o) => format!(
            "{{ {} }}",
            o.iter()
                .map(|(k, x)| format!("{k} = {}", toml_value(x)))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        other => other.to_string(),
    }
}

/// The field's type, in a scene's words.
fn type_text(root: &Value, s: &Value) -> String {
    if let Some(alts) = s.get("anyOf").and_then(Value::as_array) {
        return alts
            .iter()
            .map(|a| type_text(root, a))
            .collect::<Vec<_>>()
            .join(" or ");
    }
    if s.get("oneOf").is_some() {
        return "string".into();
    }
    match s.get("type").and_then(Value::as_str) {
        Some("array") => {
            let items = s.get("items").map(|i| merged(root, i)).unwrap_or_default();
            let (min, max) = (
                s.get("minItems").and_then(Value::as_u64),
                s.get("maxItems").and_then(Value::as_u64),
            );
            let item_type = items.get("type").and_then(Value::as_str).unwrap_or("");
            match (item_type, min, max) {
                ("number", Some(2), Some(3)) => "[x, y] or [x, y, z]".into(),
                ("number", Some(3), Some(3)) => "[x, y, z]".into(),
                ("number", Some(2), Some(2)) => "[number, number]".into(),
                ("array", _, _) => format!("array of {}", type_text(root, &items)),
                (_, _, _) if is_struct(&items) => "array of tables".into(),
                (t, _, _) => format!("array of {t}s"),
            }
        }
        Some("object") if is_struct(s) => "table".into(),
        Some("object") => match s.get("additionalProperties") {
            Some(v) if v.is_object() => format!("table of {}", type_text(root, &merged(root, v))),
            _ => "table".into(),
        },
        Some(t) => t.to_string(),
        None => "any".into(),
    }
}

/// The values a field takes, where they are a list: an enum's variants, or a rule's `OneOf`.
fn allowed(s: &Value, path: &str) -> Vec<String> {
    let variants: Vec<String> = s
        .get("oneOf")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .filter_map(|v| v.get("const"))
        .map(toml_value)
        .collect();
    if !variants.is_empty() {
        return variants;
    }
    let mut out = Vec::new();
    for r in rules_of(path) {
        let values: Vec<String> = match r.schema {
            Schema::OneOf(v) => v.iter().map(|x| format!("\"{x}\"")).collect(),
            Schema::OneOfIntegers(v) => v.iter().map(|x| x.to_string()).collect(),
            _ => continue,
        };
        let list = values.join(", ");
        out.push(format!("{}{list}", dims_tag(r.dims)));
    }
    out
}

fn cell(text: &str) -> String {
    schema::unwrap_lines(text)
        .replace("\n\n", "<br>")
        .replace('|', "\\|")
}

fn anchor(heading: &str) -> String {
    heading
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| {
            if c == ' ' {
                '-'
            } else {
                c.to_ascii_lowercase()
            }
        })
        .collect()
}

fn section_title(t: &Table) -> String {
    match t.path.as_str() {
        "" => "Top level".into(),
        _ => format!("`{}`", t.heading),
    }
}

/// The reference page (Markdown).
pub fn scene_reference() -> String {
    let mut root = schema::raw();
    schema::tidy(&mut root);
    let tables = tables(&root);
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Scene reference\n\n\
         <!-- Generated by `fmu-harness reference -o {FILE_NAME}` from the scene structs \
         (fmu-beam/src/scene/mod.rs) and the validator's rules (fmu-beam/src/scene/rules.rs); \
         do not edit: a test fails when this page differs from what the code generates. -->\n\n\
         A scene is a TOML file (`scenes/*.toml`); `fmu-harness package` turns it into an FMU. \
         This page lists every key of every table: its type, unit (SI), default, allowed values, \
         the kind of scene it belongs to (planar, `dimensions = 2`; 3D, `dimensions = 3`) and \
         each rule the validator applies to it, by the code its error messages carry. A key not \
         listed here is refused. Every number must be finite (rule `finite`). The JSON Schema \
         `scenes/scene.schema.json` (`fmu-harness schema`) carries the same descriptions and the \
         rules that a schema can express: start a scene with `#:schema ./scene.schema.json` and a \
         Taplo-based editor (VS Code's Even Better TOML, Helix, Zed) completes and checks it as \
         you type.\n\n\
         A key marked *required* must be given; \"both\" means planar and 3D scenes. Vectors are \
         `[x, y]` in a planar scene and `[x, y, z]` in a 3D one; a torque or an inertia is a \
         number (about z) in a planar scene.\n"
    );
    let _ = writeln!(md, "## Tables\n");
    for t in &tables {
        let _ = writeln!(
            md,
            "- [{}](#{}): {}",
            section_title(t),
            anchor(&section_title(t)),
            cell(t.description.lines().next().unwrap_or(""))
        );
    }
    let _ = writeln!(md, "- [Rules](#rules): every rule of the validator\n");
    for t in &tables {
        let _ = writeln!(md, "## {}\n\n{}\n", section_title(t), cell(&t.description));
        let _ = writeln!(
            md,
            "| key | type | unit | default | allowed values | scenes | meaning |\n\
             |---|---|---|---|---|---|---|"
        );
        for f in &t.fields {
            let s = &f.schema;
            let ty = match f.table {
                true => {
                    let sub = tables
                        .iter()
                        .find(|x| x.path == f.path || x.path == format!("{}[]", f.path));
                    match sub {
                        Some(x) => {
                            format!("[{}](#{})", type_text(&root, s), anchor(&section_title(x)))
                        }
                        None => type_text(&root, s),
                    }
                }
                false => type_text(&root, s),
            };
            let unit = s.get("x-unit").and_then(Value::as_str).unwrap_or("");
            let default = match (f.required, s.get("default")) {
                (true, _) => "*required*".to_string(),
                (false, _) if f.table => String::new(),
                (false, Some(d)) => format!("`{}`", toml_value(d)),
                (false, None) => "—".to_string(),
            };
            let values = allowed(s, &f.path)
                .iter()
                .map(|v| format!("`{v}`"))
                .collect::<Vec<_>>()
                .join("<br>");
            let _ = writeln!(
                md,
                "| `{}` | {} | {} | {} | {} | {} | {} |",
                f.key,
                ty,
                unit,
                default,
                values,
                scenes_of(&f.path),
                cell(s.get("description").and_then(Value::as_str).unwrap_or(""))
            );
        }
        let ruled: Vec<(&Field, Vec<&Rule>)> = t
            .fields
            .iter()
            .map(|f| (f, rules_of(&f.path)))
            .filter(|(_, r)| !r.is_empty())
            .collect();
        if !ruled.is_empty() {
            let _ = writeln!(md, "\nRules:\n");
            for (f, rs) in ruled {
                let texts: Vec<String> = rs
                    .iter()
                    .map(|r| format!("{}{} (`{}`)", dims_tag(r.dims), r.text, r.code))
                    .collect();
                let _ = writeln!(md, "- `{}`: {}", f.key, texts.join("; "));
            }
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(
        md,
        "## Rules\n\n\
         Every rule of the validator, in the order it checks them. A refused scene's message \
         names the file, the field, the value and the rule, e.g. \
         ``scene.toml: field `beam \"arm\".length` = -1: must be positive`` (a beam, body, joint \
         or load named by its name, or by its index `beam[0]` where the name cannot). \"schema\" says whether \
         `scenes/scene.schema.json` checks the rule too (an editor flags it as you type); the \
         others need several fields' values or arithmetic, and only `fmu-harness package` sees \
         them. Fields: `[]` any index or part name, `<name>` any key, `*` every number.\n\n\
         | code | scenes | fields | rule | schema |\n|---|---|---|---|---|"
    );
    for r in rules::RULES {
        let scenes = match r.dims {
            Dims::Any => "both",
            Dims::Planar => "planar",
            Dims::Spatial => "3D",
        };
        let fields = r
            .fields
            .iter()
            .map(|f| format!("`{f}`"))
            .collect::<Vec<_>>()
            .join(", ");
        let in_schema = match r.schema {
            Schema::None => "no",
            _ => "yes",
        };
        let _ = writeln!(
            md,
            "| `{}` | {scenes} | {fields} | {} | {in_schema} |",
            r.code,
            cell(r.text)
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rule_patterns_reduce_to_their_field() {
        assert_eq!(base_of("body[].frames.<name>[2]"), "body[].frames");
        assert_eq!(base_of("joint[].drive.table[][]"), "joint[].drive.table");
        assert_eq!(base_of("world.gravity[2]"), "world.gravity");
        assert_eq!(base_of("beam[].section.A"), "beam[].section.A");
        assert_eq!(base_of("effects[]"), "effects");
    }

    #[test]
    fn every_rule_field_is_a_field_of_the_reference() {
        let mut root = schema::raw();
        schema::tidy(&mut root);
        let paths: Vec<String> = tables(&root)
            .iter()
            .flat_map(|t| t.fields.iter().map(|f| f.path.clone()))
            .collect();
        for r in rules::RULES {
            for f in r.fields.iter().filter(|f| **f != "*") {
                assert!(
                    paths.iter().any(|p| p == base_of(f)),
                    "rule {}: field {f} is not in the reference",
                    r.code
                );
            }
        }
    }

    #[test]
    fn three_d_only_fields_are_marked() {
        assert_eq!(scenes_of("beam[].axis"), "3D");
        assert_eq!(scenes_of("beam[].section.Iy"), "3D");
        assert_eq!(scenes_of("beam[].section.J"), "planar");
        assert_eq!(scenes_of("beam[].length"), "both");
    }
}
