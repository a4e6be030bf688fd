//! The study's outputs: `points.csv` (every point, read by `tests/plot_work_precision.py` for
//! the `<case>.png` charts) and `REPORT.md` (per case: the reference, the chart, the sweep
//! table, the cheapest run to a given accuracy per formulation, the effects tables), then the
//! 3D section of [`spatial`].

use super::{spatial, CaseResult, EffectRow, Point, Status};
use crate::error::BenchError;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Relative errors the summary asks "how fast can a formulation get there" for.
pub const GOALS: [f64; 4] = [1e-1, 1e-2, 1e-3, 1e-4];

fn quote(s: &str) -> String {
    format!("\"{}\"", s.replace('"', "'"))
}

fn status_text(s: &Status) -> (&'static str, &str) {
    match s {
        Status::Ok => ("ok", ""),
        Status::Failed(m) => ("failed", m),
        Status::Skipped(m) => ("skipped", m),
    }
}

/// Every point of every case, one row each (`kind` = sweep, effects or variants).
pub fn csv(results: &[CaseResult], spatial: Option<&spatial::Results>) -> String {
    let mut s = String::from(
        "case,kind,formulation,effects,mode,setting,status,runs,cpu_seconds_median,cpu_seconds_min,\
         cpu_seconds_max,steps,newton_iterations,factorizations,output,error_max,error_relative,message\n",
    );
    let mut row = |kind: &str, p: &Point| {
        let (status, message) = status_text(&p.status);
        let _ = writeln!(
            s,
            "{},{kind},{},{},{},{:e},{status},{},{:.6},{:.6},{:.6},{},{},{},{},{:e},{:e},{}",
            p.case,
            quote(&p.formulation),
            quote(&p.effects),
            p.setting.mode(),
            p.setting.value(),
            p.runs,
            p.seconds[0],
            p.seconds[1],
            p.seconds[2],
            p.steps,
            p.newton,
            p.factorizations,
            quote(p.output),
            p.errors[0],
            p.relative[0],
            quote(message)
        );
    };
    for r in results {
        for p in &r.points {
            row("sweep", p);
        }
        for rows in &r.effects {
            for e in rows {
                row("effects", &e.point);
            }
        }
    }
    if let Some(r) = spatial {
        spatial::csv_rows(r, &mut row);
    }
    s
}

/// Three significant digits, fixed point.
pub fn sig3(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    let decimals = (2 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

pub(super) fn cpu(p: &Point) -> String {
    format!(
        "{} ({}–{})",
        sig3(p.seconds[0]),
        sig3(p.seconds[1]),
        sig3(p.seconds[2])
    )
}

pub(super) fn sci(x: f64) -> String {
    if x.is_nan() {
        "–".into()
    } else {
        format!("{x:.2e}")
    }
}

fn sweep_table(r: &CaseResult) -> String {
    points_table(r.case.outputs, r.check.is_some(), &r.points)
}

/// Every point of a sweep: error of each of `outputs`, the check's column if `check`, time
/// and counters.
pub(super) fn points_table(outputs: &[&str], check: bool, points: &[Point]) -> String {
    let mut s = String::from("| formulation | integrator | ");
    let _ = write!(s, "error `{}` (relative)", outputs[0]);
    for o in &outputs[1..] {
        let _ = write!(s, " | relative error `{o}`");
    }
    if check {
        s += " | error vs exact rigid";
    }
    s += " | CPU s median (min–max) | steps | Newton | LU |\n|---|---|---|";
    s += &"---|".repeat(outputs.len() - 1 + usize::from(check));
    s += "---|---|---|---|\n";
    for p in points {
        let _ = write!(s, "| {} | {} |", p.formulation, p.setting);
        match &p.status {
            Status::Ok => {
                let _ = write!(s, " {} ({}) |", sci(p.errors[0]), sci(p.relative[0]));
                for i in 1..outputs.len() {
                    let missing = p.missing.iter().any(|m| m == outputs[i]);
                    let _ = write!(
                        s,
                        " {}{} |",
                        sci(p.relative[i]),
                        if missing { " (none: taken as 0)" } else { "" }
                    );
                }
                if check {
                    let _ = write!(s, " {} |", p.check.map_or("–".into(), sci));
                }
                let _ = writeln!(
                    s,
                    " {} | {} | {} | {} |",
                    cpu(p),
                    p.steps,
                    p.newton,
                    p.factorizations
                );
            }
            Status::Failed(m) | Status::Skipped(m) => {
                let span = outputs.len() + usize::from(check) + 4;
                let _ = writeln!(s, " {m}{} |", " |".repeat(span - 1));
            }
        }
    }
    s
}

/// Per formulation: its most accurate run, and the cheapest run that reaches each of `GOALS`.
fn summary(r: &CaseResult) -> String {
    let names: Vec<String> = r
        .case
        .formulations
        .iter()
        .map(|f| f.name.to_string())
        .collect();
    summary_of(&names, &r.points)
}

/// Per formulation of `names`: its most accurate point, and the cheapest that reaches each
/// of `GOALS`.
pub(super) fn summary_of(names: &[String], points: &[Point]) -> String {
    let mut s = format!(
        "| formulation | smallest relative error (CPU s, integrator) | {} |\n|---|---|{}\n",
        GOALS
            .iter()
            .map(|g| format!("cheapest to ≤ {g:.0e}"))
            .collect::<Vec<_>>()
            .join(" | "),
        "---|".repeat(GOALS.len())
    );
    for name in names {
        let pts: Vec<&Point> = points
            .iter()
            .filter(|p| &p.formulation == name && p.ok() && !p.relative[0].is_nan())
            .collect();
        let best = pts
            .iter()
            .min_by(|a, b| a.relative[0].total_cmp(&b.relative[0]));
        let _ = write!(
            s,
            "| {} | {} |",
            name,
            best.map_or("every run failed".into(), |p| format!(
                "{:.2e} ({} s, {})",
                p.relative[0],
                sig3(p.seconds[0]),
                p.setting
            ))
        );
        for g in GOALS {
            let cheapest = pts
                .iter()
                .filter(|p| p.relative[0] <= g)
                .min_by(|a, b| a.seconds[0].total_cmp(&b.seconds[0]));
            let _ = write!(
                s,
                " {} |",
                cheapest.map_or("not reached".into(), |p| format!(
                    "{} s ({})",
                    sig3(p.seconds[0]),
                    p.setting
                ))
            );
        }
        s += "\n";
    }
    s
}

fn effects_table(rows: &[EffectRow], output: &str) -> String {
    let full = &rows[0].point;
    let mut s = format!(
        "| effects | CPU s median (min–max) | time / full | steps | Newton | error `{output}` (relative) | error added | change from full | note |\n\
         |---|---|---|---|---|---|---|---|---|\n"
    );
    for row in rows {
        let p = &row.point;
        let label = match row.removed {
            Some(e) => format!("all but {e}"),
            None => p.effects.clone(),
        };
        match &p.status {
            Status::Ok => {
                let added = if full.ok() {
                    sci(p.errors[0] - full.errors[0])
                } else {
                    "–".into()
                };
                let ratio = if full.ok() {
                    sig3(p.seconds[0] / full.seconds[0])
                } else {
                    "–".into()
                };
                let missing = if p.missing.is_empty() {
                    String::new()
                } else {
                    format!(" (no `{}`: taken as 0)", p.missing.join("`, `"))
                };
                let change = if full.ok() {
                    sci(super::error(&p.values, &full.values).0)
                } else {
                    "–".into()
                };
                let _ = writeln!(
                    s,
                    "| {label} | {} | {ratio} | {} | {} | {} ({}) | {added} | {change} | {}{missing} |",
                    cpu(p),
                    p.steps,
                    p.newton,
                    sci(p.errors[0]),
                    sci(p.relative[0]),
                    row.note
                );
            }
            Status::Failed(m) | Status::Skipped(m) => {
                let _ = writeln!(
                    s,
                    "| {label} | – | – | – | – | {m} | – | – | {} |",
                    row.note
                );
            }
        }
    }
    s
}

/// The whole report; `header` goes first (run time, machine, repeats).
pub fn markdown(
    results: &[CaseResult],
    spatial: Option<&spatial::Results>,
    header: &str,
) -> String {
    let mut s = String::from("# Work-precision report (`make bench`)\n\n");
    s += header;
    s += "\n";
    for r in results {
        let c = &r.case;
        let _ = writeln!(s, "## {}: {}\n", c.name, c.title);
        let _ = writeln!(
            s,
            "Scene `scenes/{}`; outputs compared at every communication point ({} s) over {} s. \
             Error = max |y − y_ref| over the run; relative = over max |y_ref|.\n",
            c.scene, c.comm, c.stop
        );
        let _ = writeln!(s, "**Reference**: {}.\n", r.reference);
        if let Some(check) = &r.check {
            let _ = writeln!(s, "**Check**: the rigid formulation against {check}.\n");
        }
        if !c.note.is_empty() {
            let _ = writeln!(s, "{}\n", c.note);
        }
        let _ = writeln!(
            s,
            "![{0}: error against CPU time]({0}.png)\n\n{1}\n{2}",
            c.name,
            summary(r),
            sweep_table(r)
        );
        for (rows, (name, setting)) in r.effects.iter().zip(&c.effects) {
            let _ = writeln!(
                s,
                "### {}: effects switched off in turn ({name}, {setting})\n\n\
                 Each row lists every effect of `fmu_beam::EFFECTS` but one (`effects = \
                 [...]`); `auto` lets the generator decide. Time / full is the median CPU time \
                 over the full model's; error added is this row's error less the full model's, \
                 both against the case's reference (negative: the omission happens to move the \
                 output towards the reference); change from full is max |y − y_full|, what the \
                 omission itself changes at this integrator setting.\n\n{}",
                c.name,
                effects_table(rows, c.outputs[0])
            );
        }
    }
    if let Some(r) = spatial {
        s += &spatial::markdown(r);
    }
    s
}

/// Writes `points.csv` and `REPORT.md` into `out_dir`.
pub fn write(
    out_dir: &Path,
    results: &[CaseResult],
    spatial: Option<&spatial::Results>,
    header: &str,
) -> Result<Vec<PathBuf>, BenchError> {
    std::fs::create_dir_all(out_dir)
        .map_err(|e| BenchError::io(out_dir, "creating the output directory", e))?;
    let mut written = Vec::new();
    for (name, text) in [
        ("points.csv", csv(results, spatial)),
        ("REPORT.md", markdown(results, spatial, header)),
    ] {
        let path = out_dir.join(name);
        std::fs::write(&path, text).map_err(|e| BenchError::io(&path, "writing", e))?;
        written.push(path);
    }
    Ok(written)
}
