//! Shared helpers of the case tests: load a scene, set parameters, run the engine with a
//! fixed communication step and record outputs.
#![allow(dead_code)]

use fmu_beam::{Engine, Scene};
use std::path::Path;

pub fn scene(file: &str) -> Scene {
    Scene::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes")
            .join(file),
    )
    .expect("valid scene")
}

pub fn vr(e: &Engine, name: &str) -> u32 {
    e.variables()
        .by_name(name)
        .unwrap_or_else(|| panic!("no variable {name}"))
        .vr
}

/// Time series of `outputs` (first column: time) every `hc` seconds up to `stop`.
pub struct Run {
    pub rows: Vec<Vec<f64>>,
    pub engine: Engine,
}

impl Run {
    pub fn column(&self, k: usize) -> Vec<f64> {
        self.rows.iter().map(|r| r[k]).collect()
    }
    pub fn last(&self, k: usize) -> f64 {
        self.rows.last().unwrap()[k]
    }
}

pub fn run(scene: Scene, params: &[(&str, f64)], outputs: &[&str], hc: f64, stop: f64) -> Run {
    let mut e = Engine::new(scene);
    for (p, v) in params {
        let var = e
            .variables()
            .by_name(p)
            .unwrap_or_else(|| panic!("no parameter {p}"))
            .clone();
        match var.ty {
            fmu_beam::VarType::Boolean => e.set_boolean(var.vr, *v != 0.0).unwrap(),
            _ => e.set_real(var.vr, *v).unwrap(),
        }
    }
    e.exit_initialization().unwrap();
    let vrs: Vec<u32> = outputs.iter().map(|o| vr(&e, o)).collect();
    let mut rows = Vec::new();
    let record = |e: &mut Engine, t: f64, rows: &mut Vec<Vec<f64>>| {
        let mut r = vec![t];
        r.extend(vrs.iter().map(|&v| e.get_real(v).unwrap()));
        rows.push(r);
    };
    record(&mut e, 0.0, &mut rows);
    let n = (stop / hc).round() as usize;
    let mut t = 0.0;
    for k in 0..n {
        e.do_step(t, hc)
            .unwrap_or_else(|err| panic!("step at t = {t}: {err}"));
        t = (k + 1) as f64 * hc;
        record(&mut e, t, &mut rows);
    }
    Run { rows, engine: e }
}

/// Columns of a reference CSV of `bench/reference/` (header line, then numbers).
pub fn reference(file: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../bench/reference")
        .join(file);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    let mut lines = text.lines();
    let names = lines
        .next()
        .expect("a header")
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').map(|x| x.parse().expect("a number")).collect())
        .collect();
    (names, rows)
}
