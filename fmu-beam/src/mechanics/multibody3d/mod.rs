//! Spatial multibody systems: [`SpatialBeam`](crate::mechanics::beam::spatial_beam::SpatialBeam) bodies
//! (one frame or substructures welded tip to root) and rigid bodies, joined by weld, revolute,
//! prismatic and spherical joints, in the same index-3 form M(q) q'' + Gᵀλ = Q, g(q, t) = 0 as
//! the planar [`crate::mechanics::multibody::System`], so the same generalized-α integrator runs it
//! through [`crate::mechanics::multibody::Equations`].
//!
//! Orientation: each body carries a unit quaternion p = (e0, e) in its coordinates
//! z = [R (3), p (4), q_f], with the norm constraint pᵀp − 1 = 0 as one extra constraint row
//! per body. Why quaternions with a constraint rather than rotation updates on SO(3):
//! - no singularity: the map p ↦ A(p) covers every orientation smoothly (Euler or Cardan angles
//!   lock at ±90°);
//! - q stays a vector: q'' is the second time derivative of q, so the vector-space
//!   generalized-α (Newmark updates of q, q', q'') applies unchanged, with no Lie-group
//!   integrator, no exponential map in the update and no special iteration matrix;
//! - the cost is one coordinate and one equation per body; the mass matrix in q is singular
//!   along p itself (M_q = Tᵀ M_v T with G(p) p = 0), and the norm row supplies exactly that
//!   direction, so [[M, Gᵀ], [G, 0]] is regular.
//!
//! The body-frame angular velocity is ω = 2 G(p) ṗ with G(p) = [−e, e0 I − ẽ] (linear in p),
//! so ω̇ = 2 G(ṗ) ṗ + 2 G(p) p̈ = 2 G(p) p̈: G(ṗ) ṗ = −ė ė0 + ė0 ė − ė × ė = 0. Each body's
//! residual in (q, q', q'') is therefore Tᵀ r_v(A(p), q_f, T q', T q''), with
//! T = diag(I, 2 G(p), I) and r_v the body's residual over v = [Ṙ, ω, q̇_f].
//!
//! The constraint Jacobian is in closed form: each column is the joint rows' derivative along
//! the frame-pose derivatives of one coordinate ([`frame::Frame3::pose_derivatives`],
//! [`joint::Joint3::rows_acceleration`]); so are the joint-coordinate gradient and the load
//! forces. K_t and C_t are forward differences per body over its own coordinates (the residual
//! is block-local), a beam's matrix–vector products updated by one column per q_f or q̇_f
//! column; the bias is a second directional difference of g along q' plus the drive law's
//! second derivative. The norm rows are exact.

pub(crate) mod body;
pub(crate) mod damping;
pub(crate) mod frame;
pub(crate) mod joint;
pub(crate) mod quaternion;
pub(crate) mod rigid_body;
pub(crate) mod system;

pub use body::Body3;
pub use frame::Frame3;
pub use rigid_body::RigidBody3;
pub use system::{Load3, System3};
