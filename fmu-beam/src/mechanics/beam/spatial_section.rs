//! Cross-section constants of a spatial beam: area, both second moments, the Saint-Venant
//! torsion constant J_t and the polar moment I_p = I_y + I_z (rotary inertia of torsion).
//! Kept apart from the element that uses them, like [`super::section::Section`] for the
//! planar beam.
//!
//! Axes: the beam axis is x; `a` is the height along y (the planar beam's in-plane height), `b`
//! the width along z. I_z = ∫y² dA resists bending in the x–y plane (v, θ_z), I_y = ∫z² dA
//! bending in the x–z plane (w, θ_y).

use super::section::Section;
use std::f64::consts::PI;

/// Section constants of a spatial beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpatialSection {
    /// Area A (m^2).
    pub area: f64,
    /// Second moment I_y = ∫z² dA, bending in the x–z plane (m^4).
    pub iy: f64,
    /// Second moment I_z = ∫y² dA, bending in the x–y plane (m^4).
    pub iz: f64,
    /// Saint-Venant torsion constant J_t: torsional stiffness G J_t (m^4). Equals the polar
    /// moment only for circles and tubes.
    pub torsion_constant: f64,
    /// Polar moment I_p = I_y + I_z: rotary inertia ρ I_p of the section about the axis (m^4).
    pub polar_moment: f64,
}

/// Terms of the series in [`torsion_constant_rectangle`]: the n-th odd term is below
/// (1/n)^5 ≈ 3e-10 of the first at n = 99.
const RECTANGLE_SERIES_TERMS: usize = 50;

/// Saint-Venant torsion constant of a solid rectangle (Timoshenko & Goodier, Theory of
/// Elasticity, §109), long side h, short side t:
/// J_t = h t³/3 · [1 − (192/π⁵)(t/h) Σ_{n = 1, 3, 5, …} tanh(nπh/(2t))/n⁵],
/// summed to n = 99 (exact to about 1e-10 relative). Square: 0.140577 a⁴.
pub fn torsion_constant_rectangle(a: f64, b: f64) -> f64 {
    let (h, t) = if a >= b { (a, b) } else { (b, a) };
    let sum: f64 = (0..RECTANGLE_SERIES_TERMS)
        .map(|k| {
            let n = (2 * k + 1) as f64;
            (n * PI * h / (2.0 * t)).tanh() / n.powi(5)
        })
        .sum();
    h * t.powi(3) / 3.0 * (1.0 - 192.0 / PI.powi(5) * (t / h) * sum)
}

impl SpatialSection {
    /// Constants given directly (as in case C5's table); I_p = I_y + I_z.
    pub fn given(area: f64, iy: f64, iz: f64, torsion_constant: f64) -> SpatialSection {
        SpatialSection {
            area,
            iy,
            iz,
            torsion_constant,
            polar_moment: iy + iz,
        }
    }

    /// Solid rectangle, height a (along y) × width b (along z); J_t by the series of
    /// `torsion_constant_rectangle`.
    pub fn rectangle(a: f64, b: f64) -> SpatialSection {
        SpatialSection::given(
            a * b,
            a * b.powi(3) / 12.0,
            b * a.powi(3) / 12.0,
            torsion_constant_rectangle(a, b),
        )
    }

    /// Rectangular box a × b, wall thickness t. J_t by the thin-walled closed-section formula
    /// (Bredt–Batho) on the wall's mid-line: J_t = 4 A_m² t / p_m, A_m = (a − t)(b − t),
    /// p_m = 2 (a − t + b − t); good for t ≪ a, b.
    pub fn hollow_rectangle(a: f64, b: f64, t: f64) -> SpatialSection {
        let (ai, bi) = (a - 2.0 * t, b - 2.0 * t);
        let am = (a - t) * (b - t);
        let pm = 2.0 * (a - t + b - t);
        SpatialSection::given(
            a * b - ai * bi,
            (a * b.powi(3) - ai * bi.powi(3)) / 12.0,
            (b * a.powi(3) - bi * ai.powi(3)) / 12.0,
            4.0 * am * am * t / pm,
        )
    }

    /// Solid circle of diameter d: J_t = I_p = π d⁴/32 (exact).
    pub fn circle(d: f64) -> SpatialSection {
        let i = PI * d.powi(4) / 64.0;
        SpatialSection::given(PI * d * d / 4.0, i, i, 2.0 * i)
    }

    /// Tube of outer diameter d and wall thickness t: J_t = I_p = π (d⁴ − d_i⁴)/32 (exact).
    pub fn hollow_circle(d: f64, t: f64) -> SpatialSection {
        let di = d - 2.0 * t;
        let i = PI * (d.powi(4) - di.powi(4)) / 64.0;
        SpatialSection::given(PI * (d * d - di * di) / 4.0, i, i, 2.0 * i)
    }

    /// The planar section of motion in the x–y plane (second moment I_z).
    pub fn planar(&self) -> Section {
        Section {
            area: self.area,
            second_moment: self.iz,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangle_matches_planar_and_swaps_axes() {
        let s = SpatialSection::rectangle(0.02, 0.01);
        assert_eq!(s.planar(), Section::rectangle(0.02, 0.01));
        let t = SpatialSection::rectangle(0.01, 0.02);
        assert!((s.iy - t.iz).abs() < 1e-22 && (s.iz - t.iy).abs() < 1e-22);
        assert!((s.torsion_constant - t.torsion_constant).abs() < 1e-22);
        assert!((s.polar_moment - (s.iy + s.iz)).abs() < 1e-22);
    }

    /// Square: k = 0.1406 (Timoshenko & Goodier's table, 0.141; Roark 0.1406 a⁴); long thin
    /// strip: J_t → h t³/3 (1 − 0.630249 t/h), 0.630249 = (192/π⁵)·(31/32)ζ(5).
    #[test]
    fn rectangle_torsion_constant_against_tables() {
        let a = 0.03;
        let k = torsion_constant_rectangle(a, a) / a.powi(4);
        assert!((k - 0.140_577).abs() < 2e-6, "square k = {k}");
        let (h, t): (f64, f64) = (1.0, 0.01);
        let strip = h * t.powi(3) / 3.0 * (1.0 - 0.630_249 * t / h);
        let j = torsion_constant_rectangle(h, t);
        assert!((j / strip - 1.0).abs() < 1e-6, "strip {j} vs {strip}");
    }

    #[test]
    fn circles_have_polar_torsion_constant() {
        let c = SpatialSection::circle(0.1);
        assert!((c.torsion_constant - PI * 1e-4 / 32.0).abs() < 1e-18);
        assert_eq!(c.torsion_constant, c.polar_moment);
        let tube = SpatialSection::hollow_circle(0.1, 0.01);
        let inner = SpatialSection::circle(0.08);
        assert!(
            (tube.torsion_constant - (c.torsion_constant - inner.torsion_constant)).abs() < 1e-18
        );
        assert_eq!(tube.planar(), Section::hollow_circle(0.1, 0.01));
    }

    /// A thin square box: Bredt's J_t against the exact value of a thin square tube of
    /// mid-line side s, 4 (s²)² t/(4 s) = s³ t; the second moments by differences.
    #[test]
    fn hollow_rectangle_thin_wall() {
        let (a, t) = (0.1, 0.002);
        let s = a - t;
        let b = SpatialSection::hollow_rectangle(a, a, t);
        assert!((b.torsion_constant / (s.powi(3) * t) - 1.0).abs() < 1e-12);
        assert_eq!(b.planar(), Section::hollow_rectangle(a, a, t));
        assert!((b.iy - b.iz).abs() < 1e-20);
    }
}
