//! What the shape outputs cost (issue 15): C3 and C4 (Ω = 10) run through `Engine` at their
//! communication steps over their whole experiment, without reading any output, and reading
//! every shape output (`<beam>.shape.*`, `<beam>.axis.*`) after each step; rounds interleaved
//! (not read, read), wall time per communication step as min / median / max over the rounds,
//! and the time spent in the reads alone.
//!
//! `cargo run --release -p fmu-beam --example shape_cost [-- ROUNDS]` (default 7 rounds)

use fmu_beam::{Engine, Scene};
use std::path::Path;
use std::time::Instant;

/// One run: seconds spent stepping, seconds spent reading, communication steps.
fn run(file: &str, read: bool) -> (f64, f64, usize) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes")
        .join(file);
    let scene = Scene::load(&path).expect("scene");
    let (h, stop) = (scene.experiment.step_size, scene.experiment.stop_time);
    let mut e = Engine::new(scene);
    let shape: Vec<u32> = e
        .variables()
        .variables
        .iter()
        .filter(|v| v.name.contains(".shape.") || v.name.contains(".axis."))
        .map(|v| v.vr)
        .collect();
    e.exit_initialization().expect("init");
    let n = (stop / h).round() as usize;
    let (mut stepping, mut reading) = (0.0, 0.0);
    let mut sink = 0.0;
    for k in 0..n {
        let t0 = Instant::now();
        e.do_step(k as f64 * h, h).expect("step");
        let t1 = Instant::now();
        if read {
            for &v in &shape {
                sink += e.get_real(v).expect("read");
            }
        }
        stepping += (t1 - t0).as_secs_f64();
        reading += t1.elapsed().as_secs_f64();
    }
    std::hint::black_box(sink);
    (stepping, reading, n)
}

/// min / median / max.
fn spread(mut v: Vec<f64>) -> [f64; 3] {
    v.sort_by(f64::total_cmp);
    [v[0], v[v.len() / 2], v[v.len() - 1]]
}

fn show([lo, mid, hi]: [f64; 3], digits: usize) -> String {
    format!("{lo:.digits$} / {mid:.digits$} / {hi:.digits$}")
}

fn main() {
    let rounds: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(7);
    println!("{rounds} rounds; µs per communication step, min / median / max");
    println!();
    println!("| case | shape outputs | comm. steps | not read | read after every step | the reads alone | reads / not read (medians) |");
    println!("|---|---|---|---|---|---|---|");
    for (case, file) in [
        ("C3", "slider_crank.toml"),
        ("C4 Ω = 10", "spin_up_omega10.toml"),
    ] {
        let count = {
            let s = Scene::load(
                &Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("../scenes")
                    .join(file),
            )
            .expect("scene");
            Engine::new(s)
                .variables()
                .variables
                .iter()
                .filter(|v| v.name.contains(".shape.") || v.name.contains(".axis."))
                .count()
        };
        let (mut plain, mut with, mut reads) = (Vec::new(), Vec::new(), Vec::new());
        let mut steps = 0;
        for _ in 0..rounds {
            let (s, _, n) = run(file, false);
            plain.push(1e6 * s / n as f64);
            let (s, r, n) = run(file, true);
            with.push(1e6 * (s + r) / n as f64);
            reads.push(1e6 * r / n as f64);
            steps = n;
        }
        let (p, w, r) = (spread(plain), spread(with), spread(reads));
        println!(
            "| {case} | {count} | {steps} | {} | {} | {} | {:.2} % |",
            show(p, 1),
            show(w, 1),
            show(r, 2),
            100.0 * r[1] / p[1]
        );
    }
}
