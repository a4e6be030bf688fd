//! Unit quaternions p = (e0, e1, e2, e3) for orientation: rotation matrix A(p) (body → world)
//! and the body-frame map ω = 2 G(p) ṗ.

use nalgebra::{Matrix3, Matrix3x4, Rotation3, UnitQuaternion, Vector3, Vector4};

/// A(p) = (e0² − eᵀe) I + 2 e eᵀ + 2 e0 ẽ (orthogonal when |p| = 1).
pub fn rotation(p: &Vector4<f64>) -> Matrix3<f64> {
    let e0 = p[0];
    let e = Vector3::new(p[1], p[2], p[3]);
    Matrix3::identity() * (e0 * e0 - e.dot(&e))
        + e * e.transpose() * 2.0
        + crate::beam::spatial_beam::skew(&e) * (2.0 * e0)
}

/// G(p) = [−e, e0 I − ẽ]: ω = 2 G(p) ṗ in the body frame (Ȧ = A ω̃), G(p) p = 0.
pub fn g_body(p: &Vector4<f64>) -> Matrix3x4<f64> {
    let e0 = p[0];
    let e = Vector3::new(p[1], p[2], p[3]);
    let b = Matrix3::identity() * e0 - crate::beam::spatial_beam::skew(&e);
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
