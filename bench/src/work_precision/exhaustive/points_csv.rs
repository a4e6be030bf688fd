//! The exhaustive sweep's points as CSV (`build/bench/exhaustive.csv`) and back, so that a
//! report can be rebuilt without running the sweep again.

use super::{Point, CASES};
use crate::error::BenchError;
use fmu_harness::accuracy::cost::{Counts, Shape};
use std::fmt::Write as _;
use std::path::Path;

/// The points as CSV.
pub fn csv(points: &[Point]) -> String {
    let mut s = String::from(
        "case,mesh,step_s,newton,status,error,steps,iterations,jacobians,unknowns,blocks,largest,work,cpu_s,cpu_least_s,points\n",
    );
    for p in points {
        let (status, error) = match &p.error {
            Ok(e) => ("ok".to_string(), format!("{e:.4e}")),
            Err(m) => (
                format!("\"failed: {}\"", m.replace('"', "'")),
                String::new(),
            ),
        };
        let _ = writeln!(
            s,
            "{},\"{}\",{:e},{:e},{status},{error},{},{},{},{},{},{},{:.6},{:.6},{:.6},{}",
            p.case,
            p.mesh,
            p.step,
            p.newton,
            p.counts.steps,
            p.counts.iterations,
            p.counts.jacobians,
            p.shape.unknowns,
            p.shape.blocks,
            p.shape.largest,
            p.work(),
            p.cpu[0],
            p.cpu[1],
            p.counts.points
        );
    }
    s
}

/// Reads [`csv`]'s points back.
pub fn read(path: &Path) -> Result<Vec<Point>, BenchError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| BenchError::io(path, "reading the sweep's points", e))?;
    let bad = |k: usize| BenchError::Input {
        origin: path.display().to_string(),
        message: format!("line {}: not a point of `fmu-bench exhaustive`", k + 1),
    };
    let mut points = Vec::new();
    for (k, line) in text.lines().enumerate().skip(1) {
        let f = split_csv(line);
        if f.len() != 15 && f.len() != 16 {
            return Err(bad(k));
        }
        let num = |i: usize| f[i].parse::<f64>().map_err(|_| bad(k));
        let int = |i: usize| f[i].parse::<u64>().map_err(|_| bad(k));
        points.push(Point {
            case: f[0].clone(),
            mesh: f[1].clone(),
            step: num(2)?,
            newton: num(3)?,
            error: if f[4] == "ok" {
                Ok(num(5)?)
            } else {
                Err(f[4].clone())
            },
            counts: Counts {
                steps: int(6)?,
                iterations: int(7)?,
                jacobians: int(8)?,
                // a sweep before the column: the case's grid
                points: if f.len() == 16 {
                    int(15)?
                } else {
                    CASES.iter().find(|c| c.name == f[0]).map_or(0, |c| {
                        (if c.name.starts_with("c4") {
                            20.0
                        } else if c.name == "c2" {
                            1.0
                        } else {
                            1.6
                        } / c.comm)
                            .round() as u64
                    })
                },
            },
            shape: Shape {
                unknowns: num(9)?,
                blocks: num(10)?,
                largest: num(11)?,
            },
            cpu: [num(13)?, num(14)?],
        });
    }
    Ok(points)
}

/// A CSV line's fields (double quotes around a field that holds commas).
fn split_csv(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    for ch in line.chars() {
        match ch {
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cur)),
            c => cur.push(c),
        }
    }
    out.push(cur);
    out
}
