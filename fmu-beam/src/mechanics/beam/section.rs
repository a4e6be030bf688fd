//! Cross-section properties: area and second moment of area for in-plane bending.
//! Kept apart from the element that uses them.

use std::f64::consts::PI;

/// Section constants of a planar beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// Area A (m^2).
    pub area: f64,
    /// Second moment of area J about the axis normal to the plane of motion (m^4).
    pub second_moment: f64,
}

impl Section {
    /// Solid rectangle of height a (in the plane of bending) and width b (m).
    pub fn rectangle(a: f64, b: f64) -> Section {
        Section {
            area: a * b,
            second_moment: b * a.powi(3) / 12.0,
        }
    }

    /// Rectangle a×b with wall thickness t.
    pub fn hollow_rectangle(a: f64, b: f64, t: f64) -> Section {
        let (ai, bi) = (a - 2.0 * t, b - 2.0 * t);
        Section {
            area: a * b - ai * bi,
            second_moment: (b * a.powi(3) - bi * ai.powi(3)) / 12.0,
        }
    }

    /// Solid circle of diameter d (m).
    pub fn circle(d: f64) -> Section {
        Section {
            area: PI * d * d / 4.0,
            second_moment: PI * d.powi(4) / 64.0,
        }
    }

    /// Tube of outer diameter d and wall thickness t.
    pub fn hollow_circle(d: f64, t: f64) -> Section {
        let di = d - 2.0 * t;
        Section {
            area: PI * (d * d - di * di) / 4.0,
            second_moment: PI * (d.powi(4) - di.powi(4)) / 64.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn c1_square_section() {
        let s = Section::rectangle(0.01, 0.01);
        assert!((s.area - 1e-4).abs() < 1e-18);
        assert!((s.second_moment - 0.01f64.powi(4) / 12.0).abs() < 1e-22);
    }

    #[test]
    fn hollow_shapes_reduce_to_differences() {
        let outer = Section::circle(0.1);
        let inner = Section::circle(0.08);
        let tube = Section::hollow_circle(0.1, 0.01);
        assert!((tube.area - (outer.area - inner.area)).abs() < 1e-15);
        assert!((tube.second_moment - (outer.second_moment - inner.second_moment)).abs() < 1e-18);
        let box_ = Section::hollow_rectangle(0.1, 0.05, 0.005);
        let (o, i) = (
            Section::rectangle(0.1, 0.05),
            Section::rectangle(0.09, 0.04),
        );
        assert!((box_.area - (o.area - i.area)).abs() < 1e-15);
        assert!((box_.second_moment - (o.second_moment - i.second_moment)).abs() < 1e-18);
    }
}
