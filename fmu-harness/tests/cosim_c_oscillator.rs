//! The master (`simulate` and `cosim`) on an FMU that is not ours: `tests/c/oscillator`, a damped
//! oscillator written in C with a hand-written modelDescription.xml, compiled with gcc and zipped
//! here. Checked against closed-form solutions:
//! - one oscillator, free vibration: x = x0 cos(ω t), ω² = k/m;
//! - two oscillators coupled by springs through `cosim` (A.u = B.x, B.u = A.x): normal modes ω1² =
//!   k/m, ω2² = (k + 2 k_c)/m; the coupling error shrinks with the communication step h as h^(p+1)
//!   for inputs approximated by polynomials of degree p (held: 1, linear: 2, quadratic: 3);
//! - rollback: a unit that refuses steps longer than `max_step` with fmi2Discard; with rollback
//!   the steps are halved and the run completes on the grid, without it the run fails naming the
//!   unit, t, h and the unit's message;
//! - a unit without canInterpolateInputs gets held inputs even when the system asks `linear`.

use fmu_harness::cosim::{self, system::System, CosimError};
use fmu_harness::simulate::{self, Options, Results};
use std::path::{Path, PathBuf};
use std::process::Command;

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cosim-c-oscillator")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}

fn source_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/c/oscillator")
}

/// Compiles oscillator.c and zips it with `xml` as `<dir>/<name>.fmu`.
fn build_fmu(dir: &Path, name: &str, xml: &str) -> PathBuf {
    let so = dir.join(format!("{name}.so"));
    let out = Command::new("gcc")
        .args([
            "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-fPIC", "-shared",
        ])
        .args(["-fvisibility=hidden", "-o"])
        .arg(&so)
        .arg(source_dir().join("oscillator.c"))
        .arg("-lm")
        .output()
        .expect("gcc is needed for this test (`make tools` installs it)");
    assert!(
        out.status.success(),
        "gcc failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let fmu = dir.join(format!("{name}.fmu"));
    let mut z = zip::ZipWriter::new(std::fs::File::create(&fmu).expect("create fmu"));
    let opts = zip::write::SimpleFileOptions::default();
    z.start_file("modelDescription.xml", opts).unwrap();
    std::io::Write::write_all(&mut z, xml.as_bytes()).unwrap();
    z.start_file("binaries/linux64/oscillator.so", opts)
        .unwrap();
    std::io::Write::write_all(&mut z, &std::fs::read(&so).unwrap()).unwrap();
    z.finish().unwrap();
    fmu
}

fn oscillator_fmu(dir: &Path) -> PathBuf {
    let xml = std::fs::read_to_string(source_dir().join("modelDescription.xml")).unwrap();
    build_fmu(dir, "oscillator", &xml)
}

fn column<'a>(r: &'a Results, name: &str) -> impl Iterator<Item = (f64, f64)> + 'a {
    let i = 1 + r.columns.iter().position(|c| c == name).expect(name);
    r.rows.iter().map(move |row| (row[0], row[i]))
}

const K: f64 = 100.0;
const KC: f64 = 50.0;
const X0: f64 = 0.1;

/// Two unit-mass oscillators, A starting at X0, B at rest at 0, springs K to ground and KC
/// between them: x_A,B = X0/2 (cos ω1 t ± cos ω2 t).
fn exact_pair(t: f64) -> (f64, f64) {
    let (w1, w2) = (K.sqrt(), (K + 2.0 * KC).sqrt());
    let (a, b) = ((w1 * t).cos(), (w2 * t).cos());
    (X0 / 2.0 * (a + b), X0 / 2.0 * (a - b))
}

fn pair_system(dir: &Path, h: f64, algorithm: &str, extrapolation: &str, extra: &str) -> PathBuf {
    let text = format!(
        r#"stop_time = 2.0
step = {{ size = {h:e} }}
algorithm = "{algorithm}"
extrapolation = "{extrapolation}"
connections = ["a.x -> b.u", "b.x -> a.u"]
outputs = ["a.x", "b.x"]

[[unit]]
name = "a"
fmu = "oscillator.fmu"
start = {{ k = {K:e}, k_c = {KC:e}, x0 = {X0:e}, dt = 1e-4 }}

[[unit]]
name = "b"
fmu = "oscillator.fmu"
start = {{ k = {K:e}, k_c = {KC:e}, x0 = 0.0, dt = 1e-4 }}
{extra}"#
    );
    let path = dir.join(format!("{algorithm}-{extrapolation}-{h:e}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

fn pair_error(r: &Results) -> f64 {
    column(r, "a.x")
        .zip(column(r, "b.x"))
        .map(|((t, a), (_, b))| {
            let (ea, eb) = exact_pair(t);
            (a - ea).abs().max((b - eb).abs())
        })
        .fold(0.0, f64::max)
}

#[test]
fn simulate_runs_the_c_fmu_on_the_closed_form_free_vibration() {
    let dir = scratch("simulate");
    let fmu = oscillator_fmu(&dir);
    let (r, ended) = simulate::simulate(
        &fmu,
        &Options {
            stop_time: Some(2.0),
            step: Some(1e-2),
            outputs: vec!["x".into(), "v".into()],
            on_warning: None,
        },
    )
    .expect("simulate the C oscillator");
    assert_eq!(ended, None);
    assert_eq!(r.rows.len(), 201);
    let w = K.sqrt();
    let err = column(&r, "x")
        .map(|(t, x)| (x - X0 * (w * t).cos()).abs())
        .fold(0.0, f64::max);
    println!("simulate: max |x - x0 cos(wt)| = {err:e}");
    // RK4 with dt = 1e-4 and ω = 10: global error ≈ (ω dt)^4 ω t X0 ≈ 2e-15·...; round-off dominates.
    assert!(err < 1e-10, "{err:e}");
}

#[test]
fn coupled_oscillators_converge_to_the_normal_modes_at_the_order_of_the_input_approximation() {
    let dir = scratch("pair");
    oscillator_fmu(&dir);
    let steps = [1e-2, 5e-3, 2.5e-3];
    for (algorithm, extrapolation, order) in [
        ("jacobi", "none", 1.0),
        ("gauss-seidel", "none", 1.0),
        ("jacobi", "linear", 2.0),
        ("gauss-seidel", "linear", 2.0),
        ("gauss-seidel", "quadratic", 3.0),
    ] {
        let errors: Vec<f64> = steps
            .iter()
            .map(|&h| {
                let (r, s) = cosim::cosim(&pair_system(&dir, h, algorithm, extrapolation, ""))
                    .unwrap_or_else(|e| panic!("{algorithm}/{extrapolation}/{h}: {e}"));
                assert_eq!(s.accepted_steps, (2.0 / h).round() as u64);
                assert_eq!(r.rows.len() as u64, s.accepted_steps + 1);
                pair_error(&r)
            })
            .collect();
        let observed: Vec<f64> = errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect();
        let shown: Vec<String> = errors.iter().map(|e| format!("{e:.3e}")).collect();
        println!("{algorithm:>12} {extrapolation:>9}: max error {shown:?} for h = {steps:?}; observed order {observed:.2?}");
        for o in &observed {
            assert!(
                (o - order).abs() < 0.35,
                "{algorithm}/{extrapolation}: observed order {o:.2}, expected {order}"
            );
        }
        // Held inputs: 5 % of the amplitude at h = 2.5e-3 (ω2 h = 0.035); interpolated far less.
        assert!(errors[2] < 6e-2 * X0, "{errors:?}");
    }
}

#[test]
fn variable_step_meets_its_coupling_tolerance_and_varies_the_step() {
    let dir = scratch("variable");
    oscillator_fmu(&dir);
    let path = pair_system(&dir, 1e-3, "gauss-seidel", "linear", "[rollback]\n");
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "step = { size = 1e-3 }",
        "step = { size = 1e-3, variable = { min = 1e-5, max = 5e-2, tolerance = 1e-4, abs_tolerance = 1e-6 } }",
    );
    std::fs::write(&path, text).unwrap();
    let (r, s) = cosim::cosim(&path).expect("variable-step run");
    let err = pair_error(&r);
    println!("variable step: {s:?}, max error {err:e}");
    assert!((r.rows.last().unwrap()[0] - 2.0).abs() < 1e-12);
    assert!(s.max_step > 3.0 * s.min_step, "{s:?}");
    assert!(err < 2e-3 * X0, "{err:e}");
}

#[test]
fn a_discarded_step_is_retried_with_half_the_step_only_with_rollback() {
    let dir = scratch("rollback");
    oscillator_fmu(&dir);
    // Unit a refuses steps longer than 4e-3; the system asks 1e-2.
    let refusing = |extra: &str| {
        let path = pair_system(&dir, 1e-2, "jacobi", "none", extra);
        let text = std::fs::read_to_string(&path).unwrap().replacen(
            "dt = 1e-4 }",
            "dt = 1e-4, max_step = 4e-3 }",
            1,
        );
        std::fs::write(&path, text).unwrap();
        path
    };
    let e = cosim::cosim(&refusing("")).unwrap_err();
    let msg = e.to_string();
    println!("without rollback: {msg}");
    assert!(matches!(e, CosimError::StepRefused { .. }), "{e:?}");
    for part in [
        "t = 0",
        "h = 0.01",
        "unit `a`",
        "fmi2Discard",
        "max_step = 0.004",
        "add [rollback]",
    ] {
        assert!(msg.contains(part), "`{part}` missing in: {msg}");
    }

    let (r, s) = cosim::cosim(&refusing("[rollback]\nmax_halvings = 3\n")).expect("rollback run");
    println!("with rollback: {}", s.text());
    // Each 1e-2 interval: 1e-2 and 5e-3 refused, 2.5e-3 accepted, 7.5e-3 refused, 3.75e-3 twice.
    assert_eq!(s.rollbacks, 3 * 200);
    assert_eq!(s.accepted_steps, 3 * 200);
    assert_eq!(r.rows.len(), 201, "rows only at the communication grid");
    for (i, row) in r.rows.iter().enumerate() {
        assert!((row[0] - i as f64 * 1e-2).abs() < 1e-12, "{}", row[0]);
    }
    // Smaller steps than the plain 1e-2 Jacobi run: closer to the exact solution.
    let (plain, _) = cosim::cosim(&pair_system(&dir, 1e-2, "jacobi", "none", "")).unwrap();
    println!(
        "error: with rollback {:e}, plain h = 1e-2 {:e}",
        pair_error(&r),
        pair_error(&plain)
    );
    assert!(pair_error(&r) < 0.6 * pair_error(&plain));

    let e = cosim::cosim(&refusing("[rollback]\nmax_halvings = 1\n")).unwrap_err();
    println!("too few halvings: {e}");
    assert!(
        matches!(e, CosimError::RollbackExhausted { halvings: 1, .. }),
        "{e:?}"
    );
    assert!(e.to_string().contains("rollback.max_halvings = 1"), "{e}");
}

#[test]
fn a_failed_check_rolls_back_and_gives_up_with_the_bound() {
    let dir = scratch("check");
    oscillator_fmu(&dir);
    let path = pair_system(
        &dir,
        1e-2,
        "jacobi",
        "none",
        "[rollback]\nmax_halvings = 2\ncheck = [{ variable = \"b.x\", max = 1e-6 }]\n",
    );
    let e = cosim::cosim(&path).unwrap_err();
    println!("{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("check `b.x`") && msg.contains("max = 1e-6"),
        "{msg}"
    );
    assert!(matches!(e, CosimError::RollbackExhausted { .. }), "{e:?}");
}

#[test]
fn without_can_interpolate_inputs_the_inputs_are_held() {
    let dir = scratch("hold");
    oscillator_fmu(&dir);
    let xml = std::fs::read_to_string(source_dir().join("modelDescription.xml"))
        .unwrap()
        .replace(
            "canInterpolateInputs=\"true\"",
            "canInterpolateInputs=\"false\"",
        );
    std::fs::create_dir_all(dir.join("held")).unwrap();
    build_fmu(&dir.join("held"), "oscillator", &xml);
    let run = |path: PathBuf| cosim::cosim(&path).unwrap().0;
    let interpolating = run(pair_system(&dir, 1e-2, "jacobi", "linear", ""));
    let none = run(pair_system(&dir, 1e-2, "jacobi", "none", ""));
    let held_path = pair_system(&dir.join("held"), 1e-2, "jacobi", "linear", "");
    let held = run(held_path);
    assert_eq!(
        held.rows, none.rows,
        "linear on a non-interpolating unit = held"
    );
    assert_ne!(interpolating.rows, none.rows);
}

#[test]
fn a_bad_system_file_names_the_file_and_the_field() {
    let dir = scratch("bad");
    oscillator_fmu(&dir);
    let path = pair_system(&dir, 1e-2, "jacobi", "none", "");
    let text = std::fs::read_to_string(&path).unwrap();
    for (from, to, expected) in [
        (
            "\"a.x -> b.u\"",
            "\"a.x -> b.w\"",
            "connection target `b.w`: no variable named `w`",
        ),
        (
            "\"a.x -> b.u\"",
            "\"a.k -> b.u\"",
            "connection source `a.k`: has causality Parameter",
        ),
        ("k = 1e2,", "kk = 1e2,", "start value `a.kk`"),
        ("algorithm", "algorithmus", "unknown field `algorithmus`"),
    ] {
        std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
        let e = cosim::cosim(&path).unwrap_err().to_string();
        assert!(
            e.contains(&path.display().to_string()) || e.contains("unit `a`"),
            "{e}"
        );
        assert!(e.contains(expected), "expected `{expected}` in {e}");
    }
    assert!(System::load(&dir.join("missing.toml")).is_err());
}
