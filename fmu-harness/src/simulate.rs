//! `fmu-harness simulate`: one co-simulation unit run through [`Slave`] with a fixed
//! communication step, the chosen variables recorded at every communication point.
//!
//! The loop is fmpy's `simulate_fmu` for FMI 2.0 and 3.0 CS, so that both give the same calls:
//! `fmi2SetupExperiment(tolerance of DefaultExperiment if any, start, stop)` (FMI 3.0: the same
//! arguments to fmi3EnterInitializationMode), communication points start + (n+1)·h, the last
//! step shortened to land on the stop time, the run ends when t is within 1e-9 relative of the
//! stop time. An FMI 3.0 array is recorded as one column per element, named as FMI 2.0 names
//! the scalars (`beam.shape.x[1]`), so the CSVs of a scene's 2.0 and 3.0 units compare line by
//! line.
//!
//! Discard (FMI 2.0 §4.2.3, FMI 3.0 §4.2.4): when the FMU says it cannot go on (fmi2Terminated,
//! fmi3DoStep's terminateSimulation), the run ends cleanly at its last good time
//! (fmi2LastSuccessfulTime, fmi3DoStep's lastSuccessfulTime), recorded as the last row, and
//! [`simulate_into`] returns [`Ended`] with the FMU's messages (`fmu-harness simulate` exits
//! with status 3). Otherwise the step is retried from the last good time in halves, at most
//! [`MAX_HALVINGS`] times, before the run fails. Here the master differs from fmpy, which
//! retries with the same step.
//!
//! Rows go to a [`RowSink`] as they are recorded: the command line streams them to the CSV
//! ([`CsvWriter`]), so a long run holds one row in memory, not all of them; [`simulate`] keeps
//! them ([`Results`]). A run is refused before it starts when it would take more than
//! [`MAX_COMMUNICATION_STEPS`] steps (a `stepSize="1e-300"` of a hostile FMU).

use crate::binding::{LogMessage, Status};
use crate::platform::FmiVersion;
use crate::slave::{Slave, SlaveError, VarType, Variable};
use std::io::Write;
use std::path::Path;

/// Communication steps of one run: 1e8 (a day at 1 ms is 8.6e7). More is refused as absurd
/// before the FMU is instantiated.
pub const MAX_COMMUNICATION_STEPS: f64 = 1e8;

/// Halvings of a communication step that an FMU discarded without ending the simulation:
/// 10, a step down to 1/1024 of the communication step.
pub const MAX_HALVINGS: u32 = 10;

/// A run that the FMU ended before the stop time (Discard, and the FMU asked to terminate).
#[derive(Debug, Clone, PartialEq)]
pub struct Ended {
    /// The FMU's last good time, the last row's (s).
    pub time: f64,
    /// The stop time the run was to reach (s).
    pub stop: f64,
    /// What the FMU logged about it.
    pub messages: Vec<String>,
}

impl std::fmt::Display for Ended {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the FMU ended the simulation at t = {} s of {} s (Discard, and it asked to terminate); \
             every row up to that time is recorded",
            self.time, self.stop
        )?;
        for m in &self.messages {
            write!(f, "\n  {m}")?;
        }
        Ok(())
    }
}

/// Where recorded rows go, one at a time: first the columns, then each row (time first).
pub trait RowSink {
    fn columns(&mut self, names: &[String], types: &[VarType]) -> std::io::Result<()>;
    fn row(&mut self, row: &[f64]) -> std::io::Result<()>;
}

/// What to run; `None` takes the model description's DefaultExperiment.
#[derive(Debug, Clone, Default)]
pub struct Options {
    pub stop_time: Option<f64>,
    pub step: Option<f64>,
    /// Variable names; empty = every output.
    pub outputs: Vec<String>,
    /// Called with each warning the FMU logs (status fmi2Warning) as the run goes: at
    /// initialization and after each communication step. None drops them.
    pub on_warning: Option<fn(&str)>,
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
    /// round-trip form (the same bytes [`CsvWriter`] streams).
    pub fn csv(&self) -> String {
        let mut w = CsvWriter::new(Vec::new());
        // Writing to a Vec cannot fail.
        let _ = w.columns(&self.columns, &self.types);
        for row in &self.rows {
            let _ = w.row(row);
        }
        String::from_utf8_lossy(&w.into_inner()).into_owned()
    }
}

impl RowSink for Results {
    fn columns(&mut self, names: &[String], types: &[VarType]) -> std::io::Result<()> {
        self.columns = names.to_vec();
        self.types = types.to_vec();
        Ok(())
    }

    fn row(&mut self, row: &[f64]) -> std::io::Result<()> {
        self.rows.push(row.to_vec());
        Ok(())
    }
}

/// Writes rows as CSV while they come: the header `time,<names>`, then one line per row, reals
/// in shortest round-trip form (`{:e}`), Integer, Boolean and Enumeration as integers.
pub struct CsvWriter<W: Write> {
    out: W,
    types: Vec<VarType>,
    line: String,
}

impl<W: Write> CsvWriter<W> {
    pub fn new(out: W) -> Self {
        CsvWriter {
            out,
            types: Vec::new(),
            line: String::new(),
        }
    }

    pub fn into_inner(self) -> W {
        self.out
    }
}

impl<W: Write> RowSink for CsvWriter<W> {
    fn columns(&mut self, names: &[String], types: &[VarType]) -> std::io::Result<()> {
        self.types = types.to_vec();
        self.line.clear();
        self.line.push_str("time");
        for c in names {
            self.line.push(',');
            self.line.push_str(c);
        }
        self.line.push('\n');
        self.out.write_all(self.line.as_bytes())
    }

    fn row(&mut self, row: &[f64]) -> std::io::Result<()> {
        use std::fmt::Write as _;
        self.line.clear();
        for (i, v) in row.iter().enumerate() {
            if i > 0 {
                self.line.push(',');
            }
            // Writing to a String cannot fail.
            let _ = match i.checked_sub(1).and_then(|k| self.types.get(k)) {
                Some(VarType::Integer | VarType::Boolean | VarType::Enumeration) => {
                    write!(self.line, "{}", *v as i64)
                }
                _ => write!(self.line, "{v:e}"),
            };
        }
        self.line.push('\n');
        self.out.write_all(self.line.as_bytes())
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
        read_into(slave, v, &mut row)?;
    }
    Ok(row)
}

/// Appends the values of `v` (one for a scalar, an FMI 3.0 array's elements in order) to `row`
/// as numbers: Integer, Enumeration and Boolean too; NaN for what is no number.
pub fn read_into(slave: &mut Slave, v: &Variable, row: &mut Vec<f64>) -> Result<(), SlaveError> {
    let vr = [v.value_reference];
    match v.var_type {
        VarType::Real => row.extend(slave.get_real(&vr)?),
        VarType::Integer | VarType::Enumeration => {
            row.extend(slave.get_integer(&vr)?.into_iter().map(f64::from))
        }
        VarType::Boolean => row.extend(
            slave
                .get_boolean(&vr)?
                .into_iter()
                .map(|b| f64::from(u8::from(b))),
        ),
        VarType::String | VarType::Other(_) => {
            row.extend(std::iter::repeat_n(f64::NAN, v.value_count()))
        }
    }
    Ok(())
}

/// The column names and types of the recorded variables: an FMI 3.0 array's elements one
/// column each, named as FMI 2.0 names them (`beam.shape.x[1]`).
pub fn columns(vars: &[Variable]) -> (Vec<String>, Vec<VarType>) {
    let mut names = Vec::new();
    let mut types = Vec::new();
    for v in vars {
        let c = v.columns();
        types.extend(std::iter::repeat_n(v.var_type, c.len()));
        names.extend(c);
    }
    (names, types)
}

#[derive(Debug, thiserror::Error)]
pub enum SimulateError {
    #[error(transparent)]
    Slave(#[from] SlaveError),
    #[error(
        "`{name}` is a {type_name} variable: the CSV holds numbers only (Real or Float64, \
         Integer or Int32, Boolean, FMI 2.0's Enumeration)"
    )]
    StringVariable {
        name: String,
        type_name: &'static str,
    },
    #[error(
        "bad experiment: start {start}, stop {stop}, step {step} (need stop > start, step > 0)"
    )]
    BadExperiment { start: f64, stop: f64, step: f64 },
    #[error(
        "step {step:e} from {start} to {stop} is {steps:.3e} communication steps; the master \
         takes at most {limit:e} (give a larger --step)"
    )]
    TooManySteps {
        start: f64,
        stop: f64,
        step: f64,
        steps: f64,
        limit: f64,
    },
    #[error("writing the results: {0}")]
    Output(#[source] std::io::Error),
}

/// Runs the FMU from start to stop with communication step `step`, keeping every row; with
/// [`Ended`] where the FMU ended the run before the stop time.
pub fn simulate(fmu: &Path, options: &Options) -> Result<(Results, Option<Ended>), SimulateError> {
    let mut results = Results {
        columns: Vec::new(),
        types: Vec::new(),
        rows: Vec::new(),
    };
    let ended = simulate_into(fmu, options, &mut results)?;
    Ok((results, ended))
}

/// Runs the FMU from start to stop with communication step `step`, each row to `sink` as soon
/// as it is recorded; `Some(Ended)` where the FMU ended the run early.
pub fn simulate_into(
    fmu: &Path,
    options: &Options,
    sink: &mut dyn RowSink,
) -> Result<Option<Ended>, SimulateError> {
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
    let steps = ((stop - start) / step).ceil();
    if steps.is_nan() || steps > MAX_COMMUNICATION_STEPS {
        return Err(SimulateError::TooManySteps {
            start,
            stop,
            step,
            steps,
            limit: MAX_COMMUNICATION_STEPS,
        });
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
    if let Some(v) = vars.iter().find(|v| !v.var_type.is_numeric()) {
        return Err(SimulateError::StringVariable {
            name: v.name.clone(),
            type_name: v.var_type.name(md.fmi_version),
        });
    }

    slave.instantiate(&md.model_identifier, false)?;
    slave.setup_experiment(de.tolerance, start, Some(stop))?;
    slave.enter_initialization_mode()?;
    slave.exit_initialization_mode()?;
    pass_warnings(&mut slave, options);
    let (names, types) = columns(&vars);
    sink.columns(&names, &types)
        .map_err(SimulateError::Output)?;
    sink.row(&record(&mut slave, start, &vars)?)
        .map_err(SimulateError::Output)?;
    let mut t = start;
    let mut n: u64 = 0;
    while !(t > stop || is_close(t, stop)) {
        let mut next = start + (n + 1) as f64 * step;
        if next > stop && !is_close(next, stop) {
            next = stop;
        }
        if let Some((end, messages)) = advance(&mut slave, t, next)? {
            if end > t {
                sink.row(&record(&mut slave, end, &vars)?)
                    .map_err(SimulateError::Output)?;
            }
            slave.terminate()?;
            return Ok(Some(Ended {
                time: end,
                stop,
                messages: messages.iter().map(|m| m.message.clone()).collect(),
            }));
        }
        pass_warnings(&mut slave, options);
        t = next;
        n += 1;
        sink.row(&record(&mut slave, t, &vars)?)
            .map_err(SimulateError::Output)?;
    }
    slave.terminate()?;
    Ok(None)
}

/// Hands the warnings the FMU logged since the last call to `options.on_warning`.
fn pass_warnings(slave: &mut Slave, options: &Options) {
    if let Some(warn) = options.on_warning {
        for m in slave.take_messages() {
            if m.status == Status::Warning {
                warn(&m.message);
            }
        }
    }
}

/// Steps the slave from `t` to `next`; a Discard is retried from the last good time with half
/// the step, up to [`MAX_HALVINGS`] times. `Some(last good time)` when the FMU ended the
/// simulation (fmi2Terminated), with what it logged.
fn advance(
    slave: &mut Slave,
    t: f64,
    next: f64,
) -> Result<Option<(f64, Vec<LogMessage>)>, SimulateError> {
    let (mut at, mut h, mut halvings) = (t, next - t, 0);
    while !is_close(at, next) && at < next {
        let h_now = if is_close(at + h, next) || at + h > next {
            next - at
        } else {
            h
        };
        match slave.do_step(at, h_now, true) {
            Ok(_) => at += h_now,
            Err(SlaveError::Call {
                status: Status::Discard,
                messages,
                ..
            }) => {
                if slave.terminated()? {
                    let end = slave.last_successful_time()?;
                    return Ok(Some((end, messages)));
                }
                if halvings == MAX_HALVINGS {
                    return Err(SimulateError::Slave(SlaveError::Call {
                        function: match slave.model_description.fmi_version {
                            FmiVersion::V2 => "fmi2DoStep",
                            FmiVersion::V3 => "fmi3DoStep",
                        },
                        status: Status::Discard,
                        messages,
                    }));
                }
                at = slave.last_successful_time()?;
                h = h_now / 2.0;
                halvings += 1;
            }
            Err(e) => return Err(e.into()),
        }
    }
    Ok(None)
}
