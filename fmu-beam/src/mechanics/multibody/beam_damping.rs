//! Mass-proportional (Rayleigh α) damping of a beam as a whole, one floating frame or welded
//! substructures alike: it acts on the velocity of each material point relative to the beam's
//! reference frame, so that rigid motion of the whole beam is never damped and the deformation
//! carried by the substructures' frames is (`docs/effects.md`, "Rayleigh damping").
//!
//! The reference frame moves with a velocity s = S q' (k = 3 components in the plane: V_x, V_y,
//! ω; k = 6 in space: V, ω), linear in the beam's rates: the root (flange a) and, for a tangent
//! frame, the root's rotation; for a pinned frame, the rotation of the chord from root to tip.
//! Each body j of the beam moves rigidly with that frame at the rates T_j s (its frame's
//! velocity V + ω × (R_j − o), its rotation rate from ω, no deformation rate), so its velocity
//! relative to the reference is u_j = q'_j − T_j s. The dissipation function
//!
//!   F = ½ α Σ_j u_jᵀ M_j u_j,
//!
//! with M_j the body's mass matrix, is ½ α ∫ρ |v − v_ref|² dV when M_j is the consistent mass,
//! and the generalized damping force is −∂F/∂q' = −α Eᵀ M E q', E = I − T S:
//! f_j = α M_j u_j on every body, less Sᵀ Σ_j T_jᵀ f_j on the bodies S reads. Its power is
//! −2F ≤ 0 for every state (energy is never created), and zero exactly for a rigid motion
//! (S T = I makes E T = 0). For a single tangent frame, E keeps the deformation rates and
//! αEᵀME = α m_ff on them: the classical floating-frame damping α m_ff q̇_f.

use super::sparsity::BlockDiagonal;
use nalgebra::{DMatrix, DVector};

/// One body of a damped beam at the current coordinates.
#[derive(Debug, Clone)]
pub struct DampedBody {
    /// Index of the body in the system's bodies (its block in [`BlockDiagonal`]).
    pub body: usize,
    /// Index of its first coordinate in q.
    pub offset: usize,
    /// Its mass matrix M_j over its coordinates.
    pub mass: DMatrix<f64>,
    /// T_j (n_j × k): its rates when it moves rigidly with the reference frame at unit
    /// velocity components.
    pub rigid: DMatrix<f64>,
    /// S_j (k × n_j): its part of the reference frame's velocity, `None` where it reads none.
    pub reference: Option<DMatrix<f64>>,
}

/// The α part of a beam's Rayleigh damping at the current coordinates (see the module doc).
#[derive(Debug, Clone)]
pub struct BeamDamping {
    /// α (1/s).
    pub alpha: f64,
    /// The beam's bodies, from flange a to flange b.
    pub bodies: Vec<DampedBody>,
}

impl BeamDamping {
    /// The damping of `bodies` (flange a to b) whose reference frame's velocity the first body
    /// reads through `s_first` and, for a chord frame, the last through `s_last` (folded into
    /// the first where the beam is one body).
    pub fn with_reference(
        alpha: f64,
        mut bodies: Vec<DampedBody>,
        mut s_first: DMatrix<f64>,
        s_last: Option<DMatrix<f64>>,
    ) -> BeamDamping {
        if let Some(s_last) = s_last {
            match bodies.len() {
                1 => s_first += s_last,
                n => bodies[n - 1].reference = Some(s_last),
            }
        }
        bodies[0].reference = Some(s_first);
        BeamDamping { alpha, bodies }
    }

    fn rates<'a>(&self, b: &DampedBody, v: &'a DVector<f64>) -> nalgebra::DVectorView<'a, f64> {
        v.rows(b.offset, b.mass.nrows())
    }

    /// The reference frame's velocity s = Σ_j S_j q'_j.
    pub fn reference_velocity(&self, v: &DVector<f64>) -> DVector<f64> {
        let k = self.bodies.first().map_or(0, |b| b.rigid.ncols());
        let mut s = DVector::zeros(k);
        for b in &self.bodies {
            if let Some(sj) = &b.reference {
                s += sj * self.rates(b, v);
            }
        }
        s
    }

    /// Each body's velocity relative to the reference frame, u_j = q'_j − T_j s.
    fn relative(&self, v: &DVector<f64>) -> Vec<DVector<f64>> {
        let s = self.reference_velocity(v);
        self.bodies
            .iter()
            .map(|b| self.rates(b, v) - &b.rigid * &s)
            .collect()
    }

    /// Adds the damping force α Eᵀ M E q' into the residual `r` (it enters r as inertia does:
    /// r = M q'' + … + D q').
    pub fn add_force(&self, v: &DVector<f64>, r: &mut DVector<f64>) {
        let u = self.relative(v);
        let k = self.bodies.first().map_or(0, |b| b.rigid.ncols());
        let mut rigid_sum = DVector::zeros(k);
        for (b, u) in self.bodies.iter().zip(&u) {
            let f = &b.mass * u * self.alpha;
            rigid_sum += b.rigid.tr_mul(&f);
            let mut rows = r.rows_mut(b.offset, f.len());
            rows += &f;
        }
        for b in &self.bodies {
            if let Some(sj) = &b.reference {
                let mut rows = r.rows_mut(b.offset, sj.ncols());
                rows -= sj.tr_mul(&rigid_sum);
            }
        }
    }

    /// The power the damping takes out of the beam, 2F = α Σ_j u_jᵀ M_j u_j (W, ≥ 0 with
    /// positive semi-definite mass matrices).
    pub fn dissipation(&self, v: &DVector<f64>) -> f64 {
        let u = self.relative(v);
        self.bodies
            .iter()
            .zip(&u)
            .map(|(b, u)| self.alpha * u.dot(&(&b.mass * u)))
            .sum()
    }

    /// Adds the body blocks of D = α Eᵀ M E into C_t (the coupling blocks between the bodies
    /// that S reads and the others are left out, as the tangents leave out other couplings).
    /// Block jj: α M_j for a body S does not read; for one it reads,
    /// α [(I − T_j S_j)ᵀ M_j (I − T_j S_j) + S_jᵀ (Σ_{i≠j} T_iᵀ M_i T_i) S_j].
    pub fn add_tangent(&self, ct: &mut BlockDiagonal) {
        let rigid_mass: Vec<DMatrix<f64>> = self
            .bodies
            .iter()
            .map(|b| b.rigid.tr_mul(&(&b.mass * &b.rigid)))
            .collect();
        for (j, b) in self.bodies.iter().enumerate() {
            let n = b.mass.nrows();
            let mut block = ct.blocks[b.body].dense_mut().view_mut((0, 0), (n, n));
            match &b.reference {
                None => block += &b.mass * self.alpha,
                Some(sj) => {
                    let e = DMatrix::identity(n, n) - &b.rigid * sj;
                    let mut d = e.tr_mul(&(&b.mass * &e));
                    let others = rigid_mass
                        .iter()
                        .enumerate()
                        .filter(|(i, _)| *i != j)
                        .fold(DMatrix::zeros(sj.nrows(), sj.nrows()), |acc, (_, m)| {
                            acc + m
                        });
                    d += sj.tr_mul(&(others * sj));
                    block += d * self.alpha;
                }
            }
        }
    }
}
