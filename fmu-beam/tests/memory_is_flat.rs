//! 1e5 steps of an engine leave the resident memory flat. Alone in its test binary, so that
//! no other test's allocations move the process's memory while it measures.

mod common;
use common::scene;
use fmu_beam::Engine;

/// 1e5 doStep calls: the resident memory does not grow.
#[test]
fn memory_is_flat_over_1e5_steps() {
    fn rss_kib() -> usize {
        let s = std::fs::read_to_string("/proc/self/statm").unwrap();
        let pages: usize = s.split_whitespace().nth(1).unwrap().parse().unwrap();
        pages * 4
    }
    let mut s = scene("cantilever_free_vibration.toml");
    s.beams[0].elements = Some(4);
    let mut e = Engine::new(s);
    e.exit_initialization().unwrap();
    let h = 1e-4;
    let mut before = 0;
    for k in 0..100_000usize {
        e.do_step(k as f64 * h, h).unwrap();
        if k == 10_000 {
            before = rss_kib();
        }
    }
    let after = rss_kib();
    println!("resident memory after 1e4 steps {before} KiB, after 1e5 steps {after} KiB");
    assert!(after <= before + 256);
}
