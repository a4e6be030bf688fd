//! A planar beam's construction: the full-beam integrals of the shape functions (4-point
//! Gauss, exact for every integrand of the planar paper's eq. (11)), the frame's boundary
//! conditions and the options applied (no axial coordinates, band structure, modal truncation).

use super::*;
use crate::mechanics::beam::band::Banded;

impl PlanarBeam {
    /// The full model: the terms of [`BeamOptions::default`] (all but geometric stiffening),
    /// no truncation.
    pub fn new(
        name: &str,
        length: f64,
        elements: usize,
        frame: FloatingFrame,
        rho: f64,
        e: f64,
        section: Section,
        rayleigh_alpha: f64,
        rayleigh_beta: f64,
    ) -> PlanarBeam {
        PlanarBeam::with_options(
            name,
            length,
            elements,
            frame,
            rho,
            e,
            section,
            rayleigh_alpha,
            rayleigh_beta,
            BeamOptions::default(),
        )
    }

    /// The beam computing the terms of `options` (on `options.modes` modes when set), of
    /// density `rho` (kg/m^3) and Young's modulus `e` (Pa).
    #[allow(clippy::too_many_arguments)]
    pub fn with_options(
        name: &str,
        length: f64,
        elements: usize,
        frame: FloatingFrame,
        rho: f64,
        e: f64,
        section: Section,
        rayleigh_alpha: f64,
        rayleigh_beta: f64,
        options: BeamOptions,
    ) -> PlanarBeam {
        let n_full = 3 * (elements + 1);
        let kept: Vec<usize> = (0..n_full)
            .filter(|&i| match frame {
                FloatingFrame::Tangent => i >= 3,
                FloatingFrame::Pinned => i >= 2 && i != 3 * elements + 1,
            })
            .filter(|&i| options.axial || i % 3 != 0)
            .collect();
        let mu = rho * section.area;
        let ea = e * section.area;
        let ej = e * section.second_moment;
        let index = kept_index(&kept);
        let full = kept_integrals(length, elements, mu, ea, ej, &index, kept.len());
        let pick_cols = |m: &DMatrix<f64>| m.select_columns(kept.iter());
        let pick_v = |v: &DVector<f64>| v.select_rows(kept.iter());
        let dff = full.kff.scaled(rayleigh_beta);
        let mass = mu * length;
        let node_map = |node: usize, x: f64| {
            let mut sp_full = DMatrix::zeros(2, n_full);
            sp_full[(0, 3 * node)] = 1.0;
            sp_full[(1, 3 * node + 1)] = 1.0;
            let mut sphi_full = DVector::zeros(n_full);
            sphi_full[3 * node + 2] = 1.0;
            PointMap {
                s0: Vector2::new(x, 0.0),
                sp: pick_cols(&sp_full),
                sphi: pick_v(&sphi_full),
            }
        };
        let beam = PlanarBeam {
            name: name.to_string(),
            length,
            elements,
            frame,
            section,
            mu,
            ea,
            ej,
            rayleigh_alpha,
            rayleigh_beta,
            mass,
            st0: Vector2::new(mass * length / 2.0, 0.0),
            i0: mass * length * length / 3.0,
            sbar: full.sbar,
            a: full.a,
            b: full.b,
            w: full.w,
            mff: full.mff,
            kff: full.kff,
            dff,
            flange_a: node_map(0, 0.0),
            flange_b: node_map(elements, length),
            kept_index: index,
            kept,
            geometric_stiffening: options.geometric_stiffening,
            options,
            basis: None,
            counts: TermCounts::default(),
            turn: Default::default(),
            band: Vec::new(),
            strain: StrainRows::new(length / elements as f64),
        };
        match options.modes {
            Some(k) => {
                let k = k.min(beam.kept.len());
                beam.truncated(k).banded()
            }
            None => beam.banded(),
        }
    }

    /// The beam with its [`PlanarBeam::band`] found from its matrices.
    pub(super) fn banded(mut self) -> PlanarBeam {
        let nf = self.mff.nrows();
        // without truncation a coordinate's entries lie within the elements of its node
        let window = |k: usize| match self.basis {
            Some(_) => 0..nf,
            None => {
                let node = self.kept[k] / 3;
                let first = (3 * node.saturating_sub(1)..3 * node + 6)
                    .find_map(|f| self.flex_index(f))
                    .unwrap_or(k);
                let last = (3 * node.saturating_sub(1)..3 * node + 6)
                    .rev()
                    .find_map(|f| self.flex_index(f))
                    .unwrap_or(k);
                first..last + 1
            }
        };
        self.band = (0..nf)
            .map(|k| {
                let nonzero = |l: usize| {
                    self.mff[(k, l)] != 0.0
                        || self.mff[(l, k)] != 0.0
                        || self.w[(k, l)] != 0.0
                        || self.w[(l, k)] != 0.0
                        || self.kff[(k, l)] != 0.0
                        || self.dff[(k, l)] != 0.0
                };
                let lo = window(k).find(|&l| nonzero(l)).unwrap_or(k);
                let hi = window(k).rev().find(|&l| nonzero(l)).map_or(k, |l| l + 1);
                lo..hi.max(lo)
            })
            .collect();
        self
    }

    /// The beam on the lowest `k` modes of (K_ff, M_ff): q_nodal = Φ q_f with Φᵀ M_ff Φ = I, so
    /// every constant of eq. (11) becomes its projection (S̄ Φ, Φᵀ a, Φᵀ W Φ, ...).
    pub(super) fn truncated(mut self, k: usize) -> PlanarBeam {
        let phi = lowest_modes(&self.kff.to_dense(), &self.mff.to_dense(), k);
        let pt = phi.transpose();
        self.sbar = &self.sbar * &phi;
        self.a = &pt * &self.a;
        self.b = &pt * &self.b;
        self.w = Banded::from_dense(&(&pt * self.w.to_dense() * &phi));
        self.mff = Banded::from_dense(&(&pt * self.mff.to_dense() * &phi));
        self.kff = Banded::from_dense(&(&pt * self.kff.to_dense() * &phi));
        self.dff = self.kff.scaled(self.rayleigh_beta);
        for map in [&mut self.flange_a, &mut self.flange_b] {
            reduce_map(map, &phi);
        }
        self.basis = Some(phi);
        self
    }
}

/// The beam's integrals over the coordinates the boundary conditions keep.
pub(super) struct KeptIntegrals {
    sbar: DMatrix<f64>,
    a: DVector<f64>,
    b: DVector<f64>,
    mff: Banded,
    w: Banded,
    kff: Banded,
}

/// Integrals of eq. (11) over all N elements (eq. (8)–(12)), each element's entries added
/// only where the boundary conditions keep both coordinates (`index`: the kept index of each
/// full nodal coordinate, `nk` kept): the full matrices never exist, so the set-up stays
/// linear in the elements apart from zeroing the dense n_k × n_k storage.
pub(super) fn kept_integrals(
    length: f64,
    elements: usize,
    mu: f64,
    ea: f64,
    ej: f64,
    index: &[Option<usize>],
    nk: usize,
) -> KeptIntegrals {
    let l = length / elements as f64;
    let of_element =
        |j: usize| (0..ELEMENT_DOFS).filter_map(move |p| index.get(3 * j + p).copied().flatten());
    let width = (0..elements)
        .filter_map(|j| Some(of_element(j).max()? - of_element(j).min()?))
        .max()
        .unwrap_or(0);
    let mut out = KeptIntegrals {
        sbar: DMatrix::zeros(2, nk),
        a: DVector::zeros(nk),
        b: DVector::zeros(nk),
        mff: Banded::zeros(nk, width),
        w: Banded::zeros(nk, width),
        kff: Banded::zeros(nk, width),
    };
    let ke = planar_element::stiffness(ea, ej, l);
    for j in 0..elements {
        // the connectivity matrix B_j of eq. (9), then the boundary conditions
        let idx: [Option<usize>; ELEMENT_DOFS] =
            std::array::from_fn(|p| index.get(3 * j + p).copied().flatten());
        for &(xi, wgt) in &GAUSS_4 {
            let (s1, s2) = planar_element::shape(xi, l);
            let dm = mu * l * wgt;
            let x0 = (j as f64 + xi) * l;
            for p in 0..ELEMENT_DOFS {
                let Some(kp) = idx[p] else { continue };
                out.sbar[(0, kp)] += dm * s1[p];
                out.sbar[(1, kp)] += dm * s2[p];
                out.a[kp] += dm * s1[p] * x0;
                out.b[kp] += dm * s2[p] * x0;
                for q in 0..ELEMENT_DOFS {
                    let Some(kq) = idx[q] else { continue };
                    out.mff[(kp, kq)] += dm * (s1[p] * s1[q] + s2[p] * s2[q]);
                    out.w[(kp, kq)] += dm * (s1[p] * s2[q] - s2[p] * s1[q]);
                }
            }
        }
        for p in 0..ELEMENT_DOFS {
            let Some(kp) = idx[p] else { continue };
            for q in 0..ELEMENT_DOFS {
                let Some(kq) = idx[q] else { continue };
                out.kff[(kp, kq)] += ke[p][q];
            }
        }
    }
    out
}

/// The lowest `k` modes of K φ = ω² M φ (columns, ascending ω, Φᵀ M Φ = I), through the
/// Cholesky factor of the (positive definite) mass matrix.
pub fn lowest_modes(kff: &DMatrix<f64>, mff: &DMatrix<f64>, k: usize) -> DMatrix<f64> {
    let l = mff
        .clone()
        .cholesky()
        .expect("the consistent mass matrix is positive definite")
        .l();
    let linv = l
        .clone()
        .try_inverse()
        .expect("a Cholesky factor is invertible");
    let a = &linv * kff * linv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let eig = a.symmetric_eigen();
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let cols: Vec<_> = order[..k]
        .iter()
        .map(|&i| linv.tr_mul(&eig.eigenvectors.column(i).into_owned()))
        .collect();
    DMatrix::from_columns(&cols)
}

/// Reduced index of each full nodal coordinate, where kept.
fn kept_index(kept: &[usize]) -> Vec<Option<usize>> {
    let mut index = vec![None; kept.iter().max().map_or(0, |&k| k + 1)];
    for (k, &f) in kept.iter().enumerate() {
        index[f] = Some(k);
    }
    index
}
