//! A study checked against the truth: a reference CSV (time first, then named columns, such as
//! `bench/reference/`'s exact ANCF solutions) on the study's grid, and each run's true error in
//! the study's norm, so that the estimates can be judged.

use super::estimate::{distances, peaks, Series};
use super::{AccuracyError, Study};
use std::path::Path;

/// The largest reference read (bench/reference/'s largest file is 95 kB; a million rows of a
/// few outputs fit).
pub const MAX_REFERENCE_BYTES: u64 = 64 << 20;

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
    let names: Vec<&str> = lines
        .next()
        .ok_or_else(|| bad("empty".into()))?
        .split(',')
        .map(str::trim)
        .collect();
    let idx: Vec<usize> = columns
        .iter()
        .map(|c| {
            names
                .iter()
                .position(|n| n == c)
                .ok_or_else(|| bad(format!("no column {c} (it has: {})", names.join(", "))))
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
