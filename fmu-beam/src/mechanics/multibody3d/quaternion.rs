//! Unit quaternions p = (e0, e1, e2, e3) for orientation: rotation matrix A(p) (body → world)
//! and the body-frame map ω = 2 G(p) ṗ.

use nalgebra::{Matrix3, Matrix3x4, Rotation3, UnitQuaternion, Vector3, Vector4};

/// A(p) = (e0² − eᵀe) I + 2 e eᵀ + 2 e0 ẽ (orthogonal when |p| = 1).
pub fn rotation(p: &Vector4<f64>) -> Matrix3<f64> {
    let e0 = p[0];
    let e = Vector3::new(p[1], p[2], p[3]);
    Matrix3::identity() * (e0 * e0 - e.dot(&e))
        + e * e.transpose() * 2.0
        + crate::mechanics::beam::spatial_beam::skew(&e) * (2.0 * e0)
}

/// G(p) = [−e, e0 I − ẽ]: ω = 2 G(p) ṗ in the body frame (Ȧ = A ω̃), G(p) p = 0.
pub fn g_body(p: &Vector4<f64>) -> Matrix3x4<f64> {
    let e0 = p[0];
    let e = Vector3::new(p[1], p[2], p[3]);
    let b = Matrix3::identity() * e0 - crate::mechanics::beam::spatial_beam::skew(&e);
    let mut g = Matrix3x4::zeros();
    g.column_mut(0).copy_from(&(-e));
    g.fixed_columns_mut::<3>(1).copy_from(&b);
    g
}

/// The unit quaternion (e0 ≥ 0) of a rotation matrix.
pub fn from_rotation(a: &Matrix3<f64>) -> Vector4<f64> {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(a));
    let p = Vector4::new(q.w, q.i, q.j, q.k);
    if p[0] < 0.0 {
        -p
    } else {
        p
    }
}

/// The vector part of the rotation A0ᵀ A1 for small relative rotations: ½ vee(R − Rᵀ).
pub fn rotation_error(a0: &Matrix3<f64>, a1: &Matrix3<f64>) -> Vector3<f64> {
    let r = a0.transpose() * a1;
    Vector3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    ) * 0.5
}

/// ∂A/∂p_k (k = 0..4) of [`rotation`] as written (not restricted to |p| = 1):
/// ∂A/∂e0 = 2 e0 I + 2 ẽ, ∂A/∂e_i = −2 e_i I + 2 (u_i eᵀ + e u_iᵀ) + 2 e0 ũ_i.
pub fn rotation_derivatives(p: &Vector4<f64>) -> [Matrix3<f64>; 4] {
    let e0 = p[0];
    let e = Vector3::new(p[1], p[2], p[3]);
    let skew = crate::mechanics::beam::spatial_beam::skew;
    let d = |i: usize| {
        let u = Vector3::ith(i, 1.0);
        Matrix3::identity() * (-2.0 * e[i])
            + (u * e.transpose() + e * u.transpose()) * 2.0
            + skew(&u) * (2.0 * e0)
    };
    [
        Matrix3::identity() * (2.0 * e0) + skew(&e) * 2.0,
        d(0),
        d(1),
        d(2),
    ]
}

/// Left Jacobian of the rotation vector: d exp(φ̃) = (J_l(φ) dφ)~ exp(φ̃), with
/// J_l = I + (1 − cos θ)/θ² φ̃ + (θ − sin θ)/θ³ φ̃², θ = |φ| (series below θ = 1e-2).
pub fn left_jacobian(phi: &Vector3<f64>) -> Matrix3<f64> {
    let x = phi.norm_squared();
    let (b, c) = if x < 1e-4 {
        (
            0.5 - x / 24.0 + x * x / 720.0,
            1.0 / 6.0 - x / 120.0 + x * x / 5040.0,
        )
    } else {
        let th = x.sqrt();
        ((1.0 - th.cos()) / x, (th - th.sin()) / (x * th))
    };
    let s = crate::mechanics::beam::spatial_beam::skew(phi);
    Matrix3::identity() + s * b + s * s * c
}
