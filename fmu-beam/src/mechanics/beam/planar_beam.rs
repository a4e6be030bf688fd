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

use super::band::{Banded, BlockMut};
use super::planar_element::{self, ELEMENT_DOFS, GAUSS_4};
use super::section::Section;
use super::sines::RecentTurn;
use super::FloatingFrame;
use nalgebra::{DMatrix, DVector, DVectorView, Matrix2, Vector2};
use std::cell::Cell;

mod build;
mod energy;
mod stiffening;

/// Which terms a beam computes (the resolved effects of its scene). A term
/// that is off is not evaluated at all; the full model has every term on and no truncation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BeamOptions {
    /// Axial deformation coordinates u kept (off: the beam is inextensible, its u are removed).
    pub axial: bool,
    /// Quadratic-velocity (centrifugal and Coriolis) terms h(z, ż).
    pub quadratic_velocity: bool,
    /// Rayleigh damping D_ff q̇_f.
    pub damping: bool,
    /// Geometric stiffening (nonlinear axial strain); needs `axial`.
    pub geometric_stiffening: bool,
    /// Modal truncation: keep the lowest k modes of (K_ff, M_ff) as coordinates.
    pub modes: Option<usize>,
}

impl Default for BeamOptions {
    fn default() -> Self {
        BeamOptions {
            axial: true,
            quadratic_velocity: true,
            damping: true,
            geometric_stiffening: false,
            modes: None,
        }
    }
}

/// How often each optional term was evaluated (residual or tangent), so a test can prove that a
/// term switched off costs nothing: its count stays zero.
#[derive(Debug, Clone, Default)]
pub struct TermCounts {
    pub gravity: Cell<u64>,
    pub quadratic_velocity: Cell<u64>,
    pub damping: Cell<u64>,
    pub geometric_stiffening: Cell<u64>,
    pub axial: Cell<u64>,
}

impl TermCounts {
    pub fn bump(c: &Cell<u64>) {
        c.set(c.get() + 1);
    }

    /// Adds another body's counts into these.
    pub fn add(&self, other: &TermCounts) {
        for (a, b) in self.cells().into_iter().zip(other.cells()) {
            a.set(a.get() + b.get());
        }
    }

    fn cells(&self) -> [&Cell<u64>; 5] {
        [
            &self.gravity,
            &self.quadratic_velocity,
            &self.damping,
            &self.geometric_stiffening,
            &self.axial,
        ]
    }
}

/// Index of the angle θ in the body coordinates; q_f starts at [`FLEX`].
pub const THETA: usize = 2;
pub const FLEX: usize = 3;

/// Rotation matrix A(θ) and its derivative A_θ.
pub fn rot(theta: f64) -> (Matrix2<f64>, Matrix2<f64>) {
    rot_of(theta.sin_cos())
}

/// [`rot`] from the angle's sine and cosine.
pub fn rot_of((s, c): (f64, f64)) -> (Matrix2<f64>, Matrix2<f64>) {
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
    /// Name of the floating frame: the beam's, or that of one of its substructures.
    pub name: String,
    /// Length of this floating frame (m).
    pub length: f64,
    /// Number of equal finite elements over the length.
    pub elements: usize,
    /// Where the floating frame sits (tangent at flange a, or through both ends): which nodal
    /// coordinates are kept (§3.3).
    pub frame: FloatingFrame,
    /// Section constants: area and second moment.
    pub section: Section,
    /// Mass per unit length ρA (kg/m), EA (N), EJ (N m^2).
    pub mu: f64,
    /// Axial stiffness E·A (N).
    pub ea: f64,
    /// Bending stiffness E·J (N m^2).
    pub ej: f64,
    /// Mass-proportional Rayleigh coefficient α (1/s): the system applies it to the whole beam,
    /// relative to the beam's reference frame (`multibody/beam_damping.rs`), not in D_ff.
    pub rayleigh_alpha: f64,
    /// Stiffness-proportional Rayleigh coefficient β (s) of D_ff.
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
    pub mff: Banded,
    /// W = ∫ρ (S₁ᵀS₂ - S₂ᵀS₁) dV (skew): Ī_θf = b + Wᵀ q_f.
    pub w: Banded,
    /// K_ff, the linear stiffness matrix over the kept coordinates.
    pub kff: Banded,
    /// D_ff = β K_ff, the stiffness-proportional Rayleigh damping on the strain rates.
    pub dff: Banded,
    /// Flange a: the material point at the root (x = 0).
    pub flange_a: PointMap,
    /// Flange b: the material point at the tip (x = length).
    pub flange_b: PointMap,
    /// Nonlinear axial strain ε = u' + v'²/2 (geometric stiffening), when on.
    pub geometric_stiffening: bool,
    /// The terms this beam computes.
    pub options: BeamOptions,
    /// Modal truncation: q_nodal = Φ q_f, Φ the lowest modes (kept × k), mass-normalized.
    pub basis: Option<DMatrix<f64>>,
    /// Evaluations of the optional terms.
    pub counts: TermCounts,
    /// Its last angle's sine and cosine ([`RecentTurn`]).
    pub turn: RecentTurn,
    /// Per deformation coordinate k, the columns l where m_ff, W (either way), K_ff or D_ff
    /// have a nonzero entry: the element matrices are assembled into a band, so the products
    /// of each evaluation skip the zeros (bit for bit the same sums).
    band: Vec<std::ops::Range<usize>>,
    /// Reduced index of each full nodal coordinate (3 per node), where kept.
    kept_index: Vec<Option<usize>>,
    /// The element's slope rows at the Gauss points and ⟨v'_q v'_qᵀ⟩, constant per beam.
    strain: StrainRows,
}

impl PlanarBeam {
    /// Nodal deformation (kept coordinates) of the body coordinates z.
    fn nodal(&self, z: &DVectorView<f64>) -> DVector<f64> {
        let f = z.rows(FLEX, self.nflex());
        match &self.basis {
            Some(phi) => phi * f,
            None => f.into_owned(),
        }
    }

    /// Largest transverse nodal displacement |v| from the frame's axis (m): how far this
    /// frame's deformation is from the small-deformation range of a floating frame.
    pub fn largest_transverse<'a>(&self, z: impl Coords<'a>) -> f64 {
        let fq = self.nodal(&z.into());
        self.kept
            .iter()
            .zip(fq.iter())
            .filter(|(&k, _)| k % 3 == 1)
            .fold(0.0, |m, (_, v)| m.max(v.abs()))
    }

    /// True if deformation coordinate k is a nodal slope (an angle), false for a length or a
    /// modal amplitude.
    pub fn is_slope(&self, k: usize) -> bool {
        self.basis.is_none() && self.kept[k] % 3 == 2
    }

    /// Number of deformation coordinates nf (nodal, or modal under truncation).
    pub fn nflex(&self) -> usize {
        self.basis.as_ref().map_or(self.kept.len(), DMatrix::ncols)
    }

    /// Number of body coordinates 3 + nf.
    pub fn ndof(&self) -> usize {
        FLEX + self.nflex()
    }

    /// Reduced index of the full nodal coordinate `full`, if the boundary conditions keep it.
    pub fn flex_index(&self, full: usize) -> Option<usize> {
        self.kept_index.get(full).copied().flatten()
    }

    /// Half bandwidth of the deformation block of M, K_t and C_t (its coordinates couple only
    /// within an element); None under modal truncation, whose block is dense.
    pub fn band_width(&self) -> Option<usize> {
        if self.basis.is_some() {
            return None;
        }
        let within = self.band.iter().enumerate();
        let matrices = within.fold(0, |w, (k, r)| {
            w.max(k.saturating_sub(r.start))
                .max(r.end.saturating_sub(k + 1))
        });
        let elements = (0..self.elements).fold(0, |w, j| {
            let idx = (0..ELEMENT_DOFS).filter_map(|p| self.flex_index(3 * j + p));
            let (lo, hi) = idx.fold((usize::MAX, 0), |(lo, hi), k| (lo.min(k), hi.max(k)));
            if lo <= hi {
                w.max(hi - lo)
            } else {
                w
            }
        });
        Some(matrices.max(elements))
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
    pub fn mass_matrix<'a, B: BlockMut>(&self, z: impl Coords<'a>, mut m: B) {
        let z = z.into();
        let nf = self.nflex();
        let f = z.rows(FLEX, nf);
        let (ar, ath) = self.turn.rot(z[THETA]);
        let c = self.first_moment(&f);
        let athc = ath * c;
        m.set_zero();
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
            for l in self.band[k].clone() {
                mff_f += self.mff[(k, l)] * f[l];
                wt_f += self.w[(l, k)] * f[l];
            }
            mthth += 2.0 * self.a[k] * f[k] + f[k] * mff_f;
            let mthf = self.b[k] + wt_f;
            m[(THETA, FLEX + k)] = mthf;
            m[(FLEX + k, THETA)] = mthf;
        }
        m[(THETA, THETA)] = mthth;
        for k in 0..nf {
            for l in self.band[k].clone() {
                m[(FLEX + k, FLEX + l)] = self.mff[(k, l)];
            }
        }
    }

    /// Residual r = M z̈ + h + internal - gravity, added into `r`. Gravity is `None` when the
    /// effect is off; the options say which other terms are computed.
    pub fn residual<'a>(
        &self,
        z: impl Coords<'a>,
        zd: impl Coords<'a>,
        zdd: impl Coords<'a>,
        gravity: Option<Vector2<f64>>,
        r: &mut [f64],
    ) {
        let (qv, damping) = (self.options.quadratic_velocity, self.options.damping);
        self.count_terms(gravity.is_some());
        let (z, zd, zdd) = (z.into(), zd.into(), zdd.into());
        let nf = self.nflex();
        let f = z.rows(FLEX, nf);
        let fd = zd.rows(FLEX, nf);
        let fdd = zdd.rows(FLEX, nf);
        let (ar, ath) = self.turn.rot(z[THETA]);
        let (td, tdd) = (zd[THETA], zdd[THETA]);
        let rdd = Vector2::new(zdd[0], zdd[1]);
        let c = self.first_moment(&f);
        let (ac, athc) = (ar * c, ath * c);
        let sbar_fd = self.sbar_mul(&fd);
        let sbar_fdd = self.sbar_mul(&fdd);
        // translation
        let mut r_r = rdd * self.mass + athc * tdd + ar * sbar_fdd;
        if qv {
            r_r += ath * sbar_fd * (2.0 * td) - ac * (td * td);
        }
        if let Some(g) = gravity {
            r_r -= g * self.mass;
        }
        r[0] += r_r[0];
        r[1] += r_r[1];
        // deformation, with the sums the rotation row needs
        let local = ar.transpose() * gravity.map_or(rdd, |g| rdd - g);
        let (mut a_f, mut f_mff_f, mut mthf_fdd, mut af_fd) = (0.0, 0.0, 0.0, 0.0);
        // the band's rows as slices (each sum in the order of l, as over the band's entries)
        let (fs, fds, fdds) = (f.as_slice(), fd.as_slice(), fdd.as_slice());
        for k in 0..nf {
            let band = self.band[k].clone();
            let (mff, kff) = (self.mff.row(k, band.clone()), self.kff.row(k, band.clone()));
            let (f_b, fd_b, fdd_b) = (&fs[band.clone()], &fds[band.clone()], &fdds[band.clone()]);
            let (mut mff_f, mut mff_fdd, mut wt_f, mut kff_f) = (0.0, 0.0, 0.0, 0.0);
            for (i, w_lk) in self.w.column(k, band.clone()).enumerate() {
                mff_f += mff[i] * f_b[i];
                mff_fdd += mff[i] * fdd_b[i];
                wt_f += w_lk * f_b[i];
                kff_f += kff[i] * f_b[i];
            }
            let mthf = self.b[k] + wt_f; // Ī_θf
            a_f += self.a[k] * f[k];
            f_mff_f += f[k] * mff_f;
            mthf_fdd += mthf * fdd[k];
            let mut rk = col2(&self.sbar, k).dot(&local) + mthf * tdd + mff_fdd + kff_f;
            if qv {
                let af = self.a[k] + mff_f; // ∫ρ Sᵀū dV
                af_fd += af * fd[k];
                let w_row = self.w.row(k, band.clone());
                let w_fd: f64 = w_row.iter().zip(fd_b).map(|(w, x)| w * x).sum();
                rk -= af * (td * td) + w_fd * (2.0 * td);
            }
            if damping {
                let dff = self.dff.row(k, band);
                rk += dff.iter().zip(fd_b).map(|(d, x)| d * x).sum::<f64>();
            }
            r[FLEX + k] += rk;
        }
        // rotation
        let mthth = self.i0 + 2.0 * a_f + f_mff_f;
        r[THETA] += athc.dot(&rdd) + mthth * tdd + mthf_fdd;
        if qv {
            r[THETA] += 2.0 * td * af_fd;
        }
        if let Some(g) = gravity {
            r[THETA] -= athc.dot(&g);
        }
        if self.geometric_stiffening {
            self.stiffening_force(&z, &mut r[FLEX..FLEX + nf]);
            if damping && self.rayleigh_beta != 0.0 {
                self.stiffening_damping(&z, &zd, &mut r[FLEX..FLEX + nf]);
            }
        }
    }

    /// Counts one evaluation of each optional term that is on.
    fn count_terms(&self, gravity: bool) {
        let c = &self.counts;
        let o = &self.options;
        for (on, cell) in [
            (gravity, &c.gravity),
            (o.quadratic_velocity, &c.quadratic_velocity),
            (o.damping, &c.damping),
            (self.geometric_stiffening, &c.geometric_stiffening),
            (o.axial, &c.axial),
        ] {
            if on {
                TermCounts::bump(cell);
            }
        }
    }

    /// Tangents of the residual: K_t = ∂r/∂z (at fixed ż, z̈) and C_t = ∂r/∂ż, added into the
    /// given blocks (ndof × ndof).
    pub fn tangents<'a, B: BlockMut>(
        &self,
        z: impl Coords<'a>,
        zd: impl Coords<'a>,
        zdd: impl Coords<'a>,
        gravity: Option<Vector2<f64>>,
        mut kt: B,
        mut ct: B,
    ) {
        let (qv, damping) = (self.options.quadratic_velocity, self.options.damping);
        self.count_terms(gravity.is_some());
        let (z, zd, zdd) = (z.into(), zd.into(), zdd.into());
        let nf = self.nflex();
        let f = z.rows(FLEX, nf);
        let fd = zd.rows(FLEX, nf);
        let fdd = zdd.rows(FLEX, nf);
        let (ar, ath) = self.turn.rot(z[THETA]);
        let (td, tdd) = (zd[THETA], zdd[THETA]);
        let rdd = Vector2::new(zdd[0], zdd[1]);
        let c = self.first_moment(&f);
        let (ac, athc) = (ar * c, ath * c);
        let sbar_fd = self.sbar_mul(&fd);
        let sbar_fdd = self.sbar_mul(&fdd);
        // ∂r_R/∂θ
        let mut d_r_th = -ac * tdd + ath * sbar_fdd;
        if qv {
            d_r_th -= athc * (td * td) + ar * sbar_fd * (2.0 * td);
            // ∂r_R/∂θ̇
            let d_r_thd = -ac * (2.0 * td) + ath * sbar_fd * 2.0;
            for i in 0..2 {
                ct[(i, THETA)] += d_r_thd[i];
            }
        }
        for i in 0..2 {
            kt[(i, THETA)] += d_r_th[i];
        }
        // ∂r_θ/∂θ
        // the frame's acceleration less gravity: the inertial load on the deformation
        let accel = gravity.map_or(rdd, |g| rdd - g);
        kt[(THETA, THETA)] -= ac.dot(&accel);
        let mut af_fd = 0.0;
        let (fs, fds, fdds) = (f.as_slice(), fd.as_slice(), fdd.as_slice()); // as in the residual
        for k in 0..nf {
            let (asbar, athsbar) = (ar * col2(&self.sbar, k), ath * col2(&self.sbar, k));
            let band = self.band[k].clone();
            let (mff, w) = (self.mff.row(k, band.clone()), self.w.row(k, band.clone()));
            let (f_b, fdd_b) = (&fs[band.clone()], &fdds[band.clone()]);
            let (mut mff_f, mut w_fdd) = (0.0, 0.0);
            for ((m, wkl), (x, xdd)) in mff.iter().zip(w).zip(f_b.iter().zip(fdd_b)) {
                mff_f += m * x;
                w_fdd += wkl * xdd;
            }
            let af = self.a[k] + mff_f;
            // ∂r_R/∂f, ∂r_R/∂ḟ
            let mut d_r_f = athsbar * tdd;
            // ∂r_θ/∂f, ∂r_f/∂θ
            let d_f_th = athsbar.dot(&accel);
            kt[(THETA, FLEX + k)] += d_f_th + af * (2.0 * tdd) + w_fdd;
            kt[(FLEX + k, THETA)] += d_f_th;
            if qv {
                let (mut mff_fd, mut w_fd) = (0.0, 0.0);
                for ((m, wkl), xd) in mff.iter().zip(w).zip(&fds[band.clone()]) {
                    mff_fd += m * xd;
                    w_fd += wkl * xd;
                }
                af_fd += af * fd[k];
                d_r_f -= asbar * (td * td);
                for i in 0..2 {
                    ct[(i, FLEX + k)] += 2.0 * td * athsbar[i];
                }
                kt[(THETA, FLEX + k)] += mff_fd * (2.0 * td);
                // ∂r_θ/∂ḟ, ∂r_f/∂θ̇
                ct[(THETA, FLEX + k)] += 2.0 * td * af;
                ct[(FLEX + k, THETA)] += af * (-2.0 * td) - w_fd * 2.0;
            }
            for i in 0..2 {
                kt[(i, FLEX + k)] += d_r_f[i];
            }
        }
        if qv {
            ct[(THETA, THETA)] += 2.0 * af_fd;
        }
        // ∂r_f/∂f = Wᵀ θ̈ - θ̇² m_ff + K_ff, ∂r_f/∂ḟ = -2θ̇ W + D_ff
        for k in 0..nf {
            let band = self.band[k].clone();
            let w_col = self.w.column(k, band.clone());
            for ((l, w_lk), kkl) in band.clone().zip(w_col).zip(self.kff.row(k, band)) {
                kt[(FLEX + k, FLEX + l)] += w_lk * tdd + kkl;
            }
        }
        if qv {
            for k in 0..nf {
                let band = self.band[k].clone();
                let (mff, w) = (self.mff.row(k, band.clone()), self.w.row(k, band.clone()));
                for ((l, m), wkl) in band.zip(mff).zip(w) {
                    kt[(FLEX + k, FLEX + l)] -= td * td * m;
                    ct[(FLEX + k, FLEX + l)] -= 2.0 * td * wkl;
                }
            }
        }
        if damping {
            for k in 0..nf {
                let band = self.band[k].clone();
                for (l, d) in band.clone().zip(self.dff.row(k, band)) {
                    ct[(FLEX + k, FLEX + l)] += d;
                }
            }
        }
        if self.geometric_stiffening {
            self.stiffening_tangent(&z, &mut kt);
            if damping && self.rayleigh_beta != 0.0 {
                self.stiffening_damping_tangents(&z, &zd, &mut kt, &mut ct);
            }
        }
    }

    /// World position and angle of a material point map, and their Jacobians over z.
    pub fn point<'a>(&self, map: &PointMap, z: impl Coords<'a>) -> (Vector2<f64>, f64) {
        let z = z.into();
        let f = z.rows(FLEX, self.nflex());
        let (ar, _) = self.turn.rot(z[THETA]);
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
        let nk = self.kept.len();
        let mut sp = DMatrix::zeros(2, nk);
        let mut sphi = DVector::zeros(nk);
        for p in 0..ELEMENT_DOFS {
            if let Some(k) = self.flex_index(3 * j + p) {
                sp[(0, k)] = s1[p];
                sp[(1, k)] = s2[p];
                sphi[k] = sl[p];
            }
        }
        let mut map = PointMap {
            s0: Vector2::new(x, 0.0),
            sp,
            sphi,
        };
        if let Some(phi) = &self.basis {
            reduce_map(&mut map, phi);
        }
        map
    }

    /// Static deformation under a transverse tip force, scaled to a tip displacement `tip`
    /// (tangent frame): the initial shape of case C1.
    /// Under modal truncation the shape is the static solution within the kept modes.
    pub fn static_tip_shape(&self, tip: f64) -> Option<DVector<f64>> {
        // the tip's transverse displacement per coordinate: the unit tip load, by reciprocity
        let load = self.flange_b.sp.row(1).transpose();
        if load.amax() == 0.0 {
            return None; // the frame holds the tip
        }
        let q = self.kff.to_dense().lu().solve(&load)?;
        let scale = tip / load.dot(&q);
        scale.is_finite().then(|| q * scale)
    }
}

/// The constant parts of an element's nonlinear strain (all elements of a beam are alike).
#[derive(Debug, Clone, Default)]
struct StrainRows {
    /// dv/dx as a row on the element's coordinates, at each point of `GAUSS_4`.
    slopes: [[f64; ELEMENT_DOFS]; 4],
    /// Σ w ds dsᵀ over the points: the Hessian of the element mean of v'²/2.
    hv: [[f64; ELEMENT_DOFS]; ELEMENT_DOFS],
}

impl StrainRows {
    fn new(l: f64) -> StrainRows {
        let mut r = StrainRows::default();
        for (g, &(xi, w)) in GAUSS_4.iter().enumerate() {
            let ds = planar_element::slope(xi, l);
            for p in 0..ELEMENT_DOFS {
                r.slopes[g][p] = ds[p];
                for q in 0..ELEMENT_DOFS {
                    r.hv[p][q] += w * ds[p] * ds[q];
                }
            }
        }
        r
    }
}

/// Expresses a point map in modal coordinates: S_p Φ and Φᵀ S_φ.
fn reduce_map(map: &mut PointMap, phi: &DMatrix<f64>) {
    map.sp = &map.sp * phi;
    map.sphi = phi.tr_mul(&map.sphi);
}
