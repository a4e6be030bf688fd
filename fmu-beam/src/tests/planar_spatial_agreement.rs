//! Issue 4, item 3: the planar and the spatial (3D) formulations agree on every planar case.
//! Cases C1–C4 (CASES.md) are built in 3D with [`System3`] from the same scene file that the
//! planar engine runs, in the world x–y plane: local z = world z, revolute axes along world z,
//! the planar in-plane bending J = I_z of the 3D section. Both run at equal fixed steps.
//!
//! **Relative difference** of an output a (the planar engine's variable `a2d`, its 3D
//! counterpart `a3d`) over the communication points t_k of the run:
//!
//!   max_k |a3d(t_k) − a2d(t_k)| / max_k |a2d(t_k)|,
//!
//! the largest difference relative to the output's amplitude over the run.
//!
//! Why it needs small steps: both formulations share the spatial discretization (the same
//! Hermite elements, the same shape integrals in the plane) but parametrize the frame rotation
//! differently, a planar angle θ against a unit quaternion with its norm row. Generalized-α is
//! not invariant under that change of coordinates, so at a step h the two runs differ by time
//! discretization error, O(h²). Each case runs at two fixed steps; the printed table shows the
//! difference shrinking with h (×4 per halving where Newton's stopping error is negligible),
//! and 1e-6 is asserted at the finer step for every output. Both engines must also take the
//! same steps (asserted: a step rejected in one run only would compare different step
//! sequences).
//!
//! Spans, chosen to keep the file near 60 s in release mode (the 3D engine, with
//! finite-difference tangents and Jacobians, costs about 1–2 ms per step here):
//! - C1: the scene's 2 s. No frame rotates, so both integrate the same equations: they agree to
//!   rounding (about 1e-13) at either step; there is no discretization difference to shrink.
//! - C2: the case's 1 s; the difference grows with time, and 1e-6 needs h ≤ 2.2e-4.
//! - C3: the scene's 1.6 s. The drive torque's cut-off at 0.7 s (both engines land on it and
//!   restart) turns the crank's root at about 6e4 rad/s² just after it (an Euler–Bernoulli beam
//!   has no rotary inertia of bending) and excites modes that no practical step resolves; the
//!   rod's mid-span deflection after it is the most sensitive output (below 1e-7 before the
//!   cut-off, 4.6e-7 over the whole run at h = 2.5e-4; 2.1e-6 if both Newton tolerances are
//!   1e-11).
//! - C4 (Ω = 4, 5 substructures): the whole 20 s scene, the spin-up through the hub rate's
//!   crossing of the first bending frequency (2.9 rad/s at t ≈ 9.3 s), where the deflection
//!   and the difference peak. After it the discretization difference does not grow, but the 3D
//!   run's Newton stopping error keeps accumulating with the step count (h = 1e-3: 4.3e-7 up
//!   to 10 s, 6.3e-7 over 20 s, against 1e-6 asserted).

use crate::integrator::{initial_state, Settings, Stats, Stepper};
use crate::mechanics::beam::planar_beam::{BeamOptions, PlanarBeam};
use crate::mechanics::beam::section::Section;
use crate::mechanics::beam::spatial_beam::{InertiaModel, SpatialBeamProps};
use crate::mechanics::beam::spatial_element::{NODE_DOFS, TZ, U, V};
use crate::mechanics::beam::spatial_section::SpatialSection;
use crate::mechanics::multibody::joint::Drive;
use crate::mechanics::multibody::law::TimeLaw;
use crate::mechanics::multibody3d::{Body3, Frame3, RigidBody3, System3};
use crate::mechanics::JointKind;
use crate::scene::{BeamSpec, Scene};
use nalgebra::{DVector, Matrix3, Rotation3, Vector3};
use std::time::Instant;

/// Newton tolerances. At fixed steps the tolerance only stops Newton, whose test is on the
/// position correction (≤ 0.01 × tol, weighted): that correction is an acceleration error of
/// correction/(βh²), and it accumulates over the steps. At 1e-10 the stopping error alone
/// reached 1e-6 on C2, so both are far tighter. The planar engine (exact tangents) converges
/// to 1e-13 and serves as the converged reference. The 3D engine runs at [`SPATIAL_TOL`], or at
/// the case's own tolerance where its Newton stalls: its finite-difference Jacobians leave a
/// noise floor (on C4, with the constraint forces of the spinning beam, it rejects steps at
/// 5e-12 and runs at 1e-11).
const PLANAR_TOL: f64 = 1e-13;
const SPATIAL_TOL: f64 = 1e-12;

/// How a run is stepped: fixed step h, Newton tolerance, communication step hc, span.
#[derive(Debug, Clone, Copy)]
struct Grid {
    h: f64,
    tol: f64,
    hc: f64,
    stop: f64,
}

impl Grid {
    /// Fixed-step settings with the scene's ρ∞.
    fn settings(&self, scene: &Scene) -> Settings {
        Settings {
            adaptive: false,
            tolerance: self.tol,
            max_step: self.h,
            rho_inf: scene.solver.rho_inf,
            step_budget: crate::integrator::DEFAULT_STEP_BUDGET,
        }
    }
}

/// One run: the outputs at the communication points (time left out), steps taken, rejected.
struct Series {
    rows: Vec<Vec<f64>>,
    steps: u64,
    rejected: u64,
}

/// The planar engine on `file`, stepped by `grid`: `outputs` every `grid.hc`.
fn planar(file: &str, grid: Grid, outputs: &[&str]) -> Series {
    // the plain elements are compared here (stiffening in 3D: tests/issue_32_stiffening_3d.rs)
    let mut scene = super::common::scene(file);
    for b in &mut scene.beams {
        b.geometric_stiffening = false;
    }
    let mut r = super::common::run(
        scene,
        &[
            ("solver.adaptive", 0.0),
            ("solver.max_step", grid.h),
            ("solver.tolerance", grid.tol),
        ],
        outputs,
        grid.hc,
        grid.stop,
    );
    let mut counter = |name: &str| {
        let vr = super::common::vr(&r.engine, name);
        r.engine.get_integer(vr).expect("a counter") as u64
    };
    let (steps, rejected) = (counter("solver.steps"), counter("solver.rejected_steps"));
    Series {
        rows: r.rows.iter().map(|row| row[1..].to_vec()).collect(),
        steps,
        rejected,
    }
}

/// Runs `sys` from its assembled initial state, stepped by `grid`, recording `record(q)` every
/// `grid.hc`.
fn spatial(
    sys: &System3,
    scene: &Scene,
    grid: Grid,
    record: impl Fn(&DVector<f64>) -> Vec<f64>,
) -> Series {
    let settings = grid.settings(scene);
    // (System3 places its bodies itself; the scene is not read)
    let mut st = initial_state(sys, 0.0, &settings).expect("assembles");
    let mut stepper = Stepper::new(sys, settings);
    let mut stats = Stats::default();
    let mut rows = vec![record(&st.q)];
    for k in 1..=(grid.stop / grid.hc).round() as usize {
        let t = k as f64 * grid.hc;
        stepper
            .step_to(sys, &mut st, &mut stats, t)
            .unwrap_or_else(|e| panic!("3D step to {t}: {e}"));
        rows.push(record(&st.q));
    }
    Series {
        rows,
        steps: stats.steps,
        rejected: stats.rejected,
    }
}

/// Makes the angle columns `cols` continuous (the 3D angles are wrapped to (−π, π], the planar
/// ones are coordinates).
fn unwrap(rows: &mut [Vec<f64>], cols: &[usize]) {
    let tau = 2.0 * std::f64::consts::PI;
    for &c in cols {
        for k in 1..rows.len() {
            let (prev, x) = (rows[k - 1][c], rows[k][c]);
            rows[k][c] = x + tau * ((prev - x) / tau).round();
        }
    }
}

fn rot_z(angle: f64) -> Matrix3<f64> {
    Rotation3::from_axis_angle(&Vector3::z_axis(), angle).into_inner()
}

/// Adds the scene beam `spec` to `sys` in the x–y plane (substructures, frame kind, material,
/// placement, initial tip displacement) and returns its index in `sys.beams`. The 3D section
/// is the planar one in the plane of motion (I_z = J); the out-of-plane second moment and the
/// torsion constants do not enter a planar motion (I_y = J, J_t = 2J, G = E/2.6 unless given).
fn add_beam(sys: &mut System3, spec: &BeamSpec) -> usize {
    let (elements, k) = Scene::beam_layout(spec);
    let sec = Section::from_spec(&spec.section);
    let j = sec.second_moment;
    let props = SpatialBeamProps {
        length: spec.length,
        elements,
        frame: spec.frame.into(),
        rho: spec.material.rho,
        e: spec.material.e,
        g: spec.material.g.unwrap_or(spec.material.e / 2.6),
        section: SpatialSection::given(sec.area, j, j, 2.0 * j),
        rayleigh_alpha: spec.rayleigh.alpha,
        rayleigh_beta: spec.rayleigh.beta,
        inertia: InertiaModel::Full,
    };
    let position = Vector3::new(spec.position[0], spec.position[1], 0.0);
    let g = sys.add_beam(&spec.name, &props, k, position, rot_z(spec.angle));
    if spec.initial.tip_displacement != 0.0 {
        // the planar engine's initial shape (`System::initial_coordinates`): the static tip
        // shape of the first frame, its nodal (u, v, θ) put on the 3D nodal (u, v, θz)
        let first = sys.beams[g].bodies.start;
        let pb = PlanarBeam::part_of(
            spec,
            &spec.name,
            spec.length / k as f64,
            BeamOptions::default(),
        );
        let shape = pb
            .static_tip_shape(spec.initial.tip_displacement)
            .expect("the tip is free");
        let Body3::Beam(b) = &sys.bodies[first] else {
            unreachable!("a beam group holds beams")
        };
        let mut qf = vec![0.0; b.nflex()];
        for (i, &full) in pb.kept.iter().enumerate() {
            let dof = [U, V, TZ][full % 3];
            let k3 = b
                .flex_index(NODE_DOFS * (full / 3) + dof)
                .expect("3D keeps the planar coordinates");
            qf[k3] = shape[i];
        }
        sys.set_initial_deformation(first, &qf);
    }
    g
}

/// The scene joint's drive (the same law as the planar engine's).
fn drive(scene: &Scene, joint: &str) -> Option<Drive> {
    let spec = scene
        .joints
        .iter()
        .find(|j| j.name == joint)
        .expect("joint");
    spec.drive.as_ref().map(|d| Drive {
        kind: d.kind.into(),
        law: TimeLaw::from_spec(&d.law, None),
    })
}

/// The tip's deflection from the root axis (tangent frame), x, y and section angle.
fn tip_outputs(sys: &System3, g: usize, q: &DVector<f64>) -> [f64; 4] {
    let (x, a) = sys.beam_tip(g, q);
    [
        sys.beam_tip_local(g, q).y,
        x.x,
        x.y,
        a[(1, 0)].atan2(a[(0, 0)]),
    ]
}

/// A case: scene, outputs (the planar engine's variables, in the order its 3D twin records
/// them), angle columns, the two fixed steps, the 3D Newton tolerance, communication step and
/// span, and the 3D twin.
struct Case {
    name: &'static str,
    file: &'static str,
    outputs: Vec<&'static str>,
    angles: &'static [usize],
    steps: [f64; 2],
    tol: f64,
    hc: f64,
    stop: f64,
    run3d: fn(&Scene, Grid) -> Series,
}

/// Relative difference of each output (see the module doc).
fn differences(a3d: &[Vec<f64>], a2d: &[Vec<f64>]) -> Vec<f64> {
    assert_eq!(a3d.len(), a2d.len());
    (0..a2d[0].len())
        .map(|c| {
            let amp = a2d.iter().map(|r| r[c].abs()).fold(0.0, f64::max);
            let diff = a3d
                .iter()
                .zip(a2d)
                .map(|(x, y)| (x[c] - y[c]).abs())
                .fold(0.0, f64::max);
            diff / amp
        })
        .collect()
}

/// Runs the case's planar engine and 3D twin at each step, prints the table and asserts: the
/// same steps in both runs, each difference shrinking from the coarser step to the finer (or at
/// rounding level, below 1e-9, at both), each below 1e-6 at the finer step.
fn agree(case: Case) {
    let scene = super::common::scene(case.file);
    // the table, printed whole (the cases run on parallel threads)
    let mut table = format!(
        "{}: max |3D − planar| / max |planar| over {} s, communication step {} s, Newton \
         tolerance planar {PLANAR_TOL:.0e}, 3D {:.0e}\n  {:>8}",
        case.name, case.stop, case.hc, case.tol, "h"
    );
    for o in &case.outputs {
        table += &format!(" {o:>20}");
    }
    table += "   planar / 3D (s)   steps (rejected) planar / 3D";
    let mut rows: Vec<(f64, Vec<f64>, bool)> = Vec::new();
    for h in case.steps {
        let grid = Grid {
            h,
            tol: case.tol,
            hc: case.hc,
            stop: case.stop,
        };
        let reference = Grid {
            tol: PLANAR_TOL,
            ..grid
        };
        let t0 = Instant::now();
        let b = planar(case.file, reference, &case.outputs);
        let planar_s = t0.elapsed().as_secs_f64();
        let t0 = Instant::now();
        let mut a = (case.run3d)(&scene, grid);
        let spatial_s = t0.elapsed().as_secs_f64();
        unwrap(&mut a.rows, case.angles);
        let d = differences(&a.rows, &b.rows);
        table += &format!("\n  {h:>8.2e}");
        for x in &d {
            table += &format!(" {x:>20.2e}");
        }
        table += &format!(
            "   {planar_s:>6.1} / {spatial_s:>5.1}   {} ({}) / {} ({})",
            b.steps, b.rejected, a.steps, a.rejected
        );
        let same_steps = (a.steps, a.rejected) == (b.steps, b.rejected);
        rows.push((h, d, same_steps));
    }
    println!("{table}");
    for (h, _, same_steps) in &rows {
        assert!(
            same_steps,
            "{} at h = {h}: both engines take the same steps",
            case.name
        );
    }
    let [(h0, coarse, _), (h1, fine, _)] = [&rows[0], &rows[1]];
    for (k, o) in case.outputs.iter().enumerate() {
        assert!(
            fine[k] < coarse[k] || fine[k].max(coarse[k]) < 1e-9,
            "{} {o}: the difference shrinks with h ({:.2e} at {h0:.2e}, {:.2e} at {h1:.2e})",
            case.name,
            coarse[k],
            fine[k]
        );
        assert!(
            fine[k] < 1e-6,
            "{} {o}: {:.2e} relative at h = {h1:.2e}",
            case.name,
            fine[k]
        );
    }
}

// ---------------------------------------------------------------------------------------
// C1: cantilever welded to the world, released from its static tip shape.

fn c1_3d(scene: &Scene, grid: Grid) -> Series {
    let mut sys = System3::new(None);
    let g = add_beam(&mut sys, &scene.beams[0]);
    let fw = sys.world_frame(Vector3::zeros(), Matrix3::identity());
    let fa = sys.beam_frame(g, false, Matrix3::identity());
    sys.add_joint("clamp", JointKind::Weld, fw, fa, None);
    spatial(&sys, scene, grid, |q| tip_outputs(&sys, g, q).to_vec())
}

// ---------------------------------------------------------------------------------------
// C2: flexible pendulum on a revolute joint, gravity −y.

fn c2_3d(scene: &Scene, grid: Grid) -> Series {
    let gr = scene.world.gravity;
    let mut sys = System3::new(Some(Vector3::new(gr[0], gr[1], 0.0)));
    let g = add_beam(&mut sys, &scene.beams[0]);
    let fw = sys.world_frame(Vector3::zeros(), Matrix3::identity());
    let fa = sys.beam_frame(g, false, Matrix3::identity());
    let hinge = sys.add_joint("hinge", JointKind::Revolute, fw, fa, None);
    spatial(&sys, scene, grid, |q| {
        let mut r = vec![sys.joint_coordinate(hinge, q)];
        r.extend(tip_outputs(&sys, g, q));
        r
    })
}

// ---------------------------------------------------------------------------------------
// C3: slider-crank. The planar loop (revolute, revolute, revolute, prismatic) is redundant in
// 3D (its joints fix the out-of-plane motion three times over), so the rod hangs on two
// spherical joints: crank–world revolute (5 rows), crank–rod spherical (3), rod–block
// spherical (3), block–world prismatic (5): no redundant row, and one passive freedom, the
// rod's spin about the line through its two pins, which nothing excites in a planar motion.

fn c3_3d(scene: &Scene, grid: Grid) -> Series {
    let mut sys = System3::new(None);
    let crank = add_beam(&mut sys, scene.beam("crank").expect("crank"));
    let rod = add_beam(&mut sys, scene.beam("rod").expect("rod"));
    let spec = &scene.bodies[0];
    assert_eq!(spec.mass, 0.0, "C3's slider is massless");
    let block = sys.add_rigid(
        RigidBody3 {
            name: spec.name.clone(),
            mass: 0.0,
            com: Vector3::zeros(),
            inertia: Matrix3::zeros(),
            frames: vec![("origin".into(), Vector3::zeros(), Matrix3::identity())],
        },
        Vector3::new(spec.position[0], spec.position[1], 0.0),
        rot_z(spec.angle),
    );
    let id = Matrix3::identity();
    let fw = sys.world_frame(Vector3::zeros(), id);
    let crank_a = sys.beam_frame(crank, false, id);
    let crank_b = sys.beam_frame(crank, true, id);
    let rod_a = sys.beam_frame(rod, false, id);
    let rod_b = sys.beam_frame(rod, true, id);
    let block_o = sys.rigid_frame(block, "origin");
    let pivot = sys.add_joint(
        "crank_pivot",
        JointKind::Revolute,
        fw,
        crank_a,
        drive(scene, "crank_pivot"),
    );
    sys.add_joint("crank_rod", JointKind::Spherical, crank_b, rod_a, None);
    sys.add_joint("rod_block", JointKind::Spherical, rod_b, block_o, None);
    let slider = sys.add_joint("slider", JointKind::Prismatic, fw, block_o, None);
    // the rod's mid-span point, as the planar `System::beam_mid`
    let body = sys.beams[rod].bodies.start;
    let Body3::Beam(b) = &sys.bodies[body] else {
        unreachable!("a beam group holds beams")
    };
    let mid_map = b.point_map(b.length / 2.0);
    let mid = sys.add_frame(Frame3::on_body(body, mid_map, id));
    spatial(&sys, scene, grid, |q| {
        // transverse displacement of mid-span from the chord (pinned frame), as the planar
        // `System::beam_transverse`
        let root = sys.frame_pose(rod_a, q).0;
        let chord = (sys.frame_pose(rod_b, q).0 - root).normalize();
        let d = sys.frame_pose(mid, q).0 - root;
        vec![
            sys.joint_coordinate(slider, q),
            sys.joint_coordinate(pivot, q),
            chord.x * d.y - chord.y * d.x,
        ]
    })
}

// ---------------------------------------------------------------------------------------
// C4: spin-up, 5 substructures clamped to a hub whose angle is prescribed.

fn c4_3d(scene: &Scene, grid: Grid) -> Series {
    let mut sys = System3::new(None);
    let g = add_beam(&mut sys, &scene.beams[0]);
    let fw = sys.world_frame(Vector3::zeros(), Matrix3::identity());
    let fa = sys.beam_frame(g, false, Matrix3::identity());
    let hub = sys.add_joint("hub", JointKind::Revolute, fw, fa, drive(scene, "hub"));
    spatial(&sys, scene, grid, |q| {
        let mut r = vec![sys.joint_coordinate(hub, q)];
        r.extend(tip_outputs(&sys, g, q));
        r
    })
}

// ---------------------------------------------------------------------------------------

const TIP: [&str; 4] = [
    "beam.tip.deflection",
    "beam.tip.x",
    "beam.tip.y",
    "beam.tip.phi",
];

#[test]
fn c1_cantilever_agrees_to_rounding() {
    agree(Case {
        name: "C1",
        file: "cantilever_free_vibration.toml",
        outputs: TIP.to_vec(),
        angles: &[3],
        steps: [1e-3, 5e-4],
        tol: SPATIAL_TOL,
        hc: 1e-2,
        stop: 2.0,
        run3d: c1_3d,
    });
}

#[test]
fn c2_flexible_pendulum_agrees() {
    agree(Case {
        name: "C2",
        file: "flexible_pendulum.toml",
        outputs: [&["hinge.angle"][..], &TIP].concat(),
        angles: &[0, 4],
        steps: [4e-4, 2e-4],
        tol: SPATIAL_TOL,
        hc: 1e-2,
        stop: 1.0,
        run3d: c2_3d,
    });
}

#[test]
fn c3_slider_crank_agrees() {
    agree(Case {
        name: "C3",
        file: "slider_crank.toml",
        outputs: vec!["slider.position", "crank_pivot.angle", "rod.mid.deflection"],
        angles: &[1],
        steps: [5e-4, 2.5e-4],
        tol: SPATIAL_TOL,
        hc: 1e-2,
        stop: 1.6,
        run3d: c3_3d,
    });
}

#[test]
fn c4_spin_up_agrees() {
    agree(Case {
        name: "C4",
        file: "spin_up_omega4.toml",
        outputs: [&["hub.angle"][..], &TIP].concat(),
        angles: &[0, 4],
        steps: [2e-3, 1e-3],
        tol: 1e-11,
        hc: 5e-2,
        stop: 20.0,
        run3d: c4_3d,
    });
}
