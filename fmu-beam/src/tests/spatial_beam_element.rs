//! Element checks of the spatial floating-frame beam (issue 4): the element matrices against
//! closed forms and direct quadrature, clamped-beam frequencies (both bending planes, torsion)
//! against their exact values with the convergence over elements printed, the full mass
//! matrix against direct integration of the kinetic energy, the quadratic-velocity vector
//! against Lagrange's equations, gravity against its potential, the planar reduction (in-plane
//! states give the planar beam's terms to 1e-12), the frozen-inertia variant and the beam from
//! a matrix file (parser refusals, the element's own matrices reproducing the element).
//!
//! Over 600 lines on purpose: the spatial element's checks, one test per property, read as one
//! list.

use crate::mechanics::beam::planar_beam::{PlanarBeam, FLEX as PFLEX};
use crate::mechanics::beam::planar_element::GAUSS_4;
use crate::mechanics::beam::spatial_beam::{
    skew, InertiaModel, SpatialBeam, SpatialBeamProps, FLEX, OMEGA,
};
use crate::mechanics::beam::spatial_element::{self, ELEMENT_DOFS, NODE_DOFS, TX, TY, TZ, U, V, W};
use crate::mechanics::beam::spatial_section::SpatialSection;
use crate::mechanics::from_scene::matrix_file_beam;
use crate::mechanics::FloatingFrame;
use crate::scene::matrix_file::{self, MatrixFile, MatrixFileError};
use nalgebra::{DMatrix, DVector, Matrix3, Rotation3, Vector2, Vector3};

/// Deterministic pseudo-random numbers in [-1, 1].
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
    fn vec(&mut self, n: usize, scale: f64) -> DVector<f64> {
        DVector::from_fn(n, |_, _| scale * self.next())
    }
    fn vec3(&mut self, scale: f64) -> Vector3<f64> {
        Vector3::new(self.next(), self.next(), self.next()) * scale
    }
    fn rotation(&mut self) -> Matrix3<f64> {
        Rotation3::from_scaled_axis(self.vec3(2.0)).into_inner()
    }
}

/// Case C5's beam (3D paper §5.1): steel, a = 0.02, b = 0.06285, constants as the paper's
/// table; I_y ≈ 10 I_z.
fn c5_section() -> SpatialSection {
    SpatialSection::given(0.02 * 0.06285, 4.138e-7, 4.19e-8, 1.33242e-7)
}

fn props(length: f64, elements: usize, frame: FloatingFrame) -> SpatialBeamProps {
    SpatialBeamProps {
        length,
        elements,
        frame,
        rho: 7800.0,
        e: 210e9,
        g: 8.077e10,
        section: c5_section(),
        rayleigh_alpha: 1e-3,
        rayleigh_beta: 5e-5,
        inertia: InertiaModel::Full,
    }
}

fn beam(frame: FloatingFrame, n: usize) -> SpatialBeam {
    SpatialBeam::new("b", &props(0.8, n, frame))
}

fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax()
}

fn rel_v(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).amax() / b.amax()
}

/// Shape rows (3 × nf), twist row (nf) at (element j, ξ), over the kept coordinates.
fn reduced_rows(b: &SpatialBeam, j: usize, xi: f64) -> (DMatrix<f64>, DVector<f64>) {
    let l = b.length / b.elements as f64;
    let sh = spatial_element::shape(xi, l);
    let tw = spatial_element::twist(xi);
    let nf = b.nflex();
    let mut s = DMatrix::zeros(3, nf);
    let mut t = DVector::zeros(nf);
    for p in 0..ELEMENT_DOFS {
        if let Some(k) = b.flex_index(NODE_DOFS * j + p) {
            for i in 0..3 {
                s[(i, k)] = sh[i][p];
            }
            t[k] = tw[p];
        }
    }
    (s, t)
}

struct State {
    a: Matrix3<f64>,
    f: DVector<f64>,
    v: DVector<f64>,
}

fn random_state(b: &SpatialBeam, rng: &mut Lcg) -> State {
    State {
        a: rng.rotation(),
        f: rng.vec(b.nflex(), 0.02),
        v: rng.vec(b.ndof(), 2.0),
    }
}

/// M = Σ ρ LᵀL over Gauss points, L = [I, −A ũ, A S], plus ρI_p (e_xᵀ ω + θxᵀ q̇_f)².
fn direct_mass(b: &SpatialBeam, p: &SpatialBeamProps, s: &State) -> DMatrix<f64> {
    let (n, nf) = (b.ndof(), b.nflex());
    let l = b.length / b.elements as f64;
    let mu = p.rho * p.section.area;
    let rho_ip = p.rho * p.section.polar_moment;
    let mut m = DMatrix::zeros(n, n);
    for j in 0..b.elements {
        for &(xi, w) in &GAUSS_4 {
            let (sh, tw) = reduced_rows(b, j, xi);
            let u = Vector3::new((j as f64 + xi) * l, 0.0, 0.0) + &sh * &s.f;
            let u = Vector3::new(u[0], u[1], u[2]);
            let mut lm = DMatrix::zeros(3, n);
            lm.view_mut((0, 0), (3, 3)).copy_from(&Matrix3::identity());
            lm.view_mut((0, OMEGA), (3, 3))
                .copy_from(&(-s.a * skew(&u)));
            lm.view_mut((0, FLEX), (3, nf)).copy_from(&(s.a * &sh));
            m += lm.transpose() * lm * (mu * l * w);
            let mut rr = DVector::zeros(n);
            rr[OMEGA] = 1.0;
            rr.rows_mut(FLEX, nf).copy_from(&tw);
            m += &rr * rr.transpose() * (rho_ip * l * w);
        }
    }
    m
}

/// Kinetic energy by quadrature of ½ρ|ṙ|² + ½ρI_p(ω_x + θ̇x)², ṙ = Ṙ + A(ω × ū + S q̇_f).
fn direct_kinetic_energy(b: &SpatialBeam, p: &SpatialBeamProps, s: &State) -> f64 {
    let nf = b.nflex();
    let l = b.length / b.elements as f64;
    let mu = p.rho * p.section.area;
    let rho_ip = p.rho * p.section.polar_moment;
    let rd = Vector3::new(s.v[0], s.v[1], s.v[2]);
    let w = Vector3::new(s.v[OMEGA], s.v[OMEGA + 1], s.v[OMEGA + 2]);
    let fd = s.v.rows(FLEX, nf);
    let mut t = 0.0;
    for j in 0..b.elements {
        for &(xi, wg) in &GAUSS_4 {
            let (sh, tw) = reduced_rows(b, j, xi);
            let d = &sh * &s.f;
            let u = Vector3::new((j as f64 + xi) * l + d[0], d[1], d[2]);
            let sfd = &sh * fd;
            let rdot = rd + s.a * (w.cross(&u) + Vector3::new(sfd[0], sfd[1], sfd[2]));
            let spin = w.x + tw.dot(&fd);
            t += 0.5 * l * wg * (mu * rdot.norm_squared() + rho_ip * spin * spin);
        }
    }
    t
}

#[test]
fn element_mass_equals_quadrature_of_shape_products() {
    let (mu, rho_ip, l) = (3.1, 2.3e-4, 0.25);
    let m = spatial_element::mass(mu, rho_ip, l);
    for i in 0..ELEMENT_DOFS {
        for j in 0..ELEMENT_DOFS {
            let mut q = 0.0;
            for &(xi, w) in &GAUSS_4 {
                let s = spatial_element::shape(xi, l);
                let t = spatial_element::twist(xi);
                q += w
                    * l
                    * (mu * (0..3).map(|r| s[r][i] * s[r][j]).sum::<f64>() + rho_ip * t[i] * t[j]);
            }
            assert!(
                (q - m[i][j]).abs() <= 1e-15 * mu * l,
                "M[{i}][{j}] {} vs quadrature {q}",
                m[i][j]
            );
        }
    }
    // the textbook entries of both bending planes, the bar and the torsion block
    let c = mu * l / 420.0;
    let checks = [
        (U, U, mu * l / 3.0),
        (U, NODE_DOFS + U, mu * l / 6.0),
        (TX, TX, rho_ip * l / 3.0),
        (TX, NODE_DOFS + TX, rho_ip * l / 6.0),
        (V, V, 156.0 * c),
        (V, TZ, 22.0 * l * c),
        (V, NODE_DOFS + TZ, -13.0 * l * c),
        (W, W, 156.0 * c),
        (W, TY, -22.0 * l * c),
        (W, NODE_DOFS + TY, 13.0 * l * c),
        (TY, TY, 4.0 * l * l * c),
        (TY, NODE_DOFS + TY, -3.0 * l * l * c),
    ];
    for (i, j, v) in checks {
        assert!(
            (m[i][j] - v).abs() < 1e-15,
            "M[{i}][{j}] {} vs {v}",
            m[i][j]
        );
    }
}

#[test]
fn element_stiffness_closed_forms() {
    let (ea, gj, eiy, eiz, l) = (4.2e8, 1.1e4, 8.7e4, 8.8e3, 0.3);
    let k = spatial_element::stiffness(ea, gj, eiy, eiz, l);
    let (l2, l3) = (l * l, l * l * l);
    let checks = [
        (U, U, ea / l),
        (U, NODE_DOFS + U, -ea / l),
        (TX, TX, gj / l),
        (TX, NODE_DOFS + TX, -gj / l),
        (V, V, 12.0 * eiz / l3),
        (V, TZ, 6.0 * eiz / l2),
        (V, NODE_DOFS + V, -12.0 * eiz / l3),
        (TZ, TZ, 4.0 * eiz / l),
        (TZ, NODE_DOFS + TZ, 2.0 * eiz / l),
        (W, W, 12.0 * eiy / l3),
        (W, TY, -6.0 * eiy / l2),
        (W, NODE_DOFS + TY, -6.0 * eiy / l2),
        (TY, TY, 4.0 * eiy / l),
        (TY, NODE_DOFS + TY, 2.0 * eiy / l),
        (NODE_DOFS + W, NODE_DOFS + TY, 6.0 * eiy / l2),
    ];
    for (i, j, v) in checks {
        assert!(
            (k[i][j] - v).abs() <= 1e-12 * v.abs(),
            "K[{i}][{j}] {} vs {v}",
            k[i][j]
        );
        assert_eq!(k[i][j], k[j][i]);
    }
    // no coupling between the four fields
    let field = |i: usize| match i % NODE_DOFS {
        U => 0,
        TX => 1,
        V | TZ => 2,
        _ => 3,
    };
    for i in 0..ELEMENT_DOFS {
        for j in 0..ELEMENT_DOFS {
            if field(i) != field(j) {
                assert_eq!(k[i][j], 0.0);
            }
        }
    }
}

/// A clamped cantilever of N elements under tip loads: Hermite and linear elements are exact
/// at the nodes, so δ_y = PL³/(3EI_z), δ_z = PL³/(3EI_y) with slope θ_y = −PL²/(2EI_y),
/// φ = TL/(GJ_t), δ_x = PL/(EA).
#[test]
fn cantilever_static_tip_loads() {
    let p = props(1.3, 5, FloatingFrame::Tangent);
    let b = SpatialBeam::new("b", &p);
    let s = &p.section;
    let tip = NODE_DOFS * p.elements;
    let solve = |dof: usize, load: f64| {
        let mut rhs = DVector::zeros(b.nflex());
        rhs[b.flex_index(tip + dof).unwrap()] = load;
        b.kff.clone().cholesky().unwrap().solve(&rhs)
    };
    let at = |q: &DVector<f64>, dof: usize| q[b.flex_index(tip + dof).unwrap()];
    let l = p.length;
    let cases = [
        (V, V, 1.0, l.powi(3) / (3.0 * p.e * s.iz)),
        (V, TZ, 1.0, l.powi(2) / (2.0 * p.e * s.iz)),
        (W, W, 1.0, l.powi(3) / (3.0 * p.e * s.iy)),
        (W, TY, 1.0, -l.powi(2) / (2.0 * p.e * s.iy)),
        (TX, TX, 1.0, l / (p.g * s.torsion_constant)),
        (U, U, 1.0, l / (p.e * s.area)),
    ];
    for (load, read, f, exact) in cases {
        let q = solve(load, f);
        let got = at(&q, read);
        assert!(
            (got / exact - 1.0).abs() < 1e-10,
            "load {load}, read {read}: {got:e} vs {exact:e}"
        );
    }
}

/// Generalized eigenvalues of K φ = ω² M φ (ascending ω, rad/s), through the flexibility
/// form L_K⁻¹ M L_K⁻ᵀ (K = L_K L_Kᵀ): its largest eigenvalues 1/ω² are the lowest modes, so
/// these come out with full relative precision however fine the mesh. K and M are first
/// scaled by diag(K)^(-1/2), which balances lengths against slopes.
fn frequencies(k: &DMatrix<f64>, m: &DMatrix<f64>) -> Vec<f64> {
    let d = DMatrix::from_diagonal(&k.diagonal().map(|x| 1.0 / x.sqrt()));
    let (k, m) = (&d * k * &d, &d * m * &d);
    let l = k.cholesky().expect("clamped K_ff positive definite").l();
    let x = l.solve_lower_triangular(&m).unwrap();
    let c = l.solve_lower_triangular(&x.transpose()).unwrap();
    let c = (&c + c.transpose()) * 0.5;
    let mut w: Vec<f64> = c
        .symmetric_eigen()
        .eigenvalues
        .iter()
        .map(|&x| 1.0 / x.sqrt())
        .collect();
    w.sort_by(|a, b| a.partial_cmp(b).unwrap());
    w
}

/// Frequencies of the kept coordinates whose nodal type is in `types`.
fn field_frequencies(b: &SpatialBeam, types: &[usize]) -> Vec<f64> {
    let idx: Vec<usize> = (0..b.nflex())
        .filter(|&k| types.contains(&(b.kept[k] % NODE_DOFS)))
        .collect();
    let pick = |m: &DMatrix<f64>| m.select_rows(idx.iter()).select_columns(idx.iter());
    frequencies(&pick(&b.kff), &pick(&b.mff))
}

const BETA_L: [f64; 5] = [
    1.875_104_069,
    4.694_091_133,
    7.854_757_438,
    10.995_540_73,
    14.137_168_39,
];

/// C1 repeated about both bending axes and in torsion (issue 4), on C5's section
/// (I_y ≈ 10 I_z): clamped at flange a (tangent frame), L = 1.
/// Bending: ω_n = (β_n L)² sqrt(EI/(ρA L⁴)); torsion: ω_n = (2n−1)π/(2L) sqrt(GJ_t/(ρI_p)).
/// Hermite elements converge as h⁴, linear torsion elements as h²; the torsion (and axial)
/// frequencies of linear consistent-mass elements also have a discrete closed form,
/// ω_h² = (6c²/h²)(1 − cos κh)/(2 + cos κh), κ = (2n−1)π/(2L), checked to 1e-10.
#[test]
fn clamped_frequencies_converge_to_exact_in_both_planes_and_torsion() {
    let base = props(1.0, 1, FloatingFrame::Tangent);
    let s = base.section;
    let mu = base.rho * s.area;
    let l = base.length;
    let bend = |ei: f64, n: usize| BETA_L[n].powi(2) * (ei / (mu * l.powi(4))).sqrt();
    let c_t = (base.g * s.torsion_constant / (base.rho * s.polar_moment)).sqrt();
    let c_a = (base.e / base.rho).sqrt();
    let kappa = |n: usize| (2 * n + 1) as f64 * std::f64::consts::PI / (2.0 * l);
    let discrete = |c: f64, n: usize, h: f64| {
        let ch = (kappa(n) * h).cos();
        (6.0 * c * c / (h * h) * (1.0 - ch) / (2.0 + ch)).sqrt()
    };
    println!("relative error of the clamped frequencies (FE/exact - 1)");
    println!(
        "{:>4} | {:>10} {:>10} {:>10} {:>10} {:>10} | {:>10} {:>10} {:>10} | {:>10} {:>10} {:>10}",
        "N", "z-bend 1", "2", "3", "4", "5", "y-bend 1", "2", "3", "torsion 1", "2", "3"
    );
    let mut err_z: Vec<Vec<f64>> = Vec::new();
    let mut err_t: Vec<Vec<f64>> = Vec::new();
    let counts = [1, 2, 4, 8, 16, 32, 64];
    for &n in &counts {
        let b = SpatialBeam::new("b", &props(l, n, FloatingFrame::Tangent));
        let h = l / n as f64;
        let wv = field_frequencies(&b, &[V, TZ]);
        let ww = field_frequencies(&b, &[W, TY]);
        let wt = field_frequencies(&b, &[TX]);
        let wa = field_frequencies(&b, &[U]);
        // the x–z plane is the x–y plane with I_y for I_z: same spectrum scaled (to the
        // eigensolver's rounding, about 2e-10 at N = 64)
        let scale = (s.iy / s.iz).sqrt();
        for (a, b) in wv.iter().zip(&ww).take(5) {
            assert!(
                (b / (a * scale) - 1.0).abs() < 1e-8,
                "plane symmetry {a} {b}"
            );
        }
        for k in 0..wt.len().min(5) {
            let dt = discrete(c_t, k, h);
            let da = discrete(c_a, k, h);
            assert!((wt[k] / dt - 1.0).abs() < 1e-10, "torsion N={n} mode {k}");
            assert!((wa[k] / da - 1.0).abs() < 1e-10, "axial N={n} mode {k}");
        }
        let ez: Vec<f64> = (0..5)
            .map(|k| {
                wv.get(k)
                    .map_or(f64::NAN, |w| w / bend(base.e * s.iz, k) - 1.0)
            })
            .collect();
        let ey: Vec<f64> = (0..3)
            .map(|k| {
                ww.get(k)
                    .map_or(f64::NAN, |w| w / bend(base.e * s.iy, k) - 1.0)
            })
            .collect();
        let et: Vec<f64> = (0..3)
            .map(|k| wt.get(k).map_or(f64::NAN, |w| w / (kappa(k) * c_t) - 1.0))
            .collect();
        println!(
            "{n:>4} | {:>10.2e} {:>10.2e} {:>10.2e} {:>10.2e} {:>10.2e} | {:>10.2e} {:>10.2e} {:>10.2e} | {:>10.2e} {:>10.2e} {:>10.2e}",
            ez[0], ez[1], ez[2], ez[3], ez[4], ey[0], ey[1], ey[2], et[0], et[1], et[2]
        );
        err_z.push(ez);
        err_t.push(et);
    }
    let at = |n: usize| counts.iter().position(|&c| c == n).unwrap();
    // consistent mass: frequencies from above
    for e in err_z
        .iter()
        .chain(&err_t)
        .flatten()
        .filter(|e| e.is_finite())
    {
        assert!(
            *e > -1e-9,
            "a consistent-mass frequency below the exact one: {e}"
        );
    }
    // Hermite: N = 32 within 1e-4 for modes 1–5, N = 10-like accuracy on mode 1 already at 8
    for k in 0..5 {
        assert!(err_z[at(32)][k] < 1e-4, "bending mode {} at N = 32", k + 1);
    }
    assert!(err_z[at(8)][0] < 1e-5, "bending mode 1 at N = 8");
    // fourth order in h for bending, second for torsion
    let order = |e: &Vec<Vec<f64>>, k: usize, n: usize| (e[at(n)][k] / e[at(2 * n)][k]).log2();
    for k in 0..3 {
        let p = order(&err_z, k, 16);
        assert!((p - 4.0).abs() < 0.3, "bending mode {} order {p}", k + 1);
        let q = order(&err_t, k, 32);
        assert!((q - 2.0).abs() < 0.1, "torsion mode {} order {q}", k + 1);
        assert!(err_t[at(64)][k] < 2e-3, "torsion mode {} at N = 64", k + 1);
    }
}

#[test]
fn mass_matrix_equals_direct_integration_and_kinetic_energy() {
    let mut rng = Lcg(7);
    for frame in [FloatingFrame::Tangent, FloatingFrame::Pinned] {
        let p = props(0.8, 4, frame);
        let b = SpatialBeam::new("b", &p);
        for _ in 0..3 {
            let s = random_state(&b, &mut rng);
            let m = b.mass_matrix_owned(&s.a, &s.f);
            let md = direct_mass(&b, &p, &s);
            let err = rel(&m, &md);
            let sym = (&m - m.transpose()).amax() / m.amax();
            let t = b.kinetic_energy(&s.a, &s.f, &s.v);
            let td = direct_kinetic_energy(&b, &p, &s);
            println!(
                "{frame:?}: |M - ∫ρLᵀL|/|M| = {err:.1e}, T/T_direct - 1 = {:.1e}",
                t / td - 1.0
            );
            assert!(
                err < 1e-13,
                "{frame:?}: mass matrix relative difference {err:e}"
            );
            assert!(sym < 1e-15, "{frame:?}: asymmetry {sym:e}");
            assert!((t / td - 1.0).abs() < 1e-13, "{frame:?}: T {t} vs {td}");
        }
    }
}

/// Right Jacobian of the rotation vector: A = A0 exp(ψ̃) ⇒ ω = J_r(ψ) ψ̇ (body frame).
fn jr(psi: &Vector3<f64>) -> Matrix3<f64> {
    let p = psi.norm();
    let k = skew(psi);
    // (1 − cos p)/p² = 2 sin²(p/2)/p² without cancellation; (p − sin p)/p³ by its series
    // where it would cancel
    let a = if p > 0.0 {
        2.0 * (0.5 * p).sin().powi(2) / (p * p)
    } else {
        0.5
    };
    let b = if p < 1e-2 {
        1.0 / 6.0 - p * p / 120.0 + p.powi(4) / 5040.0
    } else {
        (p - p.sin()) / p.powi(3)
    };
    Matrix3::identity() - k * a + k * k * b
}

/// h must be the generalized inertia force of Lagrange's equations at v̇ = 0. With the local
/// coordinates q = (R, ψ, q_f), A = A0 exp(ψ̃), v = [Ṙ; J_r(ψ) ψ̇; q̇_f] and T = ½ vᵀ M v:
/// at ψ = 0, q̈ = 0 gives v̇ = 0 (J̇_r ψ̇ = −½ ψ̇ × ψ̇ = 0), so h = d/dt(∂T/∂q̇) − ∂T/∂q, both
/// by central differences.
#[test]
fn quadratic_velocity_vector_follows_from_lagrange() {
    let mut rng = Lcg(11);
    // J_r itself against differences of the exponential map
    {
        let (a0, psi, pd) = (rng.rotation(), rng.vec3(0.8), rng.vec3(1.0));
        let at = |t: f64| a0 * Rotation3::from_scaled_axis(psi + pd * t).into_inner();
        let eps = 1e-6;
        let ad = (at(eps) - at(-eps)) / (2.0 * eps);
        let w = jr(&psi) * pd;
        assert!((at(0.0).transpose() * ad - skew(&w)).amax() < 1e-8);
    }
    for frame in [FloatingFrame::Tangent, FloatingFrame::Pinned] {
        let b = beam(frame, 3);
        let (n, nf) = (b.ndof(), b.nflex());
        for _ in 0..3 {
            let s = random_state(&b, &mut rng);
            // q = [R, ψ, f], q̇ = [Ṙ, ψ̇, ḟ]
            let split = |q: &DVector<f64>| {
                let psi = Vector3::new(q[3], q[4], q[5]);
                let a = s.a * Rotation3::from_scaled_axis(psi).into_inner();
                (psi, a, q.rows(FLEX, nf).into_owned())
            };
            let velocity = |psi: &Vector3<f64>, qd: &DVector<f64>| {
                let mut v = qd.clone();
                let w = jr(psi) * Vector3::new(qd[3], qd[4], qd[5]);
                v.rows_mut(OMEGA, 3).copy_from(&w);
                v
            };
            let energy = |q: &DVector<f64>, qd: &DVector<f64>| {
                let (psi, a, f) = split(q);
                b.kinetic_energy(&a, &f, &velocity(&psi, qd))
            };
            let momentum = |q: &DVector<f64>, qd: &DVector<f64>| {
                let (psi, a, f) = split(q);
                let mut p = b.mass_matrix_owned(&a, &f) * velocity(&psi, qd);
                let pw = jr(&psi).transpose() * Vector3::new(p[3], p[4], p[5]);
                p.rows_mut(OMEGA, 3).copy_from(&pw);
                p
            };
            let mut q = DVector::zeros(n);
            q.rows_mut(FLEX, nf).copy_from(&s.f);
            let qd = s.v.clone();
            let eps = 1e-6;
            let dp =
                (momentum(&(&q + &qd * eps), &qd) - momentum(&(&q - &qd * eps), &qd)) / (2.0 * eps);
            let mut dt = DVector::zeros(n);
            for k in 0..n {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[k] += eps;
                qm[k] -= eps;
                dt[k] = (energy(&qp, &qd) - energy(&qm, &qd)) / (2.0 * eps);
            }
            let lagrange = dp - dt;
            let h = b.quadratic_velocity(&s.a, &s.f, &s.v);
            let err = rel_v(&h, &lagrange);
            println!("{frame:?}: |h - Lagrange|/|h| = {err:.1e}");
            assert!(
                err < 1e-7,
                "{frame:?}: relative difference {err:e}\n{h}\n{lagrange}"
            );
        }
    }
}

/// The generalized gravity force is minus the gradient of the potential (rotations as
/// A exp(δπ̃), δπ in the body frame, matching ω).
#[test]
fn gravity_is_the_gradient_of_the_potential() {
    let mut rng = Lcg(5);
    let b = beam(FloatingFrame::Pinned, 3);
    let g = Vector3::new(1.3, -9.81, 2.0);
    let s = random_state(&b, &mut rng);
    let r0 = rng.vec3(1.0);
    let q = b.gravity_force(&s.a, &s.f, &g);
    let eps = 1e-6;
    for k in 0..b.ndof() {
        let pot = |e: f64| {
            let (mut r, mut a, mut f) = (r0, s.a, s.f.clone());
            match k {
                0..=2 => r[k] += e,
                3..=5 => a *= Rotation3::from_scaled_axis(Vector3::ith(k - 3, e)).into_inner(),
                _ => f[k - FLEX] += e,
            }
            b.gravity_energy(&r, &a, &f, &g)
        };
        let dv = (pot(eps) - pot(-eps)) / (2.0 * eps);
        assert!(
            (q[k] + dv).abs() < 1e-6 * (1.0 + dv.abs()),
            "coordinate {k}: {} vs {}",
            q[k],
            -dv
        );
    }
}

/// The residual, evaluated by blocks, equals M v̇ + h − Q_g + [0; 0; K_ff q_f + D_ff q̇_f]
/// from the full matrices, in both inertia models.
#[test]
fn residual_equals_mass_times_acceleration_plus_forces() {
    let mut rng = Lcg(11);
    for model in [InertiaModel::Full, InertiaModel::Frozen] {
        let p = SpatialBeamProps {
            rayleigh_alpha: 3.0,
            rayleigh_beta: 1e-4,
            inertia: model,
            ..props(0.8, 3, FloatingFrame::Tangent)
        };
        let b = SpatialBeam::new("b", &p);
        let nf = b.nflex();
        for _ in 0..3 {
            let s = random_state(&b, &mut rng);
            let vd = rng.vec(b.ndof(), 5.0);
            let g = rng.vec3(9.81);
            let r = b.residual(&s.a, &s.f, &s.v, &vd, &g);
            let mut parts = b.mass_matrix_owned(&s.a, &s.f) * &vd
                + b.quadratic_velocity(&s.a, &s.f, &s.v)
                - b.gravity_force(&s.a, &s.f, &g);
            let mut pf = parts.rows_mut(FLEX, nf);
            pf += b.internal_force(&s.f, s.v.rows(FLEX, nf));
            let err = rel_v(&r, &parts);
            println!("{model:?}: |r − parts|/|parts| = {err:.1e}");
            assert!(err < 1e-13, "{model:?}: {err:e}");
        }
    }
}

#[test]
fn zero_force_at_rest_and_steady_spin() {
    let b = beam(FloatingFrame::Tangent, 4);
    let (n, nf) = (b.ndof(), b.nflex());
    let a = Rotation3::from_scaled_axis(Vector3::new(0.3, -0.2, 0.9)).into_inner();
    let zero = DVector::zeros(n);
    let f0 = DVector::zeros(nf);
    let r = b.residual(&a, &f0, &zero, &zero, &Vector3::zeros());
    assert_eq!(r.amax(), 0.0, "residual at rest {r}");
    // spin about z (or y): centripetal force −m Ω² L/2 along the axis, axial load only
    for axis in [1, 2] {
        let omega = 3.0;
        let mut v = DVector::zeros(n);
        v[OMEGA + axis] = omega;
        let h = b.quadratic_velocity(&Matrix3::identity(), &f0, &v);
        assert!((h[0] + b.mass * omega * omega * b.length / 2.0).abs() < 1e-9);
        for k in 1..FLEX {
            assert!(h[k].abs() < 1e-12, "axis {axis}: frame row {k} = {}", h[k]);
        }
        for (k, &full) in b.kept.iter().enumerate() {
            let load = h[FLEX + k];
            if full % NODE_DOFS == U {
                assert!(load < 0.0, "axial dof {full} must be pulled outwards");
            } else {
                assert!(load.abs() < 1e-12, "axis {axis}: load {load} on {full}");
            }
        }
    }
    // spin about the beam's own axis: no force at all on the undeformed beam
    let mut v = DVector::zeros(n);
    v[OMEGA] = 5.0;
    assert!(b.quadratic_velocity(&a, &f0, &v).amax() < 1e-12);
}

/// For in-plane states (R_z = 0, A = R_z(θ), q_f in u, v, θz) the spatial beam's in-plane
/// blocks (R_x, R_y, ω_z, in-plane q_f) equal the planar beam's to 1e-12, and the
/// out-of-plane rows of the residual vanish: planar motion stays planar.
#[test]
fn planar_reduction_equals_the_planar_beam() {
    let mut rng = Lcg(23);
    for frame in [FloatingFrame::Tangent, FloatingFrame::Pinned] {
        let n_el = 4;
        let p = SpatialBeamProps {
            section: SpatialSection::rectangle(0.02, 0.01),
            ..props(0.8, n_el, frame)
        };
        let sb = SpatialBeam::new("s", &p);
        let pb = PlanarBeam::new(
            "p",
            p.length,
            n_el,
            frame,
            p.rho,
            p.e,
            p.section.planar(),
            p.rayleigh_alpha,
            p.rayleigh_beta,
        );
        // planar velocity index → spatial velocity index
        let planar_to_spatial = [0, 1, OMEGA + 2, U, V, TZ];
        let mut map: Vec<usize> = vec![0, 1, OMEGA + 2];
        for &full in &pb.kept {
            let (node, d) = (full / 3, full % 3);
            let sfull = NODE_DOFS * node + planar_to_spatial[3 + d];
            map.push(FLEX + sb.flex_index(sfull).expect("in-plane coordinate kept"));
        }
        let out: Vec<usize> = (0..sb.ndof()).filter(|k| !map.contains(k)).collect();
        for _ in 0..3 {
            let np = pb.ndof();
            let mut z = rng.vec(np, 1.0);
            for k in PFLEX..np {
                z[k] *= 0.02;
            }
            let (zd, zdd) = (rng.vec(np, 2.0), rng.vec(np, 3.0));
            let g = Vector2::new(0.7, -9.81);
            let lift = |x: &DVector<f64>| {
                let mut y = DVector::zeros(sb.ndof());
                for (i, &k) in map.iter().enumerate() {
                    y[k] = x[i];
                }
                y
            };
            let a = Rotation3::from_axis_angle(&Vector3::z_axis(), z[2]).into_inner();
            let fs = lift(&z).rows(FLEX, sb.nflex()).into_owned();
            let (v, vd) = (lift(&zd), lift(&zdd));
            let g3 = Vector3::new(g.x, g.y, 0.0);
            // mass matrix
            let ms = sb.mass_matrix_owned(&a, &fs);
            let mut mp = DMatrix::zeros(np, np);
            pb.mass_matrix(&z, mp.view_mut((0, 0), (np, np)));
            let ms_in = ms.select_rows(map.iter()).select_columns(map.iter());
            let em = rel(&ms_in, &mp);
            // residual (inertia, quadratic velocity, internal, gravity)
            let rs = sb.residual(&a, &fs, &v, &vd, &g3);
            let mut rp = vec![0.0; np];
            pb.residual(&z, &zd, &zdd, Some(g), &mut rp);
            let rp = DVector::from_vec(rp);
            let rs_in = rs.select_rows(map.iter());
            let er = rel_v(&rs_in, &rp);
            let e_out = rs.select_rows(out.iter()).amax() / rp.amax();
            let m_out = ms.select_rows(out.iter()).select_columns(map.iter()).amax() / mp.amax();
            println!("{frame:?}: mass {em:.1e}, residual {er:.1e}, out-of-plane rows {e_out:.1e}");
            assert!(
                em < 1e-12,
                "{frame:?}: in-plane mass blocks differ by {em:e}"
            );
            assert!(er < 1e-12, "{frame:?}: in-plane residual differs by {er:e}");
            assert!(e_out < 1e-12, "{frame:?}: out-of-plane residual {e_out:e}");
            assert!(
                m_out < 1e-12,
                "{frame:?}: in/out-of-plane mass coupling {m_out:e}"
            );
        }
    }
}

/// Substructures: k parts of length L/k hold the whole mass; each part is the same beam.
#[test]
fn substructures_split_the_beam() {
    let p = props(1.0, 2, FloatingFrame::Tangent);
    let whole = SpatialBeam::new(
        "w",
        &SpatialBeamProps {
            elements: 10,
            ..p.clone()
        },
    );
    let k = 5;
    let part = SpatialBeam::part_of(&p, "w.substructure0", p.length / k as f64);
    assert!((part.length - 0.2).abs() < 1e-15);
    assert_eq!(part.elements, 2);
    assert!((part.mass * k as f64 - whole.mass).abs() < 1e-12 * whole.mass);
    assert_eq!(part.name, "w.substructure0");
    // flange b of the part at its own length
    assert!((part.flange_b.s0.x - 0.2).abs() < 1e-15);
}

/// The frozen inertia (3D paper §6) equals the full model at q_f = 0 (so the constants from
/// the nodal mass matrix's modes equal the shape integrals), ignores q_f, and drops the
/// Coriolis coupling with q̇_f; the test prints how far it is from the full model at a
/// deformed, moving state.
#[test]
fn frozen_inertia_is_the_undeformed_full_model() {
    let mut rng = Lcg(31);
    for frame in [FloatingFrame::Tangent, FloatingFrame::Pinned] {
        let full = beam(frame, 3);
        let mut frozen = full.clone();
        assert_eq!(
            frozen.set_inertia(InertiaModel::Frozen),
            InertiaModel::Frozen
        );
        let s = random_state(&full, &mut rng);
        let f0 = DVector::zeros(full.nflex());
        let e0 = rel(
            &frozen.mass_matrix_owned(&s.a, &s.f),
            &full.mass_matrix_owned(&s.a, &f0),
        );
        assert!(e0 < 1e-12, "{frame:?}: frozen M vs full M(q_f = 0): {e0:e}");
        let mut v_rigid = s.v.clone();
        v_rigid.rows_mut(FLEX, full.nflex()).fill(0.0);
        let eh = rel_v(
            &frozen.quadratic_velocity(&s.a, &s.f, &v_rigid),
            &full.quadratic_velocity(&s.a, &f0, &v_rigid),
        );
        assert!(
            eh < 1e-12,
            "{frame:?}: frozen h vs full h(q_f = 0, q̇_f = 0): {eh:e}"
        );
        let dm = rel(
            &frozen.mass_matrix_owned(&s.a, &s.f),
            &full.mass_matrix_owned(&s.a, &s.f),
        );
        let dh = rel_v(
            &frozen.quadratic_velocity(&s.a, &s.f, &s.v),
            &full.quadratic_velocity(&s.a, &s.f, &s.v),
        );
        println!(
            "{frame:?}: frozen vs full at |q_f| = 0.02: mass matrix {dm:.1e}, quadratic-velocity vector {dh:.1e}"
        );
        assert!(dm > 0.0 && dh > 0.0);
    }
}

// ---------------------------------------------------------------------------------------
// Beam from a matrix file (3D paper §6)

fn element_file_text(p: &SpatialBeamProps) -> String {
    let s = &p.section;
    let l = p.length;
    let m = spatial_element::mass(p.rho * s.area, p.rho * s.polar_moment, l);
    let k = spatial_element::stiffness(
        p.e * s.area,
        p.g * s.torsion_constant,
        p.e * s.iy,
        p.e * s.iz,
        l,
    );
    let to = |a: [[f64; 12]; 12]| DMatrix::from_fn(12, 12, |i, j| a[i][j]);
    MatrixFile {
        length: l,
        mass: to(m),
        stiffness: to(k),
    }
    .to_text("the element's own matrices")
}

/// A file holding the element's own matrices gives the one-element beam with frozen inertia:
/// same M, h, K_ff, D_ff, gravity, to 1e-12.
#[test]
fn matrix_file_of_the_element_reproduces_the_element() {
    let mut rng = Lcg(41);
    let dir = std::env::temp_dir().join(format!("spatial_beam_element_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for frame in [FloatingFrame::Tangent, FloatingFrame::Pinned] {
        let p = SpatialBeamProps {
            inertia: InertiaModel::Frozen,
            ..props(0.6, 1, frame)
        };
        let element = SpatialBeam::new("e", &p);
        let path = dir.join("element.txt");
        std::fs::write(&path, element_file_text(&p)).unwrap();
        let file = MatrixFile::load(&path).unwrap();
        let b = matrix_file_beam(&file, "f", frame, p.rayleigh_alpha, p.rayleigh_beta);
        assert_eq!(b.inertia, InertiaModel::Frozen);
        assert!((b.mass / element.mass - 1.0).abs() < 1e-14);
        let g = Vector3::new(0.1, -9.81, 3.0);
        let mut worst: f64 = 0.0;
        for _ in 0..3 {
            let s = random_state(&b, &mut rng);
            let vd = rng.vec(b.ndof(), 1.0);
            worst = worst
                .max(rel(
                    &b.mass_matrix_owned(&s.a, &s.f),
                    &element.mass_matrix_owned(&s.a, &s.f),
                ))
                .max(rel_v(
                    &b.quadratic_velocity(&s.a, &s.f, &s.v),
                    &element.quadratic_velocity(&s.a, &s.f, &s.v),
                ))
                .max(rel_v(
                    &b.residual(&s.a, &s.f, &s.v, &vd, &g),
                    &element.residual(&s.a, &s.f, &s.v, &vd, &g),
                ));
        }
        worst = worst
            .max(rel(&b.kff, &element.kff))
            .max(rel(&b.dff, &element.dff));
        println!("{frame:?}: file beam vs element, worst relative difference {worst:.1e}");
        assert!(worst < 1e-12, "{frame:?}: {worst:e}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

fn refusal(text: &str) -> MatrixFileError {
    matrix_file::parse(text, "bad.txt").expect_err("must be refused")
}

/// Every refusal names the file, the line (where there is one) and the rule.
#[test]
fn matrix_file_refusals_name_file_line_and_rule() {
    let good = element_file_text(&props(0.5, 1, FloatingFrame::Tangent));
    assert!(matrix_file::parse(&good, "good.txt").is_ok());
    let lines: Vec<&str> = good.lines().collect();
    let line_of = |prefix: &str| lines.iter().position(|l| l.starts_with(prefix)).unwrap();
    let replace = |n: usize, new: &str| {
        let mut v: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
        v[n] = new.to_string();
        v.join("\n")
    };
    let mass_row0 = line_of("mass") + 1;
    let stiff_row0 = line_of("stiffness") + 1;

    // a row with 11 numbers
    let short: Vec<&str> = lines[mass_row0].split_whitespace().take(11).collect();
    let e = refusal(&replace(mass_row0, &short.join(" ")));
    let msg = e.to_string();
    println!("{msg}");
    assert!(
        msg.starts_with(&format!("bad.txt:{}:", mass_row0 + 1)),
        "{msg}"
    );
    assert!(msg.contains("12 numbers") && msg.contains("11"), "{msg}");

    // a token that is not a number, and a non-finite one
    for bad in ["1.0x", "inf", "NaN"] {
        let row: Vec<String> = std::iter::once(bad.to_string())
            .chain(
                lines[stiff_row0]
                    .split_whitespace()
                    .skip(1)
                    .map(String::from),
            )
            .collect();
        let msg = refusal(&replace(stiff_row0, &row.join(" "))).to_string();
        println!("{msg}");
        assert!(
            msg.starts_with(&format!("bad.txt:{}:", stiff_row0 + 1)),
            "{msg}"
        );
        assert!(msg.contains(bad), "{msg}");
    }

    // unknown keyword, missing and repeated blocks, bad length
    let msg = refusal(&replace(0, "lenght 0.5")).to_string();
    println!("{msg}");
    assert!(
        msg.contains("bad.txt:1:") && msg.contains("lenght"),
        "{msg}"
    );
    let no_stiffness = lines[..line_of("stiffness")].join("\n");
    let msg = refusal(&no_stiffness).to_string();
    println!("{msg}");
    assert!(msg.contains("bad.txt") && msg.contains("stiffness") && msg.contains("missing"));
    let twice = format!(
        "{good}\n{}",
        lines[line_of("mass")..stiff_row0 - 1].join("\n")
    );
    let msg = refusal(&twice).to_string();
    println!("{msg}");
    assert!(
        msg.contains("mass") && msg.contains("more than once"),
        "{msg}"
    );
    let msg = refusal(&good.replacen("length 0.5", "length -0.5", 1)).to_string();
    println!("{msg}");
    assert!(msg.contains("bad.txt:") && msg.contains("length") && msg.contains("positive"));
    let truncated = lines[..stiff_row0 + 5].join("\n");
    let msg = refusal(&truncated).to_string();
    println!("{msg}");
    assert!(
        msg.contains("stiffness") && msg.contains("12 rows"),
        "{msg}"
    );

    // not symmetric: M[2][7] changed by 1e-6 relative to the largest entry
    let file = matrix_file::parse(&good, "good.txt").unwrap();
    let mut m = file.mass.clone();
    m[(2, 7)] += 1e-6 * m.amax();
    let bad = MatrixFile {
        mass: m,
        ..file.clone()
    }
    .to_text("asymmetric");
    let e = refusal(&bad);
    let msg = e.to_string();
    println!("{msg}");
    assert!(
        matches!(e, MatrixFileError::NotSymmetric { row: 2, col: 7, .. }),
        "{msg}"
    );
    assert!(msg.contains("mass") && msg.contains("symmetric") && msg.contains("bad.txt:"));
    // a rounding-level asymmetry is accepted
    let mut m = file.mass.clone();
    m[(2, 7)] *= 1.0 + 1e-12;
    assert!(matrix_file::parse(
        &MatrixFile {
            mass: m,
            ..file.clone()
        }
        .to_text("x"),
        "x"
    )
    .is_ok());

    // not positive semi-definite: a negative stiffness direction
    let mut k = file.stiffness.clone();
    let d = k[(1, 1)];
    k[(1, 1)] = -d;
    let e = refusal(
        &MatrixFile {
            stiffness: k,
            ..file.clone()
        }
        .to_text("indefinite"),
    );
    let msg = e.to_string();
    println!("{msg}");
    assert!(
        matches!(e, MatrixFileError::NotPositiveSemiDefinite { .. }),
        "{msg}"
    );
    assert!(
        msg.contains("stiffness") && msg.contains("eigenvalue"),
        "{msg}"
    );
    let mut m = file.mass.clone();
    m[(0, 6)] = 2.0 * m[(0, 0)];
    m[(6, 0)] = m[(0, 6)];
    let e = refusal(
        &MatrixFile {
            mass: m,
            ..file.clone()
        }
        .to_text("indefinite mass"),
    );
    assert!(
        matches!(e, MatrixFileError::NotPositiveSemiDefinite { .. }),
        "{e}"
    );

    // a stiffness that resists a rigid motion of the free beam
    let mut k = file.stiffness.clone();
    k[(0, 0)] += 1e-3 * k.amax();
    let e = refusal(
        &MatrixFile {
            stiffness: k,
            ..file.clone()
        }
        .to_text("grounded"),
    );
    let msg = e.to_string();
    println!("{msg}");
    assert!(
        matches!(e, MatrixFileError::RigidMotionStrained { .. }),
        "{msg}"
    );

    // a missing file names its path
    let e = MatrixFile::load(std::path::Path::new("/nonexistent/beam.txt")).unwrap_err();
    assert!(e.to_string().contains("/nonexistent/beam.txt"), "{e}");
}

/// Case C1 (CASES.md) in both bending planes: the square aluminium section, L = 2, N = 10,
/// gives the FE column of the table to 6 significant digits about either axis.
#[test]
fn c1_fe_frequencies_in_both_planes() {
    let p = SpatialBeamProps {
        length: 2.0,
        elements: 10,
        frame: FloatingFrame::Tangent,
        rho: 2700.0,
        e: 72e9,
        g: 27e9,
        section: SpatialSection::rectangle(0.01, 0.01),
        rayleigh_alpha: 0.0,
        rayleigh_beta: 0.0,
        inertia: InertiaModel::Full,
    };
    let b = SpatialBeam::new("c1", &p);
    let fe = [2.0854751, 13.069871, 36.604123, 71.779550, 118.84259];
    let two_pi = 2.0 * std::f64::consts::PI;
    for types in [[V, TZ], [W, TY]] {
        let w = field_frequencies(&b, &types);
        for (k, f) in fe.iter().enumerate() {
            let got = w[k] / two_pi;
            assert!(
                (got / f - 1.0).abs() < 5e-7,
                "plane {types:?} mode {}: {got} vs {f}",
                k + 1
            );
        }
    }
}

/// The frozen variant's cost and error against the full model (3D paper §6), measured on case
/// C6's beam (L = 0.2, one element, tangent frame) whose frame is spun up about z (in-plane)
/// and y (out of plane) to Ω = 40 rad/s in 0.5 s, then held, R fixed, no damping: the deformation obeys
/// m_ff q̈_f = −I_θfᵀ ω̇ − h_f − K_ff q_f − D_ff q̇_f (RK4, 1e-5 s). Prints the time per
/// evaluation of M and h, the tip's transverse deflection at 0.25 s (the Euler load at the
/// ramp's steepest) and its axial stretch at 1 s (centrifugal); asserts the frozen model
/// within 0.1 % of the full one (the centrifugal and Euler loads are kept, only their update with
/// q_f and the Coriolis coupling are dropped).
#[test]
fn frozen_inertia_cost_and_error_against_full() {
    // undamped, so that explicit RK4 at 1e-5 s stays stable (β K_ff would put the stiffest
    // mode's damping far outside its region)
    let p = SpatialBeamProps {
        rayleigh_alpha: 0.0,
        rayleigh_beta: 0.0,
        ..props(0.2, 1, FloatingFrame::Tangent)
    };
    let full = SpatialBeam::new("full", &p);
    let mut frozen = full.clone();
    frozen.set_inertia(InertiaModel::Frozen);
    let nf = full.nflex();
    let a = Matrix3::identity();
    // cost of one evaluation of M and h
    let mut rng = Lcg(3);
    let s = random_state(&full, &mut rng);
    for (name, b) in [("full", &full), ("frozen", &frozen)] {
        let t0 = std::time::Instant::now();
        let reps = 20_000;
        let mut sink = 0.0;
        for _ in 0..reps {
            sink += b.mass_matrix_owned(&a, &s.f)[(3, 3)];
            sink += b.quadratic_velocity(&a, &s.f, &s.v)[0];
        }
        let us = t0.elapsed().as_secs_f64() / reps as f64 * 1e6;
        println!("{name}: M + h in {us:.2} µs (1 element, nf = {nf}) [{sink:.1e}]");
    }
    let (omega, ramp) = (40.0, 0.5);
    // smooth ramp: Ω (t/T − sin(2πt/T)/(2π)) angle rate, so ω̇ starts and ends at zero
    let rate = |t: f64| {
        if t >= ramp {
            (omega, 0.0)
        } else {
            let x = 2.0 * std::f64::consts::PI * t / ramp;
            (
                omega * (t / ramp - x.sin() / (2.0 * std::f64::consts::PI)),
                omega / ramp * (1.0 - x.cos()),
            )
        }
    };
    let tip_v = full.flex_index(NODE_DOFS + V).unwrap();
    let tip_w = full.flex_index(NODE_DOFS + W).unwrap();
    let tip_u = full.flex_index(NODE_DOFS + U).unwrap();
    for axis in [2usize, 1] {
        let run = |b: &SpatialBeam| {
            let lu = b.mff.clone().lu();
            let accel = |t: f64, q: &DVector<f64>, qd: &DVector<f64>| {
                let (w, wd) = rate(t);
                let mut v = DVector::zeros(b.ndof());
                v[OMEGA + axis] = w;
                v.rows_mut(FLEX, nf).copy_from(qd);
                let mut vd = DVector::zeros(b.ndof());
                vd[OMEGA + axis] = wd;
                // residual with q̈_f = 0 is everything but m_ff q̈_f
                let r = b.residual(&a, q, &v, &vd, &Vector3::zeros());
                lu.solve(&(-r.rows(FLEX, nf))).unwrap()
            };
            let (mut q, mut qd) = (DVector::zeros(nf), DVector::zeros(nf));
            let h = 1e-5;
            let steps = 100_000;
            let t0 = std::time::Instant::now();
            let mut mid = DVector::zeros(nf);
            for i in 0..steps {
                if i == steps / 4 {
                    mid = q.clone();
                }
                let t = i as f64 * h;
                let k1 = (qd.clone(), accel(t, &q, &qd));
                let (q2, v2) = (&q + &k1.0 * (h / 2.0), &qd + &k1.1 * (h / 2.0));
                let k2 = (v2.clone(), accel(t + h / 2.0, &q2, &v2));
                let (q3, v3) = (&q + &k2.0 * (h / 2.0), &qd + &k2.1 * (h / 2.0));
                let k3 = (v3.clone(), accel(t + h / 2.0, &q3, &v3));
                let (q4, v4) = (&q + &k3.0 * h, &qd + &k3.1 * h);
                let k4 = (v4.clone(), accel(t + h, &q4, &v4));
                q += (&k1.0 + &k2.0 * 2.0 + &k3.0 * 2.0 + &k4.0) * (h / 6.0);
                qd += (&k1.1 + &k2.1 * 2.0 + &k3.1 * 2.0 + &k4.1) * (h / 6.0);
            }
            (mid, q, t0.elapsed().as_secs_f64())
        };
        let (mf, qf, tf) = run(&full);
        let (mz, qz, tz) = run(&frozen);
        let bend = if axis == 2 { tip_v } else { tip_w };
        println!(
            "spin about {}: tip transverse at 0.25 s full {:.6e} frozen {:.6e} (rel. diff {:.1e}); \
             tip axial at 1 s full {:.6e} frozen {:.6e} (rel. diff {:.1e}); CPU full {tf:.2} s, \
             frozen {tz:.2} s",
            ["x", "y", "z"][axis],
            mf[bend],
            mz[bend],
            (mz[bend] / mf[bend] - 1.0).abs(),
            qf[tip_u],
            qz[tip_u],
            (qz[tip_u] / qf[tip_u] - 1.0).abs()
        );
        assert!((mz[bend] / mf[bend] - 1.0).abs() < 1e-3);
        assert!((qz[tip_u] / qf[tip_u] - 1.0).abs() < 1e-3);
    }
}
