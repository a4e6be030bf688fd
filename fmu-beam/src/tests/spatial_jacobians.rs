//! The closed-form derivatives of the spatial system against finite differences, on random
//! states (quaternions off the unit sphere, deformed beams, rotated frames): the constraint
//! Jacobian of every joint kind with and without a motion drive, the joint-coordinate gradient
//! (joint rates, effort drives) and the generalized force of a load.

use crate::mechanics::beam::spatial_beam::{InertiaModel, SpatialBeamProps};
use crate::mechanics::beam::spatial_section::SpatialSection;
use crate::mechanics::multibody::joint::Drive;
use crate::mechanics::multibody::law::{Law, TimeLaw};
use crate::mechanics::multibody::Equations;
use crate::mechanics::multibody3d::{Load3, RigidBody3, System3};
use crate::mechanics::DriveKind;
use crate::mechanics::FloatingFrame;
use crate::mechanics::JointKind;
use nalgebra::{DMatrix, DVector, Matrix3, Rotation3, Vector3};

/// A small deterministic generator (xorshift) of numbers in [−1, 1].
struct Random(u64);

impl Random {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
    fn vector(&mut self, scale: f64) -> Vector3<f64> {
        Vector3::new(self.next(), self.next(), self.next()) * scale
    }
    fn rotation(&mut self) -> Matrix3<f64> {
        Rotation3::from_scaled_axis(self.vector(2.0)).into_inner()
    }
}

fn drive(kind: DriveKind) -> Option<Drive> {
    Some(Drive {
        kind,
        law: TimeLaw {
            law: Law::Constant(0.3),
            until: None,
            origin: 0.0,
        },
    })
}

/// Two beams (one of two substructures, welded), a rigid body, and one joint of each kind with
/// and without drives between frames on all of them, rotated at random.
fn system(rng: &mut Random) -> System3 {
    let section = SpatialSection::given(1e-4, 2e-9, 1e-9, 1.5e-9);
    let props = |frame| SpatialBeamProps {
        length: 0.8,
        elements: 2,
        frame,
        rho: 7800.0,
        e: 2e11,
        g: 8e10,
        section,
        rayleigh_alpha: 0.0,
        rayleigh_beta: 0.0,
        inertia: InertiaModel::Full,
    };
    let mut sys = System3::new(Some(Vector3::new(0.0, 0.0, -9.81)));
    let b0 = sys.add_beam(
        "b0",
        &props(FloatingFrame::Tangent),
        2,
        rng.vector(0.5),
        rng.rotation(),
    );
    let b1 = sys.add_beam(
        "b1",
        &props(FloatingFrame::Pinned),
        1,
        rng.vector(0.5),
        rng.rotation(),
    );
    let rigid = sys.add_rigid(
        RigidBody3 {
            name: "r".into(),
            mass: 2.0,
            com: rng.vector(0.1),
            inertia: Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.3)),
            frames: vec![("f".into(), rng.vector(0.3), rng.rotation())],
        },
        rng.vector(0.5),
        rng.rotation(),
    );
    let kinds = [
        (JointKind::Weld, None),
        (JointKind::Revolute, None),
        (JointKind::Revolute, drive(DriveKind::Motion)),
        (JointKind::Revolute, drive(DriveKind::Effort)),
        (JointKind::Prismatic, None),
        (JointKind::Prismatic, drive(DriveKind::Motion)),
        (JointKind::Prismatic, drive(DriveKind::Effort)),
        (JointKind::Spherical, None),
    ];
    for (i, (kind, dr)) in kinds.into_iter().enumerate() {
        let f0 = match i % 3 {
            0 => sys.beam_frame(b0, true, rng.rotation()),
            1 => sys.world_frame(rng.vector(0.5), rng.rotation()),
            _ => sys.beam_frame(b1, false, rng.rotation()),
        };
        let f1 = match i % 2 {
            0 => sys.rigid_frame(rigid, "f"),
            _ => sys.beam_frame(b1, true, rng.rotation()),
        };
        sys.add_joint(&format!("j{i}"), kind, f0, f1, dr);
    }
    let tip = sys.beam_frame(b0, true, rng.rotation());
    sys.add_load(Load3 {
        name: "load".into(),
        frame: tip,
        force: rng.vector(10.0),
        torque: rng.vector(5.0),
        law: None,
    });
    sys
}

/// A random state: frames moved and turned, quaternions off the unit sphere, beams deformed
/// (section rotations up to about 0.3 rad).
fn state(sys: &System3, rng: &mut Random) -> DVector<f64> {
    let mut q = sys.initial_coordinates().expect("placement");
    for i in 0..sys.bodies.len() {
        let o = sys.offsets[i];
        for k in 0..sys.bodies[i].ncoords() {
            q[o + k] += rng.next() * if k < 3 { 0.1 } else { 0.15 };
        }
    }
    q
}

fn relative(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax()
}

#[test]
fn constraint_jacobian_matches_central_differences_for_every_joint_kind() {
    let mut rng = Random(0x9e37_79b9_7f4a_7c15);
    let sys = system(&mut rng);
    let (n, m) = (sys.n(), sys.m());
    for _ in 0..5 {
        let q = state(&sys, &mut rng);
        let (mut g, mut gd) = (DMatrix::zeros(m, n), DMatrix::zeros(m, n));
        sys.constraint_jacobian(&q, 0.1, &mut g);
        sys.constraint_jacobian_differences(&q, 0.1, &mut gd);
        for (j, jt) in sys.joints.iter().enumerate() {
            let rows = sys.joint_row(j)..sys.joint_row(j) + jt.len();
            let (a, b) = (
                g.rows(rows.start, rows.len()),
                gd.rows(rows.start, rows.len()),
            );
            let err = (a - b).amax() / b.amax();
            println!(
                "{:?} {:?}: {err:.1e}",
                jt.kind,
                jt.drive.as_ref().map(|d| d.kind)
            );
            assert!(err < 1e-6, "joint {j} ({:?}): {err:.2e}", jt.kind);
        }
        assert!(relative(&g, &gd) < 1e-6);
    }
}

#[test]
fn joint_rates_match_central_differences_of_the_joint_coordinate() {
    let mut rng = Random(0x2545_f491_4f6c_dd1d);
    let sys = system(&mut rng);
    for _ in 0..5 {
        let q = state(&sys, &mut rng);
        let v = DVector::from_fn(sys.n(), |_, _| rng.next());
        for (j, jt) in sys.joints.iter().enumerate() {
            if !matches!(jt.kind, JointKind::Revolute | JointKind::Prismatic) {
                continue;
            }
            let rate = sys.joint_rate(j, &q, &v);
            let fd: f64 = sys
                .coordinate_gradient_differences(j, &q)
                .into_iter()
                .map(|(k, d)| d * v[k])
                .sum();
            println!("{:?}: rate {rate:.6e}, differences {fd:.6e}", jt.kind);
            assert!((rate - fd).abs() <= 1e-6 * fd.abs().max(1.0), "joint {j}");
        }
    }
}

#[test]
fn load_force_matches_central_differences_of_the_frame_pose() {
    let mut rng = Random(0x1234_5678_9abc_def1);
    let sys = system(&mut rng);
    let mut unloaded = sys.clone();
    unloaded.loads.clear();
    // effort drives act on both; their difference is the load alone
    let load = &sys.loads[0];
    for _ in 0..5 {
        let q = state(&sys, &mut rng);
        let (v, a) = (DVector::zeros(sys.n()), DVector::zeros(sys.n()));
        let (mut r, mut r0) = (DVector::zeros(sys.n()), DVector::zeros(sys.n()));
        sys.body_residual(&q, &v, &a, 0.0, &mut r);
        unloaded.body_residual(&q, &v, &a, 0.0, &mut r0);
        let force = r0 - r;
        let (_, rot) = sys.frame_pose(load.frame, &q);
        let h = 1e-6;
        let mut fd = DVector::zeros(sys.n());
        let mut qq = q.clone();
        for k in 0..sys.n() {
            qq[k] = q[k] + h;
            let (xp, ap) = sys.frame_pose(load.frame, &qq);
            qq[k] = q[k] - h;
            let (xm, am) = sys.frame_pose(load.frame, &qq);
            qq[k] = q[k];
            let w = (ap - am) * rot.transpose() / (2.0 * h);
            let dth = Vector3::new(
                w[(2, 1)] - w[(1, 2)],
                w[(0, 2)] - w[(2, 0)],
                w[(1, 0)] - w[(0, 1)],
            ) * 0.5;
            fd[k] = load.force.dot(&((xp - xm) / (2.0 * h))) + load.torque.dot(&dth);
        }
        let err = (&force - &fd).amax() / fd.amax();
        println!("load: {err:.1e}");
        assert!(err < 1e-6, "{err:.2e}");
    }
}

/// The body tangents (forward differences that update a beam's products column by column)
/// against central differences of the body residual, for a beam in both inertia models and
/// a rigid body. The deformation is small, so that the stiffness forces (which cancel in the
/// differences) leave the round-off of the forward differences below the tolerance.
#[test]
fn body_tangents_match_central_differences_of_the_residual() {
    use crate::mechanics::multibody3d::Body3;
    let mut rng = Random(0x0bad_cafe_f00d_d00d);
    let sys = system(&mut rng);
    let mut bodies: Vec<Body3> = sys.bodies.clone();
    if let Body3::Beam(b) = &sys.bodies[0] {
        let mut frozen = b.clone();
        frozen.set_inertia(InertiaModel::Frozen);
        bodies.push(Body3::Beam(frozen));
    }
    let g = Vector3::new(0.3, -1.0, -9.81);
    for body in &bodies {
        let n = body.ncoords();
        let mut z = DVector::from_fn(n, |k, _| rng.next() * if k < 7 { 0.1 } else { 1e-5 });
        z[3] += 0.9;
        let zd = DVector::from_fn(n, |_, _| 2.0 * rng.next());
        let zdd = DVector::from_fn(n, |_, _| 5.0 * rng.next());
        let (mut kt, mut ct) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
        body.tangents(
            z.rows(0, n),
            zd.rows(0, n),
            zdd.rows(0, n),
            &g,
            1e-7,
            kt.view_mut((0, 0), (n, n)),
            ct.view_mut((0, 0), (n, n)),
        );
        let r = |z: &DVector<f64>, zd: &DVector<f64>| {
            body.residual(z.rows(0, n), zd.rows(0, n), zdd.rows(0, n), &g)
        };
        let h = 1e-6;
        let (mut kd, mut cd) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
        for k in 0..n {
            let (mut zp, mut zm) = (z.clone(), z.clone());
            zp[k] += h;
            zm[k] -= h;
            kd.set_column(k, &((r(&zp, &zd) - r(&zm, &zd)) / (2.0 * h)));
            let (mut vp, mut vm) = (zd.clone(), zd.clone());
            vp[k] += h;
            vm[k] -= h;
            cd.set_column(k, &((r(&z, &vp) - r(&z, &vm)) / (2.0 * h)));
        }
        let (ek, ec) = (relative(&kt, &kd), relative(&ct, &cd));
        println!("{}: K_t {ek:.1e}, C_t {ec:.1e}", body.name());

        assert!(
            ek < 1e-5 && ec < 1e-5,
            "{}: K_t {ek:.2e}, C_t {ec:.2e}",
            body.name()
        );
    }
}

/// A beam of `elements` elements (frame kind `frame`) with geometric stiffening on, Rayleigh
/// `beta`, and a deformation of slopes up to about `slope` (every kept coordinate random; axial
/// ones 1e-3 of the element length).
fn stiffened_beam(
    frame: FloatingFrame,
    elements: usize,
    slope: f64,
    beta: f64,
    rng: &mut Random,
) -> (crate::mechanics::SpatialBeam, DVector<f64>) {
    use crate::mechanics::beam::spatial_element::{NODE_DOFS, U};
    let props = SpatialBeamProps {
        length: 0.9,
        elements,
        frame,
        rho: 2700.0,
        e: 7e10,
        g: 2.6e10,
        section: SpatialSection::rectangle(0.02, 0.005),
        rayleigh_alpha: 0.0,
        rayleigh_beta: beta,
        inertia: InertiaModel::Full,
    };
    let mut b = crate::mechanics::SpatialBeam::new("s", &props);
    b.set_geometric_stiffening(true);
    let l = props.length / elements as f64;
    let f = DVector::from_fn(b.nflex(), |k, _| {
        let dof = b.kept[k] % NODE_DOFS;
        rng.next()
            * if dof == U {
                1e-3 * l
            } else if dof < 3 {
                slope * l
            } else {
                slope
            }
    });
    (b, f)
}

/// The stiffening force f_g (internal force less K_ff q_f) against central differences of its
/// energy U_g, and its exact tangent K_g against central differences of f_g, on deformed
/// beams of both frame kinds: the derivation of `spatial_beam/stiffening.rs` checked
/// (forward differences of a quadratic-plus-quartic energy at h = 1e-6 of the coordinate
/// scale: agreement near 1e-8 relative; 1e-6 asserted). The force must also be a measurable
/// share of K_ff q_f, or the check would pass with the term missing.
#[test]
fn stiffening_force_and_tangent_match_central_differences() {
    let mut rng = Random(0x005e_ed0f_571f_f32a);
    for frame in [FloatingFrame::Tangent, FloatingFrame::Pinned] {
        let (b, f) = stiffened_beam(frame, 3, 0.2, 0.0, &mut rng);
        let nf = b.nflex();
        let zero = DVector::zeros(nf);
        let fg = |f: &DVector<f64>| b.internal_force(f, &zero) - &b.kff * f;
        let energy = |f: &DVector<f64>| b.strain_energy(f) - 0.5 * f.dot(&(&b.kff * f));
        let g0 = fg(&f);
        let kg = b.stiffening_tangent(&f);
        let (mut de, mut dg) = (DVector::zeros(nf), DMatrix::zeros(nf, nf));
        for k in 0..nf {
            let h = 1e-6 * f.amax();
            let (mut fp, mut fm) = (f.clone(), f.clone());
            fp[k] += h;
            fm[k] -= h;
            de[k] = (energy(&fp) - energy(&fm)) / (2.0 * h);
            dg.set_column(k, &((fg(&fp) - fg(&fm)) / (2.0 * h)));
        }
        let ef = (&g0 - &de).amax() / de.amax();
        let ek = relative(&kg, &dg);
        let share = g0.amax() / (&b.kff * &f).amax();
        println!("{frame:?}: f_g {ef:.1e}, K_g {ek:.1e}; |f_g| / |K_ff q_f| = {share:.2e}");
        assert!(
            ef < 1e-6 && ek < 1e-6,
            "{frame:?}: f_g {ef:.2e}, K_g {ek:.2e}"
        );
        assert!(
            share > 1e-3,
            "{frame:?}: the stiffening force is {share:.1e} of K_ff q_f"
        );
        // symmetric, as the Hessian of U_g
        assert!(relative(&kg, &kg.transpose()) < 1e-14);
    }
}

/// The body tangent's share from stiffening (tangents with it on less tangents with it off,
/// at one state) against central differences of the residuals' difference: what the
/// integrator's Newton iteration uses carries the exact K_g (updated column by column in the
/// beam's products), in both inertia models; with Rayleigh β, also the strain-rate damping's
/// ∂f_β/∂q in K_t and ∂f_β/∂q̇ in C_t.
#[test]
fn body_tangent_carries_the_stiffening_tangent() {
    use crate::mechanics::multibody3d::Body3;
    let mut rng = Random(0x0dd_ba11_cafe_5eed);
    for model in [InertiaModel::Full, InertiaModel::Frozen] {
        let (mut beam, f) = stiffened_beam(FloatingFrame::Tangent, 4, 0.1, 2e-3, &mut rng);
        beam.set_inertia(model);
        let on = Body3::Beam(Box::new(beam.clone()));
        beam.set_geometric_stiffening(false);
        let off = Body3::Beam(Box::new(beam));
        let n = on.ncoords();
        let mut z = DVector::from_fn(n, |k, _| rng.next() * if k < 7 { 0.1 } else { 0.0 });
        z[3] += 0.9;
        z.rows_mut(7, n - 7).copy_from(&f);
        let zd = DVector::from_fn(n, |_, _| 2.0 * rng.next());
        let zdd = DVector::from_fn(n, |_, _| 5.0 * rng.next());
        let g = Vector3::new(0.0, 0.0, -9.81);
        let tangent = |body: &Body3| {
            let (mut kt, mut ct) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
            body.tangents(
                z.rows(0, n),
                zd.rows(0, n),
                zdd.rows(0, n),
                &g,
                1e-7,
                kt.view_mut((0, 0), (n, n)),
                ct.view_mut((0, 0), (n, n)),
            );
            (kt, ct)
        };
        let ((kt_on, ct_on), (kt_off, ct_off)) = (tangent(&on), tangent(&off));
        let (kt, ct) = (kt_on - kt_off, ct_on - ct_off);
        let r = |z: &DVector<f64>, zd: &DVector<f64>| {
            on.residual(z.rows(0, n), zd.rows(0, n), zdd.rows(0, n), &g)
                - off.residual(z.rows(0, n), zd.rows(0, n), zdd.rows(0, n), &g)
        };
        let (mut kd, mut cd) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
        for k in 0..n {
            let h = 1e-6 * z[k].abs().max(1e-2);
            let (mut zp, mut zm) = (z.clone(), z.clone());
            zp[k] += h;
            zm[k] -= h;
            kd.set_column(k, &((r(&zp, &zd) - r(&zm, &zd)) / (2.0 * h)));
            let h = 1e-3;
            let (mut vp, mut vm) = (zd.clone(), zd.clone());
            vp[k] += h;
            vm[k] -= h;
            cd.set_column(k, &((r(&z, &vp) - r(&z, &vm)) / (2.0 * h)));
        }
        let (err, err_c) = (relative(&kt, &kd), relative(&ct, &cd));
        println!("{model:?}: K_g in the body tangent {err:.1e}, the β part of C_t {err_c:.1e}");
        assert!(err < 1e-6, "{model:?}: {err:.2e}");
        assert!(err_c < 1e-6, "{model:?}: C_t {err_c:.2e}");
        assert!(kd.amax() > 0.0 && cd.amax() > 0.0);
    }
}
