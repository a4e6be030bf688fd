//! Issue 32 item 6: the linearized modes with joints free or locked, and at speed.
//! - a uniform beam's free-free and pinned-free frequencies against the closed forms, with
//!   their rigid-body modes counted (never a tiny spurious frequency), converging in elements;
//! - locking the pin turns pinned-free into clamped-free (closed forms);
//! - a cantilever on a driven hub of zero radius, in plane (lead-lag): ω² = ω0² + (K - 1)Ω²
//!   with Southwell's K = 1.193 for the first mode, K fitted over several speeds.

use fmu_beam::{modes, ModeOptions, Scene};
use std::f64::consts::TAU;

const L: f64 = 2.0;
const RHO: f64 = 2700.0;
const E: f64 = 72e9;
const SIDE: f64 = 0.01;

/// f = (βL)² / (2π L²) √(EI / ρA) of the uniform 0.01 m square aluminium beam, L = 2 m.
fn closed_form(beta_l: f64) -> f64 {
    let (a, i) = (SIDE * SIDE, SIDE.powi(4) / 12.0);
    beta_l * beta_l / (TAU * L * L) * (E * i / (RHO * a)).sqrt()
}

/// The beam along x from the origin, with `joint` (a TOML table, or nothing) at its root.
fn beam(elements: usize, extra: &str, joint: &str) -> Scene {
    beam_cut(&format!("elements = {elements}"), extra, joint)
}

/// The beam cut as `discretization` says (`elements = n`, or substructures).
fn beam_cut(discretization: &str, extra: &str, joint: &str) -> Scene {
    let text = format!(
        "name = \"b\"\n[[beam]]\nname = \"beam\"\nlength = {L}\n{discretization}\n\
         material = {{ rho = {RHO}, E = {E} }}\n\
         section = {{ shape = \"rectangle\", a = {SIDE}, b = {SIDE} }}\n{extra}\n{joint}"
    );
    Scene::from_toml_str(&text, "b.toml").expect("valid scene")
}

const PIN: &str =
    "[[joint]]\nname = \"pin\"\ntype = \"revolute\"\nframes = [\"world\", \"beam.a\"]";

fn rel(got: f64, want: f64) -> f64 {
    (got - want).abs() / want
}

#[test]
fn free_free_beam_has_three_rigid_modes_and_the_closed_form_frequencies() {
    let exact = [4.730_040_7, 7.853_204_6, 10.995_607_8].map(closed_form);
    let mut errors = Vec::new();
    for n in [4, 8, 16] {
        let m = modes(&beam(n, "", ""), &ModeOptions::default()).unwrap();
        assert_eq!(
            m.rigid_body_modes, 3,
            "N = {n}: x, y and the turn in the plane"
        );
        let e: Vec<f64> = (0..3).map(|k| rel(m.frequencies[k], exact[k])).collect();
        let shown: Vec<String> = e.iter().map(|x| format!("{x:.2e}")).collect();
        println!(
            "free-free N = {n}: {:?} Hz, exact {exact:?}, rel. errors {shown:?}",
            &m.frequencies[..3]
        );
        errors.push(e);
    }
    // cubic elements converge as h⁴ in frequency: each halving divides the error by about 16
    for k in 0..3 {
        let ratio = errors[1][k] / errors[2][k];
        assert!(
            ratio > 10.0,
            "mode {}: error ratio {ratio} on halving",
            k + 1
        );
    }
    assert!(
        errors[2][0] < 1e-5 && errors[2][2] < 1e-3,
        "{:?}",
        errors[2]
    );
}

#[test]
fn locking_the_pin_turns_pinned_free_into_clamped_free() {
    let pinned = [3.926_602_3, 7.068_582_7, 10.210_176_1].map(closed_form);
    let clamped = [1.875_104_1, 4.694_091_1, 7.854_757_4].map(closed_form);
    let scene = beam(16, "", PIN);
    let free = modes(&scene, &ModeOptions::default()).unwrap();
    let locked = modes(
        &scene,
        &ModeOptions {
            lock: vec!["pin".into()],
            ..ModeOptions::default()
        },
    )
    .unwrap();
    println!(
        "pinned-free {:?} (exact {pinned:?}), rigid {}; locked {:?} (exact {clamped:?}), rigid {}",
        &free.frequencies[..3],
        free.rigid_body_modes,
        &locked.frequencies[..3],
        locked.rigid_body_modes
    );
    assert_eq!(free.rigid_body_modes, 1, "the swing about the pin");
    assert_eq!(locked.rigid_body_modes, 0);
    assert_eq!(locked.locked, ["pin"]);
    assert!(free.locked.is_empty());
    // 16 elements: the discretization error of mode 3 is 1.1e-4 (pinned), 4e-5 (clamped)
    for k in 0..3 {
        assert!(rel(free.frequencies[k], pinned[k]) < 2.5e-4, "pinned {k}");
        assert!(
            rel(locked.frequencies[k], clamped[k]) < 2.5e-4,
            "clamped {k}"
        );
    }
    let all = modes(
        &scene,
        &ModeOptions {
            lock_all: true,
            ..ModeOptions::default()
        },
    )
    .unwrap();
    assert_eq!(all.frequencies, locked.frequencies);
    let unknown = modes(
        &scene,
        &ModeOptions {
            lock: vec!["hinge".into()],
            ..ModeOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(unknown.contains("no joint named 'hinge'"), "{unknown}");
}

const HUB: &str =
    "[[joint]]\nname = \"hub\"\ntype = \"revolute\"\nframes = [\"world\", \"beam.a\"]\n\
    drive = { kind = \"motion\", law = \"spin_up\", omega = 10.0, ramp_time = 15.0 }";

/// Southwell's coefficient of the first mode of a uniform cantilever on a hub of zero radius
/// (the Rayleigh quotient of the centrifugal stiffness with the non-rotating mode: 1.1933).
const SOUTHWELL_K1: f64 = 1.1933;

/// K fitted to ω² - ω0² = (K - 1) Ω² + c Ω⁴ (least squares over the speeds): K is the slope
/// at Ω → 0, Southwell's coefficient; c takes up the mode's change of shape at speed.
fn fitted_k(scene: &Scene, speeds: &[f64]) -> (f64, f64, Vec<f64>) {
    let at = |w: f64| {
        modes(
            scene,
            &ModeOptions {
                speed: w,
                ..ModeOptions::default()
            },
        )
        .unwrap()
    };
    let f0 = at(0.0).frequencies[0];
    let w0 = TAU * f0;
    // normal equations of y = b x + c x², x = Ω²
    let (mut s11, mut s12, mut s22, mut t1, mut t2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut f = Vec::new();
    for &s in speeds {
        let m = at(s);
        assert_eq!(m.hub.as_deref(), Some("hub"));
        let w = TAU * m.frequencies[0];
        let (x, y) = (s * s, w * w - w0 * w0);
        s11 += x * x;
        s12 += x * x * x;
        s22 += x * x * x * x;
        t1 += x * y;
        t2 += x * x * y;
        f.push(m.frequencies[0]);
    }
    let b = (t1 * s22 - t2 * s12) / (s11 * s22 - s12 * s12);
    (1.0 + b, f0, f)
}

#[test]
fn rotating_cantilever_in_plane_follows_southwell() {
    // ω0 = 13.1 rad/s. Southwell's form holds while the mode keeps its shape: up to
    // Ω = 0.6 ω0 (η = Ω √(ρAL⁴/EI) ≈ 2.1) K drifts by less than 1e-3; at 1.5 ω0 the secant
    // through ω(20 rad/s) gives 1.167 (measured).
    let speeds = [2.0, 4.0, 6.0, 8.0];
    let mut ks = Vec::new();
    for n in [4, 8, 16] {
        let scene = beam(n, "geometric_stiffening = true", HUB);
        let (k, f0, f) = fitted_k(&scene, &speeds);
        println!("N = {n}: f0 = {f0:.6} Hz, f at {speeds:?} rad/s = {f:?} Hz, K = {k:.5}");
        ks.push(k);
    }
    // the constant axial force of each element converges as h²: each halving divides the
    // change by about 4 (measured 0.0116, then 0.0029), and Richardson's extrapolation from
    // N = 8 and 16 lands on Southwell's value
    let (d1, d2) = (ks[0] - ks[1], ks[1] - ks[2]);
    let extrapolated = ks[2] - d2 / 3.0;
    println!("K by Richardson from N = 8, 16: {extrapolated:.5}");
    assert!(d1 / d2 > 3.0 && d1 / d2 < 5.0, "h² convergence: {ks:?}");
    assert!(rel(ks[2], SOUTHWELL_K1) < 2e-3, "N = 16: K = {}", ks[2]);
    assert!(rel(extrapolated, SOUTHWELL_K1) < 5e-4, "K = {extrapolated}");
    // substructures: their frames translate with the deformation, which brings in the
    // co-rotating terms of the frames' positions (Coriolis 2ΩMJ, centrifugal Ω²MJ²); 4 × 4
    // elements measured K = 1.19342 (2 × 4: 1.19538)
    let (k, _, _) = fitted_k(
        &beam_cut(
            "substructures = 4\nelements_per_substructure = 4",
            "geometric_stiffening = true",
            HUB,
        ),
        &speeds,
    );
    println!("4 substructures of 4 elements: K = {k:.5}");
    assert!(rel(k, SOUTHWELL_K1) < 5e-4, "K = {k}");
    // without stiffening the linear frame only softens in plane: ω² = ω0² - Ω², K = 0
    let (k, _, _) = fitted_k(&beam(8, "", HUB), &speeds);
    println!("without geometric stiffening: K = {k:.5}");
    assert!(k.abs() < 1e-3, "K = {k}");
}

/// The hinged-blade rotor (rigid 0.2 m hub arm, 1 m blade on a free lag pin at its tip) spun
/// through its torque-driven axis named as the hub: the lag mode of a rigid blade hinged at e
/// from the axis is ν = Ω √(3e / 2L) (centrifugal restoring moment over the blade's inertia
/// about the hinge); the flexible blade is lower by its bending (measured 1.8e-5 at 10 rad/s,
/// 7.3e-5 at 20).
#[test]
fn lag_hinge_at_speed_has_the_rigid_blade_frequency() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/hinged_blade.toml");
    let scene = Scene::load(std::path::Path::new(path)).unwrap();
    let (e, l): (f64, f64) = (0.2, 1.0);
    for w in [10.0, 20.0] {
        let m = modes(
            &scene,
            &ModeOptions {
                speed: w,
                hub: Some("axis".into()),
                ..ModeOptions::default()
            },
        )
        .unwrap();
        let rigid = w * (1.5 * e / l).sqrt() / TAU;
        println!(
            "Ω = {w}: lag {} Hz, rigid blade {rigid} Hz",
            m.frequencies[0]
        );
        assert_eq!((m.rigid_body_modes, m.hub.as_deref()), (0, Some("axis")));
        assert!(m.frequencies[0] < rigid && rel(m.frequencies[0], rigid) < 2e-4);
    }
}

/// The same cantilever as a 3D scene on the spatial element (`formulation = "spatial"`), cut into
/// s substructures of one element each, without geometric stiffening: the flap stiffening comes
/// only from the substructures' frames turning against each other,
/// converging as 1/s² (measured K = 1.0650, 1.1618, 1.1855 for s = 4, 8, 16; 1.1934 by
/// Richardson). The lead-lag mode is the flap mode less Ω²: ω_flap² − ω_lag² = Ω² (the in-plane
/// centrifugal softening of the frame), measured within 1e-4 of Ω².
#[test]
fn rotating_cantilever_3d_flap_follows_southwell_with_substructures() {
    let speeds = [2.0, 4.0, 6.0, 8.0];
    let mut ks = Vec::new();
    for s in [4, 8, 16] {
        let text = format!(
            "name = \"f3\"\ndimensions = 3\nformulation = \"spatial\"\n[[beam]]\nname = \"beam\"\n\
             length = {L}\nsubstructures = {s}\nelements_per_substructure = 1\n\
             material = {{ rho = {RHO}, E = {E}, G = 27e9 }}\n\
             section = {{ shape = \"rectangle\", a = {SIDE}, b = {SIDE} }}\n{HUB}"
        );
        let scene = Scene::from_toml_str(&text, "f3.toml").expect("valid scene");
        let k = flap_k(&scene, &speeds, &format!("s = {s}"));
        println!("3D, {s} substructures: flap K = {k:.5}");
        ks.push(k);
    }
    let (d1, d2) = (ks[1] - ks[0], ks[2] - ks[1]);
    let extrapolated = ks[2] + d2 / 3.0;
    println!("3D flap K by Richardson from s = 8, 16: {extrapolated:.5}");
    assert!(d1 / d2 > 3.0 && d1 / d2 < 5.0, "1/s² convergence: {ks:?}");
    assert!(rel(extrapolated, SOUTHWELL_K1) < 1e-3, "K = {extrapolated}");
}

/// The same 3D cantilever in one floating frame of 16 elements with the spatial element's
/// geometric stiffening (issue 32 item 2): its flap mode follows Southwell as the planar
/// element's in-plane mode does (K = 1.1941 at N = 16 there), and its lag mode stays the flap
/// mode less Ω².
#[test]
fn rotating_cantilever_3d_flap_follows_southwell_in_one_stiffened_frame() {
    let text = format!(
        "name = \"f3\"\ndimensions = 3\nformulation = \"spatial\"\n[[beam]]\nname = \"beam\"\n\
         length = {L}\nelements = 16\ngeometric_stiffening = true\n\
         material = {{ rho = {RHO}, E = {E}, G = 27e9 }}\n\
         section = {{ shape = \"rectangle\", a = {SIDE}, b = {SIDE} }}\n{HUB}"
    );
    let scene = Scene::from_toml_str(&text, "f3.toml").expect("valid scene");
    let k = flap_k(&scene, &[2.0, 4.0, 6.0, 8.0], "one frame");
    println!("3D, one stiffened frame of 16 elements: flap K = {k:.5}");
    assert!(rel(k, SOUTHWELL_K1) < 2e-3, "K = {k}");
}

/// Southwell's K of the flap mode of a 3D cantilever scene on a hub, fitted over `speeds` as
/// ω_flap² − ω0² = K Ω² + c Ω⁴; checks on the way that the square section's flap and lag
/// coincide at rest and that ω_flap² − ω_lag² = Ω².
fn flap_k(scene: &Scene, speeds: &[f64], what: &str) -> f64 {
    let at = |w: f64| {
        modes(
            scene,
            &ModeOptions {
                speed: w,
                ..ModeOptions::default()
            },
        )
        .unwrap()
        .frequencies
    };
    let f0 = at(0.0);
    assert!(
        rel(f0[1], f0[0]) < 1e-8,
        "square section: flap = lag at rest"
    );
    let w0 = TAU * f0[0];
    let (mut s11, mut s12, mut s22, mut t1, mut t2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &w in speeds {
        let f = at(w);
        let (lag, flap) = (TAU * f[0], TAU * f[1]);
        let gap = (flap * flap - lag * lag) / (w * w) - 1.0;
        assert!(
            gap.abs() < 1e-3,
            "{what}, Ω = {w}: flap² − lag² = Ω² (1 + {gap:e})"
        );
        let (x, y) = (w * w, flap * flap - w0 * w0);
        s11 += x * x;
        s12 += x * x * x;
        s22 += x * x * x * x;
        t1 += x * y;
        t2 += x * x * y;
    }
    (t1 * s22 - t2 * s12) / (s11 * s22 - s12 * s12)
}

const CLAMP: &str =
    "[[joint]]\nname = \"clamp\"\ntype = \"weld\"\nframes = [\"world\", \"beam.a\"]";

/// A clamped beam with Rayleigh damping C = αM + βK on its deformation: each mode's damping
/// ratio is ζ = α/(2ω) + βω/2 and its damped frequency ω√(1 − ζ²) (the undamped ω printed
/// beside it).
#[test]
fn rayleigh_damping_gives_the_closed_form_damping_ratios() {
    let (alpha, beta) = (2.0, 1e-4);
    let scene = beam(
        16,
        &format!("rayleigh = {{ alpha = {alpha}, beta = {beta} }}"),
        CLAMP,
    );
    let m = modes(&scene, &ModeOptions::default()).unwrap();
    for k in 0..3 {
        let w = TAU * m.frequencies[k];
        let zeta = alpha / (2.0 * w) + beta * w / 2.0;
        let d = &m.modes[k];
        println!(
            "mode {}: {} Hz, damped {} Hz, ζ = {} (closed form {zeta})",
            k + 1,
            m.frequencies[k],
            d.damped_frequency,
            d.damping_ratio
        );
        // the state space's Schur form rounds near eps ‖M⁻¹K‖ ≈ 1e-5 /s² against |s| ≈ 10..200:
        // measured within 1.3e-7 (ζ) and 1e-7 (frequency)
        let damped = w * (1.0 - zeta * zeta).sqrt();
        assert!(rel(d.damping_ratio, zeta) < 1e-5, "mode {k}");
        assert!(rel(TAU * d.damped_frequency, damped) < 1e-6, "mode {k}");
    }
}

/// About a deformed state: a beam pinned at its root and held on a roller at its tip (a slider
/// on a prismatic joint along x, a revolute joint to the beam), pulled along its axis by T at
/// the tip, with geometric stiffening. About its static equilibrium (`equilibrium`) its first
/// bending frequency is the tensioned simply supported beam's, f² = f0² (1 + T / P_cr),
/// P_cr = π² EI / L², exactly in beam theory: T = 0.5 P_cr, measured 5e-6 off with 16
/// elements (1e-3 asserted). The undeformed placement is no equilibrium under T (measured
/// 18.8 Hz against 7.17: that linearization is not the beam's); without T both agree on f0.
#[test]
fn a_tensioned_beam_linearized_about_its_equilibrium() {
    let i = SIDE.powi(4) / 12.0;
    let p_cr = std::f64::consts::PI.powi(2) * E * i / (L * L);
    let scene = |tension: f64| {
        let supports = format!(
            "[[body]]\nname = \"slider\"\nmass = 0.01\ninertia = 1e-6\nposition = [{L}, 0.0]\n\
             [[joint]]\nname = \"pin\"\ntype = \"revolute\"\nframes = [\"world\", \"beam.a\"]\n\
             [[joint]]\nname = \"roller\"\ntype = \"prismatic\"\n\
             frames = [\"world\", \"slider.origin\"]\n\
             [[joint]]\nname = \"tip\"\ntype = \"revolute\"\n\
             frames = [\"slider.origin\", \"beam.b\"]\n\
             [[load]]\nname = \"pull\"\nframe = \"beam.b\"\nforce = [{tension}, 0.0]"
        );
        beam(16, "geometric_stiffening = true", &supports)
    };
    let at_equilibrium = ModeOptions {
        equilibrium: true,
        ..ModeOptions::default()
    };
    let f0 = closed_form(std::f64::consts::PI);
    let free = modes(&scene(0.0), &ModeOptions::default()).unwrap();
    let free_eq = modes(&scene(0.0), &at_equilibrium).unwrap();
    assert!(
        rel(free.frequencies[0], f0) < 1e-4,
        "{}",
        free.frequencies[0]
    );
    assert!(rel(free_eq.frequencies[0], free.frequencies[0]) < 1e-9);
    let tension = 0.5 * p_cr;
    let exact = f0 * (1.0 + tension / p_cr).sqrt();
    let strained = modes(&scene(tension), &at_equilibrium).unwrap();
    println!(
        "tensioned beam at equilibrium {:.6} Hz; f0 {f0:.6}, exact {exact:.6}",
        strained.frequencies[0]
    );
    assert!(strained.equilibrium && !free.equilibrium);
    // the placement says when it is no equilibrium (under T), and is quiet when it is
    let placed = modes(&scene(tension), &ModeOptions::default()).unwrap();
    assert!(
        placed.off_equilibrium.is_some_and(|a| a > 1.0),
        "{placed:?}"
    );
    assert_eq!(free.off_equilibrium, None);
    assert_eq!(strained.off_equilibrium, None);
    assert!(
        rel(strained.frequencies[0], exact) < 1e-3,
        "{} against {exact}",
        strained.frequencies[0]
    );
}
