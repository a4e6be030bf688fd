//! Bodies, frames and joints, assembled into M(q) q'' + G(q)ᵀλ = Q(q, q', t); g(q, t) = 0.

pub(crate) mod beam_damping;
pub(crate) mod body;
pub(crate) mod equations;
pub(crate) mod frame;
pub(crate) mod joint;
pub(crate) mod law;
pub(crate) mod prismatic;
pub(crate) mod revolute;
pub(crate) mod rigid_body;
pub(crate) mod sparsity;
pub(crate) mod system;
pub(crate) mod weld;

pub use equations::{CoordinateKind, Equations, Point, Turning};
pub use sparsity::{Block, BlockDiagonal, JacobianRows};
pub use system::System;
