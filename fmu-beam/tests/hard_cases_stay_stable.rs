//! Hard cases stay numerically stable (issue 7): fast spin-up, long undamped vibration, a very
//! stiff axial direction at extreme communication steps, a mechanism through its toggle
//! positions. Each test prints the figure it asserts. (Flat memory: `memory_is_flat.rs`.)

use crate::common;
use common::{run, scene};
use fmu_beam::{Engine, Scene};

fn with_substructures(file: &str, k: usize) -> Scene {
    let mut s = scene(file);
    s.beams[0].substructures = Some(k);
    s
}

fn peak_and_tail(s: Scene, params: &[(&str, f64)]) -> (f64, f64) {
    let r = run(s, params, &["beam.tip.deflection"], 0.1, 20.0);
    let peak = r.column(1).iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let tail = r
        .rows
        .iter()
        .filter(|r| r[0] > 15.0)
        .fold(0.0f64, |m, r| m.max(r[1].abs()));
    (peak, tail)
}

/// Spin-up to Omega = 20 rad/s (seven times the first bending frequency): with enough
/// substructures the deflection stays bounded and converges.
#[test]
fn spin_up_omega_20_is_bounded_and_converges() {
    let params = [("hub.drive.omega", 20.0)];
    let (p10, t10) = peak_and_tail(with_substructures("spin_up_omega10.toml", 10), &params);
    let (p20, t20) = peak_and_tail(with_substructures("spin_up_omega10.toml", 20), &params);
    println!("Omega = 20: peak {p10:.4} m (10 substructures), {p20:.4} m (20); after T at most {t10:.3e}, {t20:.3e} m");
    assert!(p20 < 8.0 * 0.5, "deflection beyond half the length");
    assert!(
        (p20 - p10).abs() < 0.05 * p20,
        "not converged with substructures"
    );
    assert!(
        t20 < 0.1 * p20,
        "the deflection after the spin-up is not small"
    );
}

/// C1 undamped for 1000 periods of mode 1: with rho_inf = 1 the energy is kept to 1e-4;
/// with numerical damping (rho_inf = 0.8) it never exceeds its start (the integrator only
/// removes energy; step to step the physical energy of generalized-α wobbles at 1e-9), and
/// mode 1 keeps its amplitude within 1 %.
#[test]
fn c1_energy_over_1000_periods() {
    let period: f64 = 1.0 / 2.0854751;
    let stop = (1000.0 * period / 0.01).ceil() * 0.01;
    let outs = ["energy.total", "beam.tip.deflection"];
    for rho in [1.0, 0.8] {
        let r = run(
            scene("cantilever_free_vibration.toml"),
            &[("solver.rho_inf", rho), ("solver.max_step", 1e-3)],
            &outs,
            0.01,
            stop,
        );
        let e = r.column(1);
        let drift = (e[e.len() - 1] - e[0]) / e[0];
        let highest = e.iter().fold(f64::MIN, |m, x| m.max(*x));
        // mode-1 amplitude: the tip's largest excursion in the first and the last 5 periods
        let amplitude = |from: f64, to: f64| {
            r.rows
                .iter()
                .filter(|row| row[0] >= from && row[0] <= to)
                .fold(0.0f64, |m, row| m.max(row[2].abs()))
        };
        let (a0, a1) = (
            amplitude(0.0, 5.0 * period),
            amplitude(stop - 5.0 * period, stop),
        );
        println!(
            "rho_inf {rho}: energy drift {drift:.2e} over {stop:.1} s, highest {:.2e} above the start; tip amplitude {a0:.6e} -> {a1:.6e} m",
            highest / e[0] - 1.0
        );
        if rho == 1.0 {
            assert!(drift.abs() < 1e-4);
        } else {
            assert!(
                drift <= 0.0 && highest <= e[0] * (1.0 + 1e-8),
                "numerical damping may only remove energy"
            );
        }
        assert!(
            (a1 - a0).abs() < 0.01 * a0,
            "mode 1 changed its amplitude by more than 1 %"
        );
    }
}

/// A very stiff axial direction (E A L² / E J = 1.2e9) and 200 elements: the iteration
/// converges at every step, with communication steps of 1e-2 s and of 1e-6 s.
#[test]
fn stiff_axial_direction_with_200_elements() {
    let text = r#"
name = "stiff"
[solver]
tolerance = 1e-6
max_step = 1e-2
[[beam]]
name = "beam"
length = 2.0
elements = 200
material = { rho = 7800.0, E = 210e9 }
section = { shape = "rectangle", a = 0.0002, b = 0.05 }
initial = { tip_displacement = 0.05 }
[[joint]]
name = "clamp"
type = "weld"
frames = ["world", "beam.a"]
"#;
    let s = Scene::from_toml_str(text, "stiff.toml").unwrap();
    let ratio = 0.05 * 0.0002 * 4.0 / (0.05 * 0.0002f64.powi(3) / 12.0);
    println!("E A L^2 / E J = {ratio:.2e}");
    assert!(ratio >= 1e8);
    for (hc, n) in [(1e-2, 20), (1e-6, 50)] {
        let mut e = Engine::new(s.clone());
        e.exit_initialization().unwrap();
        let mut t = 0.0;
        for _ in 0..n {
            e.do_step(t, hc)
                .unwrap_or_else(|err| panic!("communication step {hc}: {err}"));
            t += hc;
        }
        let vr = |e: &Engine, n: &str| e.variables().by_name(n).unwrap().vr;
        let steps = e.get_integer(vr(&e, "solver.steps")).unwrap();
        let rejected = e.get_integer(vr(&e, "solver.rejected_steps")).unwrap();
        let tip = e.get_real(vr(&e, "beam.tip.deflection")).unwrap();
        println!("communication step {hc:e}: {n} steps to {t:.2e} s, {steps} internal steps, {rejected} rejected, tip {tip:.5e} m");
        assert!(tip.is_finite() && tip.abs() <= 0.05 * 1.0001);
    }
}

/// The slider-crank driven at constant crank speed for 10 s passes its toggle (dead)
/// positions 28 times (14 turns): the constraints hold and the drive's work equals the energy.
#[test]
fn slider_crank_through_toggle_positions() {
    let mut s = scene("slider_crank.toml");
    let omega = 2.0 * std::f64::consts::PI * 1.5;
    let crank = s
        .joints
        .iter_mut()
        .find(|j| j.name == "crank_pivot")
        .unwrap();
    // the spin-up law of eq. (18): a smooth start to constant speed after 1 s (a jump of the
    // prescribed speed would be an impulse that no energy balance survives)
    crank.drive = Some(fmu_beam::scene::DriveSpec {
        kind: fmu_beam::scene::DriveKind::Motion,
        law: fmu_beam::scene::LawSpec {
            law: "spin_up".into(),
            value: None,
            time_constant: None,
            until: None,
            omega: Some(omega),
            ramp_time: Some(1.0),
            table: None,
        },
    });
    let outs = [
        "solver.constraint_residual",
        "energy.work",
        "energy.kinetic",
        "energy.strain",
        "crank_pivot.angle",
    ];
    let r = run(s, &[], &outs, 1e-2, 10.0);
    let drift = r.column(1).iter().fold(0.0f64, |m, x| m.max(*x));
    let worst = r
        .rows
        .iter()
        .fold(0.0f64, |m, row| m.max((row[2] - row[3] - row[4]).abs()));
    let kinetic = r.column(3).iter().fold(0.0f64, |m, x| m.max(*x));
    let turns = r.last(5) / (2.0 * std::f64::consts::PI);
    println!("{turns:.2} turns: max |g| {drift:.2e}, |work - energy| <= {worst:.2e} J (max kinetic {kinetic:.3e} J)");
    assert!(turns > 14.0);
    let late = r
        .rows
        .iter()
        .filter(|row| row[0] > 5.0)
        .fold(0.0f64, |m, row| m.max((row[2] - row[3] - row[4]).abs()));
    println!("energy error over the last 5 s: {late:.2e} J");
    assert!(drift < 1e-8);
    assert!(worst < 1e-3 * kinetic);
}
