//! The error estimates of an accuracy study: the norm, the observed order of a ladder of runs
//! refined by a factor 2, and Richardson's extrapolation.
//!
//! The norm is the peer bench's (`bench/src/work_precision/peer.rs`): the largest over the
//! communication grid of |y − y_ref|, over the largest |y_ref| of that output; over several
//! outputs, the largest of theirs.
//!
//! # References
//! - L. F. Richardson, "The deferred approach to the limit", Phil. Trans. R. Soc. A 226 (1927).
//! - P. J. Roache, "Quantification of uncertainty in computational fluid dynamics", Annu. Rev.
//!   Fluid Mech. 29 (1997): the observed order from three refinements by a constant ratio.

/// One run's values: per output, on the study's communication grid.
pub type Series = Vec<Vec<f64>>;

/// Orders outside this range are not taken as observed: the ladder is not in its asymptotic
/// range (or its differences are noise), and the method's nominal order is used instead.
pub const PLAUSIBLE_ORDER: (f64, f64) = (0.5, 6.0);

/// Differences below this (relative to the output's peak) are rounding: the ladder has
/// converged and the order is not measurable.
pub const ROUNDING: f64 = 1e-12;

/// Each output's largest |value| (1 where an output stays at 0, so that its error is absolute).
pub fn peaks(y: &Series) -> Vec<f64> {
    y.iter()
        .map(|v| {
            let p = v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            if p > 0.0 {
                p
            } else {
                1.0
            }
        })
        .collect()
}

/// Per output: max over the grid of |a − b| / peak.
pub fn distances(a: &Series, b: &Series, peaks: &[f64]) -> Vec<f64> {
    a.iter()
        .zip(b)
        .zip(peaks)
        .map(|((x, y), p)| {
            x.iter()
                .zip(y)
                .fold(0.0_f64, |m, (u, v)| m.max((u - v).abs()))
                / p
        })
        .collect()
}

/// The largest of [`distances`]: the study's norm.
pub fn distance(a: &Series, b: &Series, peaks: &[f64]) -> f64 {
    distances(a, b, peaks).into_iter().fold(0.0, f64::max)
}

/// How the order of a ladder was found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OrderSource {
    /// From the three finest runs: log2 of the ratio of their two differences.
    Observed,
    /// The method's nominal order: fewer than three runs, or an observed order outside
    /// [`PLAUSIBLE_ORDER`] (the value then carried).
    Nominal { observed: Option<f64> },
    /// The finest differences are rounding: nothing left to extrapolate.
    Converged,
}

/// A ladder's extrapolation.
#[derive(Debug, Clone)]
pub struct Ladder {
    /// The order used to extrapolate.
    pub order: f64,
    pub source: OrderSource,
    /// The differences of successive runs, coarse to fine (the study's norm).
    pub differences: Vec<f64>,
    /// Richardson's extrapolation from the two finest runs.
    pub limit: Series,
}

/// Extrapolates `runs` (coarse to fine, each refined by a factor 2 from the one before) with
/// the observed order where it is plausible, else with `nominal`. Needs at least two runs.
pub fn richardson(runs: &[&Series], peaks: &[f64], nominal: f64) -> Option<Ladder> {
    let n = runs.len();
    if n < 2 {
        return None;
    }
    let differences: Vec<f64> = runs
        .windows(2)
        .map(|w| distance(w[0], w[1], peaks))
        .collect();
    let last = differences[n - 2];
    let (order, source) = if last < ROUNDING {
        (nominal, OrderSource::Converged)
    } else if n >= 3 {
        let p = (differences[n - 3] / last).log2();
        if p.is_finite() && (PLAUSIBLE_ORDER.0..=PLAUSIBLE_ORDER.1).contains(&p) {
            (p, OrderSource::Observed)
        } else {
            (nominal, OrderSource::Nominal { observed: Some(p) })
        }
    } else {
        (nominal, OrderSource::Nominal { observed: None })
    };
    let (fine, coarse) = (runs[n - 1], runs[n - 2]);
    let gain = if source == OrderSource::Converged {
        0.0
    } else {
        1.0 / (2f64.powf(order) - 1.0)
    };
    let limit = fine
        .iter()
        .zip(coarse)
        .map(|(f, c)| f.iter().zip(c).map(|(a, b)| a + (a - b) * gain).collect())
        .collect();
    Some(Ladder {
        order,
        source,
        differences,
        limit,
    })
}

/// `a + (b − c)`, output by output: a limit moved by another ladder's correction.
pub fn shifted(a: &Series, b: &Series, c: &Series) -> Series {
    a.iter()
        .zip(b.iter().zip(c))
        .map(|(x, (y, z))| {
            x.iter()
                .zip(y.iter().zip(z))
                .map(|(u, (v, w))| u + v - w)
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y_h(t) = sin t + C h^p sin 3t: a ladder with a known order and limit.
    fn ladder(p: f64, levels: usize) -> (Vec<Series>, Series) {
        let t: Vec<f64> = (0..200).map(|k| k as f64 * 0.01).collect();
        let exact: Series = vec![t.iter().map(|t| t.sin()).collect()];
        let runs = (0..levels)
            .map(|k| {
                let h = 0.1 / 2f64.powi(k as i32);
                vec![t
                    .iter()
                    .map(|t| t.sin() + 3.0 * h.powf(p) * (3.0 * t).sin())
                    .collect()]
            })
            .collect();
        (runs, exact)
    }

    #[test]
    fn a_ladder_of_known_order_is_extrapolated_to_its_limit() {
        for p in [1.0, 2.0, 4.0] {
            let (runs, exact) = ladder(p, 4);
            let refs: Vec<&Series> = runs.iter().collect();
            let pk = peaks(&exact);
            let l = richardson(&refs, &pk, 2.0).unwrap();
            assert_eq!(l.source, OrderSource::Observed);
            assert!((l.order - p).abs() < 1e-9, "order {} for {p}", l.order);
            assert!(distance(&l.limit, &exact, &pk) < 1e-12);
            // each run's estimated error is its true error
            for r in &runs {
                let (est, truth) = (distance(r, &l.limit, &pk), distance(r, &exact, &pk));
                assert!((est / truth - 1.0).abs() < 1e-6, "{est} vs {truth}");
            }
        }
    }

    #[test]
    fn an_implausible_order_falls_back_to_the_nominal_one() {
        // differences that grow: not converging
        let (mut runs, exact) = ladder(2.0, 3);
        runs.reverse();
        let refs: Vec<&Series> = runs.iter().collect();
        let l = richardson(&refs, &peaks(&exact), 2.0).unwrap();
        assert!(matches!(l.source, OrderSource::Nominal { observed: Some(p) } if p < 0.0));
        assert_eq!(l.order, 2.0);
        // two runs: nominal, nothing observed
        let l = richardson(&refs[..2], &peaks(&exact), 2.0).unwrap();
        assert_eq!(l.source, OrderSource::Nominal { observed: None });
        assert!(richardson(&refs[..1], &peaks(&exact), 2.0).is_none());
    }

    #[test]
    fn identical_runs_have_converged() {
        let (runs, exact) = ladder(2.0, 1);
        let refs = vec![&runs[0], &runs[0], &runs[0]];
        let l = richardson(&refs, &peaks(&exact), 2.0).unwrap();
        assert_eq!(l.source, OrderSource::Converged);
        assert_eq!(distance(&l.limit, &runs[0], &peaks(&exact)), 0.0);
    }
}
