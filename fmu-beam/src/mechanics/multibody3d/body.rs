//! A spatial body in quaternion coordinates z = [R, p, q_f]: its residual and mass matrix in
//! (z, ż, z̈) from the body's own form over v = [Ṙ, ω, q̇_f] (see the module doc).

use super::quaternion::{g_body, rotation};
use super::rigid_body::RigidBody3;
use crate::mechanics::beam::spatial_beam::{BeamProducts, SpatialBeam};
use nalgebra::{DMatrix, DMatrixViewMut, DVector, DVectorView, Matrix3, Vector3, Vector4};

/// Coordinates of the frame: R (3) and p (4).
pub const FRAME: usize = 7;

/// A body of the spatial system, with coordinates z = [R, p, q_f] (q_f empty for a rigid one).
#[derive(Debug, Clone)]
pub enum Body3 {
    /// A floating frame of a flexible beam: a whole beam or one of its substructures.
    Beam(Box<SpatialBeam>),
    /// A rigid body (or the rigid equivalent of a beam).
    Rigid(RigidBody3),
}

/// Position, quaternion and rotation matrix of a body's frame from its coordinates.
pub fn frame_of(z: &DVectorView<f64>) -> (Vector3<f64>, Vector4<f64>, Matrix3<f64>) {
    let r = Vector3::new(z[0], z[1], z[2]);
    let p = Vector4::new(z[3], z[4], z[5], z[6]);
    (r, p, rotation(&p))
}

impl Body3 {
    /// The body's name (a substructure's is `<beam>.<i>`).
    pub fn name(&self) -> &str {
        match self {
            Body3::Beam(b) => &b.name,
            Body3::Rigid(r) => &r.name,
        }
    }

    /// Number of deformation coordinates.
    pub fn nflex(&self) -> usize {
        match self {
            Body3::Beam(b) => b.nflex(),
            Body3::Rigid(_) => 0,
        }
    }

    /// Number of coordinates 7 + nf.
    pub fn ncoords(&self) -> usize {
        FRAME + self.nflex()
    }

    /// A rigid body of zero mass: its coordinates are algebraic (no inertia acts on them).
    pub fn is_massless(&self) -> bool {
        matches!(self, Body3::Rigid(r) if r.mass == 0.0)
    }

    /// Coordinate k is an angle (quaternion component or nodal rotation).
    pub fn is_angle(&self, k: usize) -> bool {
        match self {
            _ if k < 3 => false,
            _ if k < FRAME => true,
            Body3::Beam(b) => b.kept[k - FRAME] % 6 >= 3,
            Body3::Rigid(_) => false,
        }
    }

    /// The body's size (m): a beam's length, a rigid body's largest distance from its frame
    /// to a named frame; the system's length scale is the largest.
    pub fn length_scale(&self) -> f64 {
        match self {
            Body3::Beam(b) => b.length,
            Body3::Rigid(r) => r.frames.iter().map(|f| f.1.norm()).fold(0.0, f64::max),
        }
    }

    /// T = diag(I, 2 G(p), I): v = T ż.
    pub fn velocity_map(&self, p: &Vector4<f64>) -> DMatrix<f64> {
        let nf = self.nflex();
        let mut t = DMatrix::zeros(6 + nf, FRAME + nf);
        t.view_mut((0, 0), (3, 3))
            .copy_from(&Matrix3::<f64>::identity());
        t.view_mut((3, 3), (3, 4)).copy_from(&(g_body(p) * 2.0));
        for k in 0..nf {
            t[(6 + k, FRAME + k)] = 1.0;
        }
        t
    }

    /// Mass matrix over v.
    pub fn mass_matrix_v(&self, a: &Matrix3<f64>, f: DVectorView<f64>) -> DMatrix<f64> {
        match self {
            Body3::Beam(b) => b.mass_matrix_owned(a, f),
            Body3::Rigid(r) => r.mass_matrix(a),
        }
    }

    /// Mass matrix over ż: Tᵀ M_v T, block by block. T ([`Body3::velocity_map`]) is the
    /// identity but for ω = B ṗ (B = 2 G(p), 3 × 4), so the rows and columns of R and q_f copy
    /// M_v's and those of p are B's products with its ω rows and columns: the dense triple
    /// product spent most of its work on T's zeros (a fifth of the 3D roll-up's run went to
    /// the damping's mass matrices, one a body at every residual).
    pub fn mass_matrix(&self, z: DVectorView<f64>) -> DMatrix<f64> {
        let (_, p, a) = frame_of(&z);
        self.mass_matrix_over_z(&p, &self.mass_matrix_v(&a, z.rows(FRAME, self.nflex())))
    }

    /// The residual over ż and the mass matrix over ż at z, a beam's q_f-dependent inertia
    /// computed once for both (the beams' α damping needs the mass matrix of every body at
    /// every residual).
    pub fn residual_and_mass(
        &self,
        z: DVectorView<f64>,
        zd: DVectorView<f64>,
        zdd: DVectorView<f64>,
        g: &Vector3<f64>,
    ) -> (DVector<f64>, DMatrix<f64>) {
        let pr = self.products(&z, &zd, &zdd);
        let r = self.residual_with(pr.as_ref(), z, zd, zdd, g);
        let (_, p, a) = frame_of(&z);
        let mv = match (self, &pr) {
            (Body3::Beam(b), Some(pr)) => {
                let n = b.ndof();
                let mut mv = DMatrix::zeros(n, n);
                b.mass_matrix_of(&pr.inertia, &a, mv.view_mut((0, 0), (n, n)));
                mv
            }
            _ => self.mass_matrix_v(&a, z.rows(FRAME, self.nflex())),
        };
        (r, self.mass_matrix_over_z(&p, &mv))
    }

    /// Tᵀ M_v T for the mass matrix `mv` over v, at the frame's quaternion `p`.
    fn mass_matrix_over_z(&self, p: &Vector4<f64>, mv: &DMatrix<f64>) -> DMatrix<f64> {
        let nf = self.nflex();
        let b = g_body(p) * 2.0;
        // M_v's index of each coordinate of z that T maps to itself: R and q_f
        let kept = |k: usize| if k < 3 { k } else { k - 1 };
        let others = || (0..3).chain(FRAME..FRAME + nf);
        let n = FRAME + nf;
        let mut m = DMatrix::zeros(n, n);
        for i in others() {
            for j in others() {
                m[(i, j)] = mv[(kept(i), kept(j))];
            }
            // (M_v B)'s row i and (Bᵀ M_v)'s column i
            for c in 0..4 {
                let (mut right, mut left) = (0.0, 0.0);
                for w in 0..3 {
                    right += mv[(kept(i), 3 + w)] * b[(w, c)];
                    left += b[(w, c)] * mv[(3 + w, kept(i))];
                }
                m[(i, 3 + c)] = right;
                m[(3 + c, i)] = left;
            }
        }
        let bt_mww = b.transpose() * mv.fixed_view::<3, 3>(3, 3);
        m.fixed_view_mut::<4, 4>(3, 3).copy_from(&(bt_mww * b));
        m
    }

    /// Residual over v: inertia + internal − gravity.
    pub fn residual_v(
        &self,
        a: &Matrix3<f64>,
        f: DVectorView<f64>,
        v: &DVector<f64>,
        vd: &DVector<f64>,
        g: &Vector3<f64>,
    ) -> DVector<f64> {
        match self {
            Body3::Beam(b) => b.residual(a, f, v, vd, g),
            Body3::Rigid(r) => r.residual(a, v, vd, g),
        }
    }

    /// Residual over ż: Tᵀ r_v(A, q_f, T ż, T z̈) (ω̇ = 2 G p̈ since G(ṗ) ṗ = 0).
    pub fn residual(
        &self,
        z: DVectorView<f64>,
        zd: DVectorView<f64>,
        zdd: DVectorView<f64>,
        g: &Vector3<f64>,
    ) -> DVector<f64> {
        let pr = self.products(&z, &zd, &zdd);
        self.residual_with(pr.as_ref(), z, zd, zdd, g)
    }

    /// A beam's products at (z, ż, z̈) (`None` for a rigid body).
    fn products(
        &self,
        z: &DVectorView<f64>,
        zd: &DVectorView<f64>,
        zdd: &DVectorView<f64>,
    ) -> Option<BeamProducts> {
        match self {
            Body3::Beam(b) => {
                let nf = b.nflex();
                Some(b.products(z.rows(FRAME, nf), zd.rows(FRAME, nf), zdd.rows(FRAME, nf)))
            }
            Body3::Rigid(_) => None,
        }
    }

    /// [`Body3::residual`] with a beam's products `pr` (of this state) given; T and Tᵀ
    /// applied by blocks.
    fn residual_with(
        &self,
        pr: Option<&BeamProducts>,
        z: DVectorView<f64>,
        zd: DVectorView<f64>,
        zdd: DVectorView<f64>,
        g: &Vector3<f64>,
    ) -> DVector<f64> {
        let (_, p, a) = frame_of(&z);
        let gp = g_body(&p) * 2.0;
        let to_v = |x: DVectorView<f64>| {
            let mut v = DVector::zeros(x.len() - 1);
            v.rows_mut(0, 3).copy_from(&x.rows(0, 3));
            v.rows_mut(3, 3).copy_from(&(gp * x.fixed_rows::<4>(3)));
            v.rows_mut(6, x.len() - FRAME)
                .copy_from(&x.rows(FRAME, x.len() - FRAME));
            v
        };
        let (v, vd) = (to_v(zd), to_v(zdd));
        let f = z.rows(FRAME, self.nflex());
        let rv = match (self, pr) {
            (Body3::Beam(b), Some(pr)) => {
                b.residual_with(pr, &a, f, v.rows(0, v.len()), vd.rows(0, vd.len()), g)
            }
            _ => self.residual_v(&a, f, &v, &vd, g),
        };
        let mut r = DVector::zeros(z.len());
        r.rows_mut(0, 3).copy_from(&rv.rows(0, 3));
        r.fixed_rows_mut::<4>(3)
            .copy_from(&gp.tr_mul(&rv.fixed_rows::<3>(3)));
        r.rows_mut(FRAME, z.len() - FRAME)
            .copy_from(&rv.rows(6, z.len() - FRAME));
        r
    }

    /// K_t = ∂r/∂z and C_t = ∂r/∂ż by forward differences (step `eps` max(|x|, 1)) into
    /// n × n views. The residual depends neither on R nor on Ṙ (their columns are zero); a
    /// beam's products are computed once and a column that moves q_f or q̇_f updates them by
    /// one matrix column (`BeamProducts`).
    pub fn tangents(
        &self,
        z: DVectorView<f64>,
        zd: DVectorView<f64>,
        zdd: DVectorView<f64>,
        g: &Vector3<f64>,
        eps: f64,
        mut kt: DMatrixViewMut<f64>,
        mut ct: DMatrixViewMut<f64>,
    ) {
        let n = self.ncoords();
        let (mut z, mut zd) = (z.into_owned(), zd.into_owned());
        let pr0 = self.products(&z.rows(0, n), &zd.rows(0, n), &zdd);
        let r0 = self.residual_with(pr0.as_ref(), z.rows(0, n), zd.rows(0, n), zdd, g);
        let mut pr = pr0.clone();
        kt.columns_mut(0, 3).fill(0.0);
        ct.columns_mut(0, 3).fill(0.0);
        for k in 3..n {
            let x = z[k];
            let h = eps * x.abs().max(1.0);
            z[k] = x + h;
            let zk = z.rows(0, n);
            let rk = match (self, &pr0) {
                (Body3::Beam(b), Some(pr0)) if k >= FRAME => {
                    let pr = pr.as_mut().expect("a beam has products");
                    pr.clone_from(pr0);
                    b.shift_flex(pr, zk.rows(FRAME, n - FRAME), k - FRAME, h);
                    self.residual_with(Some(pr), zk, zd.rows(0, n), zdd, g)
                }
                _ => self.residual_with(pr0.as_ref(), zk, zd.rows(0, n), zdd, g),
            };
            z[k] = x;
            kt.column_mut(k).copy_from(&((rk - &r0) / h));
        }
        for k in 3..n {
            let x = zd[k];
            let h = eps * x.abs().max(1.0);
            zd[k] = x + h;
            let (zk, zdk) = (z.rows(0, n), zd.rows(0, n));
            let rk = match (self, &pr0) {
                (Body3::Beam(b), Some(pr0)) if k >= FRAME => {
                    let pr = pr.as_mut().expect("a beam has products");
                    pr.clone_from(pr0);
                    b.shift_flex_rate(pr, k - FRAME, h);
                    self.residual_with(Some(pr), zk, zdk, zdd, g)
                }
                _ => self.residual_with(pr0.as_ref(), zk, zdk, zdd, g),
            };
            zd[k] = x;
            ct.column_mut(k).copy_from(&((rk - &r0) / h));
        }
    }

    /// Kinetic energy ½ vᵀ M_v v (J).
    pub fn kinetic_energy(&self, z: DVectorView<f64>, zd: DVectorView<f64>) -> f64 {
        let (_, p, a) = frame_of(&z);
        let v = self.velocity_map(&p) * zd;
        let mv = self.mass_matrix_v(&a, z.rows(FRAME, self.nflex()));
        0.5 * v.dot(&(mv * &v))
    }

    /// Strain energy (J).
    pub fn strain_energy(&self, z: DVectorView<f64>) -> f64 {
        match self {
            Body3::Beam(b) => b.strain_energy(z.rows(FRAME, b.nflex())),
            Body3::Rigid(_) => 0.0,
        }
    }

    /// Potential energy of gravity (J).
    pub fn gravity_energy(&self, z: DVectorView<f64>, g: &Vector3<f64>) -> f64 {
        let (r, _, a) = frame_of(&z);
        match self {
            Body3::Beam(b) => b.gravity_energy(&r, &a, z.rows(FRAME, b.nflex()), g),
            Body3::Rigid(rb) => rb.gravity_energy(&r, &a, g),
        }
    }
}
