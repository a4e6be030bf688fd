//! `fmu-harness simulate`: one co-simulation unit run through [`Slave`] with a fixed
//! communication step, the chosen variables recorded at every communication point.
//!
//! The loop is fmpy's `simulate_fmu` for FMI 2.0 CS, so that both give the same calls:
//! `fmi2SetupExperiment(tolerance of DefaultExperiment if any, start, stop)`, communication points
//! start + (n+1)·h, the last step shortened to land on the stop time, the run ends when t is
//! within 1e-9 relative of the stop time.

use crate::slave::{Slave, SlaveError, VarType, Variable};
use std::path::Path;

/// What to run; `None` takes the model description's DefaultExperiment.
#[derive(Debug, Clone, Default)]
pub struct Options {
    pub stop_time: Option<f64>,
    pub step: Option<f64>,
    /// Variable names; empty = every output.
    pub outputs: Vec<String>,
}

/// Recorded values: `rows[i][0]` is the time, then one value per column (Integer and Boolean as
/// numbers).
#[derive(Debug, Clone, PartialEq)]
pub struct Results {
    pub columns: Vec<String>,
    pub types: Vec<VarType>,
    pub rows: Vec<Vec<f64>>,
}

impl Results {
    /// CSV: a header `time,<names>`, then one line per communication point, reals in shortest
    /// round-trip form.
    pub fn csv(&self) -> String {
        let mut s = String::from("time");
        for c in &self.columns {
            s.push(',');
            s.push_str(c);
        }
        s.push('\n');
        for row in &self.rows {
            for (i, v) in row.iter().enumerate() {
                if i > 0 {
                    s.push(',');
                }
                match i.checked_sub(1).map(|k| self.types[k]) {
                    Some(VarType::Integer | VarType::Boolean | VarType::Enumeration) => {
                        s.push_str(&format!("{}", *v as i64))
                    }
                    _ => s.push_str(&format!("{v:e}")),
                }
            }
            s.push('\n');
        }
        s
    }
}

/// Same as Python's `math.isclose(a, b)` (relative 1e-9, no absolute tolerance).
fn is_close(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
}

fn record(slave: &mut Slave, t: f64, vars: &[Variable]) -> Result<Vec<f64>, SlaveError> {
    let mut row = Vec::with_capacity(vars.len() + 1);
    row.push(t);
    for v in vars {
        let vr = [v.value_reference];
        let x = match v.var_type {
            VarType::Real => slave.get_real(&vr)?[0],
            VarType::Integer | VarType::Enumeration => slave.get_integer(&vr)?[0] as f64,
            VarType::Boolean => f64::from(u8::from(slave.get_boolean(&vr)?[0])),
            VarType::String => f64::NAN,
        };
        row.push(x);
    }
    Ok(row)
}

#[derive(Debug, thiserror::Error)]
pub enum SimulateError {
    #[error(transparent)]
    Slave(#[from] SlaveError),
    #[error("`{name}` is a String variable: the CSV holds numbers only")]
    StringVariable { name: String },
    #[error(
        "bad experiment: start {start}, stop {stop}, step {step} (need stop > start, step > 0)"
    )]
    BadExperiment { start: f64, stop: f64, step: f64 },
}

/// Runs the FMU from start to stop with communication step `step`.
pub fn simulate(fmu: &Path, options: &Options) -> Result<Results, SimulateError> {
    let mut slave = Slave::load(fmu)?;
    let md = slave.model_description.clone();
    let de = md.default_experiment;
    let start = de.start_time.unwrap_or(0.0);
    let stop = options.stop_time.or(de.stop_time).unwrap_or(start + 1.0);
    let step = options
        .step
        .or(de.step_size)
        .unwrap_or((stop - start) / 500.0);
    if !(stop > start && step > 0.0 && step.is_finite() && stop.is_finite()) {
        return Err(SimulateError::BadExperiment { start, stop, step });
    }
    let vars: Vec<Variable> = if options.outputs.is_empty() {
        md.outputs().cloned().collect()
    } else {
        options
            .outputs
            .iter()
            .map(|n| md.variable(n).cloned())
            .collect::<Result<_, _>>()?
    };
    if let Some(v) = vars.iter().find(|v| v.var_type == VarType::String) {
        return Err(SimulateError::StringVariable {
            name: v.name.clone(),
        });
    }

    slave.instantiate(&md.model_identifier, false)?;
    slave.setup_experiment(de.tolerance, start, Some(stop))?;
    slave.enter_initialization_mode()?;
    slave.exit_initialization_mode()?;
    let mut rows = vec![record(&mut slave, start, &vars)?];
    let mut t = start;
    let mut n: u64 = 0;
    while !(t > stop || is_close(t, stop)) {
        let mut next = start + (n + 1) as f64 * step;
        if next > stop && !is_close(next, stop) {
            next = stop;
        }
        slave.do_step(t, next - t, true)?;
        t = next;
        n += 1;
        rows.push(record(&mut slave, t, &vars)?);
    }
    slave.terminate()?;
    Ok(Results {
        columns: vars.iter().map(|v| v.name.clone()).collect(),
        types: vars.iter().map(|v| v.var_type).collect(),
        rows,
    })
}
