//! The spatial multibody system (issue 4 items 2, 3, 5, library level), through the same
//! generalized-α as the planar engine: the quaternion kinematic identities; a free-swinging
//! 3D rigid pendulum keeps its quaternion norms and its energy; case C2 built in 3D agrees
//! with the planar engine; case C6's flexible pendulum lags its rigid twin (lag printed with
//! its convergence over elements).

use crate::integrator::{initial_state, GaState, Settings, Stats, Stepper};
use crate::mechanics::beam::spatial_beam::{InertiaModel, SpatialBeamProps};
use crate::mechanics::beam::spatial_section::SpatialSection;
use crate::mechanics::multibody3d::quaternion::{g_body, rotation};
use crate::mechanics::multibody3d::{RigidBody3, System3};
use crate::mechanics::FloatingFrame;
use crate::mechanics::JointKind;
use nalgebra::{Matrix3, Vector3, Vector4};

fn fixed(h: f64) -> Settings {
    Settings {
        adaptive: false,
        // fixed steps: the tolerance only stops Newton; tight, so that its stopping error
        // does not accumulate over thousands of steps
        tolerance: 1e-10,
        max_step: h,
        rho_inf: 0.9,
        step_budget: crate::integrator::DEFAULT_STEP_BUDGET,
    }
}

/// Runs `sys` from its assembled initial state, calling `record` every `hc` up to `stop`.
fn simulate(
    sys: &System3,
    settings: Settings,
    hc: f64,
    stop: f64,
    mut record: impl FnMut(&GaState),
) -> GaState {
    let mut st = initial_state(sys, 0.0, &settings).expect("assembles");
    let mut stepper = Stepper::new(sys, settings);
    let mut stats = Stats::default();
    record(&st);
    let steps = (stop / hc).round() as usize;
    for k in 1..=steps {
        stepper
            .step_to(sys, &mut st, &mut stats, k as f64 * hc)
            .expect("step");
        record(&st);
    }
    st
}

fn unwrap(prev: f64, x: f64) -> f64 {
    let tau = 2.0 * std::f64::consts::PI;
    x + tau * ((prev - x) / tau).round()
}

#[test]
fn quaternion_rates_give_the_body_angular_velocity_and_its_derivative() {
    // a smooth path of unit quaternions p(t) = n(t)/|n(t)|
    let path = |t: f64| {
        let n = Vector4::new(0.9, 0.2, -0.3, 0.4)
            + Vector4::new(0.3, -0.5, 0.7, 0.1) * t
            + Vector4::new(-0.4, 0.6, 0.2, -0.8) * (t * t);
        n / n.norm()
    };
    let (t, h) = (0.3, 1e-4);
    let p = path(t);
    let pd = (path(t + h) - path(t - h)) / (2.0 * h);
    let pdd = (path(t + h) - 2.0 * p + path(t - h)) / (h * h);
    // G(ṗ) ṗ = 0 exactly
    assert!((g_body(&pd) * pd).amax() < 1e-15);
    // Ȧ = A ω̃ with ω = 2 G(p) ṗ
    let w = g_body(&p) * pd * 2.0;
    let ad = (rotation(&path(t + h)) - rotation(&path(t - h))) / (2.0 * h);
    let err = (ad - rotation(&p) * crate::mechanics::beam::spatial_beam::skew(&w)).amax();
    println!("|Ȧ − A ω̃| = {err:.2e}");
    assert!(err < 1e-7);
    // ω̇ = 2 G(p) p̈
    let omega = |t: f64| {
        let p = path(t);
        let pd = (path(t + h) - path(t - h)) / (2.0 * h);
        g_body(&p) * pd * 2.0
    };
    let wd = (omega(t + h) - omega(t - h)) / (2.0 * h);
    let err = (wd - g_body(&p) * pdd * 2.0).amax();
    println!("|ω̇ − 2 G p̈| = {err:.2e}");
    assert!(err < 1e-5 * wd.amax());
}

#[test]
fn rigid_pendulum_on_a_spherical_joint_keeps_its_quaternion_and_energy() {
    let mut sys = System3::new(Some(Vector3::new(0.0, 0.0, -9.81)));
    let inertia = Matrix3::new(0.02, 0.003, -0.002, 0.003, 0.09, 0.001, -0.002, 0.001, 0.08);
    let body = sys.add_rigid(
        RigidBody3 {
            name: "bob".into(),
            mass: 2.0,
            com: Vector3::new(0.5, 0.08, -0.05),
            inertia,
            frames: vec![("pivot".into(), Vector3::zeros(), Matrix3::identity())],
        },
        Vector3::zeros(),
        nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 0.4).into_inner(),
    );
    let fw = sys.world_frame(Vector3::zeros(), Matrix3::identity());
    let fb = sys.rigid_frame(body, "pivot");
    sys.add_joint("ball", JointKind::Spherical, fw, fb, None);
    let (mut e0, mut drift, mut norm, mut swing) = (None, 0.0f64, 0.0f64, 0.0f64);
    let stop = 3.0;
    simulate(&sys, fixed(1e-3), 1e-2, stop, |st| {
        let e = sys.energy(&st.q, &st.v).total();
        let e0 = *e0.get_or_insert(e);
        drift = drift.max((e - e0).abs());
        norm = norm.max(sys.quaternion_drift(&st.q));
        swing = swing.max(sys.energy(&st.q, &st.v).kinetic);
    });
    let scale = 2.0 * 9.81 * 0.5;
    println!(
        "3 s, h = 1e-3, rho_inf 0.9: max |pᵀp − 1| = {norm:.2e}, max |ΔE| = {drift:.3e} J \
         ({:.2e} of m g |c|), max kinetic {swing:.3} J",
        drift / scale
    );
    assert!(swing > 0.5, "the pendulum swings");
    // the norm rows hold to the Newton tolerance (0.01 × tol on the weighted correction)
    assert!(norm < 1e-7);
    assert!(drift / scale < 2e-4);
}

/// Case C2's beam in 3D (section symmetric, torsion constants only for completeness).
fn c2_props(elements: usize) -> SpatialBeamProps {
    SpatialBeamProps {
        length: 0.4,
        elements,
        frame: FloatingFrame::Tangent,
        rho: 5540.0,
        e: 1e9,
        g: 1e9 / 2.6,
        section: SpatialSection::given(0.0018, 1.215e-8, 1.215e-8, 2.43e-8),
        rayleigh_alpha: 0.0,
        rayleigh_beta: 0.0,
        inertia: InertiaModel::Full,
    }
}

/// C2 in 3D: hinge angle and tip deflection every 10 ms over 1 s at fixed step h.
fn c2_3d(h: f64) -> Vec<(f64, f64)> {
    let mut sys = System3::new(Some(Vector3::new(0.0, -9.81, 0.0)));
    // in the shipped scene's frame, through both ends
    let props = SpatialBeamProps {
        frame: FloatingFrame::Pinned,
        ..c2_props(10)
    };
    let g = sys.add_beam("beam", &props, 1, Vector3::zeros(), Matrix3::identity());
    let fw = sys.world_frame(Vector3::zeros(), Matrix3::identity());
    let fa = sys.beam_frame(g, false, Matrix3::identity());
    let hinge = sys.add_joint("hinge", JointKind::Revolute, fw, fa, None);
    let mut out: Vec<(f64, f64)> = Vec::new();
    simulate(&sys, fixed(h), 1e-2, 1.0, |st| {
        let a = sys.joint_coordinate(hinge, &st.q);
        let a = out.last().map_or(a, |l| unwrap(l.0, a));
        out.push((a, sys.beam_tip_local(g, &st.q).y));
    });
    out
}

fn c2_planar(h: f64) -> Vec<(f64, f64)> {
    // the 3D system below is built without geometric stiffening: the planar one without it
    let mut scene = super::common::scene("flexible_pendulum.toml");
    scene.beams[0].geometric_stiffening = false;
    let r = super::common::run(
        scene,
        &[
            ("solver.adaptive", 0.0),
            ("solver.max_step", h),
            ("solver.tolerance", 1e-10),
        ],
        &["hinge.angle", "beam.tip.deflection"],
        1e-2,
        1.0,
    );
    r.rows.iter().map(|x| (x[1], x[2])).collect()
}

/// Largest differences of angle and deflection relative to their largest magnitudes.
fn differences(a: &[(f64, f64)], b: &[(f64, f64)]) -> (f64, f64) {
    assert_eq!(a.len(), b.len());
    let max = |f: &dyn Fn(&(f64, f64)) -> f64| b.iter().map(f).fold(0.0, f64::max);
    let (sa, sd) = (max(&|x| x.0.abs()), max(&|x| x.1.abs()));
    let da = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x.0 - y.0).abs())
        .fold(0.0, f64::max);
    let dd = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x.1 - y.1).abs())
        .fold(0.0, f64::max);
    (da / sa, dd / sd)
}

#[test]
fn c2_in_3d_agrees_with_the_planar_engine() {
    let mut rows = Vec::new();
    for h in [1e-3, 5e-4] {
        let (a, b) = (c2_3d(h), c2_planar(h));
        let (da, dd) = differences(&a, &b);
        println!(
            "C2 3D vs planar, fixed h = {h:.0e}: angle {da:.2e}, tip deflection {dd:.2e} \
             (relative to max); angle at 1 s {:.9} vs {:.9}",
            a.last().unwrap().0,
            b.last().unwrap().0
        );
        rows.push((da, dd));
    }
    // The bar of 1e-6 is not reached at h = 1e-3: generalized-α is not invariant
    // under the change of rotation coordinates (angle vs quaternion), so the two runs differ
    // by discretization error, which shrinks with h at the scheme's order 2 (measured, pinned
    // frames: angle 5.69e-6 → 1.42e-6, deflection 1.03e-5 → 2.54e-6 for h/2; tangent frames:
    // 5.7e-6 → 9.9e-7 and 1.5e-5 → 4.2e-6).
    assert!(
        rows[0].0 < 1e-5 && rows[1].0 < rows[0].0 / 3.0,
        "angle converges together"
    );
    assert!(
        rows[0].1 < 5e-5 && rows[1].1 < rows[0].1 / 2.0,
        "deflection converges together"
    );
}

/// C5's beam (its table's section, steel) of `length`, `elements` per frame, damped by a
/// mass-proportional Rayleigh `alpha`: the beam of C5 and C6.
fn c5_beam(length: f64, elements: usize, alpha: f64) -> SpatialBeamProps {
    SpatialBeamProps {
        length,
        elements,
        frame: FloatingFrame::Tangent,
        rho: 7800.0,
        e: 210e9,
        g: 8.077e10,
        section: SpatialSection::given(0.02 * 0.06285, 4.138e-7, 4.19e-8, 1.33242e-7),
        rayleigh_alpha: alpha,
        rayleigh_beta: 0.0,
        inertia: InertiaModel::Full,
    }
}

/// Case C6 (3D paper §5.2): C5's beam, L = 0.2, revolute about the world y axis at flange a,
/// horizontal along X, gravity along −Z. `elements = None` gives the rigid twin (same mass,
/// same inertia of the undeformed beam). Returns the hinge angle at every `hc` from 0 to 1 s.
fn c6(elements: Option<usize>, settings: Settings, hc: f64) -> Vec<f64> {
    let props = c5_beam(0.2, elements.unwrap_or(1), 0.0);
    let mut sys = System3::new(Some(Vector3::new(0.0, 0.0, -9.81)));
    // joint axes: z along world y (x0 = X, y0 = −Z)
    let axes = Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0);
    let fw = sys.world_frame(Vector3::zeros(), axes);
    let f1 = match elements {
        Some(_) => {
            let g = sys.add_beam("beam", &props, 1, Vector3::zeros(), Matrix3::identity());
            sys.beam_frame(g, false, axes)
        }
        None => {
            let beam = crate::mechanics::beam::spatial_beam::SpatialBeam::new("beam", &props);
            let b = sys.add_rigid(
                RigidBody3::of_beam(&beam, vec![("a".into(), Vector3::zeros(), axes)]),
                Vector3::zeros(),
                Matrix3::identity(),
            );
            sys.rigid_frame(b, "a")
        }
    };
    let hinge = sys.add_joint("hinge", JointKind::Revolute, fw, f1, None);
    let mut angles = Vec::new();
    let mut angle = 0.0;
    simulate(&sys, settings, hc, 1.0, |st| {
        angle = unwrap(angle, sys.joint_coordinate(hinge, &st.q));
        angles.push(angle);
    });
    angles
}

/// The rigid pendulum of C6 exactly: J θ'' = m g c cos θ from rest at θ = 0, with m = ρ A L,
/// c = L/2 and J = m L²/3 (the bar's inertia about the hinge; Euler–Bernoulli elements carry no
/// rotary inertia of bending, so neither does the rigid twin), by classical Runge–Kutta at
/// 1e-5 s (its error is far below 1e-10 rad). Returns θ and θ' at every `hc` (a multiple of
/// 1e-5 s) from 0 to 1 s.
fn c6_exact_rigid(hc: f64) -> Vec<(f64, f64)> {
    let (l, g) = (0.2, 9.81);
    let k = 1.5 * g / l; // m g (L/2) / (m L²/3)
    let f = |th: f64| k * th.cos();
    let (mut th, mut w, h) = (0.0f64, 0.0f64, 1e-5);
    let every = (hc / h).round() as usize;
    let mut out = vec![(th, w)];
    for i in 1..=100_000 {
        let (a1, b1) = (w, f(th));
        let (a2, b2) = (w + 0.5 * h * b1, f(th + 0.5 * h * a1));
        let (a3, b3) = (w + 0.5 * h * b2, f(th + 0.5 * h * a2));
        let (a4, b4) = (w + h * b3, f(th + h * a3));
        th += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
        w += h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
        if i % every == 0 {
            out.push((th, w));
        }
    }
    out
}

/// C6: the flexible pendulum lags the rigid one, by very little (its first bending mode is at
/// 419 Hz, out of the plane of the swing; in the plane, 5.8 kHz). The lag is measured against
/// the exact rigid pendulum, not against a simulated rigid twin: the twin's own time error is
/// larger than the lag (at tolerance 1e-9 the simulated twin was 2.2e-5 rad off the exact angle,
/// which an earlier version of this test read as a lag of 2.4e-6 s; the defect behind it,
/// Newton's rounding floor at 1e3 ε, is mended: `fixed_steps_converge_as_they_shrink`). At
/// fixed steps the lag of two elements now converges too: 6.17e-8, 5.26e-8, 5.08e-8 and 5.03e-8
/// s at 4e-5, 2e-5, 1.25e-5 and 1e-5 s (ρ∞ = 0.9, Newton at 1e-10; before the mend they
/// scattered over 4.1–6.2e-8 s and 1.25e-5 s gave −8.5e-8 s).
///
/// The lag is the mean of (θ_exact − θ)/θ'_exact over the last 0.1 s, sampled every 0.2 ms,
/// not its value at 1 s: the hinge angle carries the in-plane bending vibration the release
/// excites (±1e-8 s of lag), whose phase at 1 s no affordable run resolves. An earlier version
/// read the angle at 1 s and asserted that two elements move by less than 2e-8 rad from
/// tolerance 1e-9 to 1e-10; that held by luck of the step sequence: a change of the step-size
/// controller that rounds its factors moved the 1e-9 run by 8e-8 rad, and runs at 1e-9 to 1e-12
/// under three controllers spread over 1.2e-7 rad. The mean lag of two elements, measured:
/// 4.45e-8 s at tolerance 1e-9, 4.86e-8 at 1e-10, 4.93e-8 at 1e-11 (the same to 1e-10 s under
/// each controller), so at 1e-10 it is converged in time to about 2 %, which the test checks
/// against 3e-11. Not against 1e-9 any more: since the error estimate is filtered by the
/// scheme's damping (issue 12, item 5), the 1e-9 run no longer resolves the in-plane bending
/// mode the release rings (5.8 kHz, ωh = 7 at 2e-4 s) and takes one step per 2e-4 s sample
/// (5 000 steps instead of 72 000), where the swing's own error per step is about the
/// tolerance: its lag is 3.5e-7 s. The exact pendulum's J = m L²/3 is the rigid twin's inertia
/// about the hinge, checked here from the beam's undeformed inertia. About 25 s in release.
#[test]
fn c6_flexible_pendulum_lags_its_rigid_twin() {
    let hc = 2e-4;
    let exact = c6_exact_rigid(hc);
    // the rigid twin's inertia about the hinge axis (world y = the beam's y) and its mass
    let props = c5_beam(0.2, 1, 0.0);
    let beam = crate::mechanics::beam::spatial_beam::SpatialBeam::new("beam", &props);
    let m = beam.mass;
    let j_hinge = beam.undeformed.i0[(1, 1)];
    assert!((m / (7800.0 * 0.02 * 0.06285 * 0.2) - 1.0).abs() < 1e-12);
    assert!(
        (j_hinge / (m * 0.04 / 3.0) - 1.0).abs() < 1e-12,
        "J = m L²/3: {j_hinge} vs {}",
        m * 0.04 / 3.0
    );
    let (th, rate) = exact[exact.len() - 1];
    println!("C6 exact rigid pendulum at 1 s: {th:.10} rad, rate {rate:.6} rad/s");
    let at = |tolerance: f64| Settings {
        adaptive: true,
        tolerance,
        max_step: 1e-3,
        rho_inf: 0.9,
        step_budget: crate::integrator::DEFAULT_STEP_BUDGET,
    };
    // the time by which the flexible pendulum trails the rigid one over the last 0.1 s
    let lag = |elements: usize, tolerance: f64| {
        let angles = c6(Some(elements), at(tolerance), hc);
        assert_eq!(angles.len(), exact.len());
        let from = (0.9 / hc).round() as usize;
        let lags = (from..angles.len()).map(|i| (exact[i].0 - angles[i]) / exact[i].1);
        let lag = lags.sum::<f64>() / (angles.len() - from) as f64;
        println!("C6 {elements} elements at tolerance {tolerance:.0e}: mean lag {lag:.4e} s");
        lag
    };
    let lags: Vec<f64> = [1, 2, 4].iter().map(|&n| lag(n, 1e-10)).collect();
    let tighter = lag(2, 3e-11);
    let moved = (tighter - lags[1]).abs();
    println!("C6 2 elements, tolerance 1e-10 to 3e-11: the lag moves by {moved:.1e} s");
    assert!(
        moved < 0.15 * lags[1],
        "the flexible runs are converged in time: {moved:e} s"
    );
    assert!(lags.iter().all(|&l| l > 1e-8), "the flexible pendulum lags");
    assert!(lags.iter().all(|&l| l < 1e-6), "by a little");
    let (d1, d2) = ((lags[1] - lags[0]).abs(), (lags[2] - lags[1]).abs());
    println!("lag changes with elements: 1→2 {d1:.2e} s, 2→4 {d2:.2e} s");
    assert!(d2 < 0.5 * d1, "the lag converges with elements");
}

/// Case C5 (3D paper §5.1): C5's cantilever (L = 1) in `k` substructures of one element,
/// clamped at the root, tip moment 2π E I / L about `axis` (1: y, 2: z) ramped over 2 s and
/// held 1.5 s, q_f damped. Returns the tip's distance from the root / L and its rotation
/// about the axis / 2π, averaged over the last 0.5 s (the mean tip position, then its norm).
fn c5(k: usize, axis: usize) -> (f64, f64) {
    let props = c5_beam(1.0, 1, 200.0);
    let ei = 210e9 * if axis == 1 { 4.138e-7 } else { 4.19e-8 };
    let mut sys = System3::new(None);
    let g = sys.add_beam("beam", &props, k, Vector3::zeros(), Matrix3::identity());
    let fw = sys.world_frame(Vector3::zeros(), Matrix3::identity());
    let fa = sys.beam_frame(g, false, Matrix3::identity());
    sys.add_joint("clamp", JointKind::Weld, fw, fa, None);
    let tip = sys.beam_frame(g, true, Matrix3::identity());
    let mut torque = Vector3::zeros();
    torque[axis] = 2.0 * std::f64::consts::PI * ei;
    sys.add_load(crate::mechanics::multibody3d::Load3 {
        name: "moment".into(),
        frame: tip,
        force: Vector3::zeros(),
        torque,
        law: Some(crate::mechanics::multibody::law::TimeLaw {
            law: crate::mechanics::multibody::law::Law::Table(vec![[0.0, 0.0], [2.0, 1.0]]),
            until: None,
            origin: 0.0,
        }),
    });
    let settings = Settings {
        tolerance: 1e-8,
        ..fixed(1e-3)
    };
    let (mut angle, mut n, mut mean, mut rot) = (0.0, 0usize, Vector3::zeros(), 0.0);
    let mut t = 0.0;
    simulate(&sys, settings, 1e-2, 3.5, |st| {
        let (x, a) = sys.beam_tip(g, &st.q);
        let e = a.column(0);
        let th = if axis == 1 {
            (-e.z).atan2(e.x)
        } else {
            e.y.atan2(e.x)
        };
        angle = unwrap(angle, th);
        if t > 3.0 - 1e-9 {
            mean += x;
            rot += angle;
            n += 1;
        }
        t += 1e-2;
    });
    (
        mean.norm() / n as f64,
        rot / n as f64 / (2.0 * std::f64::consts::PI),
    )
}

#[test]
fn c5_roll_up_closes_the_circle_about_both_axes() {
    for (axis, name) in [(2, "z (weak)"), (1, "y (strong)")] {
        let mut last = (0.0, 0.0);
        for k in [10, 20] {
            let (d, r) = c5(k, axis);
            println!(
                "C5 about {name}, {k} substructures: tip from root {:.3} % of L, \
                 tip rotation / 2π − 1 = {:+.3} %",
                100.0 * d,
                100.0 * (r - 1.0)
            );
            if k == 10 {
                last = (d, r);
            }
        }
        assert!(last.0 < 0.01, "tip within 1 % of L of the root");
        assert!((last.1 - 1.0).abs() < 0.01, "tip rotation 2π within 1 %");
    }
}

/// Fixed steps converge as they shrink (issue 12 item 1, in 3D). C6's rigid twin against the
/// exact pendulum, angle at 1 s, fixed steps 1e-4 to 1.25e-5 s at ρ∞ = 0.9 and 0.5, Newton at
/// 1e-10, communication steps of 1e-2 and 2e-4 s. Before Newton's rounding floor came down from
/// 1e3 ε to the noise each system shows, the errors grew as the step shrank (ρ∞ = 0.9: 1.5e-6
/// rad at 1e-4 s, 1.2e-5 at 1.25e-5 s; ρ∞ = 0.5: 2e-6, then 1e-4 at 2.5e-5 s) and moved by up to
/// 1.6e-5 rad with the communication step. Measured now, ρ∞ = 0.9: 7.5e-7, 1.9e-7, 6.6e-8,
/// 5.4e-8; ρ∞ = 0.5: 1.1e-6, 2.8e-7, 8.7e-8, 5.9e-8; with the communication step they move by
/// at most 3.2e-9. Below 2.5e-5 s the error stops at about 5e-8 rad (a fresh matrix at every
/// step gives 1.2e-8 at 1.25e-5 s): the remainders Newton leaves with a matrix of rate 0.03 to
/// 0.1, 1e-18 of the coordinates and of one sign, add up over 80 000 steps. The 3D iteration
/// matrix does not turn with its bodies as the planar one does (docs/accuracy.md).
#[test]
fn fixed_steps_converge_as_they_shrink() {
    let exact = c6_exact_rigid(1e-2);
    let th = exact[exact.len() - 1].0;
    for rho_inf in [0.9, 0.5] {
        let mut errors = Vec::new();
        for h in [1e-4, 5e-5, 2.5e-5, 1.25e-5] {
            let at = |hc: f64| {
                let a = c6(
                    None,
                    Settings {
                        rho_inf,
                        ..fixed(h)
                    },
                    hc,
                );
                a[a.len() - 1] - th
            };
            let (coarse, fine) = (at(1e-2), at(2e-4));
            println!(
                "rigid twin, rho_inf {rho_inf}, h {h:.2e}: error {coarse:.3e} rad \
                 (communication step 2e-4 s: {fine:.3e})"
            );
            assert!(
                (coarse - fine).abs() < 1e-8,
                "h = {h}: the communication step moves the result by {:e}",
                (coarse - fine).abs()
            );
            errors.push(coarse.abs());
        }
        assert!(errors[1] < 0.3 * errors[0], "second order: {errors:?}");
        assert!(
            errors.windows(2).all(|w| w[1] < w[0]),
            "the error shrinks with the step: {errors:?}"
        );
        assert!(errors[2..].iter().all(|&e| e < 1e-7), "{errors:?}");
    }
}

/// A body's mass matrix over ż, built block by block, is the triple product Tᵀ M_v T to
/// rounding, for a deformed beam at a general quaternion and for a rigid body.
#[test]
fn mass_matrix_is_the_triple_product() {
    use crate::mechanics::beam::spatial_beam::SpatialBeam;
    use crate::mechanics::multibody3d::body::{frame_of, Body3, FRAME};
    use nalgebra::DVector;
    let beam = SpatialBeam::new("beam", &c5_beam(0.3, 2, 0.0));
    let rigid = RigidBody3::of_beam(&beam, Vec::new());
    for body in [Body3::Beam(Box::new(beam)), Body3::Rigid(rigid)] {
        let n = FRAME + body.nflex();
        let p = Vector4::new(0.8, -0.3, 0.4, 0.2).normalize();
        let z = DVector::from_fn(n, |k, _| match k {
            3..=6 => p[k - 3],
            k => 1e-3 * ((k * 7 % 5) as f64 - 2.0),
        });
        let (_, p, a) = frame_of(&z.rows(0, n));
        let t = body.velocity_map(&p);
        let dense = t.transpose() * body.mass_matrix_v(&a, z.rows(FRAME, body.nflex())) * &t;
        let m = body.mass_matrix(z.rows(0, n));
        let scale = dense.amax();
        assert!((&m - &dense).amax() <= 1e-14 * scale, "{m} vs {dense}");
        assert!((&m - m.transpose()).amax() <= 1e-14 * scale, "symmetric");
        // the residual's own inertia gives the same matrix and residual, bit for bit
        let zd = DVector::from_fn(n, |k, _| 0.1 * ((k * 3 % 7) as f64 - 3.0));
        let zdd = DVector::from_fn(n, |k, _| 0.2 * ((k * 5 % 7) as f64 - 3.0));
        let g = Vector3::new(0.0, 0.0, -9.81);
        let (zv, zdv, zddv) = (z.rows(0, n), zd.rows(0, n), zdd.rows(0, n));
        let (r, m2) = body.residual_and_mass(zv, zdv, zddv, &g);
        assert_eq!(r, body.residual(zv, zdv, zddv, &g));
        assert_eq!(m2, m);
    }
}
