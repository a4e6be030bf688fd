//! The planar Euler–Bernoulli element of the planar paper, eq. (6)–(7): linear axial and Hermite
//! cubic transverse shape functions over 6 nodal coordinates [u1, v1, θ1, u2, v2, θ2].

/// Number of nodal coordinates of one element.
pub const ELEMENT_DOFS: usize = 6;

/// 4-point Gauss–Legendre rule on [0, 1]: exact for polynomials up to degree 7, which covers
/// every integrand of the planar paper's eq. (11) (degree ≤ 6).
pub const GAUSS_4: [(f64, f64); 4] = [
    (0.069_431_844_202_973_71, 0.173_927_422_568_726_93),
    (0.330_009_478_207_571_87, 0.326_072_577_431_273_07),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_07),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_93),
];

/// Rows S_el1 (axial) and S_el2 (transverse) of the shape matrix, eq. (6), at ξ ∈ [0, 1].
pub fn shape(xi: f64, l: f64) -> ([f64; ELEMENT_DOFS], [f64; ELEMENT_DOFS]) {
    let (x2, x3) = (xi * xi, xi * xi * xi);
    (
        [1.0 - xi, 0.0, 0.0, xi, 0.0, 0.0],
        [
            0.0,
            1.0 - 3.0 * x2 + 2.0 * x3,
            l * (xi - 2.0 * x2 + x3),
            0.0,
            3.0 * x2 - 2.0 * x3,
            l * (x3 - x2),
        ],
    )
}

/// Slope dv/dx of the transverse field at ξ, as a row over the element coordinates.
pub fn slope(xi: f64, l: f64) -> [f64; ELEMENT_DOFS] {
    [
        0.0,
        (-6.0 * xi + 6.0 * xi * xi) / l,
        1.0 - 4.0 * xi + 3.0 * xi * xi,
        0.0,
        (6.0 * xi - 6.0 * xi * xi) / l,
        3.0 * xi * xi - 2.0 * xi,
    ]
}

/// Curvature d²v/dx² at ξ, as a row over the element coordinates.
#[cfg(test)]
pub(crate) fn curvature(xi: f64, l: f64) -> [f64; ELEMENT_DOFS] {
    [
        0.0,
        (-6.0 + 12.0 * xi) / (l * l),
        (-4.0 + 6.0 * xi) / l,
        0.0,
        (6.0 - 12.0 * xi) / (l * l),
        (6.0 * xi - 2.0) / l,
    ]
}

/// Structural stiffness K_ff,el (planar paper Appendix B, with the printed typos corrected:
/// 12EJ/l^3 and 6EJ/l^2, symmetric standard form).
pub fn stiffness(ea: f64, ej: f64, l: f64) -> [[f64; ELEMENT_DOFS]; ELEMENT_DOFS] {
    let mut k = [[0.0; ELEMENT_DOFS]; ELEMENT_DOFS];
    let ka = ea / l;
    k[0][0] = ka;
    k[0][3] = -ka;
    k[3][0] = -ka;
    k[3][3] = ka;
    let c = ej / (l * l * l);
    let idx = [1, 2, 4, 5];
    let kb = [
        [12.0, 6.0 * l, -12.0, 6.0 * l],
        [6.0 * l, 4.0 * l * l, -6.0 * l, 2.0 * l * l],
        [-12.0, -6.0 * l, 12.0, -6.0 * l],
        [6.0 * l, 2.0 * l * l, -6.0 * l, 4.0 * l * l],
    ];
    for (r, &i) in idx.iter().enumerate() {
        for (s, &j) in idx.iter().enumerate() {
            k[i][j] = c * kb[r][s];
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    /// K_ff,el from the strain energy of eq. (7), integrated by Gauss, equals the closed form.
    #[test]
    fn stiffness_matches_strain_energy_integral() {
        let (ea, ej, l) = (7.2e6, 60.0, 0.2);
        let k = stiffness(ea, ej, l);
        for i in 0..6 {
            for j in 0..6 {
                let mut v = 0.0;
                for &(xi, w) in &GAUSS_4 {
                    let c = curvature(xi, l);
                    // axial strain du/dx = (u2 - u1)/l
                    let da = [-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0];
                    v += w * l * (ea * da[i] * da[j] + ej * c[i] * c[j]);
                }
                let scale = k[i][i].abs().max(k[j][j].abs());
                assert!(
                    (v - k[i][j]).abs() <= 1e-12 * scale,
                    "K[{i}][{j}] {v} vs {}",
                    k[i][j]
                );
            }
        }
    }

    /// Consistent mass integrals against the textbook closed form (mu l / 420 [...]).
    #[test]
    fn mass_matches_closed_form() {
        let (mu, l) = (0.27, 0.2);
        let mut m = [[0.0; 6]; 6];
        for &(xi, w) in &GAUSS_4 {
            let (s1, s2) = shape(xi, l);
            for i in 0..6 {
                for j in 0..6 {
                    m[i][j] += w * mu * l * (s1[i] * s1[j] + s2[i] * s2[j]);
                }
            }
        }
        let c = mu * l / 420.0;
        let closed = [
            [140.0, 0.0, 0.0, 70.0, 0.0, 0.0],
            [0.0, 156.0, 22.0 * l, 0.0, 54.0, -13.0 * l],
            [0.0, 22.0 * l, 4.0 * l * l, 0.0, 13.0 * l, -3.0 * l * l],
            [70.0, 0.0, 0.0, 140.0, 0.0, 0.0],
            [0.0, 54.0, 13.0 * l, 0.0, 156.0, -22.0 * l],
            [0.0, -13.0 * l, -3.0 * l * l, 0.0, -22.0 * l, 4.0 * l * l],
        ];
        for i in 0..6 {
            for j in 0..6 {
                assert!((m[i][j] - c * closed[i][j]).abs() < 1e-15, "m[{i}][{j}]");
            }
        }
    }

    #[test]
    fn shape_interpolates_nodes() {
        let l = 0.3;
        let (s1a, s2a) = shape(0.0, l);
        let (s1b, s2b) = shape(1.0, l);
        assert_eq!(s1a, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(s2a, [0.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(s1b, [0.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
        assert!(s2b
            .iter()
            .zip([0.0, 0.0, 0.0, 0.0, 1.0, 0.0])
            .all(|(a, b)| (a - b).abs() < 1e-15));
        assert!((slope(0.0, l)[2] - 1.0).abs() < 1e-15);
        assert!((slope(1.0, l)[5] - 1.0).abs() < 1e-15);
    }
}
