//! A planar flexible beam in one floating frame (planar paper §3, eq. (1)–(13)).
//!
//! Body coordinates z = [R_x, R_y, θ, q_f]: the world position and angle of the reference frame
//! (at flange a) and the deformation coordinates left after the boundary conditions of §3.3.
//! Every shape integral of eq. (11) is computed once, here, with 4-point Gauss per element; each
//! evaluation only combines them with the current q_f. The equations are written in world
//! components for R (so joints and gravity stay simple), which is eq. (5) rotated by A.
//!
//! Residual of the body (generalized inertia + internal - applied forces):
//! r(z, ż, z̈) = M(z) z̈ + h(z, ż) + [0; 0; K_ff q_f + D_ff q̇_f] - Q_g(z)
//! with M = ∫ρ Lᵀ L, L = ∂r/∂z = [I, A_θ ū, A S], and h the quadratic-velocity vector.

use super::planar_element::{self, ELEMENT_DOFS, GAUSS_4};
use super::section::Section;
use crate::scene::{BeamSpec, FrameKind};
use nalgebra::{DMatrix, DMatrixViewMut, DVector, DVectorView, Matrix2, Vector2};

/// Index of the angle θ in the body coordinates; q_f starts at [`FLEX`].
pub const THETA: usize = 2;
pub const FLEX: usize = 3;

/// Rotation matrix A(θ) and its derivative A_θ.
pub fn rot(theta: f64) -> (Matrix2<f64>, Matrix2<f64>) {
    let (s, c) = theta.sin_cos();
    (Matrix2::new(c, -s, s, c), Matrix2::new(-s, -c, c, -s))
}

/// A material point of the beam expressed through q_f: ū = s0 + S_p q_f, slope angle S_φ q_f.
#[derive(Debug, Clone, PartialEq)]
pub struct PointMap {
    /// Undeformed position in the beam frame (m).
    pub s0: Vector2<f64>,
    /// Deformation displacement per q_f (2 × nf).
    pub sp: DMatrix<f64>,
    /// Rotation of the section per q_f (1 × nf, stored as a vector).
    pub sphi: DVector<f64>,
}

/// Body coordinates (or their rates) as the beam reads them: a whole vector or a view into the
/// system's q, without a copy.
pub trait Coords<'a>: Into<DVectorView<'a, f64>> {}
impl<'a, T: Into<DVectorView<'a, f64>>> Coords<'a> for T {}

impl PointMap {
    /// S_p q_f, the deformation displacement of the point.
    pub fn displacement(&self, f: &DVectorView<f64>) -> Vector2<f64> {
        let mut s = Vector2::zeros();
        for k in 0..self.sp.ncols() {
            s[0] += self.sp[(0, k)] * f[k];
            s[1] += self.sp[(1, k)] * f[k];
        }
        s
    }
}

/// Column k of a 2 × nf matrix.
fn col2(m: &DMatrix<f64>, k: usize) -> Vector2<f64> {
    Vector2::new(m[(0, k)], m[(1, k)])
}

/// The assembled beam: constants of eq. (11) reduced to the kept deformation coordinates.
#[derive(Debug, Clone)]
pub struct PlanarBeam {
    pub name: String,
    pub length: f64,
    pub elements: usize,
    pub frame: FrameKind,
    pub section: Section,
    /// Mass per unit length ρA (kg/m), EA (N), EJ (N m^2).
    pub mu: f64,
    pub ea: f64,
    pub ej: f64,
    pub rayleigh_alpha: f64,
    pub rayleigh_beta: f64,
    /// Full nodal indices (3 per node) kept by the boundary conditions of §3.3.
    pub kept: Vec<usize>,
    /// Total mass m.
    pub mass: f64,
    /// ∫ρ ū0 dV (S̄_t of the undeformed beam).
    pub st0: Vector2<f64>,
    /// ∫ρ ū0ᵀū0 dV.
    pub i0: f64,
    /// S̄ = ∫ρ S dV (2 × nf).
    pub sbar: DMatrix<f64>,
    /// a = ∫ρ Sᵀ ū0 dV.
    pub a: DVector<f64>,
    /// b = ∫ρ (ū0₁ S₂ - ū0₂ S₁) dV, the constant part of Ī_θf.
    pub b: DVector<f64>,
    /// m_ff = ∫ρ SᵀS dV.
    pub mff: DMatrix<f64>,
    /// W = ∫ρ (S₁ᵀS₂ - S₂ᵀS₁) dV (skew): Ī_θf = b + Wᵀ q_f.
    pub w: DMatrix<f64>,
    pub kff: DMatrix<f64>,
    /// D_ff = alpha m_ff + beta K_ff.
    pub dff: DMatrix<f64>,
    pub flange_a: PointMap,
    pub flange_b: PointMap,
    /// Nonlinear axial strain ε = u' + v'²/2 (geometric stiffening), when on.
    pub geometric_stiffening: bool,
}

/// Full-beam integrals before the boundary conditions remove coordinates.
struct FullIntegrals {
    sbar: DMatrix<f64>,
    a: DVector<f64>,
    b: DVector<f64>,
    mff: DMatrix<f64>,
    w: DMatrix<f64>,
    kff: DMatrix<f64>,
}

impl PlanarBeam {
    /// Builds the beam from its (validated) scene entry.
    pub fn from_spec(spec: &BeamSpec) -> PlanarBeam {
        PlanarBeam::part_of(spec, &spec.name, spec.length)
    }

    /// One floating frame of a (validated) scene beam: the whole beam, or one of its
    /// substructures, named `name`, of length `length`.
    pub fn part_of(spec: &BeamSpec, name: &str, length: f64) -> PlanarBeam {
        let mut b = PlanarBeam::new(
            name,
            length,
            crate::scene::Scene::beam_layout(spec).0,
            spec.frame,
            spec.material.rho,
            spec.material.e,
            Section::from_spec(&spec.section),
            spec.rayleigh.alpha,
            spec.rayleigh.beta,
        );
        b.set_geometric_stiffening(spec.geometric_stiffening);
        b
    }

    pub fn new(
        name: &str,
        length: f64,
        elements: usize,
        frame: FrameKind,
        rho: f64,
        e: f64,
        section: Section,
        rayleigh_alpha: f64,
        rayleigh_beta: f64,
    ) -> PlanarBeam {
        let n_full = 3 * (elements + 1);
        let kept: Vec<usize> = (0..n_full)
            .filter(|&i| match frame {
                FrameKind::Tangent => i >= 3,
                FrameKind::Pinned => i >= 2 && i != 3 * elements + 1,
            })
            .collect();
        let mu = rho * section.area;
        let ea = e * section.area;
        let ej = e * section.second_moment;
        let full = full_integrals(length, elements, mu, ea, ej);
        let pick_cols = |m: &DMatrix<f64>| m.select_columns(kept.iter());
        let pick = |m: &DMatrix<f64>| m.select_rows(kept.iter()).select_columns(kept.iter());
        let pick_v = |v: &DVector<f64>| v.select_rows(kept.iter());
        let mff = pick(&full.mff);
        let kff = pick(&full.kff);
        let dff = &mff * rayleigh_alpha + &kff * rayleigh_beta;
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
        PlanarBeam {
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
            sbar: pick_cols(&full.sbar),
            a: pick_v(&full.a),
            b: pick_v(&full.b),
            w: pick(&full.w),
            mff,
            kff,
            dff,
            flange_a: node_map(0, 0.0),
            flange_b: node_map(elements, length),
            kept,
            geometric_stiffening: false,
        }
    }

    /// Number of deformation coordinates nf.
    pub fn nflex(&self) -> usize {
        self.kept.len()
    }

    /// Number of body coordinates 3 + nf.
    pub fn ndof(&self) -> usize {
        FLEX + self.nflex()
    }

    /// Reduced index of the full nodal coordinate `full`, if the boundary conditions keep it.
    pub fn flex_index(&self, full: usize) -> Option<usize> {
        self.kept.iter().position(|&k| k == full)
    }

    /// First moment c = ∫ρ ū dV = S̄_t0 + S̄ q_f in the beam frame.
    fn first_moment(&self, f: &DVectorView<f64>) -> Vector2<f64> {
        self.st0 + self.sbar_mul(f)
    }

    /// S̄ f for deformation coordinates or their rates.
    fn sbar_mul(&self, f: &DVectorView<f64>) -> Vector2<f64> {
        let mut c = Vector2::zeros();
        for k in 0..f.len() {
            c += col2(&self.sbar, k) * f[k];
        }
        c
    }

    /// Mass matrix M(z), written into `m` (ndof × ndof).
    pub fn mass_matrix<'a>(&self, z: impl Coords<'a>, mut m: DMatrixViewMut<f64>) {
        let z = z.into();
        let nf = self.nflex();
        let f = z.rows(FLEX, nf);
        let (ar, ath) = rot(z[THETA]);
        let c = self.first_moment(&f);
        let athc = ath * c;
        m.fill(0.0);
        m[(0, 0)] = self.mass;
        m[(1, 1)] = self.mass;
        for i in 0..2 {
            m[(i, THETA)] = athc[i];
            m[(THETA, i)] = athc[i];
        }
        let mut mthth = self.i0;
        for k in 0..nf {
            let asbar = ar * col2(&self.sbar, k);
            for i in 0..2 {
                m[(i, FLEX + k)] = asbar[i];
                m[(FLEX + k, i)] = asbar[i];
            }
            let (mut mff_f, mut wt_f) = (0.0, 0.0);
            for l in 0..nf {
                mff_f += self.mff[(k, l)] * f[l];
                wt_f += self.w[(l, k)] * f[l];
            }
            mthth += 2.0 * self.a[k] * f[k] + f[k] * mff_f;
            let mthf = self.b[k] + wt_f;
            m[(THETA, FLEX + k)] = mthf;
            m[(FLEX + k, THETA)] = mthf;
        }
        m[(THETA, THETA)] = mthth;
        m.view_mut((FLEX, FLEX), (nf, nf)).copy_from(&self.mff);
    }

    /// Residual r = M z̈ + h + internal - gravity, added into `r`.
    pub fn residual<'a>(
        &self,
        z: impl Coords<'a>,
        zd: impl Coords<'a>,
        zdd: impl Coords<'a>,
        gravity: Vector2<f64>,
        r: &mut [f64],
    ) {
        let (z, zd, zdd) = (z.into(), zd.into(), zdd.into());
        let nf = self.nflex();
        let f = z.rows(FLEX, nf);
        let fd = zd.rows(FLEX, nf);
        let fdd = zdd.rows(FLEX, nf);
        let (ar, ath) = rot(z[THETA]);
        let (td, tdd) = (zd[THETA], zdd[THETA]);
        let rdd = Vector2::new(zdd[0], zdd[1]);
        let c = self.first_moment(&f);
        let (ac, athc) = (ar * c, ath * c);
        let sbar_fd = self.sbar_mul(&fd);
        let sbar_fdd = self.sbar_mul(&fdd);
        // translation
        let r_r = rdd * self.mass + athc * tdd + ar * sbar_fdd - ac * (td * td)
            + ath * sbar_fd * (2.0 * td)
            - gravity * self.mass;
        r[0] += r_r[0];
        r[1] += r_r[1];
        // deformation, with the sums the rotation row needs
        let local = ar.transpose() * (rdd - gravity);
        let (mut a_f, mut f_mff_f, mut mthf_fdd, mut af_fd) = (0.0, 0.0, 0.0, 0.0);
        for k in 0..nf {
            let (mut mff_f, mut mff_fdd, mut wt_f, mut w_fd, mut kff_f, mut dff_fd) =
                (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            for l in 0..nf {
                mff_f += self.mff[(k, l)] * f[l];
                mff_fdd += self.mff[(k, l)] * fdd[l];
                wt_f += self.w[(l, k)] * f[l];
                w_fd += self.w[(k, l)] * fd[l];
                kff_f += self.kff[(k, l)] * f[l];
                dff_fd += self.dff[(k, l)] * fd[l];
            }
            let mthf = self.b[k] + wt_f; // Ī_θf
            let af = self.a[k] + mff_f; // ∫ρ Sᵀū dV
            a_f += self.a[k] * f[k];
            f_mff_f += f[k] * mff_f;
            mthf_fdd += mthf * fdd[k];
            af_fd += af * fd[k];
            r[FLEX + k] += col2(&self.sbar, k).dot(&local) + mthf * tdd + mff_fdd
                - af * (td * td)
                - w_fd * (2.0 * td)
                + kff_f
                + dff_fd;
        }
        // rotation
        let mthth = self.i0 + 2.0 * a_f + f_mff_f;
        r[THETA] += athc.dot(&rdd) + mthth * tdd + mthf_fdd + 2.0 * td * af_fd - athc.dot(&gravity);
        if self.geometric_stiffening {
            self.stiffening_force(&z, &mut r[FLEX..FLEX + nf]);
        }
    }

    /// Tangents of the residual: K_t = ∂r/∂z (at fixed ż, z̈) and C_t = ∂r/∂ż, added into the
    /// given blocks (ndof × ndof).
    pub fn tangents<'a>(
        &self,
        z: impl Coords<'a>,
        zd: impl Coords<'a>,
        zdd: impl Coords<'a>,
        gravity: Vector2<f64>,
        mut kt: DMatrixViewMut<f64>,
        mut ct: DMatrixViewMut<f64>,
    ) {
        let (z, zd, zdd) = (z.into(), zd.into(), zdd.into());
        let nf = self.nflex();
        let f = z.rows(FLEX, nf);
        let fd = zd.rows(FLEX, nf);
        let fdd = zdd.rows(FLEX, nf);
        let (ar, ath) = rot(z[THETA]);
        let (td, tdd) = (zd[THETA], zdd[THETA]);
        let rdd = Vector2::new(zdd[0], zdd[1]);
        let c = self.first_moment(&f);
        let (ac, athc) = (ar * c, ath * c);
        let sbar_fd = self.sbar_mul(&fd);
        let sbar_fdd = self.sbar_mul(&fdd);
        // ∂r_R/∂θ
        let d_r_th = -ac * tdd + ath * sbar_fdd - athc * (td * td) - ar * sbar_fd * (2.0 * td);
        // ∂r_R/∂θ̇
        let d_r_thd = -ac * (2.0 * td) + ath * sbar_fd * 2.0;
        for i in 0..2 {
            kt[(i, THETA)] += d_r_th[i];
            ct[(i, THETA)] += d_r_thd[i];
        }
        // ∂r_θ/∂θ
        kt[(THETA, THETA)] += -ac.dot(&rdd) + ac.dot(&gravity);
        let mut af_fd = 0.0;
        for k in 0..nf {
            let (asbar, athsbar) = (ar * col2(&self.sbar, k), ath * col2(&self.sbar, k));
            let (mut mff_f, mut mff_fd, mut w_fdd, mut w_fd) = (0.0, 0.0, 0.0, 0.0);
            for l in 0..nf {
                mff_f += self.mff[(k, l)] * f[l];
                mff_fd += self.mff[(k, l)] * fd[l];
                w_fdd += self.w[(k, l)] * fdd[l];
                w_fd += self.w[(k, l)] * fd[l];
            }
            let af = self.a[k] + mff_f;
            af_fd += af * fd[k];
            // ∂r_R/∂f, ∂r_R/∂ḟ
            let d_r_f = athsbar * tdd - asbar * (td * td);
            for i in 0..2 {
                kt[(i, FLEX + k)] += d_r_f[i];
                ct[(i, FLEX + k)] += 2.0 * td * athsbar[i];
            }
            // ∂r_θ/∂f, ∂r_f/∂θ
            let d_f_th = athsbar.dot(&(rdd - gravity));
            kt[(THETA, FLEX + k)] += d_f_th + af * (2.0 * tdd) + w_fdd + mff_fd * (2.0 * td);
            kt[(FLEX + k, THETA)] += d_f_th;
            // ∂r_θ/∂ḟ, ∂r_f/∂θ̇
            ct[(THETA, FLEX + k)] += 2.0 * td * af;
            ct[(FLEX + k, THETA)] += af * (-2.0 * td) - w_fd * 2.0;
        }
        ct[(THETA, THETA)] += 2.0 * af_fd;
        // ∂r_f/∂f = Wᵀ θ̈ - θ̇² m_ff + K_ff, ∂r_f/∂ḟ = -2θ̇ W + D_ff
        for l in 0..nf {
            for k in 0..nf {
                kt[(FLEX + k, FLEX + l)] +=
                    self.w[(l, k)] * tdd - td * td * self.mff[(k, l)] + self.kff[(k, l)];
                ct[(FLEX + k, FLEX + l)] += -2.0 * td * self.w[(k, l)] + self.dff[(k, l)];
            }
        }
        if self.geometric_stiffening {
            self.stiffening_tangent(&z, &mut kt);
        }
    }

    /// Kinetic energy ½ żᵀ M ż (J).
    pub fn kinetic_energy<'a>(&self, z: impl Coords<'a>, zd: impl Coords<'a>) -> f64 {
        let n = self.ndof();
        let mut m = DMatrix::zeros(n, n);
        self.mass_matrix(z, m.view_mut((0, 0), (n, n)));
        let zd = zd.into();
        0.5 * zd.dot(&(&m * zd))
    }

    /// Strain energy ½ q_fᵀ K_ff q_f (J).
    pub fn strain_energy<'a>(&self, z: impl Coords<'a>) -> f64 {
        let z = z.into();
        let f = z.rows(FLEX, self.nflex());
        let extra = if self.geometric_stiffening {
            self.stiffening_energy(&z)
        } else {
            0.0
        };
        0.5 * f.dot(&(&self.kff * f)) + extra
    }

    /// Potential energy of gravity -g·∫ρ r dV (J).
    pub fn gravity_energy<'a>(&self, z: impl Coords<'a>, gravity: Vector2<f64>) -> f64 {
        let z = z.into();
        let f = z.rows(FLEX, self.nflex());
        let (ar, _) = rot(z[THETA]);
        let com = Vector2::new(z[0], z[1]) * self.mass + ar * self.first_moment(&f);
        -gravity.dot(&com)
    }

    /// World position and angle of a material point map, and their Jacobians over z.
    pub fn point<'a>(&self, map: &PointMap, z: impl Coords<'a>) -> (Vector2<f64>, f64) {
        let z = z.into();
        let f = z.rows(FLEX, self.nflex());
        let (ar, _) = rot(z[THETA]);
        let s = map.s0 + map.displacement(&f);
        (
            Vector2::new(z[0], z[1]) + ar * s,
            z[THETA] + map.sphi.dot(&f),
        )
    }

    /// Position of the map in the beam frame, s = s0 + S_p q_f.
    pub fn local_point<'a>(&self, map: &PointMap, z: impl Coords<'a>) -> Vector2<f64> {
        map.s0 + map.displacement(&z.into().rows(FLEX, self.nflex()))
    }

    /// The material point at distance x from flange a along the undeformed axis.
    pub fn point_map(&self, x: f64) -> PointMap {
        let l = self.length / self.elements as f64;
        let j = ((x / l).floor() as usize).min(self.elements - 1);
        let xi = (x / l - j as f64).clamp(0.0, 1.0);
        let (s1, s2) = planar_element::shape(xi, l);
        let sl = planar_element::slope(xi, l);
        let nf = self.nflex();
        let mut sp = DMatrix::zeros(2, nf);
        let mut sphi = DVector::zeros(nf);
        for p in 0..ELEMENT_DOFS {
            if let Some(k) = self.flex_index(3 * j + p) {
                sp[(0, k)] = s1[p];
                sp[(1, k)] = s2[p];
                sphi[k] = sl[p];
            }
        }
        PointMap {
            s0: Vector2::new(x, 0.0),
            sp,
            sphi,
        }
    }

    pub fn set_geometric_stiffening(&mut self, on: bool) {
        self.geometric_stiffening = on;
    }

    /// Visits each element with its axial strain ε = u' + ½⟨v'²⟩, the element mean of v'²
    /// making ε (and the axial force) constant per element, which avoids membrane locking:
    /// (kept index of each element coordinate, ℓ, ε, ∂ε/∂q_e, ⟨v'_q v'_qᵀ⟩).
    #[allow(clippy::type_complexity)]
    fn for_element_strains(
        &self,
        z: &DVectorView<f64>,
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
        for j in 0..self.elements {
            let idx: [Option<usize>; ELEMENT_DOFS] =
                std::array::from_fn(|p| self.flex_index(3 * j + p));
            let qe: [f64; ELEMENT_DOFS] =
                std::array::from_fn(|p| idx[p].map_or(0.0, |k| z[FLEX + k]));
            let mut eps: f64 = (0..ELEMENT_DOFS).map(|p| da[p] * qe[p]).sum();
            let mut de = da;
            let mut hv = [[0.0; ELEMENT_DOFS]; ELEMENT_DOFS];
            for &(xi, w) in &GAUSS_4 {
                let ds = planar_element::slope(xi, l);
                let dv: f64 = (0..ELEMENT_DOFS).map(|p| ds[p] * qe[p]).sum();
                eps += 0.5 * w * dv * dv;
                for p in 0..ELEMENT_DOFS {
                    de[p] += w * dv * ds[p];
                    for r in 0..ELEMENT_DOFS {
                        hv[p][r] += w * ds[p] * ds[r];
                    }
                }
            }
            visit(&idx, l, eps, &de, &hv);
        }
    }

    /// Internal force of the nonlinear strain beyond the linear K_ff q_f:
    /// EA ℓ (ε ∂ε/∂q - u' ∂u'/∂q) per element, added into `out`.
    fn stiffening_force(&self, z: &DVectorView<f64>, out: &mut [f64]) {
        let ea = self.ea;
        self.for_element_strains(z, |idx, l, eps, de, _| {
            let du =
                (idx[3].map_or(0.0, |k| z[FLEX + k]) - idx[0].map_or(0.0, |k| z[FLEX + k])) / l;
            let da = [-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0];
            for p in 0..ELEMENT_DOFS {
                if let Some(k) = idx[p] {
                    out[k] += ea * l * (eps * de[p] - du * da[p]);
                }
            }
        });
    }

    /// Tangent of [`Self::stiffening_force`]: EA ℓ (∂ε ∂εᵀ + ε ⟨v'_q v'_qᵀ⟩ - ∂u' ∂u'ᵀ).
    fn stiffening_tangent(&self, z: &DVectorView<f64>, kt: &mut DMatrixViewMut<f64>) {
        let ea = self.ea;
        self.for_element_strains(z, |idx, l, eps, de, hv| {
            let da = [-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0];
            for p in 0..ELEMENT_DOFS {
                let Some(kp) = idx[p] else { continue };
                for r in 0..ELEMENT_DOFS {
                    let Some(kr) = idx[r] else { continue };
                    kt[(FLEX + kp, FLEX + kr)] +=
                        ea * l * (de[p] * de[r] + eps * hv[p][r] - da[p] * da[r]);
                }
            }
        });
    }

    /// Strain energy of the nonlinear strain beyond ½ q_fᵀ K_ff q_f.
    fn stiffening_energy(&self, z: &DVectorView<f64>) -> f64 {
        let mut e = 0.0;
        let ea = self.ea;
        self.for_element_strains(z, |idx, l, eps, _, _| {
            let du =
                (idx[3].map_or(0.0, |k| z[FLEX + k]) - idx[0].map_or(0.0, |k| z[FLEX + k])) / l;
            e += 0.5 * ea * l * (eps * eps - du * du);
        });
        e
    }

    /// Static deformation under a transverse tip force, scaled to a tip displacement `tip`
    /// (tangent frame): the initial shape of case C1.
    pub fn static_tip_shape(&self, tip: f64) -> Option<DVector<f64>> {
        let iv = self.flex_index(3 * self.elements + 1)?;
        let mut load = DVector::zeros(self.nflex());
        load[iv] = 1.0;
        let q = self.kff.clone().lu().solve(&load)?;
        let scale = tip / q[iv];
        scale.is_finite().then(|| q * scale)
    }
}

/// Integrals of eq. (11) over all N elements, before boundary conditions (eq. (8)–(12)).
fn full_integrals(length: f64, elements: usize, mu: f64, ea: f64, ej: f64) -> FullIntegrals {
    let n_full = 3 * (elements + 1);
    let l = length / elements as f64;
    let mut out = FullIntegrals {
        sbar: DMatrix::zeros(2, n_full),
        a: DVector::zeros(n_full),
        b: DVector::zeros(n_full),
        mff: DMatrix::zeros(n_full, n_full),
        w: DMatrix::zeros(n_full, n_full),
        kff: DMatrix::zeros(n_full, n_full),
    };
    let ke = planar_element::stiffness(ea, ej, l);
    for j in 0..elements {
        let o = 3 * j; // the connectivity matrix B_j of eq. (9)
        for &(xi, wgt) in &GAUSS_4 {
            let (s1, s2) = planar_element::shape(xi, l);
            let dm = mu * l * wgt;
            let x0 = (j as f64 + xi) * l;
            for p in 0..ELEMENT_DOFS {
                out.sbar[(0, o + p)] += dm * s1[p];
                out.sbar[(1, o + p)] += dm * s2[p];
                out.a[o + p] += dm * s1[p] * x0;
                out.b[o + p] += dm * s2[p] * x0;
                for q in 0..ELEMENT_DOFS {
                    out.mff[(o + p, o + q)] += dm * (s1[p] * s1[q] + s2[p] * s2[q]);
                    out.w[(o + p, o + q)] += dm * (s1[p] * s2[q] - s2[p] * s1[q]);
                }
            }
        }
        for p in 0..ELEMENT_DOFS {
            for q in 0..ELEMENT_DOFS {
                out.kff[(o + p, o + q)] += ke[p][q];
            }
        }
    }
    out
}
