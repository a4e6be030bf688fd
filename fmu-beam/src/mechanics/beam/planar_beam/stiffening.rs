//! Geometric stiffening of a planar beam: the axial strain's second-order part, element by
//! element at the Gauss points, as a force, its tangent and its energy.

use super::*;

impl PlanarBeam {
    /// Switches geometric stiffening (the nonlinear axial strain) on or off; `options` keeps
    /// the value the beam was built with.
    pub fn set_geometric_stiffening(&mut self, on: bool) {
        self.geometric_stiffening = on;
    }

    /// Visits each element with its axial strain ε = u' + ½⟨v'²⟩, the element mean of v'²
    /// making ε (and the axial force) constant per element, which avoids membrane locking:
    /// (kept index of each element coordinate, ℓ, ε, ∂ε/∂q_e, ⟨v'_q v'_qᵀ⟩).
    #[allow(clippy::type_complexity)]
    pub(super) fn for_element_strains(
        &self,
        fq: &DVector<f64>,
        mut visit: impl FnMut(
            &[Option<usize>; ELEMENT_DOFS],
            f64,
            f64,
            &[f64; ELEMENT_DOFS],
            &[[f64; ELEMENT_DOFS]; ELEMENT_DOFS],
        ),
    ) {
        let l = self.length / self.elements as f64;
        let da = [-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0];
        let (slopes, hv) = (&self.strain.slopes, &self.strain.hv);
        for j in 0..self.elements {
            let idx: [Option<usize>; ELEMENT_DOFS] =
                std::array::from_fn(|p| self.flex_index(3 * j + p));
            let qe: [f64; ELEMENT_DOFS] = std::array::from_fn(|p| idx[p].map_or(0.0, |k| fq[k]));
            let mut eps: f64 = (0..ELEMENT_DOFS).map(|p| da[p] * qe[p]).sum();
            let mut de = da;
            for (ds, &(_, w)) in slopes.iter().zip(&GAUSS_4) {
                let dv: f64 = (0..ELEMENT_DOFS).map(|p| ds[p] * qe[p]).sum();
                eps += 0.5 * w * dv * dv;
                for p in 0..ELEMENT_DOFS {
                    de[p] += w * dv * ds[p];
                }
            }
            visit(&idx, l, eps, &de, hv);
        }
    }

    /// Internal force of the nonlinear strain beyond the linear K_ff q_f:
    /// EA ℓ (ε ∂ε/∂q - u' ∂u'/∂q) per element, added into `out` (projected on the modes under
    /// truncation).
    pub(super) fn stiffening_force(&self, z: &DVectorView<f64>, out: &mut [f64]) {
        let ea = self.ea;
        let fq = self.nodal(z);
        let mut nodal = DVector::zeros(self.kept.len());
        self.for_element_strains(&fq, |idx, l, eps, de, _| {
            let du = (idx[3].map_or(0.0, |k| fq[k]) - idx[0].map_or(0.0, |k| fq[k])) / l;
            let da = [-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0];
            for p in 0..ELEMENT_DOFS {
                if let Some(k) = idx[p] {
                    nodal[k] += ea * l * (eps * de[p] - du * da[p]);
                }
            }
        });
        let projected = match &self.basis {
            Some(phi) => phi.tr_mul(&nodal),
            None => nodal,
        };
        for (o, x) in out.iter_mut().zip(projected.iter()) {
            *o += x;
        }
    }

    /// Tangent of [`Self::stiffening_force`]: EA ℓ (∂ε ∂εᵀ + ε ⟨v'_q v'_qᵀ⟩ - ∂u' ∂u'ᵀ).
    pub(super) fn stiffening_tangent(&self, z: &DVectorView<f64>, kt: &mut DMatrixViewMut<f64>) {
        let ea = self.ea;
        let fq = self.nodal(z);
        let nk = self.kept.len();
        let mut nodal = DMatrix::zeros(nk, nk);
        self.for_element_strains(&fq, |idx, l, eps, de, hv| {
            let da = [-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0];
            for p in 0..ELEMENT_DOFS {
                let Some(kp) = idx[p] else { continue };
                for r in 0..ELEMENT_DOFS {
                    let Some(kr) = idx[r] else { continue };
                    nodal[(kp, kr)] += ea * l * (de[p] * de[r] + eps * hv[p][r] - da[p] * da[r]);
                }
            }
        });
        let nf = self.nflex();
        let mut block = kt.view_mut((FLEX, FLEX), (nf, nf));
        match &self.basis {
            Some(phi) => block += phi.tr_mul(&nodal) * phi,
            None => block += nodal,
        }
    }

    /// Strain energy of the nonlinear strain beyond ½ q_fᵀ K_ff q_f.
    pub(super) fn stiffening_energy(&self, z: &DVectorView<f64>) -> f64 {
        let mut e = 0.0;
        let ea = self.ea;
        let fq = self.nodal(z);
        self.for_element_strains(&fq, |idx, l, eps, _, _| {
            let du = (idx[3].map_or(0.0, |k| fq[k]) - idx[0].map_or(0.0, |k| fq[k])) / l;
            e += 0.5 * ea * l * (eps * eps - du * du);
        });
        e
    }
}
