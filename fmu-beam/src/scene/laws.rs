//! The rules of a time law (a drive's or a load scale's): its parameters present and finite
//! (within their ranges), a table of 2 to `MAX_TABLE_ROWS` rows at increasing times.

use super::rules as r;
use super::validate::{Checker, SceneError};
use super::LawSpec;

/// Refuses a law whose parameters its kind needs are missing or out of their rules; `field`
/// is the law's path (`joint "crank".drive`).
pub(super) fn validate_law(ck: &Checker, l: &LawSpec, field: &str) -> Result<(), SceneError> {
    let f = |name: &str| format!("{field}.{name}");
    let need = |v: Option<f64>, name: &str| -> Result<f64, SceneError> {
        let x = v.ok_or_else(|| {
            ck.fail_with(
                &r::LAW_PARAMETER,
                &f(name),
                "missing",
                &format!(" \"{}\"", l.law),
            )
        })?;
        ck.finite(&f(name), x)?;
        Ok(x)
    };
    if let Some(u) = l.until {
        ck.non_negative(&f("until"), u)?;
    }
    match l.law.as_str() {
        "constant" => {
            need(l.value, "value")?;
        }
        "exponential" => {
            need(l.value, "value")?;
            ck.positive(&f("time_constant"), need(l.time_constant, "time_constant")?)?;
        }
        "spin_up" => {
            need(l.omega, "omega")?;
            ck.positive(&f("ramp_time"), need(l.ramp_time, "ramp_time")?)?;
        }
        "table" => {
            let t = l.table.as_ref().ok_or_else(|| {
                ck.fail_with(&r::LAW_PARAMETER, &f("table"), "missing", " \"table\"")
            })?;
            if t.len() > r::MAX_TABLE_ROWS {
                return Err(ck.fail(&r::TABLE_ROWS_MAX, &f("table"), t.len()));
            }
            if t.len() < 2 {
                return Err(ck.fail(&r::TABLE_ROWS, &f("table"), t.len()));
            }
            for (k, row) in t.iter().enumerate() {
                ck.finite(&f(&format!("table[{k}][0]")), row[0])?;
                ck.finite(&f(&format!("table[{k}][1]")), row[1])?;
                if k > 0 && row[0] <= t[k - 1][0] {
                    return Err(ck.fail(&r::TABLE_TIMES, &f(&format!("table[{k}][0]")), row[0]));
                }
            }
        }
        "input" => {
            if let Some(v) = l.value {
                ck.finite(&f("value"), v)?;
            }
        }
        other => return Err(ck.fail(&r::LAW, &f("law"), format!("{other:?}"))),
    }
    Ok(())
}
