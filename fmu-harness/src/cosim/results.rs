//! What a run gives back: the recorded outputs at every communication point (the CSV rows) and
//! the [`Summary`] of its counters.

use super::joint::JointStats;
use super::{CosimError, Unit};
use crate::slave::{VarType, Variable};

/// Counters of a run, for the summary.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Summary {
    pub units: Vec<String>,
    pub connections: usize,
    pub accepted_steps: u64,
    /// Steps retried after fmi2Discard or a failed check.
    pub rollbacks: u64,
    /// Variable step: steps retried because the coupling error estimate exceeded 1.
    pub error_rejections: u64,
    pub min_step: f64,
    pub max_step: f64,
    pub stop_time: f64,
    /// The reasons of the retries, in order (first few kept).
    pub retry_reasons: Vec<String>,
    /// fmi2DoStep calls of all units (iterations and retries included).
    pub unit_steps: u64,
    /// The joint coupling's counters, when the system has joints.
    pub joints: Option<JointStats>,
    /// Why the run ended before the stop time: a unit returned fmi2Discard with fmi2Terminated.
    pub ended: Option<String>,
}

impl Summary {
    pub fn text(&self) -> String {
        let mut s = format!(
            "cosim: {} units ({}), {} connections; {} steps to t = {}, h in [{:e}, {:e}]; \
             {} rollbacks, {} rejections by the coupling error\n",
            self.units.len(),
            self.units.join(", "),
            self.connections,
            self.accepted_steps,
            self.stop_time,
            self.min_step,
            self.max_step,
            self.rollbacks,
            self.error_rejections
        );
        if let Some(j) = &self.joints {
            let per = |x: u64| x as f64 / self.accepted_steps.max(1) as f64;
            s.push_str(&format!(
                "joints: {:.2} iterations and {:.2} restores per step, {:.2} unit steps per step \
                 ({} in all), {} refused (substeps or no convergence), {} force jumps at events, \
                 largest accepted mismatch {:.2e} m\n",
                per(j.iterations),
                per(j.restores),
                per(self.unit_steps),
                self.unit_steps,
                j.refusals,
                j.jumps,
                j.largest_mismatch
            ));
        }
        for r in &self.retry_reasons {
            s.push_str(&format!("  retried: {r}\n"));
        }
        if let Some(e) = &self.ended {
            s.push_str(&format!("ended early: {e}\n"));
        }
        s
    }
}

/// The column names and types of the recorded variables (`(unit, variable, column name)`): an
/// FMI 3.0 array's elements one column each (`<column name>[1]`, ...).
pub(super) fn columns(recorded: &[(usize, Variable, String)]) -> (Vec<String>, Vec<VarType>) {
    let mut names = Vec::new();
    let mut types = Vec::new();
    for (_, v, column) in recorded {
        for c in v.columns() {
            names.push(format!("{column}{}", &c[v.name.len()..]));
            types.push(v.var_type);
        }
    }
    (names, types)
}

/// One row: t, then the recorded variables (`(unit, variable, column name)`) as read now.
pub(super) fn record(
    units: &mut [Unit],
    recorded: &[(usize, Variable, String)],
    t: f64,
) -> Result<Vec<f64>, CosimError> {
    let mut row = Vec::with_capacity(recorded.len() + 1);
    row.push(t);
    for (i, v, _) in recorded {
        let u = &mut units[*i];
        crate::simulate::read_into(&mut u.slave, v, &mut row).map_err(|e| u.fail(e))?;
    }
    Ok(row)
}
