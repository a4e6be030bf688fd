//! Issue 31: every physical number a user sweeps is an FMU parameter, and setting it before
//! initialization gives the same run, bit for bit, as a unit whose scene has the value written
//! in: rigid bodies' mass, inertia and centre of mass, loads' force and torque and their scale
//! law (table rows too), drive laws' numbers and gravity, in a planar and a 3D scene.

use fmu_beam::{Causality, Engine, Scene, VarType};

/// A rigid arm swinging on a hinge under gravity, pushed by a load whose scale follows a table,
/// its hinge turned by an exponential torque that ends at 0.15 s.
const PLANAR: &str = r#"
name = "arm"
[world]
gravity = [0.0, -9.81]
[experiment]
stop_time = 0.3
step_size = 1e-2
[[beam]]
name = "post"
length = 0.1
elements = 1
rigid = true
material = { rho = 7800.0, E = 2e11 }
section = { A = 1e-4, J = 1e-9 }
[[body]]
name = "arm"
mass = 2.0
inertia = 0.05
com = [0.3, 0.02]
frames = { tip = [0.6, 0.0] }
[[joint]]
name = "base"
type = "weld"
frames = ["world", "post.a"]
[[joint]]
name = "hinge"
type = "revolute"
frames = ["world", "arm.origin"]
drive = { kind = "effort", law = "exponential", value = 3.0, time_constant = 0.05, until = 0.15 }
[[load]]
name = "push"
frame = "arm.tip"
force = [1.0, -2.0]
torque = 0.5
scale = { law = "table", table = [[0.0, 0.0], [0.1, 1.0], [0.2, 0.5]] }
"#;

/// A rigid body on a spherical joint under gravity, pushed and twisted by a ramped load.
const SPATIAL: &str = r#"
name = "ball"
dimensions = 3
[world]
gravity = [0.0, 0.0, -9.81]
[experiment]
stop_time = 0.3
step_size = 1e-2
[[body]]
name = "ball"
mass = 1.0
inertia = [0.01, 0.02, 0.03]
com = [0.05, 0.01, -0.02]
position = [0.5, 0.0, 0.0]
frames = { pivot = [-0.5, 0.0, 0.0] }
[[beam]]
name = "post"
length = 0.1
elements = 1
rigid = true
material = { rho = 7800.0, E = 2e11, G = 8e10 }
section = { A = 1e-4, Iy = 1e-9, Iz = 1e-9, It = 2e-9 }
[[joint]]
name = "base"
type = "weld"
frames = ["world", "post.a"]
[[joint]]
name = "pivot"
type = "spherical"
frames = ["world", "ball.pivot"]
[[load]]
name = "push"
frame = "ball.origin"
force = [0.5, 1.0, -0.5]
torque = [0.02, -0.01, 0.03]
scale = { law = "exponential", value = 1.0, time_constant = 0.1 }
"#;

fn scene(text: &str) -> Scene {
    Scene::from_toml_str(text, "parameters.toml").expect("valid scene")
}

/// Every Real variable's bits at every communication point of a run of `scene` with the
/// parameters `set` before initialization.
fn run(scene: Scene, set: &[(&str, f64)]) -> Vec<Vec<u64>> {
    let mut e = Engine::new(scene);
    for (name, v) in set {
        let var = e
            .variables()
            .by_name(name)
            .unwrap_or_else(|| panic!("no {name}"));
        assert_eq!(var.causality, Causality::Parameter, "{name}");
        let vr = var.vr;
        e.set_real(vr, *v).unwrap();
    }
    e.exit_initialization().unwrap();
    let reals: Vec<u32> = e
        .variables()
        .variables
        .iter()
        .filter(|v| v.ty == VarType::Real && v.causality == Causality::Output)
        .map(|v| v.vr)
        .collect();
    let mut rows = Vec::new();
    let h = 1e-2;
    for k in 0..30 {
        e.do_step(k as f64 * h, h).unwrap();
        rows.push(
            reals
                .iter()
                .map(|&r| e.get_real(r).unwrap().to_bits())
                .collect(),
        );
    }
    rows
}

/// Setting `name` to `value` runs as the scene edited by `edit` does, bit for bit, and
/// differently from the scene as it was (so the parameter does reach the model).
fn same_as_packaged(text: &str, name: &str, value: f64, edit: impl Fn(&mut Scene)) {
    let base = scene(text);
    let mut edited = base.clone();
    edit(&mut edited);
    // the scene file with the value written in, read (and validated) as the packager reads it
    let edited = Scene::from_toml_str(&edited.to_toml_string(), "edited.toml").expect("valid");
    let set = run(base.clone(), &[(name, value)]);
    let packaged = run(edited, &[]);
    assert!(
        set == packaged,
        "{name} = {value}: differs from the packaged value"
    );
    assert!(set != run(base, &[]), "{name} = {value}: changes nothing");
}

#[test]
fn a_rigid_body_s_mass_inertia_and_centre_of_mass_run_as_packaged() {
    same_as_packaged(PLANAR, "arm.mass", 2.5, |s| s.bodies[0].mass = 2.5);
    same_as_packaged(PLANAR, "arm.inertia", 0.08, |s| {
        s.bodies[0].inertia[2] = 0.08
    });
    same_as_packaged(PLANAR, "arm.com.x", 0.25, |s| s.bodies[0].com[0] = 0.25);
    same_as_packaged(PLANAR, "arm.com.y", -0.01, |s| s.bodies[0].com[1] = -0.01);
    for (k, c) in ["x", "y", "z"].iter().enumerate() {
        let name = format!("ball.inertia.{c}");
        same_as_packaged(SPATIAL, &name, 0.04, |s| s.bodies[0].inertia[k] = 0.04);
        let name = format!("ball.com.{c}");
        same_as_packaged(SPATIAL, &name, 0.03, |s| s.bodies[0].com[k] = 0.03);
    }
    same_as_packaged(SPATIAL, "ball.mass", 1.5, |s| s.bodies[0].mass = 1.5);
}

#[test]
fn a_load_s_force_torque_and_scale_law_run_as_packaged() {
    same_as_packaged(PLANAR, "push.fx", -1.0, |s| s.loads[0].force[0] = -1.0);
    same_as_packaged(PLANAR, "push.fy", 3.0, |s| s.loads[0].force[1] = 3.0);
    same_as_packaged(PLANAR, "push.torque", -0.5, |s| s.loads[0].torque[2] = -0.5);
    let table = |s: &mut Scene| {
        s.loads[0]
            .scale
            .as_mut()
            .unwrap()
            .table
            .as_mut()
            .unwrap()
            .clone()
    };
    same_as_packaged(PLANAR, "push.scale.table.value[2]", 2.0, |s| {
        let mut t = table(s);
        t[1][1] = 2.0;
        s.loads[0].scale.as_mut().unwrap().table = Some(t);
    });
    same_as_packaged(PLANAR, "push.scale.table.t[2]", 0.05, |s| {
        let mut t = table(s);
        t[1][0] = 0.05;
        s.loads[0].scale.as_mut().unwrap().table = Some(t);
    });
    for (k, c) in ["fx", "fy", "fz", "tx", "ty", "tz"].iter().enumerate() {
        same_as_packaged(SPATIAL, &format!("push.{c}"), 0.7, |s| {
            let l = &mut s.loads[0];
            if k < 3 {
                l.force[k] = 0.7
            } else {
                l.torque[k - 3] = 0.7
            }
        });
    }
    same_as_packaged(SPATIAL, "push.scale.time_constant", 0.02, |s| {
        s.loads[0].scale.as_mut().unwrap().time_constant = Some(0.02)
    });
    same_as_packaged(SPATIAL, "push.scale.value", 3.0, |s| {
        s.loads[0].scale.as_mut().unwrap().value = Some(3.0)
    });
}

#[test]
fn a_drive_law_s_numbers_run_as_packaged() {
    fn law(s: &mut Scene) -> &mut fmu_beam::scene::LawSpec {
        &mut s.joints[1].drive.as_mut().unwrap().law
    }
    same_as_packaged(PLANAR, "hinge.drive.value", -2.0, |s| {
        law(s).value = Some(-2.0)
    });
    same_as_packaged(PLANAR, "hinge.drive.time_constant", 0.02, |s| {
        law(s).time_constant = Some(0.02)
    });
    same_as_packaged(PLANAR, "hinge.drive.until", 0.1, |s| {
        law(s).until = Some(0.1)
    });
}

#[test]
fn gravity_runs_as_packaged() {
    same_as_packaged(PLANAR, "world.gravity.x", 1.0, |s| s.world.gravity[0] = 1.0);
    same_as_packaged(PLANAR, "world.gravity.y", -1.62, |s| {
        s.world.gravity[1] = -1.62
    });
    same_as_packaged(SPATIAL, "world.gravity.y", 2.0, |s| {
        s.world.gravity[1] = 2.0
    });
    same_as_packaged(SPATIAL, "world.gravity.z", -3.7, |s| {
        s.world.gravity[2] = -3.7
    });
}

/// The new parameters are fixed (a load's force and torque are tunable: tunable_loads.rs): the
/// assembled system depends on them, so they are refused
/// after initialization, and a value the scene's rules refuse (a negative mass) is refused
/// before it, naming the variable and changing nothing.
#[test]
fn body_load_and_law_parameters_are_fixed_and_checked_by_the_rules() {
    let mut e = Engine::new(scene(PLANAR));
    let vr = |e: &Engine, n: &str| e.variables().by_name(n).unwrap().vr;
    let mass = vr(&e, "arm.mass");
    let err = e.set_real(mass, -1.0).unwrap_err().to_string();
    assert!(err.contains("arm.mass"), "{err}");
    assert_eq!(e.get_real(mass).unwrap(), 2.0);
    let row = vr(&e, "push.scale.table.t[3]");
    let err = e.set_real(row, 0.05).unwrap_err().to_string();
    assert!(err.contains("push.scale.table.t[3]"), "{err}");
    e.exit_initialization().unwrap();
    for name in [
        "arm.mass",
        "arm.com.x",
        "push.scale.table.t[2]",
        "hinge.drive.value",
    ] {
        let v = e.variables().by_name(name).unwrap();
        assert_eq!(v.variability.as_str(), "fixed", "{name}");
        assert!(e.set_real(v.vr, 1.0).is_err(), "{name}");
    }
}

/// A table offers its rows as parameters up to `TABLE_PARAMETER_ROWS` rows (a longer one, a
/// measured profile, none); the scene's size bound on its variables holds either way, also for
/// many 3D bodies and loads, so that the limit on variables refuses no scene it used to accept.
#[test]
fn table_rows_are_parameters_up_to_a_bound_and_the_size_bound_holds() {
    let rows = fmu_beam::scene::TABLE_PARAMETER_ROWS;
    for n in [rows, rows + 1] {
        let table: Vec<String> = (0..n).map(|k| format!("[{k}.0, {k}.5]")).collect();
        let mut text = SPATIAL.replace(
            r#"scale = { law = "exponential", value = 1.0, time_constant = 0.1 }"#,
            &format!(
                r#"scale = {{ law = "table", table = [{}] }}"#,
                table.join(", ")
            ),
        );
        for k in 0..20 {
            text.push_str(&format!(
                "[[body]]\nname = \"b{k}\"\nmass = 1.0\ninertia = [1.0, 1.0, 1.0]\n\
                 [[load]]\nname = \"l{k}\"\nframe = \"b{k}.origin\"\nforce = [1.0, 0.0, 0.0]\n\
                 scale = {{ law = \"table\", table = [{}] }}\n",
                table.join(", ")
            ));
        }
        let s = scene(&text);
        let table = fmu_beam::VariableTable::build(&s);
        let offered = table
            .by_name(&format!("push.scale.table.value[{n}]"))
            .is_some();
        assert_eq!(offered, n <= rows, "{n} rows");
        let count = table.variables.len() as u64;
        assert!(count <= s.size().variables, "{count} > {:?}", s.size());
    }
}

/// PLANAR with its hinge started at 0.4 rad and 2 rad/s, and a second link on an elbow at the
/// arm's tip whose start is not given.
fn planar_started() -> String {
    PLANAR.replace(
        r#"drive = { kind = "effort""#,
        r#"initial = { position = 0.4, speed = 2.0 }
drive = { kind = "effort""#,
    ) + r#"
[[body]]
name = "link"
mass = 0.5
inertia = 0.01
com = [0.2, 0.0]
position = [0.6, 0.0]
[[joint]]
name = "elbow"
type = "revolute"
frames = ["arm.tip", "link.origin"]
"#
}

/// SPATIAL with its ball on a revolute joint about world y, started at 0.3 rad and -1.5 rad/s.
fn spatial_started() -> String {
    SPATIAL.replace(
        r#"type = "spherical""#,
        "type = \"revolute\"\naxis = [0.0, 1.0, 0.0]\ninitial = { position = 0.3, speed = -1.5 }",
    )
}

fn started(text: &str, set: &[(&str, f64)]) -> Engine {
    let mut e = Engine::new(scene(text));
    for (name, v) in set {
        let vr = e.variables().by_name(name).unwrap().vr;
        e.set_real(vr, *v).unwrap();
    }
    e.exit_initialization().unwrap();
    e
}

fn get(e: &mut Engine, name: &str) -> f64 {
    let vr = e.variables().by_name(name).unwrap().vr;
    e.get_real(vr).unwrap()
}

/// A joint given a start coordinate and rate starts there, the bodies placed and moving to meet
/// it; a joint without one keeps its placed coordinate and turns with its neighbours (the elbow
/// stays straight, at rest relative to the arm).
#[test]
fn a_joint_starts_at_the_coordinate_and_rate_given() {
    let mut e = started(&planar_started(), &[]);
    assert!((get(&mut e, "hinge.angle") - 0.4).abs() < 1e-12);
    assert!((get(&mut e, "hinge.speed") - 2.0).abs() < 1e-9);
    assert!(get(&mut e, "elbow.angle").abs() < 1e-12);
    assert!(get(&mut e, "elbow.speed").abs() < 1e-9);
    // the link moved with the arm: its origin at the arm's tip, 0.6 m from the hinge at 0.4 rad
    let (x, y) = (get(&mut e, "link.x"), get(&mut e, "link.y"));
    assert!((x - 0.6 * 0.4f64.cos()).abs() < 1e-12 && (y - 0.6 * 0.4f64.sin()).abs() < 1e-12);
    let mut e = started(&planar_started(), &[("hinge.initial.speed", -1.0)]);
    assert!((get(&mut e, "hinge.speed") + 1.0).abs() < 1e-9);
    let mut e = started(&spatial_started(), &[]);
    assert!((get(&mut e, "pivot.angle") - 0.3).abs() < 1e-12);
    assert!((get(&mut e, "pivot.speed") + 1.5).abs() < 1e-9);
    // a rigid turn about world y through the pivot: ½ ω² (Iyy + m d²), d the centre of mass's
    // distance from the axis (com − pivot = [0.55, 0.01, -0.02] in body axes, turned about y)
    let expected = 0.5 * 1.5f64.powi(2) * (0.02 + 1.0 * (0.55f64.powi(2) + 0.02f64.powi(2)));
    let kinetic = get(&mut e, "energy.kinetic");
    assert!(
        (kinetic - expected).abs() < 1e-9 * expected,
        "{kinetic} {expected}"
    );
}

#[test]
fn a_joint_s_start_runs_as_packaged() {
    fn start(s: &mut Scene, j: usize) -> &mut fmu_beam::scene::JointInitialSpec {
        s.joints[j].initial.as_mut().unwrap()
    }
    let planar = planar_started();
    same_as_packaged(&planar, "hinge.initial.position", -0.2, |s| {
        start(s, 1).position = Some(-0.2)
    });
    same_as_packaged(&planar, "hinge.initial.speed", 5.0, |s| {
        start(s, 1).speed = Some(5.0)
    });
    let spatial = spatial_started();
    same_as_packaged(&spatial, "pivot.initial.position", 1.0, |s| {
        start(s, 1).position = Some(1.0)
    });
    same_as_packaged(&spatial, "pivot.initial.speed", 0.5, |s| {
        start(s, 1).speed = Some(0.5)
    });
}

/// Speeds the joints cannot all take (a crank and its slider at the dead point) are refused,
/// naming the joints; a crank's speed alone sets the whole slider-crank moving.
#[test]
fn speeds_the_joints_do_not_allow_are_refused() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/slider_crank.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let crank = text.replace(
        "frames = [\"world\", \"crank.a\"]",
        "frames = [\"world\", \"crank.a\"]\ninitial = { speed = 3.0 }",
    );
    let mut e = started(&crank, &[]);
    assert!((get(&mut e, "crank_pivot.speed") - 3.0).abs() < 1e-9);
    let both = crank.replace(
        "frames = [\"world\", \"block.origin\"]",
        "frames = [\"world\", \"block.origin\"]\ninitial = { speed = 1.0 }",
    );
    let mut e = Engine::new(scene(&both));
    let err = e.exit_initialization().unwrap_err().to_string();
    assert!(
        err.contains("initial speeds") && err.contains("slider"),
        "{err}"
    );
}

/// The FMU state carries the new parameters: a state saved from a unit whose body mass and
/// joint start were set, serialized and loaded into a fresh instance of the same scene (its
/// parameters at the packaged values), goes on bit for bit as the unit it was saved from.
#[test]
fn a_serialized_state_carries_the_parameters_set() {
    let text = planar_started();
    let set = [("arm.mass", 2.5), ("hinge.initial.speed", -1.0)];
    let mut a = started(&text, &set);
    let h = 1e-2;
    for k in 0..5 {
        a.do_step(k as f64 * h, h).unwrap();
    }
    let bytes = a.serialize(&a.snapshot());
    let mut b = Engine::new(scene(&text));
    b.exit_initialization().unwrap();
    let state = b.deserialize(&bytes).unwrap();
    b.restore(&state).unwrap();
    assert_eq!(get(&mut b, "arm.mass"), 2.5);
    for k in 5..15 {
        a.do_step(k as f64 * h, h).unwrap();
        b.do_step(k as f64 * h, h).unwrap();
        for name in ["hinge.angle", "hinge.speed", "elbow.angle", "link.x"] {
            assert_eq!(
                get(&mut a, name).to_bits(),
                get(&mut b, name).to_bits(),
                "{name}"
            );
        }
    }
}
