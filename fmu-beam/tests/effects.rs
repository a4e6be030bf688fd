//! Effects: what `auto` decides for each validation scene, that its results stay within the
//! case's tolerance of the full model, that a term switched off is never evaluated, and that
//! modal truncation keeps the lowest modes exactly and converges as modes are added.

use crate::common;

use common::{run, scene};
use fmu_beam::integrator::{initial_state, Settings, Stats, Stepper};
use fmu_beam::mechanics::Effects;
use fmu_beam::mechanics::System;
use fmu_beam::natural_frequencies;
use fmu_beam::resolve_effects as resolve;
use fmu_beam::scene::{EffectsSpec, Scene};

fn with_effects(mut s: Scene, effects: EffectsSpec) -> Scene {
    s.effects = effects;
    s
}

fn auto(file: &str) -> Scene {
    with_effects(scene(file), EffectsSpec::Mode("auto".into()))
}

/// The resolved effects as `effect(subject)=setting` entries, sorted.
fn summary(s: &Scene) -> Vec<String> {
    let mut v: Vec<String> = resolve(s)
        .decisions
        .iter()
        .map(|d| format!("{}({})={}", d.effect, d.subject, d.setting))
        .collect();
    v.sort();
    v
}

#[test]
fn auto_resolves_the_expected_effects_of_each_validation_scene() {
    // scene → the effects `auto` must choose, and why it must (the rules of `effects`)
    let table: [(&str, &[&str]); 6] = [
        // C1: clamped to the world (no rotation), no gravity, no damping, starts deformed
        (
            "cantilever_free_vibration.toml",
            &[
                "gravity(scene)=off",
                "flexibility(beam)=10 elements",
                "axial(beam)=off",
                "quadratic_velocity(beam)=off",
                "geometric_stiffening(beam)=off",
                "rayleigh_damping(beam)=off",
            ],
        ),
        // C2: gravity, a swinging frame, released from rest: a step reaches the axial modes;
        // weight and swing load the beam with 13 % of its buckling load
        (
            "flexible_pendulum.toml",
            &[
                "gravity(scene)=on",
                "flexibility(beam)=10 elements",
                "axial(beam)=on",
                "quadratic_velocity(beam)=on",
                "geometric_stiffening(beam)=on",
                "rayleigh_damping(beam)=off",
            ],
        ),
        // C3: a torque cut off at 0.7 s excites everything (axial modes too); both links rotate;
        // the rod's inertial axial force reaches 9 % of its buckling load, the crank's 0.15 %
        (
            "slider_crank.toml",
            &[
                "gravity(scene)=off",
                "flexibility(crank)=2 elements",
                "axial(crank)=on",
                "quadratic_velocity(crank)=on",
                "geometric_stiffening(crank)=off",
                "rayleigh_damping(crank)=off",
                "flexibility(rod)=4 elements",
                "axial(rod)=on",
                "quadratic_velocity(rod)=on",
                "geometric_stiffening(rod)=on",
                "rayleigh_damping(rod)=off",
            ],
        ),
        (
            "slider_crank_rigid_crank.toml",
            &[
                "gravity(scene)=off",
                "flexibility(crank)=rigid",
                "flexibility(rod)=4 elements",
                "axial(rod)=on",
                "quadratic_velocity(rod)=on",
                "geometric_stiffening(rod)=on",
                "rayleigh_damping(rod)=off",
            ],
        ),
        // C4: spinning at 3.4 x the first bending frequency, substructures or a single frame
        // need geometric stiffening, which needs the axial strain
        (
            "spin_up_omega10.toml",
            &[
                "gravity(scene)=off",
                "flexibility(beam)=10 x 1 elements",
                "axial(beam)=on",
                "quadratic_velocity(beam)=on",
                "geometric_stiffening(beam)=on",
                "rayleigh_damping(beam)=off",
            ],
        ),
        (
            "spin_up_omega10_single_frame.toml",
            &[
                "gravity(scene)=off",
                "flexibility(beam)=10 elements",
                "axial(beam)=on",
                "quadratic_velocity(beam)=on",
                "geometric_stiffening(beam)=on",
                "rayleigh_damping(beam)=off",
            ],
        ),
    ];
    for (file, expected) in table {
        let mut want: Vec<String> = expected.iter().map(|s| s.to_string()).collect();
        want.sort();
        assert_eq!(summary(&auto(file)), want, "{file}");
    }
}

#[test]
fn auto_keeps_a_few_modes_of_a_beam_driven_slowly() {
    // C4's single-frame beam spun to 0.5 rad/s (no stiffening needed) on a 150 s ramp: the
    // excitation bandwidth 0.042 rad/s is 70 x below the first bending frequency 2.9 rad/s, so
    // the response is quasi-static: four modes
    let mut s = auto("spin_up_omega10_single_frame.toml");
    let law = &mut s.joints[0].drive.as_mut().unwrap().law;
    law.ramp_time = Some(150.0);
    law.omega = Some(0.5);
    let r = resolve(&s);
    let flex = r
        .decisions
        .iter()
        .find(|d| d.effect == "flexibility")
        .unwrap();
    assert_eq!(flex.setting, "10 elements, 4 modes", "{}", flex.why);
}

/// Largest difference between two runs' column `k`, relative to the full run's amplitude.
fn relative_difference(a: &common::Run, b: &common::Run, k: usize) -> f64 {
    let amp = a.column(k).iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a
        .column(k)
        .iter()
        .zip(b.column(k))
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    diff / amp
}

#[test]
fn auto_stays_within_each_case_tolerance_of_the_full_model() {
    // (scene, output, communication step, stop, tolerance): the tolerances of CASES.md — C1
    // frequencies to 1e-6 (the dropped terms are exactly zero there), C2 and C3 deflections to
    // 1e-3 relative, C4 tip deflection to 1 %
    let cases = [
        (
            "cantilever_free_vibration.toml",
            "beam.tip.deflection",
            1e-3,
            0.5,
            1e-6,
        ),
        (
            "flexible_pendulum.toml",
            "beam.tip.deflection",
            1e-3,
            1.0,
            1e-3,
        ),
        ("slider_crank.toml", "rod.mid.deflection", 1e-3, 1.0, 1e-3),
        (
            "spin_up_omega4.toml",
            "beam.tip.deflection",
            1e-1,
            20.0,
            1e-2,
        ),
    ];
    for (file, output, hc, stop, tol) in cases {
        // the full model with the geometric stiffness auto adds (it changes the physics, on
        // purpose: `auto_adds_the_geometric_stiffness_the_exact_answer_needs`); what auto drops
        // must stay within the tolerance
        let mut full_scene = scene(file);
        let chosen = resolve(&auto(file)).effects;
        for (b, e) in full_scene.beams.iter_mut().zip(&chosen.beams) {
            b.geometric_stiffening = e.options.geometric_stiffening;
        }
        let full = run(full_scene, &[], &[output], hc, stop);
        let auto = run(auto(file), &[], &[output], hc, stop);
        let d = relative_difference(&full, &auto, 1);
        println!(
            "{file}: auto differs from the full model by {d:.2e} of the amplitude of {output}"
        );
        assert!(
            d < tol,
            "{file}: {output} differs by {d:e} (tolerance {tol:e})"
        );
    }
}

/// Integrates `scene` with `effects` to `stop` and returns the system (with its counts).
fn integrate(scene: &Scene, effects: &Effects, stop: f64) -> System {
    let sys = System::build(scene, effects);
    let settings = Settings::from_scene(scene);
    let mut st = initial_state(&sys, 0.0, &settings).expect("initial state");
    let mut stepper = Stepper::new(&sys, settings);
    let mut stats = Stats::default();
    stepper
        .step_to(&sys, &mut st, &mut stats, stop)
        .expect("integrates");
    sys
}

#[test]
fn a_term_switched_off_is_never_evaluated() {
    // C2 with damping: every term is on in the full model
    let mut s = scene("flexible_pendulum.toml");
    s.beams[0].rayleigh.alpha = 0.1;
    s.beams[0].rayleigh.beta = 1e-4;
    let full = resolve(&s).effects;
    let counts = |e: &Effects| {
        let c = integrate(&s, e, 0.05).term_counts();
        [
            ("gravity", c.gravity.get()),
            ("quadratic_velocity", c.quadratic_velocity.get()),
            ("rayleigh_damping", c.damping.get()),
            ("axial", c.axial.get()),
        ]
    };
    for (name, n) in counts(&full) {
        assert!(n > 0, "full model: {name} evaluated {n} times");
    }
    type Switch = fn(&mut Effects);
    let off: [(&str, Switch); 4] = [
        ("gravity", |e| e.gravity = false),
        ("quadratic_velocity", |e| {
            e.beams[0].options.quadratic_velocity = false
        }),
        ("rayleigh_damping", |e| e.beams[0].options.damping = false),
        ("axial", |e| e.beams[0].options.axial = false),
    ];
    for (effect, switch) in off {
        let mut e = full.clone();
        switch(&mut e);
        for (name, n) in counts(&e) {
            if name == effect {
                assert_eq!(n, 0, "{effect} off: still evaluated {n} times");
            } else {
                assert!(n > 0, "{effect} off: {name} not evaluated");
            }
        }
    }
    // geometric stiffening, on C4's single frame
    let s = scene("spin_up_omega10_stiffened.toml");
    let mut e = resolve(&s).effects;
    assert!(
        integrate(&s, &e, 0.05)
            .term_counts()
            .geometric_stiffening
            .get()
            > 0
    );
    e.beams[0].options.geometric_stiffening = false;
    assert_eq!(
        integrate(&s, &e, 0.05)
            .term_counts()
            .geometric_stiffening
            .get(),
        0
    );
}

#[test]
fn an_effects_list_switches_terms_off() {
    let s = with_effects(
        scene("flexible_pendulum.toml"),
        EffectsSpec::List(vec!["flexibility".into(), "quadratic_velocity".into()]),
    );
    let e = resolve(&s).effects;
    assert!(!e.gravity);
    let o = e.beams[0].options;
    assert!(!e.beams[0].rigid && o.quadratic_velocity && !o.axial && !o.damping);
    let c = integrate(&s, &e, 0.01).term_counts();
    assert_eq!(c.gravity.get(), 0);
    // without gravity the pendulum released at rest stays at rest
    let r = run(s, &[], &["beam.tip.deflection"], 1e-3, 0.05);
    assert_eq!(r.last(1), 0.0);
}

fn c1_with_modes(k: Option<usize>) -> Scene {
    let mut s = scene("cantilever_free_vibration.toml");
    s.beams[0].modes = k;
    s
}

#[test]
fn modal_truncation_keeps_the_lowest_frequencies_exactly() {
    let full = natural_frequencies(&c1_with_modes(None)).unwrap();
    for k in [1, 2, 4, 8] {
        let f = natural_frequencies(&c1_with_modes(Some(k))).unwrap();
        // the system adds 3 frame coordinates held by the clamp: drop the rigid-body zeros
        let f: Vec<f64> = f.into_iter().filter(|&x| x > 1e-6).collect();
        assert_eq!(f.len(), k, "{k} modes");
        for (i, (a, b)) in f.iter().zip(&full).enumerate() {
            let rel = (a - b).abs() / b;
            assert!(rel < 1e-9, "k = {k}: mode {} differs by {rel:e}", i + 1);
        }
    }
}

#[test]
fn modal_truncation_converges_to_the_full_model() {
    // C1's free vibration from its static tip shape: the tip history with k modes against all
    let output = "beam.tip.deflection";
    let full = run(c1_with_modes(None), &[], &[output], 1e-3, 0.5);
    let mut last = f64::INFINITY;
    for k in [1, 2, 4, 8] {
        let r = run(c1_with_modes(Some(k)), &[], &[output], 1e-3, 0.5);
        let d = relative_difference(&full, &r, 1);
        println!("C1 with {k} modes: tip history within {d:.2e} of the amplitude");
        assert!(d < last, "{k} modes: {d:e} is no better than {last:e}");
        last = d;
    }
    assert!(last < 1e-3, "8 modes: {last:e}");
}

#[test]
fn the_variables_are_those_of_the_effects_that_are_on() {
    use fmu_beam::VariableTable;
    let names = |s: &Scene| -> Vec<String> {
        VariableTable::build(s)
            .variables
            .iter()
            .map(|v| v.name.clone())
            .collect()
    };
    let has = |v: &[String], n: &str| v.iter().any(|x| x == n);
    // C1 under auto: no gravity field, no damping
    let full = names(&scene("cantilever_free_vibration.toml"));
    let auto = names(&auto("cantilever_free_vibration.toml"));
    for n in [
        "world.gravity.x",
        "energy.potential",
        "beam.rayleigh.alpha",
        "beam.rayleigh.beta",
    ] {
        assert!(has(&full, n) && !has(&auto, n), "{n}");
    }
    assert!(has(&auto, "beam.tip.deflection") && has(&auto, "beam.E"));
    // a rigid crank has no stiffness, damping or deflection
    let rigid = names(&scene("slider_crank_rigid_crank.toml"));
    for n in ["crank.E", "crank.tip.deflection", "crank.rayleigh.alpha"] {
        assert!(!has(&rigid, n), "{n}");
    }
    assert!(has(&rigid, "crank.tip.x") && has(&rigid, "rod.E"));
}

#[test]
fn auto_warns_when_parameters_would_change_its_choice() {
    use fmu_beam::Engine;
    // C4 single frame spun to 0.2 rad/s: auto needs no stiffening (the centrifugal force is
    // 0.3 % of the buckling load); at 10 rad/s it would
    let mut s = auto("spin_up_omega10_single_frame.toml");
    s.joints[0].drive.as_mut().unwrap().law.omega = Some(0.2);
    assert!(!resolve(&s).effects.beams[0].options.geometric_stiffening);
    let mut e = Engine::new(s.clone());
    let omega = common::vr(&e, "hub.drive.omega");
    e.set_real(omega, 10.0).unwrap();
    e.exit_initialization().unwrap();
    let warnings = e.take_messages();
    assert!(
        warnings
            .iter()
            .any(|m| m.contains("geometric_stiffening (beam) would be on")),
        "{warnings:?}"
    );
    // the packaged value raises no warning
    let mut e = Engine::new(s);
    e.exit_initialization().unwrap();
    assert!(e.take_messages().is_empty());
}

/// Issue 31: a revolute joint started at speed counts as spin. C4's single-frame beam without
/// its drive, started at 10 rad/s (3.4 x its first bending frequency), needs geometric
/// stiffening as the spin-up to 10 rad/s does; at rest it does not.
#[test]
fn auto_counts_a_joint_s_start_speed_as_spin() {
    let mut s = auto("spin_up_omega10_single_frame.toml");
    s.joints[0].drive = None;
    let stiffening = |s: &Scene| {
        summary(s)
            .iter()
            .any(|d| d == "geometric_stiffening(beam)=on")
    };
    assert!(!stiffening(&s));
    s.joints[0].initial = Some(fmu_beam::scene::JointInitialSpec {
        position: None,
        speed: Some(10.0),
    });
    assert!(stiffening(&s), "{:?}", summary(&s));
}
