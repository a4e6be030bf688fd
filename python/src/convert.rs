//! Python values to TOML values and back: a scene written as nested dicts and lists is the TOML
//! file's tables and arrays, key for key (the scene reference applies unchanged).
//!
//! Any Python object may come in (issue 45): the conversion goes at most [`MAX_DEPTH`] levels
//! deep, refuses a container met again on its own path (a dict that holds itself, a `tolist()`
//! or `items()` that returns its object) and spends at most [`MAX_SCENE_UNITS`] units over the
//! whole scene (each value, key and item one, each string its length in bytes besides), sizes
//! checked before a list, dict or string is read. Lists, tuples, dicts and their subclasses are
//! read at the C level (an overridden `__iter__`, `items` or `__getitem__` is not called); a
//! refusal shows a value it could convert, or the object's type, never its `repr()`.

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

/// Levels of nesting a scene given as Python objects may have: a scene has about 6 (a beam's
/// `material` table, a joint's `start` table, a list of points); 64 is far below what would
/// exhaust the stack, far above what a scene needs.
pub const MAX_DEPTH: usize = 64;
/// The units a scene given as Python objects may spend: as many as the bytes of the largest
/// scene text ([`fmu_beam::scene::files::MAX_SCENE_BYTES`]), since each unit becomes at least a
/// byte of that text.
pub const MAX_SCENE_UNITS: usize = fmu_beam::scene::files::MAX_SCENE_BYTES as usize;

/// What a conversion carries down: where the scene came from, the containers on the path to
/// the value being converted (by identity), and the units left.
struct Walk<'a> {
    origin: &'a str,
    ancestors: Vec<usize>,
    units: usize,
}

impl<'a> Walk<'a> {
    fn new(origin: &'a str) -> Walk<'a> {
        Walk {
            origin,
            ancestors: Vec::new(),
            units: MAX_SCENE_UNITS,
        }
    }

    /// A refusal of the value at `path`, shown as `shown`.
    fn refusal(&self, path: &str, shown: Option<String>, rule: String) -> Box<Refusal> {
        let message = if path.is_empty() {
            format!("{}: {rule}", self.origin)
        } else {
            format!("{}: field `{path}`: {rule}", self.origin)
        };
        Box::new(Refusal {
            message,
            origin: self.origin.to_string(),
            field: (!path.is_empty()).then(|| path.to_string()),
            value: shown,
            rule: Some(rule),
            code: None,
        })
    }

    /// Spends `n` units, or refuses the scene as too large at `path`.
    fn spend(&mut self, n: usize, path: &str) -> Result<(), Box<Refusal>> {
        self.afford(n, path)?;
        self.units -= n;
        Ok(())
    }

    /// Whether `n` units are left, or the refusal of the scene as too large at `path`.
    fn afford(&self, n: usize, path: &str) -> Result<(), Box<Refusal>> {
        if n <= self.units {
            return Ok(());
        }
        Err(self.refusal(
            path,
            None,
            format!(
                "the scene is too large: a scene given as objects may hold at most \
                 {MAX_SCENE_UNITS} values, keys, items and bytes of text in all, as a scene \
                 file may hold that many bytes"
            ),
        ))
    }

    /// Enters the container `obj` at `path`: refused beyond [`MAX_DEPTH`] levels or when
    /// `obj` is already on the path (it would hold itself).
    fn enter(&mut self, obj: &Bound<'_, PyAny>, path: &str) -> Result<(), Box<Refusal>> {
        let id = obj.as_ptr() as usize;
        if self.ancestors.contains(&id) {
            return Err(self.refusal(
                path,
                Some(type_shown(obj)),
                "holds itself (a container met again inside itself, or a tolist() or items() \
                 that returns its own object): a scene is a tree"
                    .into(),
            ));
        }
        if self.ancestors.len() >= MAX_DEPTH {
            return Err(self.refusal(
                path,
                Some(type_shown(obj)),
                format!(
                    "is nested more than {MAX_DEPTH} levels deep; a scene has about 6 (tables, \
                     lists of tables, lists of numbers)"
                ),
            ));
        }
        self.ancestors.push(id);
        Ok(())
    }

    fn leave(&mut self) {
        self.ancestors.pop();
    }
}

/// An object as a refusal may show it without running its code: its type.
fn type_shown(obj: &Bound<'_, PyAny>) -> String {
    let ty = obj
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_default();
    format!("a {}", cut(&ty, 80))
}

/// `s` cut after `n` characters, with an ellipsis.
fn cut(s: &str, n: usize) -> String {
    let mut out: String = s.chars().take(n).collect();
    if s.chars().count() > n {
        out.push('…');
    }
    out
}

/// `obj` (found at `path` of the scene) as a TOML value. A key whose value is None is left out
/// (TOML has no null: the field takes its default); anything that is no number, string,
/// Boolean, list or mapping (numpy arrays and scalars go through their `tolist()`) is refused
/// naming its path, and so is a scene deeper, larger or more self-referential than
/// [`Walk`] allows.
pub fn to_toml(
    obj: &Bound<'_, PyAny>,
    path: &str,
    origin: &str,
) -> Result<toml::Value, Box<Refusal>> {
    value(obj, path, &mut Walk::new(origin))
}

/// [`to_toml`] on its way down.
fn value(
    obj: &Bound<'_, PyAny>,
    path: &str,
    walk: &mut Walk<'_>,
) -> Result<toml::Value, Box<Refusal>> {
    walk.spend(1, path)?;
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(toml::Value::Boolean(b.is_true()));
    }
    if obj.is_instance_of::<PyInt>() {
        return obj.extract::<i64>().map(toml::Value::Integer).map_err(|_| {
            walk.refusal(
                path,
                Some("an integer".into()),
                "an integer out of the 64-bit range".into(),
            )
        });
    }
    if let Ok(x) = obj.cast::<PyFloat>() {
        return Ok(toml::Value::Float(x.value()));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return string(s, path, walk).map(toml::Value::String);
    }
    if let Ok(list) = obj.cast::<PyList>() {
        walk.spend(list.len(), path)?;
        walk.enter(obj, path)?;
        let items: Vec<Bound<'_, PyAny>> = list.iter().collect();
        let r = array(&items, path, walk);
        walk.leave();
        return r;
    }
    if let Ok(tuple) = obj.cast::<PyTuple>() {
        walk.spend(tuple.len(), path)?;
        walk.enter(obj, path)?;
        let items: Vec<Bound<'_, PyAny>> = tuple.iter().collect();
        let r = array(&items, path, walk);
        walk.leave();
        return r;
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        walk.spend(d.len(), path)?;
        walk.enter(obj, path)?;
        let pairs: Vec<(Bound<'_, PyAny>, Bound<'_, PyAny>)> = d.iter().collect();
        let r = table(pairs.into_iter().map(Ok), path, walk).map(toml::Value::Table);
        walk.leave();
        return r;
    }
    if obj.hasattr("tolist").unwrap_or(false) {
        walk.enter(obj, path)?;
        let r = obj
            .call_method0("tolist")
            .map_err(|e| walk.refusal(path, Some(type_shown(obj)), cut(&e.to_string(), 300)))
            .and_then(|list| value(&list, path, walk));
        walk.leave();
        return r;
    }
    if obj.hasattr("items").unwrap_or(false) {
        walk.enter(obj, path)?;
        let r = mapping_items(obj, path, walk);
        walk.leave();
        return r.map(toml::Value::Table);
    }
    let shown = type_shown(obj);
    Err(walk.refusal(
        path,
        Some(shown.clone()),
        format!("{shown} is not a scene value (a number, string, bool, list or dict)"),
    ))
}

/// A string's text, its length spent: an exact `str` measured before it is copied (a subclass
/// is copied first: its `__len__` is not called), never through its `__str__`.
fn string(
    s: &Bound<'_, PyString>,
    path: &str,
    walk: &mut Walk<'_>,
) -> Result<String, Box<Refusal>> {
    if s.is_exact_instance_of::<PyString>() {
        // code points: no more than the UTF-8 bytes spent below
        walk.afford(s.len().unwrap_or(usize::MAX), path)?;
    }
    let text = s.to_cow().map_err(|_| {
        walk.refusal(
            path,
            Some("a str".into()),
            "a string that is not valid Unicode".into(),
        )
    })?;
    walk.spend(text.len(), path)?;
    Ok(text.into_owned())
}

/// The (key, value) pairs of an object's `items()` as a TOML table, bounded as it goes.
fn mapping_items(
    obj: &Bound<'_, PyAny>,
    path: &str,
    walk: &mut Walk<'_>,
) -> Result<toml::Table, Box<Refusal>> {
    let fail = |walk: &Walk<'_>, e: PyErr| walk.refusal(path, None, cut(&e.to_string(), 300));
    let items = obj.call_method0("items").map_err(|e| fail(walk, e))?;
    // the items object may be the mapping itself (or hold it): it is on the path as well
    walk.enter(&items, path)?;
    let iter = match items.try_iter() {
        Ok(it) => it,
        Err(e) => {
            walk.leave();
            return Err(fail(walk, e));
        }
    };
    let pairs = iter.map(|pair| {
        pair.and_then(|p| p.extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>())
            .map_err(|e| cut(&e.to_string(), 300))
    });
    let r = table(pairs, path, walk);
    walk.leave();
    r
}

/// The items of a list as a TOML array; a scene's beams, bodies, joints and loads are named by
/// their names, as the engine does.
fn array(
    items: &[Bound<'_, PyAny>],
    path: &str,
    walk: &mut Walk<'_>,
) -> Result<toml::Value, Box<Refusal>> {
    let paths: Option<Vec<String>> = PARTS.contains(&path).then(|| {
        let names: Vec<String> = items
            .iter()
            .map(|item| {
                item.cast::<PyDict>()
                    .ok()
                    .and_then(|d| d.get_item("name").ok().flatten())
                    .and_then(|n| {
                        let s = n.cast::<PyString>().ok()?.to_cow().ok()?;
                        Some(cut(&s, 100))
                    })
                    .unwrap_or_default()
            })
            .collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        fmu_beam::scene::part_paths(path, &names)
    });
    let mut out = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let at = match paths.as_ref().and_then(|p| p.get(i)) {
            Some(p) => p.clone(),
            None => format!("{path}[{i}]"),
        };
        if item.is_none() {
            return Err(walk.refusal(&at, Some("None".into()), "None in a list".into()));
        }
        out.push(value(item, &at, walk)?);
    }
    Ok(toml::Value::Array(out))
}

/// (key, value) pairs as a TOML table; keys must be strings. Every pair spends a unit, also
/// one whose value is None (left out).
fn table<'py>(
    pairs: impl Iterator<Item = Result<(Bound<'py, PyAny>, Bound<'py, PyAny>), String>>,
    path: &str,
    walk: &mut Walk<'_>,
) -> Result<toml::Table, Box<Refusal>> {
    let mut out = toml::Table::new();
    for pair in pairs {
        walk.spend(1, path)?;
        let (key, v) = pair.map_err(|e| walk.refusal(path, None, e))?;
        let Ok(key) = key.cast::<PyString>() else {
            let shown = type_shown(&key);
            return Err(walk.refusal(
                path,
                Some(shown.clone()),
                format!("a key that is {shown}, not a string"),
            ));
        };
        let key = string(key, path, walk)?;
        if v.is_none() {
            continue;
        }
        let at = if path.is_empty() {
            key.clone()
        } else {
            format!("{path}.{}", cut(&key, 100))
        };
        out.insert(key, self::value(&v, &at, walk)?);
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
