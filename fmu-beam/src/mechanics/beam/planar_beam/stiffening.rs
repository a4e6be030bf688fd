//! Geometric stiffening of a planar beam: the axial strain's second-order part, element by
//! element at the Gauss points, as a force, its tangent and its energy; and the stiffness-
//! proportional (Rayleigh β) damping of that strain's rate.
//!
//! β damping with stiffening: β K_ff ḟ damps the linear axial rate u̇', but a bending beam with
//! the nonlinear strain ε = u' + ½⟨v'²⟩ must shorten its axis (u' ≈ -½⟨v'²⟩) as it bends, and
//! the axial stiffness EA makes β EA u̇' a large force against that: the axial coordinates lag,
//! ε stays off zero, and the spurious tension stiffens the beam (measured on a 2 m cantilever
//! with β = 2e-3 s: the tip deflection 12 % off at 0.5 s, against 2e-5 without β). So with
//! stiffening on, β acts on the strain rate ε̇ = ∂ε/∂q · q̇ instead of u̇': the dissipation
//! function per element is ½ β EA ℓ ε̇² in place of ½ β EA ℓ u̇'² (the part of ½ β ḟᵀ K_ff ḟ the
//! element's axial stiffness gives), so the force added to β K_ff ḟ is
//! β EA ℓ (ε̇ ∂ε − u̇' ∂u'), and the damping's power stays −2F ≤ 0.

use std::borrow::Cow;

use super::*;

/// Kept coordinates up to which [`PlanarBeam::add_nodal`] sums on the stack (a frame of 21
/// elements; beyond, one allocation per call).
const STACK_NODAL: usize = 64;

impl PlanarBeam {
    /// The nodal deformation of z (kept coordinates): z's own where they are nodal, computed
    /// under modal truncation.
    fn nodal_of<'z>(&self, z: &'z DVectorView<f64>) -> Cow<'z, [f64]> {
        let f = z.rows(FLEX, self.nflex());
        match &self.basis {
            Some(phi) => Cow::Owned((phi * f).as_slice().to_vec()),
            None => Cow::Borrowed(
                z.as_slice()
                    .get(FLEX..FLEX + self.nflex())
                    .expect("a body's coordinates hold its deformation"),
            ),
        }
    }

    /// Sums the elements' nodal contributions (`fill`) into a zeroed vector and then adds it,
    /// projected on the modes under truncation, into `out`: the sums of a vector allocated
    /// per call, in the same order, without the allocation for up to [`STACK_NODAL`] kept
    /// coordinates.
    fn add_nodal(&self, out: &mut [f64], fill: impl FnOnce(&mut [f64])) {
        let nk = self.kept.len();
        let mut stack = [0.0; STACK_NODAL];
        let mut heap = Vec::new();
        let nodal = if nk <= STACK_NODAL {
            &mut stack[..nk]
        } else {
            heap.resize(nk, 0.0);
            &mut heap[..]
        };
        fill(nodal);
        match &self.basis {
            Some(phi) => {
                let projected = phi.tr_mul(&DVectorView::from_slice(nodal, nk));
                for (o, x) in out.iter_mut().zip(projected.iter()) {
                    *o += x;
                }
            }
            None => {
                for (o, x) in out.iter_mut().zip(nodal.iter()) {
                    *o += x;
                }
            }
        }
    }

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
        fq: &[f64],
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
        let fq = self.nodal_of(z);
        self.add_nodal(out, |nodal| {
            self.for_element_strains(&fq, |idx, l, eps, de, _| {
                let du = (idx[3].map_or(0.0, |k| fq[k]) - idx[0].map_or(0.0, |k| fq[k])) / l;
                let da = [-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0];
                for p in 0..ELEMENT_DOFS {
                    if let Some(k) = idx[p] {
                        nodal[k] += ea * l * (eps * de[p] - du * da[p]);
                    }
                }
            })
        });
    }

    /// Tangent of [`Self::stiffening_force`]: EA ℓ (∂ε ∂εᵀ + ε ⟨v'_q v'_qᵀ⟩ - ∂u' ∂u'ᵀ),
    /// element by element into `kt` (through the modes under truncation).
    pub(super) fn stiffening_tangent<B: BlockMut>(&self, z: &DVectorView<f64>, kt: &mut B) {
        let ea = self.ea;
        let fq = self.nodal_of(z);
        let mut nodal = self.basis.as_ref().map(|_| {
            let nk = self.kept.len();
            DMatrix::zeros(nk, nk)
        });
        self.for_element_strains(&fq, |idx, l, eps, de, hv| {
            let da = [-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0];
            for p in 0..ELEMENT_DOFS {
                let Some(kp) = idx[p] else { continue };
                for r in 0..ELEMENT_DOFS {
                    let Some(kr) = idx[r] else { continue };
                    let x = ea * l * (de[p] * de[r] + eps * hv[p][r] - da[p] * da[r]);
                    match &mut nodal {
                        Some(m) => m[(kp, kr)] += x,
                        None => kt[(FLEX + kp, FLEX + kr)] += x,
                    }
                }
            }
        });
        if let (Some(phi), Some(nodal)) = (&self.basis, nodal) {
            add_block(kt, &(phi.tr_mul(&nodal) * phi));
        }
    }

    /// Strain energy of the nonlinear strain beyond ½ q_fᵀ K_ff q_f.
    pub(super) fn stiffening_energy(&self, z: &DVectorView<f64>) -> f64 {
        let mut e = 0.0;
        let ea = self.ea;
        let fq = self.nodal_of(z);
        self.for_element_strains(&fq, |idx, l, eps, _, _| {
            let du = (idx[3].map_or(0.0, |k| fq[k]) - idx[0].map_or(0.0, |k| fq[k])) / l;
            e += 0.5 * ea * l * (eps * eps - du * du);
        });
        e
    }

    /// The elements' (index, ℓ, ε̇, u̇', ∂ε, H q̇, H) at coordinates `z` and rates `zd`, H the
    /// element's ⟨v'_q v'_qᵀ⟩ (the visitor of [`Self::stiffening_damping`] and its tangent).
    #[allow(clippy::type_complexity)]
    fn for_element_strain_rates(
        &self,
        z: &DVectorView<f64>,
        zd: &DVectorView<f64>,
        mut visit: impl FnMut(
            &[Option<usize>; ELEMENT_DOFS],
            f64,
            f64,
            f64,
            &[f64; ELEMENT_DOFS],
            &[f64; ELEMENT_DOFS],
            &[[f64; ELEMENT_DOFS]; ELEMENT_DOFS],
        ),
    ) {
        let (fq, fqd) = (self.nodal_of(z), self.nodal_of(zd));
        self.for_element_strains(&fq, |idx, l, _, de, hv| {
            let qd: [f64; ELEMENT_DOFS] = std::array::from_fn(|p| idx[p].map_or(0.0, |k| fqd[k]));
            let eps_dot: f64 = (0..ELEMENT_DOFS).map(|p| de[p] * qd[p]).sum();
            let du_dot = (qd[3] - qd[0]) / l;
            let h_qd: [f64; ELEMENT_DOFS] =
                std::array::from_fn(|p| (0..ELEMENT_DOFS).map(|r| hv[p][r] * qd[r]).sum());
            visit(idx, l, eps_dot, du_dot, de, &h_qd, hv);
        });
    }

    /// β damping of the nonlinear strain rate beyond β K_ff ḟ (see the module doc):
    /// β EA ℓ (ε̇ ∂ε − u̇' ∂u') per element, added into `out`.
    pub(super) fn stiffening_damping(
        &self,
        z: &DVectorView<f64>,
        zd: &DVectorView<f64>,
        out: &mut [f64],
    ) {
        let c = self.rayleigh_beta * self.ea;
        self.add_nodal(out, |nodal| {
            self.for_element_strain_rates(z, zd, |idx, l, eps_dot, du_dot, de, _, _| {
                let da = [-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0];
                for p in 0..ELEMENT_DOFS {
                    if let Some(k) = idx[p] {
                        nodal[k] += c * l * (eps_dot * de[p] - du_dot * da[p]);
                    }
                }
            })
        });
    }

    /// Tangents of [`Self::stiffening_damping`]: ∂/∂ḟ = β EA ℓ (∂ε ∂εᵀ − ∂u' ∂u'ᵀ) into `ct`,
    /// ∂/∂f = β EA ℓ (∂ε (H ḟ)ᵀ + ε̇ H) into `kt`, element by element (through the modes
    /// under truncation).
    pub(super) fn stiffening_damping_tangents<B: BlockMut>(
        &self,
        z: &DVectorView<f64>,
        zd: &DVectorView<f64>,
        kt: &mut B,
        ct: &mut B,
    ) {
        let c = self.rayleigh_beta * self.ea;
        let mut nodal = self.basis.as_ref().map(|_| {
            let nk = self.kept.len();
            (DMatrix::zeros(nk, nk), DMatrix::zeros(nk, nk))
        });
        self.for_element_strain_rates(z, zd, |idx, l, eps_dot, _, de, h_qd, hv| {
            let da = [-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0];
            for p in 0..ELEMENT_DOFS {
                let Some(kp) = idx[p] else { continue };
                for r in 0..ELEMENT_DOFS {
                    let Some(kr) = idx[r] else { continue };
                    let xc = c * l * (de[p] * de[r] - da[p] * da[r]);
                    let xk = c * l * (de[p] * h_qd[r] + eps_dot * hv[p][r]);
                    match &mut nodal {
                        Some((dk, dc)) => {
                            dc[(kp, kr)] += xc;
                            dk[(kp, kr)] += xk;
                        }
                        None => {
                            ct[(FLEX + kp, FLEX + kr)] += xc;
                            kt[(FLEX + kp, FLEX + kr)] += xk;
                        }
                    }
                }
            }
        });
        if let (Some(phi), Some((dk, dc))) = (&self.basis, nodal) {
            add_block(kt, &(phi.tr_mul(&dk) * phi));
            add_block(ct, &(phi.tr_mul(&dc) * phi));
        }
    }
}

/// Adds a dense deformation block (nf × nf) into a body block from [`FLEX`] on.
fn add_block<B: BlockMut>(to: &mut B, block: &DMatrix<f64>) {
    for l in 0..block.ncols() {
        for k in 0..block.nrows() {
            to[(FLEX + k, FLEX + l)] += block[(k, l)];
        }
    }
}
