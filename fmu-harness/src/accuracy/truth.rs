//! A study checked against the truth: a reference CSV (time first, then named columns, such as
//! `bench/reference/`'s exact ANCF solutions) on the study's grid, and each run's true error in
//! the study's norm, so that the estimates can be judged. The file is read through the
//! harness's bounded reader of regular files ([`crate::input_file`]); a refusal names its
//! columns only when its first line is a header of plausible names over a row of numbers, and
//! otherwise shows nothing of it.

use super::estimate::{distances, peaks, Series};
use super::{AccuracyError, Study};
use std::path::Path;

/// The largest reference read (bench/reference/'s largest file is 95 kB; a million rows of a
/// few outputs fit).
pub const MAX_REFERENCE_BYTES: u64 = 64 << 20;

/// Columns a refusal lists by name: more, and the header is not shown.
const MAX_SHOWN_COLUMNS: usize = 50;

/// A column name a refusal may show: an FMI-like name of at most 100 characters (letters,
/// digits, `_`, `.`, `[`, `]`, `(`, `)`), starting with a letter or `_`.
fn plausible_name(name: &str) -> bool {
    name.len() <= 100
        && name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '[' | ']' | '(' | ')'))
}

/// The reference's columns `columns`, one per output, on the grid `start + k comm`,
/// k = 0..=n (the file may go on past it).
pub fn read(
    path: &Path,
    columns: &[String],
    start: f64,
    comm: f64,
    n: usize,
) -> Result<Series, AccuracyError> {
    let bad = |message: String| AccuracyError::Reference {
        path: path.display().to_string(),
        message,
    };
    let text = crate::input_file::read_text(path, "the reference", MAX_REFERENCE_BYTES)
        .map_err(|e| bad(e.to_string()))?;
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let first = lines.next().ok_or_else(|| bad("empty".into()))?;
    let names: Vec<&str> = first
        .split(',')
        .map(|c| c.trim().trim_matches('"'))
        .collect();
    // the names are shown only when the file has shown itself a reference: plausible names
    // over a row of as many numbers (issue 45: a file named by mistake or by malice is not
    // quoted)
    let second = lines.clone().next().unwrap_or("");
    let numbers = second
        .split(',')
        .filter(|x| x.trim().parse::<f64>().is_ok())
        .count();
    let shown = (names.len() <= MAX_SHOWN_COLUMNS
        && numbers == names.len()
        && names.iter().all(|c| plausible_name(c)))
    .then(|| names.join(", "));
    let idx: Vec<usize> = columns
        .iter()
        .map(|c| {
            names.iter().position(|n| n == c).ok_or_else(|| {
                bad(match &shown {
                    Some(list) => format!("no column {c} (it has: {list})"),
                    None => format!(
                        "no column {c}: its first line is not a header of column names over \
                         rows of numbers (the file is not shown)"
                    ),
                })
            })
        })
        .collect::<Result<_, _>>()?;
    let mut out: Series = vec![Vec::with_capacity(n + 1); columns.len()];
    for (k, line) in lines.take(n + 1).enumerate() {
        let row: Vec<f64> = line
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad(format!("row {}: numbers expected", k + 2)))?;
        let t = start + k as f64 * comm;
        if row.len() != names.len() || (row[0] - t).abs() > 1e-6 * comm {
            return Err(bad(format!(
                "row {}: time {} where the study's grid has {t} (every {comm} s from {start})",
                k + 2,
                row.first().copied().unwrap_or(f64::NAN)
            )));
        }
        for (o, &i) in out.iter_mut().zip(&idx) {
            o.push(row[i]);
        }
    }
    if out[0].len() != n + 1 {
        return Err(bad(format!(
            "{} rows, the study's grid has {}",
            out[0].len(),
            n + 1
        )));
    }
    Ok(out)
}

/// Each run's true error against `reference` (per output), in the study's norm.
pub fn judge(study: &mut Study, reference: &Series) {
    let pk = peaks(reference);
    for r in &mut study.runs {
        if let Ok(y) = &r.result {
            r.true_errors = distances(y, reference, &pk);
        }
    }
}
