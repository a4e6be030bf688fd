//! Timing of the time integration on the validated scenes: internal steps, Newton iterations,
//! factorizations and CPU seconds (median of 3 runs) per scene, communication step 1e-2 s.
//!
//! `cargo run --release -p fmu-beam --example step_timing [-- --save DIR | --compare DIR]`
//! `--save` writes every real output at every communication point to DIR/<scene>.csv;
//! `--compare` prints the largest difference of each output against such files; `--only NAME`
//! runs the scenes whose file name contains NAME.

use fmu_beam::{Causality, VarType};
use fmu_beam::{Engine, Scene};
use std::path::{Path, PathBuf};
use std::time::Instant;

const CASES: [(&str, f64); 4] = [
    ("flexible_pendulum.toml", 1.0),
    ("slider_crank.toml", 1.6),
    ("spin_up_omega10.toml", 20.0),
    ("cantilever_free_vibration.toml", 2.0),
];
const HC: f64 = 1e-2;

/// CPU time of this thread (s), from the scheduler's account where Linux offers it.
fn cpu_seconds(wall: Instant) -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or_else(|| wall.elapsed().as_secs_f64(), |ns| ns * 1e-9)
}

struct Outcome {
    names: Vec<String>,
    rows: Vec<Vec<f64>>,
    counters: [i32; 4],
    cpu: f64,
}

fn run(scene: &Scene, stop: f64) -> Outcome {
    let origin = Instant::now();
    let c0 = cpu_seconds(origin);
    let mut e = Engine::new(scene.clone());
    e.exit_initialization().expect("initialization");
    let outs: Vec<(String, u32)> = e
        .variables()
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Output && v.ty == VarType::Real)
        .map(|v| (v.name.clone(), v.vr))
        .collect();
    let mut rows = Vec::new();
    let n = (stop / HC).round() as usize;
    for k in 0..=n {
        if k > 0 {
            let t = (k - 1) as f64 * HC;
            e.do_step(t, HC)
                .unwrap_or_else(|err| panic!("step at {t}: {err}"));
        }
        rows.push(
            outs.iter()
                .map(|(_, vr)| e.get_real(*vr).unwrap())
                .collect(),
        );
    }
    let cpu = cpu_seconds(origin) - c0;
    let mut counter = |name: &str| {
        let vr = e.variables().by_name(name).expect("counter").vr;
        e.get_integer(vr).unwrap()
    };
    Outcome {
        names: outs.into_iter().map(|(n, _)| n).collect(),
        rows,
        counters: [
            counter("solver.steps"),
            counter("solver.newton_iterations"),
            counter("solver.jacobians"),
            counter("solver.rejected_steps"),
        ],
        cpu,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dir = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .map(|i| PathBuf::from(&args[i + 1]))
    };
    let (save, compare) = (dir("--save"), dir("--compare"));
    let only = args
        .iter()
        .position(|a| a == "--only")
        .map(|i| args[i + 1].clone());
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    println!(
        "{:<32} {:>7} {:>8} {:>7} {:>6} {:>9} {:>9}",
        "scene", "steps", "newton", "jacob", "rej", "cpu s", "µs/step"
    );
    for (file, stop) in CASES {
        if only.as_ref().is_some_and(|o| !file.contains(o.as_str())) {
            continue;
        }
        let scene = Scene::load(&scenes.join(file)).expect("scene");
        let mut runs: Vec<Outcome> = (0..3).map(|_| run(&scene, stop)).collect();
        runs.sort_by(|a, b| a.cpu.total_cmp(&b.cpu));
        let o = &runs[1];
        let [s, nw, j, r] = o.counters;
        println!(
            "{:<32} {:>7} {:>8} {:>7} {:>6} {:>9.4} {:>9.1}",
            file,
            s,
            nw,
            j,
            r,
            o.cpu,
            o.cpu / s as f64 * 1e6
        );
        let csv = |d: &Path| d.join(file.replace(".toml", ".csv"));
        if let Some(d) = &save {
            std::fs::create_dir_all(d).expect("dir");
            let mut text = o.names.join(",") + "\n";
            for row in &o.rows {
                let cells: Vec<String> = row.iter().map(|x| format!("{x:e}")).collect();
                text += &(cells.join(",") + "\n");
            }
            std::fs::write(csv(d), text).expect("write");
        }
        if let Some(d) = &compare {
            let text = std::fs::read_to_string(csv(d)).expect("reference csv");
            let mut lines = text.lines();
            let names: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
            let reference: Vec<Vec<f64>> = lines
                .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
                .collect();
            for (k, name) in names.iter().enumerate() {
                let Some(c) = o.names.iter().position(|n| n == name) else {
                    continue;
                };
                let (mut diff, mut size) = (0.0f64, 0.0f64);
                for (a, b) in o.rows.iter().zip(&reference) {
                    diff = diff.max((a[c] - b[k]).abs());
                    size = size.max(b[k].abs());
                }
                println!("    {name:<34} max |diff| {diff:.3e}  (max |value| {size:.3e})");
            }
        }
    }
}
