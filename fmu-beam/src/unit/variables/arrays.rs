//! The variables as FMI 3.0 declares them (issue 47): each beam's shape points as one Float64
//! array per world axis (`crank.shape.x`, whose elements are FMI 2.0's `crank.shape.x[1]` ...),
//! every other variable a scalar under the value reference it has in FMI 2.0, and the
//! independent variable `time` that FMI 3.0 asks for.
//!
//! An array takes the value reference of its first element; the value references of its other
//! elements are not declared in FMI 3.0. So a scalar, a parameter, an input or an output, has
//! the same value reference in both units of a scene, and an array's elements are the table's
//! variables `first .. first + len` in order.

use super::{Binding, OutputKind, VariableTable};

/// What one FMI 3.0 variable reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Declared {
    /// The table's variable of this value reference.
    Scalar(u32),
    /// The table's variables `first .. first + len`, as one array of `len` elements.
    Array {
        /// Value reference of the first element, which is the array's.
        first: u32,
        /// Number of elements.
        len: u32,
    },
    /// The independent variable (the unit's current time), declared after the table.
    Time,
}

impl Declared {
    /// The table's value references this variable stands for (none for `Time`).
    pub fn elements(self) -> std::ops::Range<u32> {
        match self {
            Declared::Scalar(vr) => vr..vr + 1,
            Declared::Array { first, len } => first..first + len,
            Declared::Time => 0..0,
        }
    }

    /// How many values a get or set of this variable moves.
    pub fn values(self) -> usize {
        match self {
            Declared::Time => 1,
            d => d.elements().len(),
        }
    }
}

/// One variable of the FMI 3.0 model description.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable3 {
    /// Its value reference in FMI 3.0.
    pub vr: u32,
    /// Its name: the table's, or the array's (`crank.shape.x`), or `time`.
    pub name: String,
    /// What it reads.
    pub declared: Declared,
}

/// The FMI 3.0 variables of a table, in value-reference order; the lookup of a value reference.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout3 {
    /// The variables, by increasing value reference.
    pub variables: Vec<Variable3>,
    /// For each value reference of the table (and the one of `time` after it), the index into
    /// `variables` of the variable it declares, if it declares one.
    index: Vec<Option<usize>>,
}

impl Layout3 {
    /// The layout of `table`: runs of shape outputs of one beam and one axis, with consecutive
    /// value references and points 1, 2, ..., become arrays.
    pub fn of(table: &VariableTable) -> Layout3 {
        let vars = &table.variables;
        let mut variables = Vec::new();
        let mut i = 0;
        while i < vars.len() {
            let run = shape_run(table, i);
            let vr = vars[i].vr;
            if run > 1 {
                let name = vars[i].name.trim_end_matches("[1]").to_string();
                variables.push(Variable3 {
                    vr,
                    name,
                    declared: Declared::Array {
                        first: vr,
                        len: run as u32,
                    },
                });
                i += run;
            } else {
                variables.push(Variable3 {
                    vr,
                    name: vars[i].name.clone(),
                    declared: Declared::Scalar(vr),
                });
                i += 1;
            }
        }
        variables.push(Variable3 {
            vr: vars.len() as u32,
            name: "time".into(),
            declared: Declared::Time,
        });
        let mut index = vec![None; vars.len() + 1];
        for (k, v) in variables.iter().enumerate() {
            index[v.vr as usize] = Some(k);
        }
        Layout3 { variables, index }
    }

    /// The variable of FMI 3.0 value reference `vr`.
    pub fn get(&self, vr: u32) -> Option<&Variable3> {
        let k = (*self.index.get(vr as usize)?)?;
        self.variables.get(k)
    }

    /// What each of `vrs` reads, in order; the first value reference that declares nothing is
    /// the error.
    pub fn resolve(&self, vrs: &[u32]) -> Result<Vec<Declared>, u32> {
        vrs.iter()
            .map(|&vr| self.get(vr).map(|v| v.declared).ok_or(vr))
            .collect()
    }
}

/// The length of the run of shape points that starts at table index `i` (0 or 1: no array).
fn shape_run(table: &VariableTable, i: usize) -> usize {
    let vars = &table.variables;
    let kind = |k: usize| match vars.get(k).map(|v| v.binding) {
        Some(Binding::Output(OutputKind::Shape { beam, point, axis })) => Some((beam, point, axis)),
        _ => None,
    };
    let Some((beam, 0, axis)) = kind(i) else {
        return 0;
    };
    let mut n = 1;
    while kind(i + n) == Some((beam, n, axis)) && vars[i + n].vr == vars[i].vr + n as u32 {
        n += 1;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    #[test]
    fn shape_points_become_one_array_per_axis_and_scalars_keep_their_references() {
        let text = "name = \"t\"\n[[beam]]\nname = \"b\"\nlength = 1.0\nelements = 2\n\
                    material = { rho = 1.0, E = 1.0 }\nsection = { A = 1.0, J = 1.0 }\n\
                    [[joint]]\nname = \"j\"\ntype = \"revolute\"\nframes = [\"world\", \"b.a\"]\n";
        let table = VariableTable::build(&Scene::from_toml_str(text, "inline").unwrap());
        let layout = Layout3::of(&table);
        let x = table.by_name("b.shape.x[1]").expect("shape points");
        let n = table
            .variables
            .iter()
            .filter(|v| v.name.starts_with("b.shape.x["))
            .count() as u32;
        assert!(n > 1);
        let array = layout.get(x.vr).unwrap();
        assert_eq!(array.name, "b.shape.x");
        assert_eq!(
            array.declared,
            Declared::Array {
                first: x.vr,
                len: n
            }
        );
        assert_eq!(layout.get(x.vr + 1), None, "an element is not a variable");
        let tip = table.by_name("b.tip.x").unwrap();
        assert_eq!(
            layout.get(tip.vr).unwrap().declared,
            Declared::Scalar(tip.vr)
        );
        let time = layout.get(table.variables.len() as u32).unwrap();
        assert_eq!(
            (time.name.as_str(), time.declared),
            ("time", Declared::Time)
        );
        assert_eq!(layout.resolve(&[tip.vr, x.vr + 1]), Err(x.vr + 1));
        // every table variable is declared once, as a scalar or an element
        let covered: usize = layout
            .variables
            .iter()
            .map(|v| v.declared.elements().len())
            .sum();
        assert_eq!(covered, table.variables.len());
    }
}
