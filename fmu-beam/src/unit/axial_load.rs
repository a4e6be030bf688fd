//! The axial force each beam of a planar scene carries, from a rigid-body run of the scene's
//! experiment: what `effects = "auto"` weighs against the beam's buckling load to decide on
//! geometric stiffening (an axial force that is a measurable share of π²EI/L² changes the
//! bending stiffness by about that share: C3's rod, whose inertial axial force is 10–15 % of
//! its buckling load, is 9.7 % off the geometrically exact mid-span deflection without it).
//!
//! Every beam is made a rigid bar, the scene runs with error control at a loose tolerance, and
//! at each of [`SAMPLES`] times the force every joint and load puts on a bar is projected on the
//! bar's axis; a beam's axial force is the largest of these. Inputs stay at their start values.
//! A scene that runs with the 3D element runs its rigid bars in the spatial system
//! ([`rigid_run_3d`]), the same way.

use crate::integrator::{initial_state, Settings, Stats, Stepper};
use crate::mechanics::multibody::joint::Joint;
use crate::mechanics::multibody::{Equations, System};
use crate::mechanics::Mechanics;
use crate::scene::{EffectsSpec, Scene};
use crate::unit::effects::Effects;
use nalgebra::{DMatrix, Vector2, Vector3};

/// Sampling times of the run.
const SAMPLES: usize = 200;

/// The largest axial force of one beam over the run, and when.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxialLoad {
    /// N, tension or compression.
    pub force: f64,
    /// s
    pub at: f64,
}

/// The scene with every beam a rigid bar, its effects, and the run's settings.
fn rigid_scene(scene: &Scene) -> (Scene, Effects, Settings) {
    let mut rigid = scene.clone();
    for b in &mut rigid.beams {
        b.rigid = true;
        b.geometric_stiffening = false;
        b.modes = None;
    }
    rigid.effects = EffectsSpec::Mode("scene".into());
    let effects: Effects = crate::unit::effects::resolve(&rigid).effects;
    let (t0, stop) = (scene.experiment.start_time, scene.experiment.stop_time);
    let settings = Settings {
        adaptive: true,
        tolerance: 1e-4,
        max_step: (stop - t0) / SAMPLES as f64,
        rho_inf: scene.solver.rho_inf,
        step_budget: crate::integrator::DEFAULT_STEP_BUDGET,
    };
    (rigid, effects, settings)
}

/// Runs `sys` (the rigid scene of `scene`) over the experiment and calls `visit` at each of the
/// [`SAMPLES`] times with the state, the time and the constraint Jacobian there.
fn sample<S: Equations>(
    sys: &S,
    scene: &Scene,
    settings: Settings,
    mut visit: impl FnMut(&crate::integrator::GaState, f64, &DMatrix<f64>),
) -> Result<(), String> {
    let t0 = scene.experiment.start_time;
    let dt = settings.max_step;
    let mut st = initial_state(sys, t0, &settings).map_err(|e| e.to_string())?;
    let mut stepper = Stepper::new(sys, settings);
    let mut stats = Stats::default();
    let mut gm = DMatrix::zeros(sys.m(), sys.n());
    for k in 0..=SAMPLES {
        let t = t0 + k as f64 * dt;
        if k > 0 {
            stepper
                .step_to(sys, &mut st, &mut stats, t)
                .map_err(|e| e.to_string())?;
        }
        sys.constraint_jacobian(&st.q, t, &mut gm);
        visit(&st, t, &gm);
    }
    Ok(())
}

/// Keeps in `load` the largest of the axial components (along `axis`) of `forces`, at `t`.
fn keep_largest<V>(
    load: &mut AxialLoad,
    forces: impl Iterator<Item = V>,
    axial: impl Fn(&V) -> f64,
    t: f64,
) {
    for f in forces {
        let a = axial(&f).abs();
        if a > load.force {
            *load = AxialLoad { force: a, at: t };
        }
    }
}

/// The axial load of each scene beam (in scene order), or why the run failed.
pub fn rigid_run(scene: &Scene) -> Result<Vec<AxialLoad>, String> {
    let (rigid, effects, settings) = rigid_scene(scene);
    let sys = System::build(&rigid, &effects);
    let mut loads = vec![
        AxialLoad {
            force: 0.0,
            at: scene.experiment.start_time
        };
        scene.beams.len()
    ];
    sample(&sys, scene, settings, |st, t, gm| {
        for (g, load) in loads.iter_mut().enumerate() {
            let body = sys.beams[g].bodies.start;
            let o = sys.offsets[body];
            let axis = Vector2::new(st.q[o + 2].cos(), st.q[o + 2].sin());
            // each joint's force on the bar: its rows' Jacobian on the bar's position, times λ
            let joints = sys.joints.iter().map(|j| {
                let rows = j.row..j.row + Joint::rows_count(j.kind, j.drive.as_ref());
                rows.fold(Vector2::zeros(), |f, r| {
                    f + Vector2::new(gm[(r, o)], gm[(r, o + 1)]) * st.lambda[r]
                })
            });
            let external = sys
                .loads
                .iter()
                .filter(|l| sys.frame_body(l.frame) == Some(body))
                .map(|l| sys.load_value(l, t).0);
            keep_largest(load, joints.chain(external), |f| f.dot(&axis), t);
        }
    })?;
    Ok(loads)
}

/// [`rigid_run`] of a scene that runs with the 3D element: each bar's axis is its frame's x.
pub fn rigid_run_3d(scene: &Scene) -> Result<Vec<AxialLoad>, String> {
    let (rigid, effects, settings) = rigid_scene(scene);
    let Mechanics::Spatial(sys, index) = Mechanics::build(&rigid, &effects) else {
        return Err("the scene runs with the planar element".into());
    };
    let mut loads = vec![
        AxialLoad {
            force: 0.0,
            at: scene.experiment.start_time
        };
        scene.beams.len()
    ];
    sample(&sys, scene, settings, |st, t, gm| {
        for (load, bodies) in loads.iter_mut().zip(&index.beam_bodies) {
            let (body, o) = (bodies.start, sys.offsets[bodies.start]);
            let (_, _, a) =
                crate::mechanics::multibody3d::body::frame_of(&sys.body_coords(body, &st.q));
            let axis = a.column(0).into_owned();
            // each joint's force on the bar: its rows' Jacobian on the bar's position, times λ
            let joints = sys.joints.iter().enumerate().map(|(j, jt)| {
                let first = sys.joint_row(j);
                (first..first + jt.len()).fold(Vector3::zeros(), |f, r| {
                    f + Vector3::new(gm[(r, o)], gm[(r, o + 1)], gm[(r, o + 2)]) * st.lambda[r]
                })
            });
            let external = sys
                .loads
                .iter()
                .filter(|l| sys.frames[l.frame].body() == Some(body))
                .map(|l| l.force * sys.load_scale(l, t));
            keep_largest(load, joints.chain(external), |f| f.dot(&axis), t);
        }
    })?;
    Ok(loads)
}
