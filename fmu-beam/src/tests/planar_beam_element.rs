//! Element checks of the floating-frame planar beam: the mass matrix against direct numerical
//! integration of ∫ρ LᵀL (eq. (11)), the quadratic-velocity vector against Lagrange's
//! equations, the tangents against finite differences, and zero force at rest.

use crate::mechanics::beam::planar_beam::{rot, BeamOptions, PlanarBeam, FLEX, THETA};
use crate::mechanics::beam::planar_element::{shape, GAUSS_4};
use crate::mechanics::beam::section::Section;
use crate::mechanics::FloatingFrame;
use nalgebra::{DMatrix, DVector, Vector2};

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
}

fn beam(frame: FloatingFrame, n: usize) -> PlanarBeam {
    beam_with(frame, n, BeamOptions::default())
}

/// Full shape rows at (element j, ξ) restricted to the kept coordinates.
fn reduced_shape(b: &PlanarBeam, j: usize, xi: f64) -> (DVector<f64>, DVector<f64>) {
    let l = b.length / b.elements as f64;
    let (s1, s2) = shape(xi, l);
    let nf = b.nflex();
    let mut r1 = DVector::zeros(nf);
    let mut r2 = DVector::zeros(nf);
    for p in 0..6 {
        if let Some(k) = b.flex_index(3 * j + p) {
            r1[k] = s1[p];
            r2[k] = s2[p];
        }
    }
    (r1, r2)
}

/// M by summing ρ LᵀL over Gauss points, L = [I, A_θ ū, A S] (planar paper Appendix A).
fn direct_mass(b: &PlanarBeam, z: &DVector<f64>) -> DMatrix<f64> {
    let n = b.ndof();
    let nf = b.nflex();
    let l = b.length / b.elements as f64;
    let (ar, ath) = rot(z[THETA]);
    let f = z.rows(FLEX, nf);
    let mut m = DMatrix::zeros(n, n);
    for j in 0..b.elements {
        for &(xi, w) in &GAUSS_4 {
            let (s1, s2) = reduced_shape(b, j, xi);
            let u = Vector2::new((j as f64 + xi) * l + s1.dot(&f), s2.dot(&f));
            let mut lm = DMatrix::zeros(2, n);
            lm[(0, 0)] = 1.0;
            lm[(1, 1)] = 1.0;
            let au = ath * u;
            lm[(0, THETA)] = au[0];
            lm[(1, THETA)] = au[1];
            for k in 0..nf {
                let col = ar * Vector2::new(s1[k], s2[k]);
                lm[(0, FLEX + k)] = col[0];
                lm[(1, FLEX + k)] = col[1];
            }
            m += lm.transpose() * lm * (b.mu * l * w);
        }
    }
    m
}

fn mass(b: &PlanarBeam, z: &DVector<f64>) -> DMatrix<f64> {
    let n = b.ndof();
    let mut m = DMatrix::zeros(n, n);
    b.mass_matrix(z, m.view_mut((0, 0), (n, n)));
    m
}

fn residual(
    b: &PlanarBeam,
    z: &DVector<f64>,
    zd: &DVector<f64>,
    zdd: &DVector<f64>,
    g: Vector2<f64>,
) -> DVector<f64> {
    residual_with(b, z, zd, zdd, Some(g))
}

fn residual_with(
    b: &PlanarBeam,
    z: &DVector<f64>,
    zd: &DVector<f64>,
    zdd: &DVector<f64>,
    g: Option<Vector2<f64>>,
) -> DVector<f64> {
    let mut r = vec![0.0; b.ndof()];
    b.residual(z, zd, zdd, g, &mut r);
    DVector::from_vec(r)
}

fn random_state(b: &PlanarBeam, rng: &mut Lcg) -> (DVector<f64>, DVector<f64>, DVector<f64>) {
    let n = b.ndof();
    let mut z = rng.vec(n, 1.0);
    for k in FLEX..n {
        z[k] *= 0.01;
    }
    (z, rng.vec(n, 2.0), rng.vec(n, 3.0))
}

#[test]
fn mass_matrix_equals_direct_integration_of_eq_11() {
    let mut rng = Lcg(7);
    for frame in [FloatingFrame::Tangent, FloatingFrame::Pinned] {
        let b = beam(frame, 5);
        for _ in 0..3 {
            let (z, _, _) = random_state(&b, &mut rng);
            let (m, md) = (mass(&b, &z), direct_mass(&b, &z));
            let err = (&m - &md).amax() / md.amax();
            assert!(err < 1e-13, "{frame:?}: relative difference {err:e}");
            assert!((&m - m.transpose()).amax() < 1e-15 * m.amax());
        }
    }
}

/// h must equal Ṁ ż - ∂T/∂z with T = ½ żᵀ M(z) ż (Lagrange's equations), and the rest of
/// the residual must be K q_f + D q̇_f - Q_g.
#[test]
fn quadratic_velocity_terms_follow_from_lagrange() {
    let mut rng = Lcg(11);
    let b = beam(FloatingFrame::Tangent, 4);
    let n = b.ndof();
    for _ in 0..3 {
        let (z, zd, _) = random_state(&b, &mut rng);
        let eps = 1e-6;
        let mut mdot_zd = DVector::zeros(n);
        let mut dt_dz = DVector::zeros(n);
        for k in 0..n {
            let mut zp = z.clone();
            let mut zm = z.clone();
            zp[k] += eps;
            zm[k] -= eps;
            let dm = (mass(&b, &zp) - mass(&b, &zm)) / (2.0 * eps);
            mdot_zd += &dm * &zd * zd[k];
            dt_dz[k] = 0.5 * zd.dot(&(&dm * &zd));
        }
        let h_lagrange = mdot_zd - dt_dz;
        let zero = DVector::zeros(n);
        let mut h = residual(&b, &z, &zd, &zero, Vector2::zeros());
        // remove the internal forces
        let f = z.rows(FLEX, b.nflex());
        let fd = zd.rows(FLEX, b.nflex());
        let internal = b.kff.to_dense() * f + b.dff.to_dense() * fd;
        for k in 0..b.nflex() {
            h[FLEX + k] -= internal[k];
        }
        let err = (&h - &h_lagrange).amax() / h_lagrange.amax();
        assert!(err < 1e-7, "relative difference {err:e}\n{h}\n{h_lagrange}");
    }
}

#[test]
fn gravity_is_the_gradient_of_the_potential() {
    let mut rng = Lcg(5);
    let b = beam(FloatingFrame::Pinned, 3);
    let n = b.ndof();
    let g = Vector2::new(1.3, -9.81);
    let (z, _, _) = random_state(&b, &mut rng);
    let zero = DVector::zeros(n);
    let r_g = residual(&b, &z, &zero, &zero, g) - residual(&b, &z, &zero, &zero, Vector2::zeros());
    for k in 0..n {
        let eps = 1e-6;
        let mut zp = z.clone();
        let mut zm = z.clone();
        zp[k] += eps;
        zm[k] -= eps;
        let dv = (b.gravity_energy(&zp, Some(g)) - b.gravity_energy(&zm, Some(g))) / (2.0 * eps);
        assert!(
            (r_g[k] - dv).abs() < 1e-6 * (1.0 + dv.abs()),
            "coordinate {k}: {} vs {dv}",
            r_g[k]
        );
    }
}

/// The beam of [`beam`] computing only the terms of `options`.
fn beam_with(frame: FloatingFrame, n: usize, options: BeamOptions) -> PlanarBeam {
    PlanarBeam::with_options(
        "b",
        0.8,
        n,
        frame,
        2700.0,
        7e9,
        Section::rectangle(0.02, 0.01),
        0.3,
        2e-4,
        options,
    )
}

#[test]
fn tangents_match_finite_differences() {
    let mut rng = Lcg(3);
    let full = BeamOptions::default();
    let stiff = BeamOptions {
        geometric_stiffening: true,
        ..full
    };
    // every switch of the effects, alone, and modal truncation with stiffening
    let variants = [
        (FloatingFrame::Tangent, full, true),
        (FloatingFrame::Pinned, full, true),
        (FloatingFrame::Tangent, stiff, true),
        (FloatingFrame::Pinned, stiff, true),
        (FloatingFrame::Tangent, full, false),
        (
            FloatingFrame::Tangent,
            BeamOptions {
                quadratic_velocity: false,
                ..full
            },
            true,
        ),
        (
            FloatingFrame::Pinned,
            BeamOptions {
                damping: false,
                ..full
            },
            true,
        ),
        (
            FloatingFrame::Tangent,
            BeamOptions {
                axial: false,
                ..full
            },
            true,
        ),
        (
            FloatingFrame::Tangent,
            BeamOptions {
                modes: Some(4),
                ..stiff
            },
            true,
        ),
    ];
    for (frame, options, gravity) in variants {
        let b = beam_with(frame, 3, options);
        let stiffening = format!("{options:?} gravity {gravity}");
        let n = b.ndof();
        let g = gravity.then(|| Vector2::new(0.5, -9.81));
        let (z, zd, zdd) = random_state(&b, &mut rng);
        let mut kt = DMatrix::zeros(n, n);
        let mut ct = DMatrix::zeros(n, n);
        b.tangents(
            &z,
            &zd,
            &zdd,
            g,
            kt.view_mut((0, 0), (n, n)),
            ct.view_mut((0, 0), (n, n)),
        );
        let mut kfd = DMatrix::zeros(n, n);
        let mut cfd = DMatrix::zeros(n, n);
        let eps = 1e-6;
        for k in 0..n {
            let (mut zp, mut zm) = (z.clone(), z.clone());
            zp[k] += eps;
            zm[k] -= eps;
            kfd.set_column(
                k,
                &((residual_with(&b, &zp, &zd, &zdd, g) - residual_with(&b, &zm, &zd, &zdd, g))
                    / (2.0 * eps)),
            );
            // r is quadratic in ż: central differences are exact for any step, and a large
            // one keeps the round-off of the (large) stiffness forces out of small C_t
            let eps_v = 1e-2;
            let (mut vp, mut vm) = (zd.clone(), zd.clone());
            vp[k] += eps_v;
            vm[k] -= eps_v;
            cfd.set_column(
                k,
                &((residual_with(&b, &z, &vp, &zdd, g) - residual_with(&b, &z, &vm, &zdd, g))
                    / (2.0 * eps_v)),
            );
        }
        let ek = (&kt - &kfd).amax() / kfd.amax();
        let ec = (&ct - &cfd).amax() / cfd.amax();
        assert!(
            ek < 1e-7,
            "{frame:?} {stiffening}: K_t relative difference {ek:e}"
        );
        assert!(
            ec < 1e-7,
            "{frame:?} {stiffening}: C_t relative difference {ec:e}"
        );
    }
}

#[test]
fn zero_force_at_rest() {
    let b = beam(FloatingFrame::Tangent, 6);
    let n = b.ndof();
    let mut z = DVector::zeros(n);
    z[0] = 0.3;
    z[1] = -1.0;
    z[THETA] = 0.7;
    let zero = DVector::zeros(n);
    let r = residual(&b, &z, &zero, &zero, Vector2::zeros());
    assert!(r.amax() == 0.0, "residual at rest {r}");
}

/// A rigidly spinning undeformed beam: the centrifugal load on q_f is θ̇² ∫ρ Sᵀū0 (axial
/// stretching only) and the frame needs no torque.
#[test]
fn steady_spin_loads_axially() {
    let b = beam(FloatingFrame::Tangent, 4);
    let n = b.ndof();
    let z = DVector::zeros(n);
    let mut zd = DVector::zeros(n);
    let omega = 3.0;
    zd[THETA] = omega;
    let r = residual(&b, &z, &zd, &DVector::zeros(n), Vector2::zeros());
    assert!(r[THETA].abs() < 1e-12);
    // net centripetal force on the frame: -m ω² L/2 along x
    assert!((r[0] + b.mass * omega * omega * b.length / 2.0).abs() < 1e-9);
    for (k, &full) in b.kept.iter().enumerate() {
        if full % 3 != 0 {
            assert!(r[FLEX + k].abs() < 1e-12, "transverse load on {full}");
        } else {
            assert!(
                r[FLEX + k] < 0.0,
                "axial dof {full} must be pulled outwards"
            );
        }
    }
}

/// With geometric stiffening, the internal force is the gradient of the strain energy, and an
/// axial pre-stretch stiffens bending: the transverse stiffness grows with the axial force.
#[test]
fn geometric_stiffening_is_conservative_and_stiffens_under_tension() {
    let mut rng = Lcg(19);
    let mut b = beam(FloatingFrame::Tangent, 4);
    b.set_geometric_stiffening(true);
    let n = b.ndof();
    let (mut z, _, _) = random_state(&b, &mut rng);
    let zero = DVector::zeros(n);
    let r = residual(&b, &z, &zero, &zero, Vector2::zeros());
    for k in FLEX..n {
        let eps = 1e-7;
        let (mut zp, mut zm) = (z.clone(), z.clone());
        zp[k] += eps;
        zm[k] -= eps;
        let de = (b.strain_energy(&zp) - b.strain_energy(&zm)) / (2.0 * eps);
        assert!(
            (r[k] - de).abs() < 1e-5 * (1.0 + de.abs()),
            "coordinate {k}: {} vs {de}",
            r[k]
        );
    }
    // tip transverse stiffness with and without a uniform axial stretch
    let tip_v = FLEX + b.flex_index(3 * b.elements + 1).unwrap();
    let stiffness = |z: &DVector<f64>| {
        let mut kt = DMatrix::zeros(n, n);
        let mut ct = DMatrix::zeros(n, n);
        b.tangents(
            z,
            &zero,
            &zero,
            None,
            kt.view_mut((0, 0), (n, n)),
            ct.view_mut((0, 0), (n, n)),
        );
        kt[(tip_v, tip_v)]
    };
    z.fill(0.0);
    let k0 = stiffness(&z);
    for (k, &full) in b.kept.iter().enumerate() {
        if full % 3 == 0 {
            z[FLEX + k] = 1e-4 * (full / 3) as f64 * b.length / b.elements as f64;
        }
    }
    assert!(stiffness(&z) > k0 * 1.01, "tension must stiffen bending");
}
