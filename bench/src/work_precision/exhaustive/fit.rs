//! The counted cost fitted to the CPU seconds of the exhaustive sweep's runs: which counts
//! predict the time (steps, Newton iterations, iteration matrices, communication points, each
//! times the model's size), and how far a ranking by the study's own work can be off.

use super::Point;
use std::fmt::Write as _;

/// A counted cost to fit: its name and the features of a point it weighs.
pub struct Model {
    pub name: &'static str,
    pub features: fn(&Point) -> Vec<f64>,
}

/// The models compared: counts of one kind, then the study's three (fitted here, and with the
/// weights the study uses, `fmu_harness::accuracy::cost`).
pub fn models() -> Vec<Model> {
    fn n(p: &Point) -> f64 {
        p.shape.unknowns
    }
    fn c(p: &Point) -> [f64; 4] {
        [
            p.counts.steps as f64,
            p.counts.iterations as f64,
            p.counts.jacobians as f64,
            p.counts.points as f64,
        ]
    }
    vec![
        Model {
            name: "steps × unknowns",
            features: |p| vec![c(p)[0] * n(p)],
        },
        Model {
            name: "Newton iterations × unknowns",
            features: |p| vec![c(p)[1] * n(p)],
        },
        Model {
            name: "iterations × unknowns, matrices × Σ frame blocks²",
            features: |p| {
                let [_, i, j, _] = c(p);
                vec![i * n(p), j * p.shape.blocks]
            },
        },
        Model {
            name: "the same and communication points × unknowns",
            features: |p| {
                let [_, i, j, k] = c(p);
                vec![i * n(p), j * p.shape.blocks, k * n(p)]
            },
        },
        Model {
            name: "the study's work (its weights, not fitted here)",
            features: |p| vec![p.work()],
        },
    ]
}

/// Fitted weights (least squares of the relative error, each weight ≥ 0: a term whose weight
/// comes out negative is dropped and the rest fitted again) and the ratios CPU / predicted.
pub fn fit(points: &[&Point], model: &Model) -> (Vec<f64>, Vec<f64>) {
    let rows: Vec<Vec<f64>> = points.iter().map(|p| (model.features)(p)).collect();
    let k = rows.first().map_or(0, Vec::len);
    let mut active: Vec<bool> = vec![true; k];
    let mut w = vec![0.0; k];
    loop {
        let idx: Vec<usize> = (0..k).filter(|&i| active[i]).collect();
        let m = idx.len();
        let mut a = nalgebra::DMatrix::<f64>::zeros(m, m);
        let mut b = nalgebra::DVector::<f64>::zeros(m);
        for (r, p) in rows.iter().zip(points) {
            let t = p.cpu[0];
            for (u, &i) in idx.iter().enumerate() {
                b[u] += r[i] / t;
                for (v, &j) in idx.iter().enumerate() {
                    a[(u, v)] += r[i] * r[j] / (t * t);
                }
            }
        }
        let Some(x) = a.lu().solve(&b) else {
            break;
        };
        w = vec![0.0; k];
        for (u, &i) in idx.iter().enumerate() {
            w[i] = x[u];
        }
        match idx.iter().position(|&i| w[i] < 0.0) {
            Some(u) => active[idx[u]] = false,
            None => break,
        }
    }
    let ratios = rows
        .iter()
        .zip(points)
        .map(|(r, p)| p.cpu[0] / r.iter().zip(&w).map(|(x, y)| x * y).sum::<f64>())
        .collect();
    (w, ratios)
}

/// exp of the standard deviation of ln r (1: a perfect fit up to a constant), and the largest
/// over the least of `r`.
pub fn spread(r: &[f64]) -> (f64, f64) {
    let logs: Vec<f64> = r.iter().map(|x| x.ln()).filter(|x| x.is_finite()).collect();
    let n = logs.len().max(1) as f64;
    let mean = logs.iter().sum::<f64>() / n;
    let var = logs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    let (lo, hi) = r
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
    (var.sqrt().exp(), hi / lo)
}

/// Runs shorter than this are left out of the fit (the scheduler's ticks).
pub const FIT_MIN_CPU: f64 = 1e-3;

/// The fit of each model: overall and per case.
pub fn fit_table(points: &[Point]) -> String {
    let ok: Vec<&Point> = points
        .iter()
        .filter(|p| p.error.is_ok() && p.cpu[0] >= FIT_MIN_CPU)
        .collect();
    let mut cases: Vec<&str> = ok.iter().map(|p| p.case.as_str()).collect();
    cases.dedup();
    let mut s = format!(
        "Counted cost against CPU seconds, {} runs of at least {FIT_MIN_CPU} s: each model's \
         weights fitted to all of them (least squares of the relative error), then the spread \
         of CPU / predicted: its geometric standard deviation (×), and in each case the \
         largest over the least (what ranking two settings of one case can be off by).\n\n\
         | model | weights | all: geo. sd | {} |\n|---|---|---|{}\n",
        ok.len(),
        cases
            .iter()
            .map(|c| format!("{c} max/min"))
            .collect::<Vec<_>>()
            .join(" | "),
        "---|".repeat(cases.len())
    );
    for m in models() {
        let (w, r) = fit(&ok, &m);
        let (sd, _) = spread(&r);
        let per_case: Vec<String> = cases
            .iter()
            .map(|c| {
                let rc: Vec<f64> = ok
                    .iter()
                    .zip(&r)
                    .filter(|(p, _)| p.case == *c)
                    .map(|(_, &x)| x)
                    .collect();
                let (sd, mm) = spread(&rc);
                format!("{mm:.2} (sd {sd:.2})")
            })
            .collect();
        let _ = writeln!(
            s,
            "| {} | {} | {sd:.3} | {} |",
            m.name,
            w.iter()
                .map(|x| format!("{x:.3e}"))
                .collect::<Vec<_>>()
                .join(", "),
            per_case.join(" | ")
        );
    }
    s
}
