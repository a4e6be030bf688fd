//! Several instances in one process share nothing (issue 7): 8 threads, each running its own
//! engine of a different scene concurrently, give bit-identical results to runs one by one.

use crate::common;
use common::{run, scene};

const CASES: [(&str, &str); 8] = [
    ("cantilever_free_vibration.toml", "beam.tip.deflection"),
    ("flexible_pendulum.toml", "hinge.angle"),
    (
        "flexible_pendulum_substructured.toml",
        "beam.tip.deflection",
    ),
    ("slider_crank.toml", "slider.position"),
    ("slider_crank_rigid_crank.toml", "rod.mid.deflection"),
    ("spin_up_omega2.toml", "beam.tip.deflection"),
    ("spin_up_omega10_stiffened.toml", "beam.tip.deflection"),
    ("flexible_arm.toml", "hub.angle"),
];

fn series(file: &str, output: &str) -> Vec<u64> {
    run(scene(file), &[], &[output], 1e-2, 0.3)
        .column(1)
        .iter()
        .map(|x| x.to_bits())
        .collect()
}

#[test]
fn eight_threads_match_sequential_runs_bit_for_bit() {
    let sequential: Vec<Vec<u64>> = CASES.iter().map(|(f, o)| series(f, o)).collect();
    let concurrent: Vec<Vec<u64>> = std::thread::scope(|s| {
        let handles: Vec<_> = CASES
            .iter()
            .map(|(f, o)| s.spawn(move || series(f, o)))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for ((f, _), (a, b)) in CASES.iter().zip(sequential.iter().zip(&concurrent)) {
        assert_eq!(a, b, "{f}: concurrent run differs");
    }
    println!(
        "8 scenes, {} samples each: concurrent == sequential",
        sequential[0].len()
    );
}
