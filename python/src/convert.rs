//! Python values to TOML values and back: a scene written as nested dicts and lists is the TOML
//! file's tables and arrays, key for key (the scene reference applies unchanged).

use crate::errors::Refusal;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// The scene's lists whose items have names.
const PARTS: [&str; 4] = ["beam", "body", "joint", "load"];

/// A field's path whose leading `beam[i]` (or `body`, `joint`, `load`) is named as the engine
/// names it ([`fmu_beam::scene::part_path`]), from the scene's table.
pub fn named_path(path: &str, table: &toml::Table) -> String {
    let Some((word, rest)) = path.split_once('[') else {
        return path.to_string();
    };
    let Some((index, after)) = rest.split_once(']') else {
        return path.to_string();
    };
    let (Ok(i), true) = (index.parse::<usize>(), PARTS.contains(&word)) else {
        return path.to_string();
    };
    let Some(toml::Value::Array(items)) = table.get(word) else {
        return path.to_string();
    };
    let names: Vec<&str> = items
        .iter()
        .map(|t| t.get("name").and_then(toml::Value::as_str).unwrap_or(""))
        .collect();
    format!("{}{after}", fmu_beam::scene::part_path(word, i, &names))
}

/// `obj` (found at `path` of the scene) as a TOML value. A key whose value is None is left out
/// (TOML has no null: the field takes its default); anything that is no number, string,
/// Boolean, list or mapping (numpy arrays and scalars go through their `tolist()`) is refused
/// naming its path.
pub fn to_toml(
    obj: &Bound<'_, PyAny>,
    path: &str,
    origin: &str,
) -> Result<toml::Value, Box<Refusal>> {
    let refuse = |rule: String| {
        Box::new(Refusal {
            message: format!("{origin}: field `{path}`: {rule}"),
            origin: origin.to_string(),
            field: Some(path.to_string()),
            value: obj.repr().ok().map(|r| r.to_string()),
            rule: Some(rule),
            code: None,
        })
    };
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(toml::Value::Boolean(b.is_true()));
    }
    if obj.is_instance_of::<PyInt>() {
        return obj
            .extract::<i64>()
            .map(toml::Value::Integer)
            .map_err(|_| refuse("an integer out of the 64-bit range".into()));
    }
    if let Ok(x) = obj.cast::<PyFloat>() {
        return Ok(toml::Value::Float(x.value()));
    }
    if obj.is_instance_of::<PyString>() {
        return obj
            .extract::<String>()
            .map(toml::Value::String)
            .map_err(|_| refuse("a string that is not valid Unicode".into()));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        // a scene's beams, bodies, joints and loads are named by their names, as the engine does
        let paths: Option<Vec<String>> = PARTS.contains(&path).then(|| {
            let names: Vec<String> = obj
                .try_iter()
                .into_iter()
                .flatten()
                .map(|item| {
                    item.ok()
                        .and_then(|d| d.get_item("name").ok())
                        .and_then(|n| n.extract::<String>().ok())
                        .unwrap_or_default()
                })
                .collect();
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            fmu_beam::scene::part_paths(path, &names)
        });
        let mut items = Vec::new();
        for (i, item) in obj
            .try_iter()
            .map_err(|e| refuse(e.to_string()))?
            .enumerate()
        {
            let item = item.map_err(|e| refuse(e.to_string()))?;
            let at = match paths.as_ref().and_then(|p| p.get(i)) {
                Some(p) => p.clone(),
                None => format!("{path}[{i}]"),
            };
            if item.is_none() {
                return Err(Box::new(Refusal {
                    message: format!("{origin}: field `{at}`: None in a list"),
                    origin: origin.to_string(),
                    field: Some(at),
                    value: Some("None".into()),
                    rule: Some("None in a list".into()),
                    code: None,
                }));
            }
            items.push(to_toml(&item, &at, origin)?);
        }
        return Ok(toml::Value::Array(items));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        return table(d.items().as_any(), path, origin).map(toml::Value::Table);
    }
    if obj.hasattr("tolist").unwrap_or(false) {
        let list = obj
            .call_method0("tolist")
            .map_err(|e| refuse(e.to_string()))?;
        return to_toml(&list, path, origin);
    }
    if obj.hasattr("items").unwrap_or(false) {
        let items = obj
            .call_method0("items")
            .map_err(|e| refuse(e.to_string()))?;
        return table(&items, path, origin).map(toml::Value::Table);
    }
    let ty = obj
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_default();
    Err(refuse(format!(
        "a {ty} is not a scene value (a number, string, bool, list or dict)"
    )))
}

/// The (key, value) pairs of a mapping as a TOML table; keys must be strings.
fn table(items: &Bound<'_, PyAny>, path: &str, origin: &str) -> Result<toml::Table, Box<Refusal>> {
    let fail = |field: String, rule: String| {
        Box::new(Refusal {
            message: format!("{origin}: field `{field}`: {rule}"),
            origin: origin.to_string(),
            field: Some(field),
            rule: Some(rule),
            ..Refusal::default()
        })
    };
    let mut out = toml::Table::new();
    let iter = items
        .try_iter()
        .map_err(|e| fail(path.to_string(), e.to_string()))?;
    for pair in iter {
        let (key, value): (Bound<'_, PyAny>, Bound<'_, PyAny>) = pair
            .and_then(|p| p.extract())
            .map_err(|e| fail(path.to_string(), e.to_string()))?;
        let Ok(key) = key.extract::<String>() else {
            let shown = key.repr().map(|r| r.to_string()).unwrap_or_default();
            return Err(fail(
                path.to_string(),
                format!("key {shown} is not a string"),
            ));
        };
        if value.is_none() {
            continue;
        }
        let at = if path.is_empty() {
            key.clone()
        } else {
            format!("{path}.{key}")
        };
        out.insert(key, to_toml(&value, &at, origin)?);
    }
    Ok(out)
}

/// A TOML value as Python: tables as dicts, arrays as lists, dates as their text.
pub fn to_python<'py>(py: Python<'py>, value: &toml::Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        toml::Value::String(s) => s.into_pyobject(py)?.into_any(),
        toml::Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        toml::Value::Float(x) => x.into_pyobject(py)?.into_any(),
        toml::Value::Boolean(b) => b.into_pyobject(py)?.to_owned().into_any(),
        toml::Value::Datetime(d) => d.to_string().into_pyobject(py)?.into_any(),
        toml::Value::Array(a) => {
            let list = PyList::empty(py);
            for x in a {
                list.append(to_python(py, x)?)?;
            }
            list.into_any()
        }
        toml::Value::Table(t) => table_to_python(py, t)?.into_any(),
    })
}

/// A TOML table as a dict, keys in the table's order.
pub fn table_to_python<'py>(py: Python<'py>, t: &toml::Table) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in t {
        d.set_item(k, to_python(py, v)?)?;
    }
    Ok(d)
}
