//! Bodies, frames and joints, assembled into M(q) q'' + G(q)ᵀλ = Q(q, q', t); g(q, t) = 0.

pub mod body;
pub mod equations;
pub mod frame;
pub mod joint;
pub mod law;
pub mod prismatic;
pub mod revolute;
pub mod rigid_body;
pub mod sparsity;
pub mod system;
pub mod weld;

pub use equations::{CoordinateKind, Equations, Turning};
pub use sparsity::{BlockDiagonal, JacobianRows};
pub use system::System;
