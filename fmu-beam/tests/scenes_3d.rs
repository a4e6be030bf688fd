//! 3D scene files (issue 4, items 3–5): what `dimensions = 3` accepts and refuses, the rule
//! that a 3D scene whose motion is planar runs with the planar element, the fast variants as
//! scenes (frozen inertia, a matrix file) against the full model, and the canonical text.

use crate::common;

use common::{run, scene, vr};
use fmu_beam::mechanics::SpatialSection;
use fmu_beam::mechanics::{spatial_element_mass, spatial_element_stiffness};
use fmu_beam::scene::matrix_file::MatrixFile;
use fmu_beam::{Engine, Scene};
use nalgebra::DMatrix;
use std::path::Path;

const SCENES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes");

/// The text of the C6 beam's own one-element matrices (L = 0.2 m, C5's section).
fn c6_element_text() -> String {
    let s = SpatialSection::given(0.02 * 0.06285, 4.138e-7, 4.19e-8, 1.33242e-7);
    let (rho, e, g, l) = (7800.0, 210e9, 8.077e10, 0.2);
    let m = spatial_element_mass(rho * s.area, rho * s.polar_moment, l);
    let k = spatial_element_stiffness(e * s.area, g * s.torsion_constant, e * s.iy, e * s.iz, l);
    let to = |a: [[f64; 12]; 12]| DMatrix::from_fn(12, 12, |i, j| a[i][j]);
    MatrixFile {
        length: l,
        mass: to(m),
        stiffness: to(k),
    }
    .to_text(
        "C6 beam (L = 0.2 m, rho 7800, E 210e9, G 8.077e10, C5's section), one Euler-Bernoulli \
         element; written by fmu-beam/tests/scenes_3d.rs (UPDATE_MATRICES=1)",
    )
}

/// The scene's matrix file is the C6 element's own matrices (regenerate with
/// UPDATE_MATRICES=1).
#[test]
fn the_matrix_file_scene_holds_the_c6_element() {
    let path = Path::new(SCENES).join("matrices/pendulum_3d_element.txt");
    let text = c6_element_text();
    if std::env::var_os("UPDATE_MATRICES").is_some() {
        std::fs::write(&path, &text).expect("write the matrix file");
    }
    let file = std::fs::read_to_string(&path).expect("matrix file exists");
    assert_eq!(file, text, "{} is stale: UPDATE_MATRICES=1", path.display());
}

fn refused(text: &str) -> String {
    match Scene::from_toml_str(text, "t.toml") {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

const PLANAR: &str = "name = \"p\"\n[[beam]]\nname = \"beam\"\nlength = 1.0\nelements = 2\n\
    material = { rho = 7800.0, E = 2e11 }\nsection = { A = 1e-4, J = 1e-9 }\n";
const SPATIAL: &str = "name = \"s\"\ndimensions = 3\n[[beam]]\nname = \"beam\"\nlength = 1.0\n\
    elements = 2\nmaterial = { rho = 7800.0, E = 2e11, G = 8e10 }\n\
    section = { A = 1e-4, Iy = 2e-9, Iz = 1e-9, It = 1.5e-9 }\n";

#[test]
fn scene_rules_of_each_dimension_name_the_field() {
    assert!(Scene::from_toml_str(PLANAR, "t").is_ok());
    assert!(Scene::from_toml_str(SPATIAL, "t").is_ok());
    let cases: [(String, &str, &str); 11] = [
        (
            PLANAR.replace(
                "name = \"p\"\n",
                "name = \"p\"\n[world]\ngravity = [0, 0, -9.81]\n",
            ),
            "world.gravity[2]",
            "x–y plane",
        ),
        (
            PLANAR.replace("elements = 2\n", "elements = 2\naxis = [0, 1, 0]\n"),
            "beam \"beam\".axis",
            "3D scenes",
        ),
        (
            PLANAR.replace("J = 1e-9", "J = 1e-9, Iy = 1e-9"),
            "beam \"beam\".section.Iy",
            "3D scenes",
        ),
        (
            SPATIAL.replace("Iy = 2e-9, ", ""),
            "beam \"beam\".section.Iy",
            "required",
        ),
        (
            SPATIAL.replace("It = 1.5e-9", "It = 1.5e-9, J = 1e-9"),
            "beam \"beam\".section.J",
            "Iy, Iz and It",
        ),
        (
            SPATIAL.replace(", G = 8e10", ""),
            "beam \"beam\".material.G",
            "shear modulus",
        ),
        (
            SPATIAL.replace(
                "elements = 2\n",
                "elements = 2\naxis = [1, 0, 0]\nnormal = [1, 0, 1]\n",
            ),
            "beam \"beam\".normal",
            "normal to the beam axis",
        ),
        (
            SPATIAL.replace("elements = 2\n", "elements = 2\naxis = [0, 0, 0]\n"),
            "beam \"beam\".axis",
            "non-zero direction",
        ),
        (
            format!(
                "{SPATIAL}[[joint]]\nname = \"j\"\ntype = \"spherical\"\nframes = [\"world\", \
                 \"beam.a\"]\ndrive = {{ kind = \"motion\", law = \"constant\", value = 1.0 }}\n"
            ),
            "joint \"j\".drive",
            "spherical",
        ),
        (
            format!("{SPATIAL}modes = 2\n[world]\ngravity = [0, 0, -9.81]\n"),
            "beam \"beam\".modes",
            "planar element only",
        ),
        (
            format!(
                "{SPATIAL}[[load]]\nname = \"l\"\nframe = \"beam.b\"\ninput = true\n\
                 scale = {{ law = \"table\", table = [[0, 0], [1, 1]] }}\n"
            ),
            "load \"l\".scale",
            "input",
        ),
    ];
    for (text, field, rule) in cases {
        let msg = refused(&text);
        println!("{msg}");
        assert!(msg.contains(&format!("`{field}`")), "{msg}");
        assert!(msg.contains(rule), "{msg}");
    }
    // a planar torque is a number; a vector with an in-plane part is refused
    let msg = refused(&format!(
        "{PLANAR}[[load]]\nname = \"l\"\nframe = \"beam.b\"\ntorque = [1, 0, 0]\n"
    ));
    assert!(msg.contains("load \"l\".torque[0]"), "{msg}");
}

#[test]
fn a_bad_matrix_file_is_refused_with_its_line_and_rule() {
    let good = c6_element_text();
    let scene = |text: &str| {
        format!(
            "name = \"m\"\ndimensions = 3\n[[beam]]\nname = \"beam\"\nlength = 0.2\n\
             elements = 1\nmatrix_file = \"e.txt\"\nmatrix_text = '''\n{text}'''\n\
             material = {{ rho = 7800.0, E = 2e11 }}\n"
        )
    };
    assert!(Scene::from_toml_str(&scene(&good), "t").is_ok());
    // one mass entry made unsymmetric
    let lines: Vec<&str> = good.lines().collect();
    let at = lines.iter().position(|l| l.starts_with("mass")).unwrap() + 1;
    let mut row: Vec<String> = lines[at].split_whitespace().map(String::from).collect();
    row[1] = "1.0".into();
    let mut bad: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    bad[at] = row.join(" ");
    let msg = refused(&scene(&(bad.join("\n") + "\n")));
    println!("{msg}");
    assert!(
        msg.contains("`beam \"beam\".matrix_file`") && msg.contains("e.txt"),
        "{msg}"
    );
    assert!(msg.contains("symmetric"), "{msg}");
    // the scene's length must be the file's
    let msg = refused(&scene(&good).replace("length = 0.2", "length = 0.3"));
    assert!(
        msg.contains("beam \"beam\".length") && msg.contains("0.2"),
        "{msg}"
    );
}

#[test]
fn a_3d_scene_whose_motion_is_planar_reduces_to_the_planar_element() {
    let z = scene("rollup_3d_z.toml");
    let planar = z.planar_reduction().expect("rolls up in the x-y plane");
    assert_eq!(planar.dimensions, 2);
    assert_eq!(planar.beams[0].section.second_moment, Some(4.19e-8));
    for (file, why) in [
        ("rollup_3d.toml", "torque about an in-plane axis"),
        ("pendulum_3d.toml", "gravity has a z component"),
        ("pendulum_3d_frozen.toml", "gravity has a z component"),
    ] {
        let e = scene(file).planar_reduction().unwrap_err();
        assert!(e.contains(why), "{file}: {e}");
    }
    // a planar scene written in 3D form: same model, same numbers
    let planar_text = std::fs::read_to_string(Path::new(SCENES).join("flexible_pendulum.toml"))
        .unwrap()
        .replace("gravity = [0.0, -9.81]", "gravity = [0.0, -9.81, 0.0]")
        .replace(
            "section = { A = 0.0018, J = 1.215e-8 }",
            "section = { A = 0.0018, Iy = 1e-8, Iz = 1.215e-8, It = 1e-8 }\naxis = [1.0, 0.0, 0.0]",
        )
        .replace(
            "material = { rho = 5540.0, E = 1e9 }",
            "material = { rho = 5540.0, E = 1e9, G = 4e8 }",
        )
        .replace(
            "name = \"flexible_pendulum\"",
            "name = \"flexible_pendulum\"\ndimensions = 3",
        );
    let as_3d = Scene::from_toml_str(&planar_text, "3d.toml").expect("valid 3D scene");
    let two = run(
        scene("flexible_pendulum.toml"),
        &[],
        &["beam.tip.x", "beam.tip.y"],
        0.05,
        0.3,
    );
    let three = run(
        as_3d,
        &[],
        &["beam.tip.x", "beam.tip.y", "beam.tip.z"],
        0.05,
        0.3,
    );
    for (a, b) in two.rows.iter().zip(&three.rows) {
        assert_eq!(a[1], b[1]);
        assert_eq!(a[2], b[2]);
        assert_eq!(b[3], 0.0);
    }
}

/// Fixed steps of 2e-4 s for the variant comparison: every model then carries nearly the same
/// time-discretization error, so the differences are the models' own.
const FIXED: [(&str, f64); 3] = [
    ("solver.adaptive", 0.0),
    ("solver.max_step", 2e-4),
    ("solver.tolerance", 1e-10),
];

/// Hinge angle of a C6 scene at 1 s, the largest tip deflection (local z, in the plane of
/// the swing) over the run, and the wall time of the run.
fn c6_run(s: Scene) -> (f64, f64, f64) {
    let t0 = std::time::Instant::now();
    let r = run(
        s,
        &FIXED,
        &["hinge.angle", "beam.tip.deflection_z"],
        0.01,
        1.0,
    );
    let sag = r.column(2).iter().fold(0.0f64, |m, x| m.max(x.abs()));
    (r.last(1), sag, t0.elapsed().as_secs_f64())
}

/// The fast variants as scenes. The matrix-file beam (the element's own matrices) equals the
/// frozen one-element beam to 1e-9 rad. Frozen inertia against the full model on C6: the
/// deflection the flexible model is there to compute (the tip's, largest over the swing)
/// within 1 % (measured 8e-9), the hinge angle at 1 s within 2e-6 rad (measured 7.7e-7 rad,
/// 1.2e-6 of the swing). On C6 flexibility
/// itself moves the swing by only 5.4e-7 rad (a lag of 5.7e-8 s, `spatial_system.rs`), so
/// the angle tells little here; `make bench`'s spin-up shows where frozen inertia loses
/// (7.5 % of the tip deflection). Times are one run each; `make bench` repeats them.
#[test]
fn fast_variant_scenes_match_the_full_model() {
    let (full, sag_full, t_full) = c6_run(scene("pendulum_3d.toml"));
    let (frozen, sag_frozen, t_frozen) = c6_run(scene("pendulum_3d_frozen.toml"));
    let (matrix, _, t_matrix) = c6_run(scene("pendulum_3d_matrix.toml"));
    let mut one = scene("pendulum_3d_frozen.toml");
    one.beams[0].elements = Some(1);
    let (one_el, _, t_one) = c6_run(one);
    println!(
        "C6 (fixed step 2e-4 s): hinge angle at 1 s: full {full:.9} ({t_full:.2} s), frozen \
         {frozen:.9} ({t_frozen:.2} s, {:+.1e}), matrix file {matrix:.9} ({t_matrix:.2} s), \
         frozen 1 element {one_el:.9} ({t_one:.2} s, {:+.1e}); largest tip deflection: full \
         {sag_full:.4e} m, frozen {sag_frozen:.4e} m ({:+.2e} relative)",
        frozen - full,
        one_el - full,
        sag_frozen / sag_full - 1.0
    );
    assert!((matrix - one_el).abs() < 1e-9, "{matrix} vs {one_el}");
    assert!((sag_frozen / sag_full - 1.0).abs() < 0.01);
    assert!((frozen - full).abs() < 2e-6, "{frozen} vs {full}");
}

/// A 3D scene's canonical text (what the FMU carries) reads back to the same scene, matrix
/// text included; parameters of a 3D scene reach the model.
#[test]
fn the_canonical_text_of_a_3d_scene_round_trips() {
    for file in [
        "rollup_3d.toml",
        "pendulum_3d_matrix.toml",
        "pendulum_3d_rigid.toml",
    ] {
        let s = scene(file);
        let back = Scene::from_toml_str(&s.to_toml_string(), file).expect("reads back");
        assert_eq!(back, s, "{file}");
    }
    let mut e = Engine::new(scene("pendulum_3d.toml"));
    let g = vr(&e, "world.gravity.z");
    e.set_real(g, 0.0).unwrap();
    e.exit_initialization().unwrap();
    e.do_step(0.0, 0.1).unwrap();
    let angle = e.get_real(vr(&e, "hinge.angle")).unwrap();
    assert_eq!(angle, 0.0, "without gravity the pendulum stays");
}

/// The C6 scene's beam, linearized: the hinge about world y leaves bending in the x–y plane
/// clamped (I_z) and bending in x–z pinned-free (I_y), with torsion clamped. Its frequencies
/// against Euler–Bernoulli beam theory (2 elements: cubic bending is close, linear torsion
/// within 3 %), which checks the 3D scene's axes, section and joint mapping.
#[test]
fn the_3d_pendulum_modes_match_beam_theory() {
    // the elastic modes (the free swing about the hinge is a zero frequency)
    let f: Vec<f64> = fmu_beam::natural_frequencies(&scene("pendulum_3d.toml"))
        .expect("modes")
        .into_iter()
        .filter(|&x| x > 1.0)
        .collect();
    let (rho, e, g, l) = (7800.0, 210e9, 8.077e10, 0.2);
    let s = SpatialSection::given(0.02 * 0.06285, 4.138e-7, 4.19e-8, 1.33242e-7);
    let tau = 2.0 * std::f64::consts::PI;
    let bending =
        |beta_l: f64, i: f64| beta_l * beta_l / (tau * l * l) * (e * i / (rho * s.area)).sqrt();
    let clamped_xy = bending(1.875_104_07, s.iz);
    let pinned_free_xz = bending(3.926_602_31, s.iy);
    let torsion = (g * s.torsion_constant / (rho * s.polar_moment)).sqrt() / (4.0 * l);
    println!(
        "pendulum_3d modes {:?} Hz; theory: clamped x-y {clamped_xy:.1}, torsion \
         {torsion:.1}, pinned-free x-z {pinned_free_xz:.1}",
        &f[..4]
    );
    assert!((f[0] / clamped_xy - 1.0).abs() < 1e-3, "{}", f[0]);
    assert!((f[1] / torsion - 1.0).abs() < 0.03, "{}", f[1]);
    assert!((f[3] / pinned_free_xz - 1.0).abs() < 0.01, "{}", f[3]);
}

/// A 3D cantilever along world y (L = 0.5 m, 4 elements, C5's section), its section's z axis
/// along world x, damped (α = 400 /s), with an input load at its tip.
const CANTILEVER_3D: &str = "name = \"c\"\ndimensions = 3\n[experiment]\nstop_time = 2.0\n\
    [solver]\nadaptive = false\nmax_step = 1e-3\ntolerance = 1e-10\n\
    [[beam]]\nname = \"beam\"\nlength = 0.5\nelements = 4\naxis = [0, 1, 0]\n\
    normal = [1, 0, 0]\nmaterial = { rho = 7800.0, E = 2.1e11, G = 8.077e10 }\n\
    section = { A = 1.257e-3, Iy = 4.138e-7, Iz = 4.19e-8, It = 1.33242e-7 }\n\
    rayleigh = { alpha = 400.0 }\n\
    [[joint]]\nname = \"clamp\"\ntype = \"weld\"\nframes = [\"world\", \"beam.a\"]\n\
    [[load]]\nname = \"tip\"\nframe = \"beam.b\"\ninput = true\n";

/// A 3D cantilever along world y with its section's z axis along world x, loaded at the tip
/// through FMU inputs (a force along world x = the local z axis, a torque about world y = the
/// beam axis): the static deflection along local z is F L³ / (3 E I_y) (bending in x–z) and
/// the twist T L / (G J_t), both exact for Euler–Bernoulli elements with linear torsion.
/// The small load keeps the response linear (deflection 1e-4 L); Rayleigh damping settles it.
#[test]
fn a_3d_cantilever_under_input_loads_deflects_and_twists_as_beam_theory_says() {
    let s = Scene::from_toml_str(CANTILEVER_3D, "cantilever.toml").expect("valid");
    assert!(
        s.planar_reduction().is_err(),
        "input loads keep the 3D element"
    );
    let (l, e, g): (f64, f64, f64) = (0.5, 2.1e11, 8.077e10);
    let (iy, jt) = (4.138e-7, 1.33242e-7);
    // a tip deflection of 1e-4 L
    let (force, torque) = (3.0 * e * iy * 1e-4 / (l * l), 10.0);
    let r = run(
        s,
        &[("tip.fx", force), ("tip.ty", torque)],
        &[
            "beam.tip.deflection_y",
            "beam.tip.deflection_z",
            "beam.tip.twist",
            "beam.tip.x",
        ],
        0.01,
        2.0,
    );
    let (dy, dz, twist, x) = (r.last(1), r.last(2), r.last(3), r.last(4));
    let dz_exact = force * l.powi(3) / (3.0 * e * iy);
    let twist_exact = torque * l / (g * jt);
    println!(
        "tip: deflection_z {dz:.6e} (theory {dz_exact:.6e}), twist {twist:.6e} (theory \
         {twist_exact:.6e}), deflection_y {dy:.1e}, world x {x:.6e}"
    );
    // the local z axis is world x: a force along +x bends the tip along +z local
    assert!((dz / dz_exact - 1.0).abs() < 1e-3, "{dz} vs {dz_exact}");
    assert!(
        (x - dz).abs() < 1e-9 * l,
        "world x is the local z deflection"
    );
    assert!(
        (twist / twist_exact - 1.0).abs() < 1e-3,
        "{twist} vs {twist_exact}"
    );
    // no bending in the local x–y plane beyond the second-order coupling of the twist with
    // the deflection (twist × deflection_z = 2.3e-8 m here)
    assert!(dy.abs() < 2.0 * twist * dz.abs(), "{dy}");
}

/// Effects of 3D scenes: the element is a decision with its reason; a scene run with the 3D
/// element switches gravity, flexibility and damping (terms off are not computed: no gravity,
/// no swing) and refuses a planar-only effect by name.
#[test]
fn effects_of_3d_scenes_say_which_element_runs() {
    let first = |file: &str| {
        let r = fmu_beam::resolve_effects(&scene(file));
        let d = &r.decisions[0];
        (d.effect, d.setting.clone())
    };
    assert_eq!(first("rollup_3d_z.toml"), ("formulation", "planar".into()));
    assert_eq!(first("rollup_3d.toml"), ("formulation", "spatial".into()));
    let mut s = scene("pendulum_3d.toml");
    s.effects = fmu_beam::scene::EffectsSpec::List(vec!["flexibility".into()]);
    let text = s.to_toml_string();
    let s = Scene::from_toml_str(&text, "no_gravity.toml").expect("valid");
    let mut e = Engine::new(s.clone());
    assert!(e.variables().by_name("world.gravity.z").is_none());
    e.exit_initialization().unwrap();
    e.do_step(0.0, 0.1).unwrap();
    assert_eq!(e.get_real(vr(&e, "hinge.angle")).unwrap(), 0.0);
    let msg = refused(&text.replace("\"flexibility\"", "\"flexibility\", \"axial\""));
    assert!(
        msg.contains("effects[1]") && msg.contains("3D element"),
        "{msg}"
    );
}

/// FMU state of a 3D model: a snapshot (and its serialized bytes) taken mid-run and restored
/// continues bit for bit; a failed step (a NaN input) keeps the last good state.
#[test]
fn a_3d_model_restores_its_state_bit_for_bit_and_survives_bad_input() {
    let text = std::fs::read_to_string(Path::new(SCENES).join("pendulum_3d.toml")).unwrap();
    let mut e = Engine::new(Scene::from_toml_str(&text, "pendulum_3d.toml").unwrap());
    let angle = vr(&e, "hinge.angle");
    e.exit_initialization().unwrap();
    for k in 0..10 {
        e.do_step(k as f64 * 0.01, 0.01).unwrap();
    }
    let snap = e.snapshot();
    let bytes = e.serialize(&snap);
    let run = |e: &mut Engine| -> Vec<f64> {
        (10..30)
            .map(|k| {
                e.do_step(k as f64 * 0.01, 0.01).unwrap();
                e.get_real(angle).unwrap()
            })
            .collect()
    };
    let first = run(&mut e);
    e.restore(&snap).unwrap();
    assert_eq!(run(&mut e), first);
    let back = e.deserialize(&bytes).unwrap();
    e.restore(&back).unwrap();
    assert_eq!(run(&mut e), first);
    // a step with a NaN gravity is refused before it runs; the state stays
    assert!(e.set_real(vr(&e, "world.gravity.z"), f64::NAN).is_err());
    assert_eq!(e.get_real(angle).unwrap(), *first.last().unwrap());
}

/// The validity monitor watches 3D frames too: a tip force that bends a single-frame 3D
/// cantilever by more than 5 % of its length gets one warning naming the beam and the frame;
/// the run goes on.
#[test]
fn a_3d_frame_bent_past_the_small_deformation_range_is_warned_about() {
    let mut e = Engine::new(Scene::from_toml_str(CANTILEVER_3D, "cantilever.toml").expect("valid"));
    // F L³ / (3 E I_y) = 8 % of L
    let force = 0.08 * 0.5 * 3.0 * 2.1e11 * 4.138e-7 / 0.125;
    e.set_real(vr(&e, "tip.fx"), force).unwrap();
    e.exit_initialization().unwrap();
    let mut warnings = Vec::new();
    for k in 0..50 {
        e.do_step(k as f64 * 0.01, 0.01).expect("the run goes on");
        warnings.extend(e.take_messages());
    }
    let dz = e.get_real(vr(&e, "beam.tip.deflection_z")).unwrap();
    println!("tip deflection {dz:.4} m; {warnings:?}");
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("beam 'beam'") && warnings[0].contains("small-deformation"));
}
