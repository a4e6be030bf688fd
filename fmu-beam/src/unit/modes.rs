//! Linearized natural frequencies: with the scene's joints free or some of them locked, at rest
//! or spinning at a steady speed about a hub joint (the co-rotating steady state, deformed by
//! its centrifugal load), as M x'' + C x' + K x = 0 on the motions the joints leave free.
//!
//! At rest the state is the scene's undeformed placement (its multipliers from the consistent
//! start, so a hanging pendulum feels gravity), or with `equilibrium` the static equilibrium
//! under gravity and the loads at t = 0 (a tensioned or sagging beam, its geometric stiffening
//! from the axial strain it takes). At speed Ω the steady state is solved in the
//! co-rotating frame (`linearize::steady_state`), and the systems' invariance to turning about
//! world z makes the perturbation equations constant in that frame (`linearize::corotating`): the
//! gyroscopic matrix 2ΩMJ and the centrifugal terms come out of the system's own residual.
//! Motions without any stiffness (rigid-body modes) are counted and taken out exactly
//! (`eigen::solve`), never reported as a tiny frequency.

mod eigen;
mod linearize;

use crate::error::EngineError;
use crate::integrator::{initial_state, Settings};
use crate::mechanics::Mechanics;
use crate::scene::{DriveKind, DriveSpec, JointKind, LawSpec, Scene};
use crate::unit::engine::Engine;

/// How to linearize: which joints to lock, and at what hub speed.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ModeOptions {
    /// Joints (by name) whose coordinate is held where the scene starts it.
    pub lock: Vec<String>,
    /// Lock every revolute, prismatic and spherical joint.
    pub lock_all: bool,
    /// Hub speed Ω (rad/s): linearize about the steady state spinning at Ω.
    pub speed: f64,
    /// The hub joint (a revolute joint to `world`); by default the one revolute joint to
    /// `world` with a motion drive.
    pub hub: Option<String>,
    /// At rest: linearize about the static equilibrium under gravity and the loads at t = 0
    /// (the deformed state, its axial forces included), not the undeformed placement.
    pub equilibrium: bool,
}

/// One oscillating mode of the damped system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DampedMode {
    /// Damped natural frequency |Im s| / 2π (Hz).
    pub frequency: f64,
    /// Damping ratio -Re s / |s|.
    pub damping_ratio: f64,
}

/// The modes of a linearized scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Modes {
    /// Natural frequencies without the scene's damping (Hz, ascending): gyroscopic terms
    /// kept at speed; rigid-body modes left out.
    pub frequencies: Vec<f64>,
    /// With the scene's Rayleigh damping, where a beam has some (else empty): one per
    /// oscillating mode, by ascending frequency.
    pub damped: Vec<DampedMode>,
    /// How many motions have no stiffness at all (rigid-body modes).
    pub rigid_body_modes: usize,
    /// Modes that do not oscillate (real eigenvalue pairs: overdamped, or diverging when
    /// centrifugal softening exceeds the stiffness).
    pub non_oscillating: usize,
    /// The joints held fixed (named, or all with `lock_all`), in scene order.
    pub locked: Vec<String>,
    /// The joints the scene itself holds with a motion drive (the hub's included).
    pub driven: Vec<String>,
    /// The hub joint (driven at Ω) when spinning or named.
    pub hub: Option<String>,
    /// Hub speed (rad/s).
    pub speed: f64,
    /// Linearized at rest about the static equilibrium ([`ModeOptions::equilibrium`]).
    pub equilibrium: bool,
    /// At rest about the placement: the largest acceleration (of any coordinate) the scene
    /// starts with there, where it is not at rest under gravity and its loads (above 1e-6):
    /// then the placement is no equilibrium, and `equilibrium` linearizes about the deformed
    /// state instead.
    pub off_equilibrium: Option<f64>,
}

/// Natural frequencies (Hz), ascending, of the scene linearized about its initial
/// configuration at rest with its joints free: one 0 for each rigid-body mode, then the
/// elastic ones. A 3D scene is linearized with the element it runs with (planar when its
/// motion is planar).
pub fn natural_frequencies(scene: &Scene) -> Result<Vec<f64>, EngineError> {
    let m = modes(scene, &ModeOptions::default())?;
    let mut f = vec![0.0; m.rigid_body_modes];
    f.extend(m.frequencies);
    Ok(f)
}

/// The modes of the scene linearized as `options` say.
pub fn modes(scene: &Scene, options: &ModeOptions) -> Result<Modes, EngineError> {
    if !options.speed.is_finite() {
        return Err(modes_error(format!(
            "speed {} rad/s is not a finite number",
            options.speed
        )));
    }
    let spinning = options.speed != 0.0;
    // the hub is held at every speed, 0 included, so that a Campbell diagram's columns agree
    let hub = (spinning || options.hub.is_some())
        .then(|| hub_joint(scene, options))
        .transpose()?;
    let mut to_lock = lock_list(scene, options)?;
    if let Some(h) = &hub {
        to_lock.retain(|n| n != h);
    }
    let given = scene;
    let locked_scene = lock(given, &to_lock, hub.as_deref())?;
    // the undeformed placement (as before: an initial tip displacement is a start, not a load)
    let mut scene = locked_scene;
    for b in &mut scene.beams {
        b.initial.tip_displacement = 0.0;
    }
    let damped_scene = scene.clone();
    let has_damping = scene
        .beams
        .iter()
        .any(|b| b.rayleigh.alpha != 0.0 || b.rayleigh.beta != 0.0);
    for b in &mut scene.beams {
        b.rayleigh.alpha = 0.0;
        b.rayleigh.beta = 0.0;
    }
    crate::unit::memory::ensure_available(&scene, "natural frequencies")?;
    let (undamped, placed_acceleration) = linear_model(&scene, options)?;
    let solved = eigen::solve(&undamped, spinning)?;
    let damped = if has_damping {
        let (lin, _) = linear_model(&damped_scene, options)?;
        eigen::solve(&lin, true)?.damped
    } else {
        Vec::new()
    };
    Ok(Modes {
        frequencies: solved.frequencies,
        damped,
        rigid_body_modes: solved.rigid,
        non_oscillating: solved.non_oscillating,
        locked: to_lock,
        driven: given
            .joints
            .iter()
            .filter(|j| {
                j.drive
                    .as_ref()
                    .is_some_and(|d| d.kind == DriveKind::Motion)
            })
            .map(|j| j.name.clone())
            .collect(),
        hub,
        speed: options.speed,
        equilibrium: options.equilibrium && !spinning,
        off_equilibrium: (!spinning && !options.equilibrium && placed_acceleration > 1e-6)
            .then_some(placed_acceleration),
    })
}

/// The scene's system linearized at rest (its start, or its static equilibrium) or at the
/// steady state at the options' speed; and the largest acceleration of the consistent start.
fn linear_model(
    scene: &Scene,
    options: &ModeOptions,
) -> Result<(linearize::Linear, f64), EngineError> {
    let (lin, st) = linear_model_at(scene, options)?;
    Ok((lin, st.qdd.amax()))
}

/// [`linear_model`], with the consistent start it began from.
fn linear_model_at(
    scene: &Scene,
    options: &ModeOptions,
) -> Result<(linearize::Linear, crate::integrator::GaState), EngineError> {
    let speed = options.speed;
    let settings = Settings::from_scene(scene);
    let effects = crate::unit::effects::resolve(scene).effects;
    let sys = Mechanics::build(scene, &effects);
    let st = initial_state(&sys, 0.0, &settings)?;
    let spin = linearize::Spin::of(&sys);
    if speed == 0.0 {
        let lin = if options.equilibrium {
            let (q, lambda) = linearize::steady_state(&sys, &spin, &st.q, &st.lambda, 0.0)?;
            linearize::corotating(&sys, &spin, &q, &lambda, 0.0)?
        } else {
            linearize::corotating(&sys, &spin, &st.q, &st.lambda, 0.0)?
        };
        return Ok((lin, st));
    }
    let (gravity, loads) = match &sys {
        Mechanics::Planar(s) => (
            s.gravity.is_some_and(|g| g.norm() > 0.0),
            s.loads
                .iter()
                .any(|l| l.force.norm() > 0.0 || l.torque != 0.0 || l.inputs.is_some()),
        ),
        Mechanics::Spatial(s, _) => (
            s.gravity.is_some_and(|g| g.norm() > 0.0),
            !s.loads.is_empty(),
        ),
    };
    if gravity || loads {
        return Err(modes_error(
            "gravity or a load makes the spinning state periodic, not steady: set them to \
             zero to linearize at speed"
                .into(),
        ));
    }
    let (q, lambda) = linearize::steady_state(&sys, &spin, &st.q, &st.lambda, speed)?;
    Ok((linearize::corotating(&sys, &spin, &q, &lambda, speed)?, st))
}

/// The hub joint at speed: the one named, else the one revolute joint to `world` with a motion
/// drive.
fn hub_joint(scene: &Scene, options: &ModeOptions) -> Result<String, EngineError> {
    let to_world = |j: &&crate::scene::JointSpec| {
        j.kind == JointKind::Revolute && j.frames.iter().any(|f| f == "world")
    };
    if let Some(name) = &options.hub {
        let j = scene
            .joints
            .iter()
            .find(|j| &j.name == name)
            .ok_or_else(|| modes_error(format!("no joint named '{name}' to spin as the hub")))?;
        if !to_world(&j) {
            return Err(modes_error(format!(
                "hub '{name}' must be a revolute joint to `world`"
            )));
        }
        return about_z(j);
    }
    let driven: Vec<_> = scene
        .joints
        .iter()
        .filter(to_world)
        .filter(|j| {
            j.drive
                .as_ref()
                .is_some_and(|d| d.kind == DriveKind::Motion)
        })
        .collect();
    match driven.as_slice() {
        [j] => about_z(j),
        [] => Err(modes_error(
            "no revolute joint to `world` with a motion drive to spin: name the hub".into(),
        )),
        _ => Err(modes_error(format!(
            "{} driven revolute joints to `world`: name the hub",
            driven.len()
        ))),
    }
}

/// The hub's name, if it turns about the world z axis (the co-rotating frame's axis).
fn about_z(j: &crate::scene::JointSpec) -> Result<String, EngineError> {
    match j.axis {
        Some(a) if a[0].abs() > 1e-12 || a[1].abs() > 1e-12 || a[2] <= 0.0 => {
            Err(modes_error(format!(
                "hub '{}' turns about {a:?}: at speed the hub's axis must be world z",
                j.name
            )))
        }
        _ => Ok(j.name.clone()),
    }
}

/// The joints to lock, in scene order: those named (each must exist), or every joint that
/// moves with `lock_all`.
fn lock_list(scene: &Scene, options: &ModeOptions) -> Result<Vec<String>, EngineError> {
    for name in &options.lock {
        if !scene.joints.iter().any(|j| &j.name == name) {
            let known: Vec<_> = scene.joints.iter().map(|j| j.name.as_str()).collect();
            return Err(modes_error(format!(
                "no joint named '{name}' to lock (joints: {})",
                known.join(", ")
            )));
        }
    }
    Ok(scene
        .joints
        .iter()
        .filter(|j| {
            (options.lock_all && j.kind != JointKind::Weld) || options.lock.contains(&j.name)
        })
        .map(|j| j.name.clone())
        .collect())
}

/// The scene with the joints `names` and the `hub` held: a revolute or prismatic joint gets a
/// motion drive holding its coordinate where the scene starts it (read from the unit, so that
/// a joint's given start is honoured), a spherical joint becomes a weld.
fn lock(scene: &Scene, names: &[String], hub: Option<&str>) -> Result<Scene, EngineError> {
    let holds = |j: &crate::scene::JointSpec| {
        (names.contains(&j.name) || hub == Some(j.name.as_str()))
            && !j
                .drive
                .as_ref()
                .is_some_and(|d| d.kind == DriveKind::Motion)
    };
    if !scene.joints.iter().any(holds) {
        return Ok(scene.clone());
    }
    let mut started = Engine::new(scene.clone());
    started.exit_initialization()?;
    let mut out = scene.clone();
    for j in out.joints.iter_mut().filter(|j| holds(j)) {
        let output = match j.kind {
            JointKind::Weld => continue,
            JointKind::Spherical => {
                j.kind = JointKind::Weld;
                j.initial = None;
                j.drive = None;
                continue;
            }
            JointKind::Revolute => format!("{}.angle", j.name),
            JointKind::Prismatic => format!("{}.position", j.name),
        };
        let vr = started
            .variables()
            .by_name(&output)
            .map(|v| v.vr)
            .ok_or_else(|| modes_error(format!("joint '{}': no output {output}", j.name)))?;
        let value = started.get_real(vr)?;
        j.initial = None;
        j.drive = Some(DriveSpec {
            kind: DriveKind::Motion,
            law: LawSpec {
                law: "constant".into(),
                value: Some(value),
                time_constant: None,
                until: None,
                omega: None,
                ramp_time: None,
                table: None,
            },
        });
    }
    out.validate("modes")?;
    Ok(out)
}

fn modes_error(message: String) -> EngineError {
    EngineError::Modes { message }
}
