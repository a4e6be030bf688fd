//! A jump of the loads strikes a flexible body's modes; met through the iteration matrix of
//! the step after it (`initial::meet_jump`), the energy falls behind the work and never rises
//! above it, at steps that do not resolve the fast modes. Checked here for the jumps that come
//! from outside the unit or meet its communication points (C3's own cut-off and C2's release:
//! `c3_slider_crank.rs`, `c2_flexible_pendulum.rs`):
//! - an input's jump (`Stepper::meet_jump_from`, after the mass matrix's consistent restart with
//!   the inputs the last step ended with): the flexible arm (`flexible_arm.toml`, ρ∞ = 0.9)
//!   driven by an input torque of 10 N m reversed at 1 s. Met through the mass matrix alone, its
//!   energy at 1e-2 s grew to 4 × the largest work done on it by 2 s;
//! - a drive law's jump a few ulps past the communication point a unit with inputs landed on:
//!   the split slider-crank's crank unit, whose master adds up steps of 2.5e-3 s and reaches
//!   0.6999999999999961 s, 4e-15 s before the torque's cut-off. The jump was taken for one
//!   already passed and never met: 2.6e-4 J made (0.45 % of the work).

use crate::common;
use common::{scene, vr};
use fmu_beam::Engine;

#[test]
fn a_reversed_input_torque_creates_no_energy_at_a_fixed_step() {
    for h in [1e-2, 5e-3] {
        let mut e = Engine::new(scene("flexible_arm.toml"));
        let adaptive = vr(&e, "solver.adaptive");
        e.set_boolean(adaptive, false).unwrap();
        let max_step = vr(&e, "solver.max_step");
        e.set_real(max_step, h).unwrap();
        e.exit_initialization().unwrap();
        let [torque, work, kinetic, strain] = [
            "hub.drive.torque",
            "energy.work",
            "energy.kinetic",
            "energy.strain",
        ]
        .map(|n| vr(&e, n));
        let (mut low, mut largest) = (f64::MAX, 0.0f64);
        for k in 0..200 {
            let t = k as f64 * 1e-2;
            e.set_real(torque, if t < 1.0 { 10.0 } else { -10.0 })
                .unwrap();
            e.do_step(t, 1e-2).unwrap();
            let w = e.get_real(work).unwrap();
            let taken = w - e.get_real(kinetic).unwrap() - e.get_real(strain).unwrap();
            (low, largest) = (low.min(taken), largest.max(w.abs()));
        }
        println!(
            "arm at {h:e} s: work - energy down to {:.2e} of the largest work",
            low / largest
        );
        assert!(low > -1e-6 * largest, "no energy created");
    }
}

#[test]
fn a_law_jump_just_past_a_communication_point_is_met() {
    let mut e = Engine::new(scene("slider_crank_split_crank.toml"));
    let adaptive = vr(&e, "solver.adaptive");
    e.set_boolean(adaptive, false).unwrap();
    e.exit_initialization().unwrap();
    let [work, kinetic, strain] =
        ["energy.work", "energy.kinetic", "energy.strain"].map(|n| vr(&e, n));
    let (mut t, mut low, mut largest) = (0.0f64, f64::MAX, 0.0f64);
    while t < 0.8 {
        e.do_step(t, 2.5e-3).unwrap();
        t += 2.5e-3;
        let w = e.get_real(work).unwrap();
        let taken = w - e.get_real(kinetic).unwrap() - e.get_real(strain).unwrap();
        (low, largest) = (low.min(taken), largest.max(w));
    }
    println!(
        "split crank: work - energy down to {:.2e} of the work",
        low / largest
    );
    assert!(low > -1e-6 * largest, "no energy created");
}
