//! Issue 32, item 2: geometric stiffening in the 3D element (`spatial_beam/stiffening.rs`).
//!
//! - A rotor blade (aluminium, 2 m, 100 × 10 mm, flap frequency 2.056 Hz) on a hub spun up to
//!   8 rad/s about world z, gravity along −z: out of the plane of rotation, so it droops, and
//!   the centrifugal tension stiffens the flap bending. One floating frame with stiffening
//!   droops within 1 % of plain substructures (no stiffening; the floating frames' own rotations
//!   carry the large-deflection stiffening), which converge as they are refined (4, 8, 16).
//! - Case C4 (Ω = 10, one frame of 10 elements with stiffening) written as a 3D scene with
//!   `formulation = "spatial"`, so that the 3D element runs it, agrees with the planar unit.
//! - `auto` turns stiffening on in 3D for the spinning blade, with its reason.

use crate::common;
use common::{run, scene};
use fmu_beam::{resolve_effects, Scene};

/// The blade scene spun up to 8 rad/s: `layout` the beam's elements line(s), `extra` more
/// beam lines, `effects` the scene's effects line.
fn blade(layout: &str, extra: &str, effects: &str) -> Scene {
    blade_at(8.0, layout, extra, effects)
}

/// [`blade`] spun up to `omega` (rad/s).
fn blade_at(omega: f64, layout: &str, extra: &str, effects: &str) -> Scene {
    let text = format!(
        r#"name = "blade"
dimensions = 3
{effects}
[world]
gravity = [0.0, 0.0, -9.81]

[experiment]
stop_time = 12.0
step_size = 0.01

[solver]
adaptive = true
tolerance = 1e-6
max_step = 1e-2

[[beam]]
name = "blade"
length = 2.0
{layout}
material = {{ rho = 2700.0, E = 70e9, G = 26e9 }}
section = {{ shape = "rectangle", a = 0.1, b = 0.01 }}
rayleigh = {{ alpha = 3.0 }}
{extra}

[[joint]]
name = "hub"
type = "revolute"
frames = ["world", "blade.a"]
axis = [0.0, 0.0, 1.0]
drive = {{ kind = "motion", law = "spin_up", omega = {omega:?}, ramp_time = 4.0 }}
"#
    );
    Scene::from_toml_str(&text, "blade").expect("a valid scene")
}

/// The blade's droop (world z of the tip) at 8 rad/s: its mean over 11–12 s, after the
/// spin-up (4 s) and 7 s at speed (alpha = 3 damps every mode at e^-1.5 per second), and how
/// far that mean is from the one over 10–11 s. Mass-proportional damping, because
/// stiffness-proportional damping (beta K_ff) resists the axial motion that follows a change
/// of droop under stiffening (u' = ε − ½w'²): the droop then creeps towards equilibrium with
/// a time constant that grows with beta (0.01: 2.4e-4 m still moving over 11–12 s).
fn droop(s: Scene) -> (f64, f64) {
    let t0 = std::time::Instant::now();
    let r = run(s, &[], &["blade.tip.z", "hub.speed"], 0.02, 12.0);
    let rate = r.last(2);
    assert!((rate - 8.0).abs() < 1e-2, "at speed: {rate}");
    let mean = |a: f64, b: f64| {
        let z: Vec<f64> = r
            .rows
            .iter()
            .filter(|row| row[0] > a + 1e-9 && row[0] < b + 1e-9)
            .map(|row| row[1])
            .collect();
        z.iter().sum::<f64>() / z.len() as f64
    };
    let (z, before) = (mean(11.0, 12.0), mean(10.0, 11.0));
    println!(
        "  droop {z:.6} m (moves {:.1e} m from 10–11 s to 11–12 s), {:.1} s",
        z - before,
        t0.elapsed().as_secs_f64()
    );
    (z, (z - before).abs())
}

#[test]
fn rotor_blade_single_frame_with_stiffening_droops_as_converged_substructures() {
    let mut subs = Vec::new();
    for k in [4, 8, 16] {
        println!("{k} x 2 substructures, no stiffening:");
        let (z, moving) = droop(blade(
            &format!("substructures = {k}\nelements_per_substructure = 2"),
            "",
            "",
        ));
        assert!(moving < 1e-5, "settled");
        subs.push(z);
    }
    println!("one frame of 16 elements, geometric stiffening:");
    let (single, moving) = droop(blade("elements = 16", "geometric_stiffening = true", ""));
    assert!(moving < 1e-5, "settled");
    println!("one frame of 16 elements, no stiffening:");
    let (plain, _) = droop(blade("elements = 16", "", ""));
    let (d1, d2) = ((subs[1] - subs[0]).abs(), (subs[2] - subs[1]).abs());
    // second order in the substructure length (each halving divides the change by about 4):
    // the converged value by Richardson extrapolation from 8 and 16
    let converged = subs[2] + (subs[2] - subs[1]) / 3.0;
    println!(
        "substructures 4, 8, 16: {subs:.6?} m (changes {d1:.2e}, {d2:.2e}, ratio {:.2}); \
         converged {converged:.6} m; single frame stiffened {single:.6} m ({:+.3} %), plain \
         {plain:.6} m ({:+.1} %)",
        d1 / d2,
        100.0 * (single - converged) / converged,
        100.0 * (plain - converged) / converged
    );
    assert!(
        (3.0..5.5).contains(&(d1 / d2)),
        "substructures converge at second order: {d1:.2e}, {d2:.2e}"
    );
    assert!((converged - subs[2]).abs() < 5e-3 * converged.abs());
    // the issue's figure: about -0.06 m
    assert!((converged + 0.060).abs() < 0.003, "{converged}");
    // one frame with stiffening within 1 % of the converged value; without it, far off
    assert!(
        (single - converged).abs() < 0.01 * converged.abs(),
        "{single} vs {converged}"
    );
    assert!((plain - converged).abs() > 0.3 * converged.abs());
}

/// C4 at Ω = 10 (`spin_up_omega10_stiffened.toml`: one pinned frame of 10 elements, stiffening) as a
/// 3D scene: the same beam in the world x–y plane, hub axis z, the in-plane second moment
/// I_z = J (I_y = J, J_t = 2J, G = E/2.6 do not enter a planar motion); `formulation =
/// "spatial"` makes it run with the 3D element, which would otherwise reduce it to the plane.
const C4_3D: &str = r#"name = "spin_up_omega10_stiffened_3d"
dimensions = 3
formulation = "spatial"

[experiment]
stop_time = 20.0
step_size = 1e-2

[solver]
rho_inf = 0.9

[[beam]]
name = "beam"
length = 8.0
elements = 10
frame = "pinned"
material = { rho = 2767.0, E = 6.895e10, G = 2.652e10 }
section = { A = 7.299e-5, Iy = 8.214e-9, Iz = 8.214e-9, It = 1.6428e-8 }
geometric_stiffening = true

[[joint]]
name = "hub"
type = "revolute"
frames = ["world", "beam.a"]
axis = [0.0, 0.0, 1.0]
drive = { kind = "motion", law = "spin_up", omega = 10.0, ramp_time = 15.0 }
"#;

/// The 3D element with stiffening against the planar unit on C4 (Ω = 10, whose single frame
/// without stiffening grows without bound past the first bending frequency): the tip
/// deflection in the hub frame every 0.05 s over the whole 20 s, both at the same fixed step
/// (2e-3 s) and a tight Newton tolerance, so that they differ only by the frame rotation's
/// parametrization (an angle against a quaternion: O(h²), see
/// `src/tests/planar_spatial_agreement.rs`). Asserted: within 1e-4 of the peak.
#[test]
fn c4_omega10_3d_scene_with_stiffening_agrees_with_the_planar_unit() {
    let spatial = Scene::from_toml_str(C4_3D, "c4_3d").expect("a valid scene");
    let r = resolve_effects(&spatial);
    let said = |effect: &str, subject: &str| {
        r.decisions
            .iter()
            .find(|d| d.effect == effect && d.subject == subject)
            .map(|d| d.setting.clone())
    };
    assert_eq!(said("formulation", "scene").as_deref(), Some("spatial"));
    assert_eq!(said("geometric_stiffening", "beam").as_deref(), Some("on"));
    let fixed = [
        ("solver.adaptive", 0.0),
        ("solver.max_step", 2e-3),
        ("solver.tolerance", 1e-9),
    ];
    let t0 = std::time::Instant::now();
    let a2d = run(
        scene("spin_up_omega10_stiffened.toml"),
        &fixed,
        &["beam.tip.deflection"],
        0.05,
        20.0,
    );
    let t2d = t0.elapsed().as_secs_f64();
    let a3d = run(spatial, &fixed, &["beam.tip.deflection_y"], 0.05, 20.0);
    let t3d = t0.elapsed().as_secs_f64() - t2d;
    let peak = a2d.column(1).iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let (worst, at) = a2d
        .rows
        .iter()
        .zip(&a3d.rows)
        .map(|(p, s)| ((p[1] - s[1]).abs(), p[0]))
        .fold((0.0, 0.0), |m, x| if x.0 > m.0 { x } else { m });
    println!(
        "C4 Ω = 10, one stiffened frame: planar peak {peak:.6} m; largest |3D − planar| \
         {worst:.2e} m at t = {at:.2} s ({:.2e} of the peak); planar {t2d:.1} s, 3D {t3d:.1} s",
        worst / peak
    );
    assert!(
        peak > 1.0,
        "the stiffened single frame peaks near 1.08 m: {peak}"
    );
    assert!(worst < 1e-4 * peak, "{:.2e} of the peak", worst / peak);
}

/// `auto` in 3D: the blade spun to 8 rad/s, 0.62 x its flap frequency 12.92 rad/s (above
/// `SPIN_RATIO` = 0.3), gets stiffening and says why; spun to 2 or 1 rad/s (0.15, 0.08 x) only
/// where the rigid-body run's centrifugal pull exceeds 1 % of the buckling load
/// (`AXIAL_SHARE`); a 3D cantilever (formulation spatial) with an axial tip load of 5 % of its
/// buckling load gets it, with 0.5 % it does not. `"all"` turns it on, `"scene"` and a list follow the beam's flag.
#[test]
fn auto_chooses_stiffening_in_3d_and_says_why() {
    let stiffening = |s: &Scene| {
        let r = resolve_effects(s);
        let d = r
            .decisions
            .iter()
            .find(|d| d.effect == "geometric_stiffening" && d.subject == "blade")
            .expect("a decision")
            .clone();
        assert!(r.explain(s).contains(&d.why), "explain carries the reason");
        assert_eq!(
            r.effects.beams[0].options.geometric_stiffening,
            d.setting == "on"
        );
        (d.setting, d.why)
    };
    let (set, why) = stiffening(&blade("elements = 16", "", "effects = \"auto\""));
    println!("8 rad/s: {set}: {why}");
    assert_eq!(set, "on");
    assert!(
        why.contains("spin up to 8.000 rad/s") && why.contains("12.92"),
        "{why}"
    );
    // at 2 rad/s the centrifugal pull m ω² L/2 = 21.6 N is 1.5 % of the buckling load: on;
    // at 1 rad/s 5.4 N, 0.4 %: off
    let (set, why) = stiffening(&blade_at(2.0, "elements = 16", "", "effects = \"auto\""));
    println!("2 rad/s: {set}: {why}");
    assert_eq!(set, "on");
    assert!(why.contains("axial force of 2.16"), "{why}");
    let (set, why) = stiffening(&blade_at(1.0, "elements = 16", "", "effects = \"auto\""));
    println!("1 rad/s: {set}: {why}");
    assert_eq!(set, "off");
    assert!(why.contains("below 0.3") && why.contains("5.40"), "{why}");
    for (share, want) in [(0.05, "on"), (0.005, "off")] {
        // E I_y = 583.3 N m² over 2 m: buckling load π²EI/L² = 1439 N
        let force = share * std::f64::consts::PI.powi(2) * 70e9 * (0.1 * 1e-6 / 12.0) / 4.0;
        let text = format!(
            "name = \"pulled\"\ndimensions = 3\nformulation = \"spatial\"\neffects = \"auto\"\n\
             [experiment]\nstop_time = 1.0\n[[beam]]\nname = \"blade\"\nlength = 2.0\n\
             elements = 4\nmaterial = {{ rho = 2700.0, E = 70e9, G = 26e9 }}\n\
             section = {{ shape = \"rectangle\", a = 0.1, b = 0.01 }}\n[[joint]]\n\
             name = \"clamp\"\ntype = \"weld\"\nframes = [\"world\", \"blade.a\"]\n[[load]]\n\
             name = \"pull\"\nframe = \"blade.b\"\nforce = [{force}, 0.0, 0.0]\n"
        );
        let s = Scene::from_toml_str(&text, "pulled").expect("valid");
        let (set, why) = stiffening(&s);
        println!(
            "axial pull {:.1} % of buckling: {set}: {why}",
            100.0 * share
        );
        assert_eq!(set, want, "{why}");
        assert!(why.contains("axial force"), "{why}");
    }
    for (effects, extra, want) in [
        ("effects = \"all\"", "", "on"),
        ("", "", "off"),
        ("", "geometric_stiffening = true", "on"),
        (
            "effects = [\"gravity\", \"flexibility\", \"geometric_stiffening\"]",
            "geometric_stiffening = true",
            "on",
        ),
        (
            "effects = [\"gravity\", \"flexibility\"]",
            "geometric_stiffening = true",
            "off",
        ),
    ] {
        let (set, why) = stiffening(&blade("elements = 16", extra, effects));
        println!("{effects:?} {extra:?}: {set}: {why}");
        assert_eq!(set, want, "{effects} {extra}");
    }
}
