//! Geometric stiffening of a spatial beam: the planar beam's nonlinear axial strain
//! (`planar_beam/stiffening.rs`) extended to both bending planes.
//!
//! Per element of length ℓ, the axial strain is taken constant (the element mean of the slope
//! terms, which avoids membrane locking):
//!
//!   ε = u' + ½ ⟨v'² + w'²⟩,   ⟨g⟩ = Σ_gauss w_g g(ξ_g) (4-point Gauss, exact: v'² is quartic),
//!
//! with u' = (u₂ − u₁)/ℓ, v' = θz and w' = −θy at the nodes (`spatial_element`). The strain
//! energy of the axial strain is U = Σ_e ½ EA ℓ ε², of which the linear part ½ EA ℓ u'² is
//! already in K_ff; this module adds the rest,
//!
//!   U_g = Σ_e ½ EA ℓ (ε² − u'²),
//!   f_g = ∂U_g/∂q = Σ_e EA ℓ (ε ∂ε − u' ∂u'),
//!   K_g = ∂f_g/∂q = Σ_e EA ℓ (∂ε ∂εᵀ + ε H − ∂u' ∂u'ᵀ),   H = ⟨v'_q v'_qᵀ + w'_q w'_qᵀ⟩,
//!
//! the exact gradient and Hessian of U_g. The axial force N = EA ε couples with the transverse
//! slopes of both planes: tension (a spinning blade's centrifugal load) stiffens bending in y
//! and z alike. Torsion does not enter (no Wagner term), as in the planar beam.
//!
//! With Rayleigh β, β acts on the strain rate ε̇ = ∂ε · q̇ rather than on u̇' alone, as in the
//! planar beam (`planar_beam/stiffening.rs` says why: β EA u̇' held the axis from shortening as
//! the beam bends, and the spurious tension stiffened it): the force added to β K_ff q̇_f is
//!
//!   f_β = Σ_e β EA ℓ (ε̇ ∂ε − u̇' ∂u'),
//!   ∂f_β/∂q̇ = Σ_e β EA ℓ (∂ε ∂εᵀ − ∂u' ∂u'ᵀ),   ∂f_β/∂q = Σ_e β EA ℓ (∂ε (H q̇)ᵀ + ε̇ H).

use super::*;

/// The constant parts of an element's nonlinear strain (all elements of a frame are alike).
#[derive(Debug, Clone)]
pub(super) struct StrainRows {
    /// ℓ, the element length.
    l: f64,
    /// du/dx as a row over the element coordinates.
    du: Row,
    /// dv/dx and dw/dx as rows, at each point of `GAUSS_4`.
    slopes: [[Row; 2]; 4],
    /// H = Σ w (v'_q v'_qᵀ + w'_q w'_qᵀ): the Hessian of ½⟨v'² + w'²⟩.
    h: [Row; ELEMENT_DOFS],
    /// Kept index of each element's coordinates.
    index: Vec<[Option<usize>; ELEMENT_DOFS]>,
}

impl StrainRows {
    pub(super) fn new(length: f64, elements: usize, kept: &[usize]) -> StrainRows {
        let l = length / elements as f64;
        let mut du = [0.0; ELEMENT_DOFS];
        du[U] = -1.0 / l;
        du[NODE_DOFS + U] = 1.0 / l;
        let mut slopes = [[[0.0; ELEMENT_DOFS]; 2]; 4];
        let mut h = [[0.0; ELEMENT_DOFS]; ELEMENT_DOFS];
        for (g, &(xi, w)) in GAUSS_4.iter().enumerate() {
            // section rotation rows (θx, θy, θz) = (twist, −w', v')
            let r = spatial_element::section_rotation(xi, l);
            slopes[g] = [r[2], r[1].map(|x| -x)];
            for s in &slopes[g] {
                for p in 0..ELEMENT_DOFS {
                    for q in 0..ELEMENT_DOFS {
                        h[p][q] += w * s[p] * s[q];
                    }
                }
            }
        }
        let position = |full: usize| kept.iter().position(|&k| k == full);
        let index = (0..elements)
            .map(|j| std::array::from_fn(|p| position(NODE_DOFS * j + p)))
            .collect();
        StrainRows {
            l,
            du,
            slopes,
            h,
            index,
        }
    }
}

/// One element's strain at a state: u', ε and ∂ε/∂q_e; and with β damping, its rates u̇', ε̇
/// and H q̇_e.
#[derive(Debug, Clone, Copy)]
pub(super) struct ElementStrain {
    du: f64,
    eps: f64,
    de: Row,
    du_dot: f64,
    eps_dot: f64,
    h_qd: Row,
}

/// The stiffening force f_g at a state and each element's strain there (from which any column
/// of K_g follows in O(1)): part of [`BeamProducts`].
#[derive(Debug, Clone)]
pub struct Stiffening {
    force: DVector<f64>,
    elements: Vec<ElementStrain>,
}

impl Stiffening {
    pub(super) fn force(&self) -> &DVector<f64> {
        &self.force
    }

    pub(super) fn copy_from(&mut self, other: &Stiffening) {
        self.force.copy_from(&other.force);
        self.elements.copy_from_slice(&other.elements);
    }
}

impl SpatialBeam {
    /// Switches geometric stiffening (the nonlinear axial strain) on or off.
    pub fn set_geometric_stiffening(&mut self, on: bool) {
        self.geometric_stiffening = on;
    }

    /// Each element's strain at q_f, and its rates at q̇_f.
    fn element_strains(&self, f: &DVectorView<f64>, fd: &DVectorView<f64>) -> Vec<ElementStrain> {
        let rows = &self.strain;
        rows.index
            .iter()
            .map(|idx| {
                let qe: Row = std::array::from_fn(|p| idx[p].map_or(0.0, |k| f[k]));
                let qd: Row = std::array::from_fn(|p| idx[p].map_or(0.0, |k| fd[k]));
                let du: f64 = (0..ELEMENT_DOFS).map(|p| rows.du[p] * qe[p]).sum();
                let (mut eps, mut de) = (du, rows.du);
                for (pair, &(_, w)) in rows.slopes.iter().zip(&GAUSS_4) {
                    for s in pair {
                        let d: f64 = (0..ELEMENT_DOFS).map(|p| s[p] * qe[p]).sum();
                        eps += 0.5 * w * d * d;
                        for p in 0..ELEMENT_DOFS {
                            de[p] += w * d * s[p];
                        }
                    }
                }
                ElementStrain {
                    du,
                    eps,
                    de,
                    du_dot: (0..ELEMENT_DOFS).map(|p| rows.du[p] * qd[p]).sum(),
                    eps_dot: (0..ELEMENT_DOFS).map(|p| de[p] * qd[p]).sum(),
                    h_qd: std::array::from_fn(|p| {
                        (0..ELEMENT_DOFS).map(|r| rows.h[p][r] * qd[r]).sum()
                    }),
                }
            })
            .collect()
    }

    /// f_g (and f_β, with β damping) and the element strains at q_f, q̇_f, if stiffening is on.
    pub(super) fn stiffening(
        &self,
        f: &DVectorView<f64>,
        fd: &DVectorView<f64>,
    ) -> Option<Stiffening> {
        if !self.geometric_stiffening {
            return None;
        }
        let elements = self.element_strains(f, fd);
        let mut force = DVector::zeros(self.nflex());
        let (ea_l, du) = (self.ea * self.strain.l, &self.strain.du);
        let beta = self.rayleigh_beta;
        for (idx, e) in self.strain.index.iter().zip(&elements) {
            for p in 0..ELEMENT_DOFS {
                if let Some(k) = idx[p] {
                    force[k] += ea_l
                        * (e.eps * e.de[p] - e.du * du[p]
                            + beta * (e.eps_dot * e.de[p] - e.du_dot * du[p]));
                }
            }
        }
        Some(Stiffening { force, elements })
    }

    /// Adds h × column `k` of K_g (at the state of `st`) to its force: the tangent column of
    /// a move of q_f by h in coordinate k, exact (only the elements at k's node take part).
    pub(super) fn shift_stiffening(&self, st: &mut Stiffening, k: usize, h: f64) {
        let node = self.kept[k] / NODE_DOFS;
        let rows = &self.strain;
        let ea_l = self.ea * rows.l;
        for j in node.saturating_sub(1)..node.min(self.elements - 1) + 1 {
            let p = self.kept[k] - NODE_DOFS * j;
            if p >= ELEMENT_DOFS {
                continue;
            }
            let e = st.elements[j];
            let beta = self.rayleigh_beta;
            for (r, idx) in rows.index[j].iter().enumerate() {
                if let Some(kr) = idx {
                    let g = e.de[p] * e.de[r] + e.eps * rows.h[p][r] - rows.du[p] * rows.du[r]
                        + beta * (e.h_qd[p] * e.de[r] + e.eps_dot * rows.h[p][r]);
                    st.force[*kr] += h * ea_l * g;
                }
            }
        }
    }

    /// Adds h × column `k` of ∂f_β/∂q̇_f to the force: the tangent column of a move of q̇_f by
    /// h in coordinate k (nothing without β damping).
    pub(super) fn shift_stiffening_rate(&self, st: &mut Stiffening, k: usize, h: f64) {
        if self.rayleigh_beta == 0.0 {
            return;
        }
        let node = self.kept[k] / NODE_DOFS;
        let rows = &self.strain;
        let c = self.rayleigh_beta * self.ea * rows.l;
        for j in node.saturating_sub(1)..node.min(self.elements - 1) + 1 {
            let p = self.kept[k] - NODE_DOFS * j;
            if p >= ELEMENT_DOFS {
                continue;
            }
            let e = st.elements[j];
            for (r, idx) in rows.index[j].iter().enumerate() {
                if let Some(kr) = idx {
                    let g = e.de[p] * e.de[r] - rows.du[p] * rows.du[r];
                    st.force[*kr] += h * c * g;
                }
            }
        }
    }

    /// K_g = ∂f_g/∂q_f at q_f, at rest (nf × nf; zero when stiffening is off).
    pub fn stiffening_tangent<'a>(&self, f: impl Into<DVectorView<'a, f64>>) -> DMatrix<f64> {
        let f = f.into();
        let nf = self.nflex();
        let mut kg = DMatrix::zeros(nf, nf);
        let rest = DVector::zeros(nf);
        if let Some(mut st) = self.stiffening(&f, &rest.as_view()) {
            for k in 0..nf {
                st.force.fill(0.0);
                self.shift_stiffening(&mut st, k, 1.0);
                kg.set_column(k, &st.force);
            }
        }
        kg
    }

    /// U_g, the strain energy of the nonlinear strain beyond ½ q_fᵀ K_ff q_f (J).
    pub(super) fn stiffening_energy(&self, f: &DVectorView<f64>) -> f64 {
        if !self.geometric_stiffening {
            return 0.0;
        }
        let ea_l = self.ea * self.strain.l;
        let rest = DVector::zeros(self.nflex());
        self.element_strains(f, &rest.as_view())
            .iter()
            .map(|e| 0.5 * ea_l * (e.eps * e.eps - e.du * e.du))
            .sum()
    }
}
