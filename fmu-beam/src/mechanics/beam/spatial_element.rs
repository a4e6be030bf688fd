//! The spatial Euler–Bernoulli element: 12 nodal coordinates
//! [u1, v1, w1, θx1, θy1, θz1, u2, v2, w2, θx2, θy2, θz2], linear axial u and torsion θx,
//! Hermite cubic v (x–y plane) and w (x–z plane).
//!
//! The 3D paper's printed shape matrix (its eq. (13)) and Appendix B are garbled (see
//! reference/CASES.md, "Notes on the seed texts"); this element is derived from the standard
//! shape functions instead. Rotations are right-handed about the frame axes, so for small
//! deformation θz = dv/dx and θy = −dw/dx: the w–θy plane is the v–θz plane with the sign of the
//! slope terms flipped.

/// Number of nodal coordinates of one element.
pub const ELEMENT_DOFS: usize = 12;

/// Nodal coordinate indices of one node: axial, two transverse, torsion, two slopes.
pub const U: usize = 0;
pub const V: usize = 1;
pub const W: usize = 2;
pub const TX: usize = 3;
pub const TY: usize = 4;
pub const TZ: usize = 5;
/// Coordinates per node.
pub const NODE_DOFS: usize = 6;

/// A row over the 12 element coordinates.
pub type Row = [f64; ELEMENT_DOFS];

/// Hermite cubics on [0, 1] for an element of length l: values (H1, H2, H3, H4) with
/// v = H1 v1 + H2 θ1 + H3 v2 + H4 θ2.
fn hermite(xi: f64, l: f64) -> [f64; 4] {
    let (x2, x3) = (xi * xi, xi * xi * xi);
    [
        1.0 - 3.0 * x2 + 2.0 * x3,
        l * (xi - 2.0 * x2 + x3),
        3.0 * x2 - 2.0 * x3,
        l * (x3 - x2),
    ]
}

/// d/dx of [`hermite`].
fn hermite_dx(xi: f64, l: f64) -> [f64; 4] {
    [
        (-6.0 * xi + 6.0 * xi * xi) / l,
        1.0 - 4.0 * xi + 3.0 * xi * xi,
        (6.0 * xi - 6.0 * xi * xi) / l,
        3.0 * xi * xi - 2.0 * xi,
    ]
}

/// d²/dx² of [`hermite`].
#[cfg(test)]
fn hermite_dxx(xi: f64, l: f64) -> [f64; 4] {
    [
        (-6.0 + 12.0 * xi) / (l * l),
        (-4.0 + 6.0 * xi) / l,
        (6.0 - 12.0 * xi) / (l * l),
        (6.0 * xi - 2.0) / l,
    ]
}

/// Puts the four Hermite values into the v row (v, θz) and the w row (w, −θy).
fn bending_rows(h: [f64; 4]) -> (Row, Row) {
    let mut v = [0.0; ELEMENT_DOFS];
    let mut w = [0.0; ELEMENT_DOFS];
    v[V] = h[0];
    v[TZ] = h[1];
    v[NODE_DOFS + V] = h[2];
    v[NODE_DOFS + TZ] = h[3];
    w[W] = h[0];
    w[TY] = -h[1];
    w[NODE_DOFS + W] = h[2];
    w[NODE_DOFS + TY] = -h[3];
    (v, w)
}

/// Rows of the shape matrix S_el (3 × 12) at ξ ∈ [0, 1]: displacement (u, v, w) of the axis
/// point.
pub fn shape(xi: f64, l: f64) -> [Row; 3] {
    let mut u = [0.0; ELEMENT_DOFS];
    u[U] = 1.0 - xi;
    u[NODE_DOFS + U] = xi;
    let (v, w) = bending_rows(hermite(xi, l));
    [u, v, w]
}

/// Twist angle θx of the section at ξ (linear).
pub fn twist(xi: f64) -> Row {
    let mut t = [0.0; ELEMENT_DOFS];
    t[TX] = 1.0 - xi;
    t[NODE_DOFS + TX] = xi;
    t
}

/// Small rotation of the section at ξ, rows (θx, θy, θz) = (twist, −w', v').
pub fn section_rotation(xi: f64, l: f64) -> [Row; 3] {
    let (v, w) = bending_rows(hermite_dx(xi, l));
    [twist(xi), w.map(|x| -x), v]
}

/// Strain rows at ξ: axial strain u', twist rate θx', curvatures v'' and w''.
#[cfg(test)]
pub(crate) fn strains(xi: f64, l: f64) -> [Row; 4] {
    let mut du = [0.0; ELEMENT_DOFS];
    du[U] = -1.0 / l;
    du[NODE_DOFS + U] = 1.0 / l;
    let mut dt = [0.0; ELEMENT_DOFS];
    dt[TX] = -1.0 / l;
    dt[NODE_DOFS + TX] = 1.0 / l;
    let (v, w) = bending_rows(hermite_dxx(xi, l));
    [du, dt, v, w]
}

/// Writes c · k (4 × 4, over the indices `idx`) into `m`.
fn put4(m: &mut [Row; ELEMENT_DOFS], idx: [usize; 4], c: f64, k: [[f64; 4]; 4]) {
    for (r, &i) in idx.iter().enumerate() {
        for (s, &j) in idx.iter().enumerate() {
            m[i][j] += c * k[r][s];
        }
    }
}

/// Writes c · [[2, 1], [1, 2]]-type 2 × 2 blocks (given) over (i, j).
fn put2(m: &mut [Row; ELEMENT_DOFS], i: usize, j: usize, c: f64, k: [[f64; 2]; 2]) {
    let idx = [i, j];
    for r in 0..2 {
        for s in 0..2 {
            m[idx[r]][idx[s]] += c * k[r][s];
        }
    }
}

/// The v–θz bending block pattern over (v1, θz1, v2, θz2) with factor 1, and its w–θy form
/// (slope entries of opposite sign): `sign` = 1 or −1.
fn bending_pattern(a: [[f64; 4]; 4], sign: f64) -> [[f64; 4]; 4] {
    let s = [1.0, sign, 1.0, sign];
    std::array::from_fn(|r| std::array::from_fn(|c| a[r][c] * s[r] * s[c]))
}

/// Element stiffness K_el (closed form): axial EA/l, torsion G J_t/l, bending EI_z in the x–y
/// plane and EI_y in the x–z plane (12EI/l³, 6EI/l², 4EI/l, 2EI/l).
pub fn stiffness(ea: f64, gj: f64, eiy: f64, eiz: f64, l: f64) -> [Row; ELEMENT_DOFS] {
    let mut k = [[0.0; ELEMENT_DOFS]; ELEMENT_DOFS];
    let bar = [[1.0, -1.0], [-1.0, 1.0]];
    put2(&mut k, U, NODE_DOFS + U, ea / l, bar);
    put2(&mut k, TX, NODE_DOFS + TX, gj / l, bar);
    let b = [
        [12.0, 6.0 * l, -12.0, 6.0 * l],
        [6.0 * l, 4.0 * l * l, -6.0 * l, 2.0 * l * l],
        [-12.0, -6.0 * l, 12.0, -6.0 * l],
        [6.0 * l, 2.0 * l * l, -6.0 * l, 4.0 * l * l],
    ];
    let c3 = 1.0 / (l * l * l);
    put4(
        &mut k,
        [V, TZ, NODE_DOFS + V, NODE_DOFS + TZ],
        eiz * c3,
        bending_pattern(b, 1.0),
    );
    put4(
        &mut k,
        [W, TY, NODE_DOFS + W, NODE_DOFS + TY],
        eiy * c3,
        bending_pattern(b, -1.0),
    );
    k
}

/// Consistent element mass ∫ρ(S_elᵀS_el) dx + ∫ρI_p twistᵀtwist dx (closed form): mass per
/// length μ = ρA, rotary inertia of torsion per length ρI_p; no rotary inertia of bending
/// (Euler–Bernoulli, as the planar element).
pub fn mass(mu: f64, rho_ip: f64, l: f64) -> [Row; ELEMENT_DOFS] {
    let mut m = [[0.0; ELEMENT_DOFS]; ELEMENT_DOFS];
    let bar = [[2.0, 1.0], [1.0, 2.0]];
    put2(&mut m, U, NODE_DOFS + U, mu * l / 6.0, bar);
    put2(&mut m, TX, NODE_DOFS + TX, rho_ip * l / 6.0, bar);
    let b = [
        [156.0, 22.0 * l, 54.0, -13.0 * l],
        [22.0 * l, 4.0 * l * l, 13.0 * l, -3.0 * l * l],
        [54.0, 13.0 * l, 156.0, -22.0 * l],
        [-13.0 * l, -3.0 * l * l, -22.0 * l, 4.0 * l * l],
    ];
    let c = mu * l / 420.0;
    put4(
        &mut m,
        [V, TZ, NODE_DOFS + V, NODE_DOFS + TZ],
        c,
        bending_pattern(b, 1.0),
    );
    put4(
        &mut m,
        [W, TY, NODE_DOFS + W, NODE_DOFS + TY],
        c,
        bending_pattern(b, -1.0),
    );
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::beam::planar_element::{self, GAUSS_4};

    /// The x–y plane rows equal the planar element's, coordinate for coordinate.
    #[test]
    fn in_plane_rows_are_the_planar_element() {
        let l = 0.3;
        let map = [
            (0, U),
            (1, V),
            (2, TZ),
            (3, NODE_DOFS + U),
            (4, NODE_DOFS + V),
            (5, NODE_DOFS + TZ),
        ];
        for xi in [0.0, 0.2, 0.7, 1.0] {
            let (p1, p2) = planar_element::shape(xi, l);
            let s = shape(xi, l);
            let ps = planar_element::slope(xi, l);
            let r = section_rotation(xi, l);
            let pc = planar_element::curvature(xi, l);
            let c = strains(xi, l);
            for (p, q) in map {
                assert_eq!(p1[p], s[0][q]);
                assert_eq!(p2[p], s[1][q]);
                assert_eq!(ps[p], r[2][q]);
                assert_eq!(pc[p], c[2][q]);
            }
        }
    }

    /// θy is the slope of w with a minus sign: at the nodes, −dw/dx picks θy.
    #[test]
    fn w_plane_sign_convention() {
        let l = 0.4;
        let r0 = section_rotation(0.0, l);
        let r1 = section_rotation(1.0, l);
        let mut e0 = [0.0; ELEMENT_DOFS];
        e0[TY] = 1.0;
        let mut e1 = [0.0; ELEMENT_DOFS];
        e1[NODE_DOFS + TY] = 1.0;
        for k in 0..ELEMENT_DOFS {
            assert!((r0[1][k] - e0[k]).abs() < 1e-15, "node 1, coordinate {k}");
            assert!((r1[1][k] - e1[k]).abs() < 1e-15, "node 2, coordinate {k}");
        }
    }

    #[test]
    fn stiffness_matches_strain_energy_integral() {
        let (ea, gj, eiy, eiz, l) = (7.2e6, 31.0, 60.0, 11.0, 0.2);
        let k = stiffness(ea, gj, eiy, eiz, l);
        let coef = [ea, gj, eiz, eiy];
        for i in 0..ELEMENT_DOFS {
            for j in 0..ELEMENT_DOFS {
                let mut v = 0.0;
                for &(xi, w) in &GAUSS_4 {
                    let s = strains(xi, l);
                    for (c, row) in coef.iter().zip(s.iter()) {
                        v += w * l * c * row[i] * row[j];
                    }
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
}
