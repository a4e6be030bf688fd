//! A spatial flexible beam in one floating frame (3D paper §2–3, derived afresh from the
//! standard element of [`super::spatial_element`]; the paper's printed integrals are garbled).
//!
//! Position of an axis point: r = R + A (ū0 + S q_f), ū0 = x e_x, R the world position of the
//! frame (at flange a), A its rotation matrix (body → world). Velocities are
//! v = [Ṙ (world); ω (body frame, Ȧ = A ω̃); q̇_f], so ṙ = L v with L = [I, −A ũ, A S]. The
//! section also turns about the axis with ω_x + θ̇x (rotary inertia ρI_p of torsion only: the
//! Euler–Bernoulli element has no rotary inertia of bending, like the planar one).
//!
//! Generalized inertia force (Kane / d'Alembert, exact for this kinematics):
//! ∫ρ Lᵀ r̈ dx = M(A, q_f) v̇ + h(A, q_f, v), with
//! - M_RR = m I, M_Rω = −A c̃, M_Rf = A S̄, c = ∫ρ ū = c0 + S̄ q_f (the static moment S̄_t),
//! - M_ωω = I_θθ = ∫ρ (ūᵀū I − ū ūᵀ) + ρI_p L e_x e_xᵀ,
//! - M_ωf = I_θf = ∫ρ ũ S + e_x ∫ρI_p θxᵀ, M_ff = m_ff = ∫ρ SᵀS + ∫ρI_p θxᵀθx,
//! - h_R = A [ω×(ω×c) + 2 ω×(S̄ q̇_f)],
//!   h_ω = ω×(I_θθ ω) + 2 ∫ρ ū×(ω×S q̇_f) + ω×e_x ∫ρI_p θ̇x,
//!   h_f = ∫ρ Sᵀ [ω×(ω×ū) + 2 ω×S q̇_f].
//!
//! Every shape integral is computed once with 4-point Gauss per element (the integrands are
//! polynomials of degree ≤ 6): S̄, D = ∫ρ x S, M^{ij} = ∫ρ S_iᵀS_j (i ≤ j), the torsion
//! integrals. Each evaluation only combines them with q_f.
//!
//! [`InertiaModel::Frozen`] is the 3D paper's fast variant (§6, conclusions): M at q_f = 0 and
//! the quadratic-velocity vector of the undeformed beam (centrifugal and gyroscopic terms of
//! the rigid motion; no update with q_f, no Coriolis coupling with q̇_f). Its constants come
//! from the nodal mass matrix through the rigid-body and stretch modes
//! ([`UndeformedInertia::from_nodal_mass`]), so a beam whose 12 × 12 matrices come from a file
//! ([`crate::scene::matrix_file`]) gets exactly the same treatment.
//!
//! Geometric stiffening (off unless switched on): the nonlinear axial strain of
//! `spatial_beam/stiffening.rs`, its force f_g one more product of the state.
//!
//! Over 600 lines: the spatial beam's inertia (full and frozen), its products, forces and energies
//! share the shape integrals' private layout (its construction is `spatial_beam/build.rs`).

use super::planar_element::GAUSS_4;
use super::spatial_element::{self, Row, ELEMENT_DOFS, NODE_DOFS, TX, TY, TZ, U, V, W};
use super::spatial_section::SpatialSection;
use super::FloatingFrame;
use nalgebra::{DMatrix, DMatrixViewMut, DVector, DVectorView, Matrix3, Rotation3, Vector3};

mod build;
mod stiffening;

pub use stiffening::Stiffening;

/// Index of ω in the velocity vector; q̇_f starts at [`FLEX`].
pub const OMEGA: usize = 3;
pub const FLEX: usize = 6;

/// ṽ, the cross-product matrix: ṽ w = v × w.
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// m x for a 3 × n matrix, as a fixed-size vector.
fn mul3(m: &DMatrix<f64>, x: &DVectorView<f64>) -> Vector3<f64> {
    let mut y = Vector3::zeros();
    for k in 0..x.len() {
        for i in 0..3 {
            y[i] += m[(i, k)] * x[k];
        }
    }
    y
}

/// How the inertia terms are evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InertiaModel {
    /// M(q_f) and h(q_f, v) updated at every evaluation.
    #[default]
    Full,
    /// 3D paper §6: M frozen at q_f = 0 (only A rotates the R rows), h of the undeformed beam
    /// in rigid motion (no q_f update, no Coriolis coupling with q̇_f).
    Frozen,
}

/// Material, geometry and options of a spatial beam (what a scene entry will resolve to).
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialBeamProps {
    /// Length of one floating frame (m).
    pub length: f64,
    /// Elements in one floating frame.
    pub elements: usize,
    /// Where each floating frame sits (tangent at flange a, or through both ends): which
    /// nodal coordinates it removes (`kept_coordinates`).
    pub frame: FloatingFrame,
    /// Density ρ (kg/m^3), Young's modulus E and shear modulus G (Pa).
    pub rho: f64,
    /// Young's modulus E (Pa): axial and bending stiffness E A, E I_y, E I_z.
    pub e: f64,
    /// Shear modulus G (Pa): torsional stiffness G J_t.
    pub g: f64,
    /// Section constants: area, second moments, torsion constant, polar moment.
    pub section: SpatialSection,
    /// Mass-proportional Rayleigh coefficient α (1/s), applied by the system to the whole beam
    /// (`multibody/beam_damping.rs`).
    pub rayleigh_alpha: f64,
    /// Stiffness-proportional Rayleigh coefficient β (s) of D_ff.
    pub rayleigh_beta: f64,
    /// How the inertia terms are evaluated (full or frozen at q_f = 0).
    pub inertia: InertiaModel,
}

/// A material point of the beam through q_f: ū = s0 + S_p q_f, small section rotation
/// φ = S_φ q_f (body frame).
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialPointMap {
    /// Undeformed position in the beam frame (m).
    pub s0: Vector3<f64>,
    /// Displacement per q_f (3 × nf).
    pub sp: DMatrix<f64>,
    /// Section rotation (θx, θy, θz) per q_f (3 × nf).
    pub sphi: DMatrix<f64>,
}

/// Shape integrals over the kept coordinates (full model only).
#[derive(Debug, Clone)]
pub struct ShapeIntegrals {
    /// S̄ = ∫ρ S dx (3 × nf).
    pub sbar: DMatrix<f64>,
    /// D = ∫ρ x S dx (3 × nf): ∫ρ ū0 (S q)ᵀ = e_x (D q)ᵀ.
    pub d: DMatrix<f64>,
    /// M^{ij} = ∫ρ S_iᵀ S_j dx for (i, j) in [`PAIRS`]; M^{ji} = M^{ij}ᵀ.
    pub mij: [DMatrix<f64>; 6],
    /// ∫ρ I_p θx dx as a row over q_f (torsion rotary inertia).
    pub twist: DVector<f64>,
    /// ∫ρ x² dx and ρ I_p L.
    pub j0: f64,
    pub rotary: f64,
}

/// The (i, j) pairs of [`ShapeIntegrals::mij`].
pub const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];

fn pair_index(i: usize, j: usize) -> (usize, bool) {
    let (a, b, t) = if i <= j { (i, j, false) } else { (j, i, true) };
    (PAIRS.iter().position(|&p| p == (a, b)).unwrap(), t)
}

/// The q_f-dependent inertia of the model in force, computed once per q_f and shared by the
/// mass matrix, the quadratic-velocity vector and the residual (and by the tangent columns
/// that leave q_f unchanged).
#[derive(Debug)]
pub struct FlexInertia {
    /// Static moment c, I_θθ and I_θf (3 × nf).
    pub c: Vector3<f64>,
    pub ithth: Matrix3<f64>,
    pub ithf: DMatrix<f64>,
    /// Full model: M^k q_f for k in [`PAIRS`], and M^kᵀ q_f for the three off the diagonal
    /// (k = 3, 4, 5); `None` in the frozen model.
    products: Option<Products>,
}

/// M^k q_f for k in [`PAIRS`] and M^kᵀ q_f for k = 3, 4, 5.
type Products = ([DVector<f64>; 6], [DVector<f64>; 3]);

impl FlexInertia {
    /// M^{ij} q_f (`transposed`: M^{ij}ᵀ q_f = M^{ji} q_f) of the full model.
    fn product(&self, k: usize, transposed: bool) -> &DVector<f64> {
        let (mf, mtf) = self.products.as_ref().expect("full model");
        if transposed && k >= 3 {
            &mtf[k - 3]
        } else {
            &mf[k]
        }
    }
}

/// Every matrix–vector product of the residual at one state, computed once: the q_f-dependent
/// inertia, K_ff q_f, D_ff q̇_f, m_ff q̈_f and (full model) (M^k − M^kᵀ) q̇_f for k = 3, 4, 5.
/// A tangent column that moves one coordinate updates them by one matrix column
/// ([`SpatialBeam::shift_flex`], [`SpatialBeam::shift_flex_rate`]): O(nf) instead of O(nf²).
#[derive(Debug)]
pub struct BeamProducts {
    pub inertia: FlexInertia,
    kf: DVector<f64>,
    dfd: DVector<f64>,
    mfdd: DVector<f64>,
    skew_fd: Vec<DVector<f64>>,
    stiffening: Option<Stiffening>,
}

/// Copies in place on `clone_from` (a tangent column starts from the state's products without
/// allocating).
impl Clone for FlexInertia {
    fn clone(&self) -> FlexInertia {
        FlexInertia {
            c: self.c,
            ithth: self.ithth,
            ithf: self.ithf.clone(),
            products: self.products.clone(),
        }
    }

    fn clone_from(&mut self, source: &FlexInertia) {
        self.c = source.c;
        self.ithth = source.ithth;
        self.ithf.copy_from(&source.ithf);
        match (self.products.as_mut(), source.products.as_ref()) {
            (Some((mf, mtf)), Some((smf, smtf))) => {
                mf.iter_mut().zip(smf).for_each(|(x, y)| x.copy_from(y));
                mtf.iter_mut().zip(smtf).for_each(|(x, y)| x.copy_from(y));
            }
            _ => self.products = source.products.clone(),
        }
    }
}

impl Clone for BeamProducts {
    fn clone(&self) -> BeamProducts {
        BeamProducts {
            inertia: self.inertia.clone(),
            kf: self.kf.clone(),
            dfd: self.dfd.clone(),
            mfdd: self.mfdd.clone(),
            skew_fd: self.skew_fd.clone(),
            stiffening: self.stiffening.clone(),
        }
    }

    fn clone_from(&mut self, source: &BeamProducts) {
        self.inertia.clone_from(&source.inertia);
        self.kf.copy_from(&source.kf);
        self.dfd.copy_from(&source.dfd);
        self.mfdd.copy_from(&source.mfdd);
        self.skew_fd
            .iter_mut()
            .zip(&source.skew_fd)
            .for_each(|(x, y)| x.copy_from(y));
        match (self.stiffening.as_mut(), source.stiffening.as_ref()) {
            (Some(x), Some(y)) => x.copy_from(y),
            _ => self.stiffening = source.stiffening.clone(),
        }
    }
}

/// Inertia of the undeformed beam in its frame: everything [`InertiaModel::Frozen`] needs, and
/// all a 12 × 12 nodal mass matrix can give.
#[derive(Debug, Clone)]
pub struct UndeformedInertia {
    /// Translational mass block T_tᵀ M T_t (m I for a beam; the beam uses its mean diagonal).
    pub mtt: Matrix3<f64>,
    /// Static moment c0 = ∫ρ ū0 dx.
    pub c0: Vector3<f64>,
    /// I_θθ at q_f = 0.
    pub i0: Matrix3<f64>,
    /// S̄ (3 × nf).
    pub sbar: DMatrix<f64>,
    /// I_θf at q_f = 0 (3 × nf).
    pub b0: DMatrix<f64>,
    /// D = ∫ρ x S (3 × nf): the centrifugal load Σ_i (ω̃²)_{i0} D_iᵀ.
    pub d: DMatrix<f64>,
}

impl UndeformedInertia {
    /// From the nodal mass matrix (6 per node, nodes at `x`) and the kept coordinates, through
    /// the modes of the undeformed beam: translations t_i, rotations r_i (nodal field of
    /// e_i × ū0 with unit nodal rotation i) and the stretch s (u = x). With P selecting the kept
    /// coordinates: mtt = T_tᵀ M T_t, i0 = Φ_rᵀ M Φ_r, S̄ = Φ_tᵀ M P, I_θf = Φ_rᵀ M P,
    /// D = [s; r_z; −r_y]ᵀ M P, c0 from the skew part of Φ_tᵀ M Φ_r = −c̃0.
    pub fn from_nodal_mass(m: &DMatrix<f64>, x: &[f64], kept: &[usize]) -> UndeformedInertia {
        let n = m.nrows();
        let modes = DMatrix::from_fn(n, 7, |row, col| {
            let (node, dof) = (row / NODE_DOFS, row % NODE_DOFS);
            let xn = x[node];
            match (col, dof) {
                (0, U) | (1, V) | (2, W) => 1.0,
                (3, TX) | (4, TY) | (5, TZ) => 1.0,
                (4, W) => -xn,
                (5, V) => xn,
                (6, U) => xn,
                _ => 0.0,
            }
        });
        let mm = modes.transpose() * m * &modes;
        let mp = modes.transpose() * m.select_columns(kept.iter());
        let block = |r: usize, c: usize| Matrix3::from_fn(|i, j| mm[(r + i, c + j)]);
        let tr = block(0, 3);
        let c_skew = -(tr - tr.transpose()) * 0.5;
        let rows = |r: &[usize], sign: &[f64]| {
            DMatrix::from_fn(3, mp.ncols(), |i, k| sign[i] * mp[(r[i], k)])
        };
        UndeformedInertia {
            mtt: block(0, 0),
            c0: Vector3::new(c_skew[(2, 1)], c_skew[(0, 2)], c_skew[(1, 0)]),
            i0: block(3, 3),
            sbar: rows(&[0, 1, 2], &[1.0, 1.0, 1.0]),
            b0: rows(&[3, 4, 5], &[1.0, 1.0, 1.0]),
            d: rows(&[6, 5, 4], &[1.0, 1.0, -1.0]),
        }
    }
}

/// The assembled beam in one floating frame.
#[derive(Debug, Clone)]
pub struct SpatialBeam {
    /// Name of the floating frame: the beam's, or `<beam>.<i>` for substructure i.
    pub name: String,
    /// Length of this floating frame (m).
    pub length: f64,
    /// Equal elements over the length (1 for a beam from a matrix file).
    pub elements: usize,
    /// Where the floating frame sits: which nodal coordinates are kept.
    pub frame: FloatingFrame,
    /// How the inertia terms are evaluated; always [`InertiaModel::Frozen`] without shape
    /// integrals ([`SpatialBeam::set_inertia`]).
    pub inertia: InertiaModel,
    /// Mass-proportional Rayleigh coefficient α (1/s): the system applies it to the whole beam,
    /// relative to the beam's reference frame (`multibody/beam_damping.rs`), not in D_ff.
    pub rayleigh_alpha: f64,
    /// Stiffness-proportional Rayleigh coefficient β (s).
    pub rayleigh_beta: f64,
    /// Full nodal indices (6 per node) kept by the frame's boundary conditions.
    pub kept: Vec<usize>,
    /// Total mass m.
    pub mass: f64,
    /// Shape integrals of the full model (`None` for a beam from a matrix file).
    pub integrals: Option<ShapeIntegrals>,
    /// Inertia of the undeformed beam from its nodal mass matrix: what the frozen model uses.
    pub undeformed: UndeformedInertia,
    /// m_ff (with the torsion rotary inertia), K_ff, D_ff over the kept coordinates.
    pub mff: DMatrix<f64>,
    /// K_ff, the stiffness matrix over the kept coordinates.
    pub kff: DMatrix<f64>,
    /// D_ff = β K_ff, the stiffness-proportional Rayleigh damping on the strain rates (the α
    /// part acts on the whole beam, `multibody/beam_damping.rs`).
    pub dff: DMatrix<f64>,
    /// Flange a: the material point at the root (x = 0).
    pub flange_a: SpatialPointMap,
    /// Flange b: the material point at the tip (x = length).
    pub flange_b: SpatialPointMap,
    /// Nonlinear axial strain ε = u' + ½(v'² + w'²) (geometric stiffening), when on.
    pub geometric_stiffening: bool,
    /// Axial stiffness EA (N) of the stiffening (a matrix file's: its first axial entry × ℓ).
    pub ea: f64,
    /// The element's slope rows and kept indices, constant per frame.
    strain: stiffening::StrainRows,
}

/// Full nodal indices a frame kind keeps: tangent removes the 6 root coordinates; pinned
/// removes the root's u, v, w, θx and the tip's v, w (frame axis through both ends).
pub fn kept_coordinates(frame: FloatingFrame, elements: usize) -> Vec<usize> {
    let n_full = NODE_DOFS * (elements + 1);
    let tip = NODE_DOFS * elements;
    (0..n_full)
        .filter(|&i| match frame {
            FloatingFrame::Tangent => i >= NODE_DOFS,
            FloatingFrame::Pinned => i > TX && i != tip + V && i != tip + W,
        })
        .collect()
}

impl SpatialBeam {
    /// Sets the inertia model; a beam without shape integrals (from a matrix file) stays
    /// [`InertiaModel::Frozen`]. Returns the model in force.
    pub fn set_inertia(&mut self, model: InertiaModel) -> InertiaModel {
        if self.integrals.is_some() {
            self.inertia = model;
        }
        self.inertia
    }

    /// Largest transverse nodal displacement √(v² + w²) of the deformation `f` (m): how far
    /// the beam has bent away from its floating frame's axis.
    pub fn largest_transverse(&self, f: DVectorView<f64>) -> f64 {
        (0..=self.elements)
            .map(|j| {
                let c = |p: usize| self.flex_index(NODE_DOFS * j + p).map_or(0.0, |k| f[k]);
                c(V).hypot(c(W))
            })
            .fold(0.0, f64::max)
    }

    /// Number of deformation coordinates nf.
    pub fn nflex(&self) -> usize {
        self.kept.len()
    }

    /// Number of velocity coordinates 6 + nf (Ṙ, ω, q̇_f).
    pub fn ndof(&self) -> usize {
        FLEX + self.nflex()
    }

    /// Reduced index of the full nodal coordinate `full`, if the frame keeps it.
    pub fn flex_index(&self, full: usize) -> Option<usize> {
        self.kept.iter().position(|&k| k == full)
    }

    /// The shape integrals when the full model is in force.
    fn full(&self) -> Option<&ShapeIntegrals> {
        match self.inertia {
            InertiaModel::Full => self.integrals.as_ref(),
            InertiaModel::Frozen => None,
        }
    }

    /// Static moment c = ∫ρ ū dx = c0 + S̄ q_f (exact in either inertia model).
    pub fn first_moment(&self, f: &DVectorView<f64>) -> Vector3<f64> {
        self.undeformed.c0 + mul3(&self.undeformed.sbar, f)
    }

    /// (c, I_θθ, I_θf) of the inertia model in force.
    pub fn inertia_blocks(
        &self,
        f: &DVectorView<f64>,
    ) -> (Vector3<f64>, Matrix3<f64>, DMatrix<f64>) {
        let fi = self.flex_inertia(*f);
        (fi.c, fi.ithth, fi.ithf)
    }

    /// The q_f-dependent inertia of the model in force (nine products M^k q_f, then O(nf)).
    pub fn flex_inertia<'a>(&self, f: impl Into<DVectorView<'a, f64>>) -> FlexInertia {
        let f = f.into();
        let u = &self.undeformed;
        let Some(s) = self.full() else {
            return FlexInertia {
                c: u.c0,
                ithth: u.i0,
                ithf: u.b0.clone(),
                products: None,
            };
        };
        let mut fi = FlexInertia {
            c: Vector3::zeros(),
            ithth: Matrix3::zeros(),
            ithf: DMatrix::zeros(3, self.nflex()),
            products: Some((
                std::array::from_fn(|k| &s.mij[k] * f),
                std::array::from_fn(|k| s.mij[k + 3].tr_mul(&f)),
            )),
        };
        self.assemble_full(s, f, &mut fi);
        fi
    }

    /// The full model's c, I_θθ and I_θf at q_f from the products M^k q_f, M^kᵀ q_f in `fi`.
    fn assemble_full(&self, s: &ShapeIntegrals, f: DVectorView<f64>, fi: &mut FlexInertia) {
        let Some((mf, mtf)) = fi.products.as_ref() else {
            unreachable!("the full model keeps its products")
        };
        let df = mul3(&s.d, &f);
        // U = ∫ρ ū ūᵀ
        let mut uu = Matrix3::zeros();
        uu[(0, 0)] = s.j0;
        for i in 0..3 {
            uu[(0, i)] += df[i];
            uu[(i, 0)] += df[i];
        }
        for (k, &(i, j)) in PAIRS.iter().enumerate() {
            let e = f.dot(&mf[k]);
            uu[(i, j)] += e;
            if i != j {
                uu[(j, i)] += e;
            }
        }
        let mut ithth = Matrix3::identity() * uu.trace() - uu;
        ithth[(0, 0)] += s.rotary;
        // I_θf column k = e_x ∫ρI_p θx_k + e_x × D_k + ∫ρ (S q_f) × S_k, the last from the
        // skew parts M^kᵀ q_f − M^k q_f of the pairs (1, 2), (0, 2), (0, 1)
        for k in 0..self.nflex() {
            fi.ithf[(0, k)] = s.twist[k] + (mtf[2][k] - mf[5][k]);
            fi.ithf[(1, k)] = -s.d[(2, k)] - (mtf[1][k] - mf[4][k]);
            fi.ithf[(2, k)] = s.d[(1, k)] + (mtf[0][k] - mf[3][k]);
        }
        fi.c = self.first_moment(&f);
        fi.ithth = ithth;
    }

    /// All products of the residual at (q_f, q̇_f, q̈_f).
    pub fn products(
        &self,
        f: DVectorView<f64>,
        fd: DVectorView<f64>,
        fdd: DVectorView<f64>,
    ) -> BeamProducts {
        let skew_fd = match self.full() {
            Some(s) => (3..6)
                .map(|k| &s.mij[k] * fd - s.mij[k].tr_mul(&fd))
                .collect(),
            None => Vec::new(),
        };
        BeamProducts {
            inertia: self.flex_inertia(f),
            kf: &self.kff * f,
            dfd: &self.dff * fd,
            mfdd: &self.mff * fdd,
            skew_fd,
            stiffening: self.stiffening(&f, &fd),
        }
    }

    /// Updates `pr` for q_f moved by `h` in coordinate `k` (`f` the moved q_f).
    pub fn shift_flex(&self, pr: &mut BeamProducts, f: DVectorView<f64>, k: usize, h: f64) {
        pr.kf.axpy(h, &self.kff.column(k), 1.0);
        if let Some(st) = pr.stiffening.as_mut() {
            self.shift_stiffening(st, k, h);
        }
        let Some(s) = self.full() else { return };
        let Some((mf, mtf)) = pr.inertia.products.as_mut() else {
            unreachable!("the full model keeps its products")
        };
        for j in 0..6 {
            mf[j].axpy(h, &s.mij[j].column(k), 1.0);
        }
        for j in 0..3 {
            mtf[j].axpy(h, &s.mij[j + 3].row(k).transpose(), 1.0);
        }
        self.assemble_full(s, f, &mut pr.inertia);
    }

    /// Updates `pr` for q̇_f moved by `h` in coordinate `k`.
    pub fn shift_flex_rate(&self, pr: &mut BeamProducts, k: usize, h: f64) {
        pr.dfd.axpy(h, &self.dff.column(k), 1.0);
        if let Some(st) = pr.stiffening.as_mut() {
            self.shift_stiffening_rate(st, k, h);
        }
        if let Some(s) = self.full() {
            for (j, sk) in pr.skew_fd.iter_mut().enumerate() {
                let m = &s.mij[j + 3];
                sk.axpy(h, &m.column(k), 1.0);
                sk.axpy(-h, &m.row(k).transpose(), 1.0);
            }
        }
    }

    /// Mass matrix over v = [Ṙ, ω, q̇_f], written into `m` (ndof × ndof).
    pub fn mass_matrix<'a>(
        &self,
        a: &Matrix3<f64>,
        f: impl Into<DVectorView<'a, f64>>,
        m: DMatrixViewMut<f64>,
    ) {
        self.mass_matrix_of(&self.flex_inertia(f), a, m);
    }

    /// [`SpatialBeam::mass_matrix`] from the q_f-dependent inertia at hand (a residual's
    /// products hold it).
    pub fn mass_matrix_of(&self, fi: &FlexInertia, a: &Matrix3<f64>, mut m: DMatrixViewMut<f64>) {
        let FlexInertia { c, ithth, ithf, .. } = fi;
        let (c, ithth) = (*c, *ithth);
        let nf = self.nflex();
        m.fill(0.0);
        let mrr = Matrix3::identity() * self.mass;
        let mrw = -a * skew(&c);
        let mrf = a * &self.undeformed.sbar;
        m.view_mut((0, 0), (3, 3)).copy_from(&mrr);
        m.view_mut((0, OMEGA), (3, 3)).copy_from(&mrw);
        m.view_mut((OMEGA, 0), (3, 3)).copy_from(&mrw.transpose());
        m.view_mut((OMEGA, OMEGA), (3, 3)).copy_from(&ithth);
        m.view_mut((0, FLEX), (3, nf)).copy_from(&mrf);
        m.view_mut((FLEX, 0), (nf, 3)).copy_from(&mrf.transpose());
        m.view_mut((OMEGA, FLEX), (3, nf)).copy_from(ithf);
        m.view_mut((FLEX, OMEGA), (nf, 3))
            .copy_from(&ithf.transpose());
        m.view_mut((FLEX, FLEX), (nf, nf)).copy_from(&self.mff);
    }

    /// The mass matrix as a new matrix.
    pub fn mass_matrix_owned<'a>(
        &self,
        a: &Matrix3<f64>,
        f: impl Into<DVectorView<'a, f64>>,
    ) -> DMatrix<f64> {
        let n = self.ndof();
        let mut m = DMatrix::zeros(n, n);
        self.mass_matrix(a, f, m.view_mut((0, 0), (n, n)));
        m
    }

    /// Quadratic-velocity vector h(A, q_f, v) (ndof): the generalized inertia force at v̇ = 0.
    pub fn quadratic_velocity<'a>(
        &self,
        a: &Matrix3<f64>,
        f: impl Into<DVectorView<'a, f64>>,
        v: impl Into<DVectorView<'a, f64>>,
    ) -> DVector<f64> {
        let (f, v) = (f.into(), v.into());
        let fd = v.rows(FLEX, self.nflex());
        let pr = self.products(f, fd, fd);
        self.quadratic_velocity_with(&pr, a, v)
    }

    /// [`SpatialBeam::quadratic_velocity`] with the products of this state given.
    pub fn quadratic_velocity_with(
        &self,
        pr: &BeamProducts,
        a: &Matrix3<f64>,
        v: DVectorView<f64>,
    ) -> DVector<f64> {
        let fi = &pr.inertia;
        let nf = self.nflex();
        let w = Vector3::new(v[OMEGA], v[OMEGA + 1], v[OMEGA + 2]);
        let fd = v.rows(FLEX, nf);
        let wt = skew(&w);
        let ww = wt * wt;
        let u = &self.undeformed;
        let mut h = DVector::zeros(self.ndof());
        // centrifugal load on q_f of the undeformed axis: ∫ρ Sᵀ ω̃² (x e_x)
        let mut hf = u.d.tr_mul(&ww.column(0));
        let (hr, hw) = match self.full() {
            None => (a * (w.cross(&w.cross(&u.c0))), w.cross(&(u.i0 * w))),
            Some(s) => {
                let sfd = mul3(&u.sbar, &fd);
                let hr = a * (w.cross(&w.cross(&fi.c)) + 2.0 * w.cross(&sfd));
                // G = ∫ρ (S q̇_f) ūᵀ: G_ij = q̇_fᵀ M^{ij} q_f
                let dfd = mul3(&s.d, &fd);
                let mut g = Matrix3::zeros();
                for i in 0..3 {
                    g[(i, 0)] += dfd[i];
                    for j in 0..3 {
                        let (k, t) = pair_index(i, j);
                        g[(i, j)] += fd.dot(fi.product(k, t));
                    }
                }
                let rot = s.twist.dot(&fd);
                let hw = w.cross(&(fi.ithth * w))
                    + 2.0 * (w * g.trace() - g * w)
                    + w.cross(&Vector3::x()) * rot;
                // ∫ρ Sᵀ ω̃² S q_f + 2 ∫ρ Sᵀ ω̃ S q̇_f
                for (k, &(i, j)) in PAIRS.iter().enumerate() {
                    if i == j {
                        hf.axpy(ww[(i, i)], fi.product(k, false), 1.0);
                    } else {
                        hf.axpy(ww[(i, j)], fi.product(k, false), 1.0);
                        hf.axpy(ww[(i, j)], fi.product(k, true), 1.0);
                        hf.axpy(2.0 * wt[(i, j)], &pr.skew_fd[k - 3], 1.0);
                    }
                }
                (hr, hw)
            }
        };
        h.rows_mut(0, 3).copy_from(&hr);
        h.rows_mut(OMEGA, 3).copy_from(&hw);
        h.rows_mut(FLEX, nf).copy_from(&hf);
        h
    }

    /// Generalized gravity force Q_g = [m g; c × Aᵀg; S̄ᵀ Aᵀ g] (exact in either model).
    pub fn gravity_force<'a>(
        &self,
        a: &Matrix3<f64>,
        f: impl Into<DVectorView<'a, f64>>,
        g: &Vector3<f64>,
    ) -> DVector<f64> {
        let f = f.into();
        let gl = a.transpose() * g;
        let mut q = DVector::zeros(self.ndof());
        q.rows_mut(0, 3).copy_from(&(g * self.mass));
        q.rows_mut(OMEGA, 3)
            .copy_from(&self.first_moment(&f).cross(&gl));
        q.rows_mut(FLEX, self.nflex())
            .copy_from(&self.undeformed.sbar.tr_mul(&gl));
        q
    }

    /// Internal force K_ff q_f + f_g + D_ff q̇_f (+ f_β with stiffening) on the deformation rows.
    pub fn internal_force<'a>(
        &self,
        f: impl Into<DVectorView<'a, f64>>,
        fd: impl Into<DVectorView<'a, f64>>,
    ) -> DVector<f64> {
        let (f, fd) = (f.into(), fd.into());
        let linear = &self.kff * f + &self.dff * fd;
        match self.stiffening(&f, &fd) {
            Some(st) => linear + st.force(),
            None => linear,
        }
    }

    /// Residual r = M v̇ + h + [0; 0; K_ff q_f + f_g + D_ff q̇_f] − Q_g (ndof).
    pub fn residual<'a>(
        &self,
        a: &Matrix3<f64>,
        f: impl Into<DVectorView<'a, f64>>,
        v: impl Into<DVectorView<'a, f64>>,
        vd: impl Into<DVectorView<'a, f64>>,
        g: &Vector3<f64>,
    ) -> DVector<f64> {
        let (f, v, vd) = (f.into(), v.into(), vd.into());
        let nf = self.nflex();
        let pr = self.products(f, v.rows(FLEX, nf), vd.rows(FLEX, nf));
        self.residual_with(&pr, a, f, v, vd, g)
    }

    /// [`SpatialBeam::residual`] with the products of this state given; M v̇ by blocks,
    /// M_Rω = −A c̃, M_Rf = A S̄.
    pub fn residual_with(
        &self,
        pr: &BeamProducts,
        a: &Matrix3<f64>,
        f: DVectorView<f64>,
        v: DVectorView<f64>,
        vd: DVectorView<f64>,
        g: &Vector3<f64>,
    ) -> DVector<f64> {
        let nf = self.nflex();
        let sbar = &self.undeformed.sbar;
        let rd = Vector3::new(vd[0], vd[1], vd[2]);
        let wd = Vector3::new(vd[OMEGA], vd[OMEGA + 1], vd[OMEGA + 2]);
        let fdd = vd.rows(FLEX, nf);
        let rd_body = a.transpose() * rd;
        let fi = &pr.inertia;
        let mut r = self.quadratic_velocity_with(pr, a, v);
        let hr = rd * self.mass - a * fi.c.cross(&wd) + a * mul3(sbar, &fdd) - g * self.mass;
        let gl = a.transpose() * g;
        let hw = fi.c.cross(&rd_body) + fi.ithth * wd + &fi.ithf * fdd
            - self.first_moment(&f).cross(&gl);
        for i in 0..3 {
            r[i] += hr[i];
            r[OMEGA + i] += hw[i];
        }
        let mut rf = r.rows_mut(FLEX, nf);
        rf += sbar.tr_mul(&(rd_body - gl)) + fi.ithf.tr_mul(&wd) + &pr.mfdd;
        rf += &pr.kf + &pr.dfd;
        if let Some(st) = &pr.stiffening {
            rf += st.force();
        }
        r
    }

    /// Kinetic energy ½ vᵀ M v (J).
    pub fn kinetic_energy<'a>(
        &self,
        a: &Matrix3<f64>,
        f: impl Into<DVectorView<'a, f64>>,
        v: impl Into<DVectorView<'a, f64>>,
    ) -> f64 {
        let v = v.into();
        0.5 * v.dot(&(self.mass_matrix_owned(a, f) * v))
    }

    /// Strain energy ½ q_fᵀ K_ff q_f + U_g (J).
    pub fn strain_energy<'a>(&self, f: impl Into<DVectorView<'a, f64>>) -> f64 {
        let f = f.into();
        0.5 * f.dot(&(&self.kff * f)) + self.stiffening_energy(&f)
    }

    /// Potential energy of gravity −g·∫ρ r dx (J).
    pub fn gravity_energy<'a>(
        &self,
        r: &Vector3<f64>,
        a: &Matrix3<f64>,
        f: impl Into<DVectorView<'a, f64>>,
        g: &Vector3<f64>,
    ) -> f64 {
        let f = f.into();
        -g.dot(&(r * self.mass + a * self.first_moment(&f)))
    }

    /// The material point at distance x from flange a along the undeformed axis (a beam from
    /// a matrix file is interpolated with the element's shape functions).
    pub fn point_map(&self, x: f64) -> SpatialPointMap {
        let l = self.length / self.elements as f64;
        let j = ((x / l).floor() as usize).min(self.elements - 1);
        let xi = (x / l - j as f64).clamp(0.0, 1.0);
        let sh = spatial_element::shape(xi, l);
        let rt = spatial_element::section_rotation(xi, l);
        let nf = self.nflex();
        let mut sp = DMatrix::zeros(3, nf);
        let mut sphi = DMatrix::zeros(3, nf);
        for p in 0..ELEMENT_DOFS {
            if let Some(k) = self.flex_index(NODE_DOFS * j + p) {
                for i in 0..3 {
                    sp[(i, k)] = sh[i][p];
                    sphi[(i, k)] = rt[i][p];
                }
            }
        }
        SpatialPointMap {
            s0: Vector3::new(x, 0.0, 0.0),
            sp,
            sphi,
        }
    }

    /// World position and orientation of a material point: R + A (s0 + S_p q_f) and
    /// A exp(φ̃), φ = S_φ q_f.
    pub fn point<'a>(
        &self,
        map: &SpatialPointMap,
        r: &Vector3<f64>,
        a: &Matrix3<f64>,
        f: impl Into<DVectorView<'a, f64>>,
    ) -> (Vector3<f64>, Matrix3<f64>) {
        let f = f.into();
        let s = map.s0 + &map.sp * f;
        let phi: Vector3<f64> = (&map.sphi * f).fixed_rows::<3>(0).into_owned();
        (r + a * s, a * Rotation3::from_scaled_axis(phi).into_inner())
    }
}
