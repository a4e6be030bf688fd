//! Closed-form references of the work-precision study.
//!
//! # References
//! - Clamped–free Euler–Bernoulli modes: cos βL cosh βL = −1, ω = (βL)² √(EJ/(ρA L⁴)); a tip
//!   force's static shape has tip modal participation 12/(βₙL)⁴ (they sum to 1).
//! - Compound pendulum: I α'' = −m g (L/2) cos α with I = m L²/3; period from rest at the
//!   horizontal 4K(k)/ω₀, k = sin 45°, ω₀ = √(3g/2L).

use fmu_beam::mechanics::Section;
use fmu_beam::Scene;
use std::f64::consts::PI;

/// Modes summed by [`clamped_beam_tip`]: the tail beyond them is below 1e-13 of the deflection.
pub const CLAMPED_MODES: usize = 4000;

/// Roots βₙL of cos x cosh x = −1, written cos x + sech x = 0 (no overflow), by Newton from
/// (2n − 1)π/2.
pub fn clamped_free_roots(count: usize) -> Vec<f64> {
    (1..=count)
        .map(|n| {
            let mut x = (2 * n - 1) as f64 * PI / 2.0;
            if n == 1 {
                x = 1.875;
            }
            for _ in 0..50 {
                let sech = 1.0 / x.cosh();
                let f = x.cos() + sech;
                let df = -x.sin() - sech * x.tanh();
                let dx = f / df;
                x -= dx;
                if dx.abs() < 1e-15 * x {
                    break;
                }
            }
            x
        })
        .collect()
}

/// C1: the exact tip deflection at `times` of the scene's first beam, clamped at flange a and
/// released at rest from the static shape of a tip force with tip deflection δ.
pub fn clamped_beam_tip(scene: &Scene, times: &[f64]) -> Vec<f64> {
    let b = &scene.beams[0];
    let sec = Section::from_spec(&b.section);
    let delta = b.initial.tip_displacement;
    let c =
        (b.material.e * sec.second_moment / (b.material.rho * sec.area * b.length.powi(4))).sqrt();
    let modes: Vec<(f64, f64)> = clamped_free_roots(CLAMPED_MODES)
        .into_iter()
        .map(|x| (12.0 / x.powi(4), x * x * c))
        .collect();
    times
        .iter()
        .map(|&t| {
            // smallest terms first
            delta
                * modes
                    .iter()
                    .rev()
                    .map(|(a, w)| a * (w * t).cos())
                    .sum::<f64>()
        })
        .collect()
}

/// Complete elliptic integral of the first kind K(k), by the arithmetic–geometric mean.
pub fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut g) = (1.0, (1.0 - k * k).sqrt());
    // quadratic convergence: far fewer rounds reach rounding for any k < 1 - 1e-12
    for _ in 0..30 {
        (a, g) = (0.5 * (a + g), (a * g).sqrt());
    }
    PI / (2.0 * a)
}

/// `g` and `L` of the C2 scene: |world.gravity| and the first beam's length.
fn pendulum(scene: &Scene) -> (f64, f64) {
    let [gx, gy, _] = scene.world.gravity;
    (gx.hypot(gy), scene.beams[0].length)
}

/// C2: the period of the rigid compound pendulum released from rest at the horizontal.
pub fn rigid_pendulum_period(scene: &Scene) -> f64 {
    let (g, l) = pendulum(scene);
    4.0 * elliptic_k(std::f64::consts::FRAC_1_SQRT_2) / (1.5 * g / l).sqrt()
}

/// C2: the hinge angle at `times` (ascending) of the rigid compound pendulum released from
/// rest at the horizontal (angle 0, falling to negative angles), by RK4 with step 1e-5 s.
pub fn rigid_pendulum_angle(scene: &Scene, times: &[f64]) -> Vec<f64> {
    let (g, l) = pendulum(scene);
    let w2 = 1.5 * g / l;
    let f = |y: [f64; 2]| [y[1], -w2 * y[0].cos()];
    let mut y = [0.0, 0.0];
    let mut t = 0.0;
    let mut out = Vec::with_capacity(times.len());
    for &target in times {
        while t < target - 1e-12 {
            let h = (target - t).min(1e-5);
            let k1 = f(y);
            let k2 = f([y[0] + 0.5 * h * k1[0], y[1] + 0.5 * h * k1[1]]);
            let k3 = f([y[0] + 0.5 * h * k2[0], y[1] + 0.5 * h * k2[1]]);
            let k4 = f([y[0] + h * k3[0], y[1] + h * k3[1]]);
            for i in 0..2 {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            t += h;
        }
        out.push(y[0]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clamped_roots_and_participations() {
        let r = clamped_free_roots(CLAMPED_MODES);
        for (got, want) in r
            .iter()
            .zip([1.875104069, 4.694091133, 7.854757438, 10.99554073])
        {
            assert!((got - want).abs() < 1e-8, "{got} vs {want}");
        }
        // the static tip shape is fully represented: Σ 12/(βL)⁴ = 1
        let s: f64 = r.iter().rev().map(|x| 12.0 / x.powi(4)).sum();
        assert!((s - 1.0).abs() < 1e-12, "sum {s}");
    }

    #[test]
    fn pendulum_period_matches_cases_md() {
        let scene = Scene::from_toml_str(
            "name = \"p\"\n[world]\ngravity = [0.0, -9.81]\n[[beam]]\nname = \"beam\"\n\
             length = 0.4\nelements = 2\nmaterial = { rho = 5540.0, E = 1e9 }\n\
             section = { A = 0.0018, J = 1.215e-8 }\n",
            "p.toml",
        )
        .unwrap();
        let p = rigid_pendulum_period(&scene);
        assert!((p - 1.22275).abs() < 5e-5, "{p}");
        // a quarter period after release the pendulum hangs straight down
        let a = rigid_pendulum_angle(&scene, &[p / 4.0]);
        assert!((a[0] + PI / 2.0).abs() < 1e-9, "{}", a[0]);
    }
}
