//! An input's jump strikes a flexible body's modes as a drive law's does, and is met the same
//! way (`Stepper::meet_jump_from`, after the mass matrix's consistent restart with the inputs
//! the last step ended with): the energy falls behind the work and never rises above it.
//! Checked on the flexible arm (`flexible_arm.toml`, ρ∞ = 0.9) driven by an input torque of
//! 10 N m reversed at 1 s, at fixed steps that do not resolve its fast modes. Met through the
//! mass matrix alone, its energy at 1e-2 s grew to 4 × the largest work done on it by 2 s.

mod common;
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
