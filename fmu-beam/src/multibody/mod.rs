//! Bodies, frames and joints, assembled into M(q) q'' + G(q)ᵀλ = Q(q, q', t); g(q, t) = 0.

pub mod frame;
pub mod system;
pub mod weld;

pub use system::System;
