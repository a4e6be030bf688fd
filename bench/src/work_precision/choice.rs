//! The accuracy study's choice against the peer bench's cheapest setting (`fmu-bench choice`,
//! `make bench-choice`; issue 34 item 2: at most 1.5×). The scene `fmu-harness accuracy`
//! chose for a target (its `chosen.toml`) and the cheapest of our peer points that meets the
//! same target on the same output for good (`ours_points.csv`, [`peer::cheapest`]) are timed
//! in one process, round by round with the order alternating, so that a change of the shared
//! machine's load falls on both alike; both are scored against the exact reference.

use super::peer::{self, PeerCase, PeerPoint};
use super::Timing;
use crate::error::BenchError;
use fmu_beam::Scene;
use std::path::Path;

/// One side of the comparison: what it runs, its true error, its CPU seconds per round.
#[derive(Debug, Clone)]
pub struct Side {
    pub label: String,
    pub error: f64,
    pub seconds: Vec<f64>,
}

/// The two sides, timed in the same rounds.
#[derive(Debug, Clone)]
pub struct Comparison {
    pub case: String,
    pub output: String,
    pub target: f64,
    pub study: Side,
    pub peer: Side,
}

/// Median, least and largest of `v` (not empty).
pub fn spread(v: &[f64]) -> [f64; 3] {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    let median = if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    };
    [median, s[0], s[n - 1]]
}

impl Comparison {
    /// The study's CPU time over the peer's, per round.
    pub fn ratios(&self) -> Vec<f64> {
        self.study
            .seconds
            .iter()
            .zip(&self.peer.seconds)
            .map(|(a, b)| a / b)
            .collect()
    }

    /// A row of the table: case and output, target, each side (setting, true error, CPU s
    /// median (least–largest)), the ratio median (least–largest).
    pub fn row(&self) -> String {
        let side = |s: &Side| {
            let [m, lo, hi] = spread(&s.seconds);
            format!(
                "{}: error {:.2e}, {m:.4} s ({lo:.4}–{hi:.4})",
                s.label, s.error
            )
        };
        let [m, lo, hi] = spread(&self.ratios());
        format!(
            "| {} {} | {:.0e} | {} | {} | **{m:.2}** ({lo:.2}–{hi:.2}) |",
            self.case,
            self.output,
            self.target,
            side(&self.study),
            side(&self.peer),
        )
    }
}

/// The table's header.
pub const HEADER: &str = "| case, output | target | the study's choice | the peer bench's \
                          cheapest of ours | CPU ratio, study / peer |\n|---|---|---|---|---|";

/// A scene's integrator setting and mesh, as text: `fixed step 3.9e-5 s, tolerance 1e-9,
/// beam 10×2`.
pub fn describe(s: &Scene) -> String {
    let mut t = if s.solver.adaptive {
        format!("error control, tolerance {:.0e}", s.solver.tolerance)
    } else {
        format!(
            "fixed step {:.2e} s, tolerance {:.0e}",
            s.solver.max_step, s.solver.tolerance
        )
    };
    for b in s.beams.iter().filter(|b| !b.rigid) {
        match b.substructures {
            Some(k) => {
                t += &format!(
                    ", {} {k}×{}",
                    b.name,
                    b.elements_per_substructure.unwrap_or(1)
                )
            }
            None => t += &format!(", {} {} el.", b.name, b.elements.unwrap_or(1)),
        }
    }
    t
}

/// Times the study's `chosen` scene against the cheapest of `ours` meeting `target` on
/// `output` of `case`: `repeats` rounds after a first untimed run of each (which also sizes
/// the batch of short runs).
pub fn compare(
    scenes: &Path,
    references: &Path,
    case: &PeerCase,
    output: &str,
    target: f64,
    chosen: &Path,
    ours: &[PeerPoint],
    repeats: usize,
) -> Result<Comparison, BenchError> {
    let input = |message: String| BenchError::Input {
        origin: format!("{} {output} at {target:.0e}", case.name),
        message,
    };
    let k = case
        .outputs
        .iter()
        .position(|(c, _)| *c == output)
        .ok_or_else(|| input("the case has no such output".into()))?;
    let best = peer::cheapest(ours, "fmu-beam", case.name, output, target)
        .ok_or_else(|| input("no point of ours meets the target for good".into()))?;
    let f = case
        .formulations
        .iter()
        .find(|f| f.name == best.formulation)
        .ok_or_else(|| input(format!("no formulation {:?}", best.formulation)))?;
    let (setting, newton) = peer::parse_setting(&best.setting)
        .ok_or_else(|| input(format!("a setting not ours: {:?}", best.setting)))?;
    let base = Scene::load(&scenes.join(case.scene))?;
    let theirs = peer::configure(&base, f, setting, newton)?;
    let mine = Scene::load(chosen)?;

    let (names, rows) = peer::read_reference(&references.join(case.reference))?;
    let col = names
        .iter()
        .position(|c| c == output)
        .ok_or_else(|| input(format!("no column {output} in {}", case.reference)))?;
    let reference: Vec<f64> = rows.iter().map(|r| r[col]).collect();

    let engine = |e| BenchError::Engine {
        origin: format!("{} {output} at {target:.0e}", case.name),
        source: e,
    };
    let run_mine = || peer::simulate(&mine, case);
    let run_theirs = || peer::simulate(&theirs, case);
    let mut a = Timing::start(&run_mine).map_err(engine)?;
    let mut b = Timing::start(&run_theirs).map_err(engine)?;
    // each run on the points it reports (`peer::stride`: a fixed step above the grid, at its
    // step points)
    let error = |t: &Timing, scene: &Scene| {
        let y = &t.first.values[k];
        let stride = peer::stride(scene, case);
        if y.len() != reference.len().div_ceil(stride) {
            return Err(input(format!(
                "{} values against {} reference rows",
                y.len(),
                reference.len()
            )));
        }
        Ok(peer::scored(y, &reference, stride))
    };
    let (ea, eb) = (error(&a, &mine)?, error(&b, &theirs)?);
    a.samples.clear();
    b.samples.clear();
    for round in 0..repeats.max(1) {
        if round % 2 == 0 {
            a.sample().map_err(engine)?;
            b.sample().map_err(engine)?;
        } else {
            b.sample().map_err(engine)?;
            a.sample().map_err(engine)?;
        }
    }
    Ok(Comparison {
        case: case.name.into(),
        output: output.into(),
        target,
        study: Side {
            label: describe(&mine),
            error: ea,
            seconds: a.samples,
        },
        peer: Side {
            label: format!("{} at {}", best.formulation, best.setting),
            error: eb,
            seconds: b.samples,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratios_are_paired_by_round() {
        let c = Comparison {
            case: "c2".into(),
            output: "tip_deflection".into(),
            target: 1e-2,
            study: Side {
                label: "a".into(),
                error: 1e-3,
                seconds: vec![2.0, 3.0, 9.0],
            },
            peer: Side {
                label: "b".into(),
                error: 2e-3,
                seconds: vec![1.0, 1.0, 3.0],
            },
        };
        assert_eq!(c.ratios(), vec![2.0, 3.0, 3.0]);
        assert_eq!(spread(&[4.0, 1.0, 2.0, 3.0]), [2.5, 1.0, 4.0]);
        assert!(c.row().ends_with("| **3.00** (2.00–3.00) |"), "{}", c.row());
    }
}
