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
mod shapes;

use crate::error::EngineError;
use crate::integrator::{initial_state, Settings};
use crate::mechanics::multibody::equations::Equations;
use crate::mechanics::Mechanics;
use crate::scene::{DriveKind, DriveSpec, Formulation, JointKind, LawSpec, Scene};
use crate::unit::effects::Effects;
use crate::unit::engine::Engine;
use nalgebra::DVector;

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

/// One oscillating mode: its frequencies, damping ratio and shape.
#[derive(Debug, Clone, PartialEq)]
pub struct Mode {
    /// Natural frequency |s|/2π (Hz): without damping, the undamped frequency; with Rayleigh
    /// damping proportional to the mode, the same.
    pub frequency: f64,
    /// Damped natural frequency |Im s|/2π = `frequency` √(1 − ζ²) (Hz).
    pub damped_frequency: f64,
    /// Damping ratio ζ = −Re s/|s| (0 without damping).
    pub damping_ratio: f64,
    /// The shape on [`Modes::coordinates`], its largest component 1: the real part of the
    /// eigenvector turned by the phase that makes it as real as possible (exactly real
    /// without damping or spin).
    pub shape: Vec<f64>,
}

/// The modes of a linearized scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Modes {
    /// Natural frequencies without the scene's damping (Hz, ascending): gyroscopic terms
    /// kept at speed; rigid-body modes left out.
    pub frequencies: Vec<f64>,
    /// The oscillating modes by ascending natural frequency: the damped system's where a beam
    /// has Rayleigh damping ([`Modes::damped`]), else the undamped ones (one per entry of
    /// `frequencies`).
    pub modes: Vec<Mode>,
    /// Whether a beam has Rayleigh damping (then `modes` are the damped system's).
    pub damped: bool,
    /// The names of a shape's entries: each beam's shape points (`<beam>.shape.x[i]`, `.y[i]`,
    /// `.z[i]`, the unit's shape outputs, i from 1 at flange a; then the section's rotation
    /// `.phi[i]` planar, `.rx[i]`, `.ry[i]`, `.rz[i]` 3D, world axes), then each rigid body's
    /// origin (`<body>.x`, …).
    pub coordinates: Vec<String>,
    /// How many motions have no stiffness at all (rigid-body modes).
    pub rigid_body_modes: usize,
    /// Modes that do not oscillate: real eigenvalue pairs (overdamped, or diverging when
    /// centrifugal softening exceeds the stiffness), of the damped system where it is damped.
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
    /// A 3D scene that runs with the planar element (its motion stays in the x–y plane,
    /// [`Scene::planar_reduction`]): its modes are still the 3D structure's, linearized with
    /// the spatial element, so that the out-of-plane ones are there.
    pub runs_planar: bool,
}

/// Natural frequencies (Hz), ascending, of the scene linearized about its initial
/// configuration at rest with its joints free: one 0 for each rigid-body mode, then the
/// elastic ones. A 3D scene is linearized with the spatial element (out-of-plane modes
/// included), even where its motion is planar and runs with the planar one.
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
    let runs_planar = spatial_structure(&mut scene)?;
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
    let undamped = linear_model(&scene, options)?;
    let solved = eigen::solve(&undamped.lin, spinning, false)?;
    let placed_acceleration = undamped.start.qdd.amax();
    let (at, solved_damped) = if has_damping {
        let lin = linear_model(&damped_scene, options)?;
        let s = eigen::solve(&lin.lin, true, true)?;
        (lin, Some(s))
    } else {
        (undamped, None)
    };
    let (listed, non_oscillating) = match &solved_damped {
        Some(s) => (&s.modes, s.non_oscillating),
        None => (&solved.modes, solved.non_oscillating),
    };
    let (coordinates, modes) = at.shapes(&damped_scene, listed);
    Ok(Modes {
        frequencies: solved.frequencies,
        modes,
        damped: has_damping,
        coordinates,
        rigid_body_modes: solved.rigid,
        non_oscillating,
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
        runs_planar,
    })
}

/// A 3D scene is linearized with the spatial element: the planar reduction is exact for its
/// motion, which stays in the x–y plane, but a mode is any small motion about it, out of the
/// plane too (a blade's flap modes). Returns whether the scene runs with the planar element.
fn spatial_structure(scene: &mut Scene) -> Result<bool, EngineError> {
    if !scene.is_3d() || scene.planar_reduction().is_err() {
        return Ok(false);
    }
    scene.formulation = Formulation::Spatial;
    scene.validate("modes").map_err(|e| {
        modes_error(format!(
            "the scene runs with the planar element; its 3D modes need the spatial one, which \
             it cannot use: {e}"
        ))
    })?;
    Ok(true)
}

/// A scene's system, linearized: the linearization, the system and where it was taken, and
/// the consistent start it began from.
struct Linearized {
    lin: linearize::Linear,
    sys: Mechanics,
    q: DVector<f64>,
    effects: Effects,
    start: crate::integrator::GaState,
}

impl Linearized {
    /// The coordinates' names and the modes with their shapes on them.
    fn shapes(&self, scene: &Scene, modes: &[eigen::RawMode]) -> (Vec<String>, Vec<Mode>) {
        let points = shapes::Coordinates::new(scene, &self.effects, &self.sys);
        let scale = self.sys.length_scale().max(1e-3);
        let out = modes
            .iter()
            .map(|m| {
                let re = points.map(&self.sys, &self.q, &(&self.lin.basis * &m.shape.0), scale);
                let im = points.map(&self.sys, &self.q, &(&self.lin.basis * &m.shape.1), scale);
                Mode {
                    frequency: m.natural,
                    damped_frequency: m.damped,
                    damping_ratio: m.ratio,
                    shape: most_real(&re, &im),
                }
            })
            .collect();
        (points.names, out)
    }
}

/// Re(e^{iφ} (a + ib)) with the phase φ that makes it longest (as real as possible),
/// scaled so that its largest component is 1: φ = −½ arg Σ (a_k + i b_k)².
fn most_real(a: &[f64], b: &[f64]) -> Vec<f64> {
    let (mut re, mut im) = (0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        re += x * x - y * y;
        im += 2.0 * x * y;
    }
    let phi = -0.5 * im.atan2(re);
    let (s, c) = phi.sin_cos();
    let v: Vec<f64> = a.iter().zip(b).map(|(x, y)| x * c - y * s).collect();
    let big = v
        .iter()
        .copied()
        .fold(0.0f64, |m, x| if x.abs() > m.abs() { x } else { m });
    if big == 0.0 {
        return v;
    }
    v.into_iter().map(|x| x / big).collect()
}

/// The scene's system linearized at rest (its start, or its static equilibrium) or at the
/// steady state at the options' speed.
fn linear_model(scene: &Scene, options: &ModeOptions) -> Result<Linearized, EngineError> {
    let speed = options.speed;
    let settings = Settings::from_scene(scene);
    let effects = crate::unit::effects::resolve(scene).effects;
    let sys = Mechanics::build(scene, &effects);
    let st = initial_state(&sys, 0.0, &settings)?;
    let spin = linearize::Spin::of(&sys);
    let (q, lambda) = if speed == 0.0 {
        if options.equilibrium {
            linearize::steady_state(&sys, &spin, &st.q, &st.lambda, &linearize::ramp(0.0))?
        } else {
            (st.q.clone(), st.lambda.clone())
        }
    } else {
        steady_at_speed(&sys)?;
        spinning(&sys, &spin, &st, speed)?
    };
    let lin = linearize::corotating(&sys, &spin, &q, &lambda, speed)?;
    Ok(Linearized {
        lin,
        sys,
        q,
        effects,
        start: st,
    })
}

/// The steady state spinning at `speed`, reached in 8 steps of speed from rest; under gravity
/// (along the hub's axis) first without it, which then comes in 8 steps at full speed: a
/// hinged part has no steady state under gravity at low speeds (it hangs).
fn spinning(
    sys: &Mechanics,
    spin: &linearize::Spin,
    start: &crate::integrator::GaState,
    speed: f64,
) -> Result<(DVector<f64>, DVector<f64>), EngineError> {
    let with_gravity = |share: f64| {
        let mut s = sys.clone();
        if let Mechanics::Spatial(s, _) = &mut s {
            s.gravity = s.gravity.map(|g| g * share);
        }
        s
    };
    let weighs =
        matches!(sys, Mechanics::Spatial(s, _) if s.gravity.is_some_and(|g| g.norm() > 0.0));
    if !weighs {
        return linearize::steady_state(
            sys,
            spin,
            &start.q,
            &start.lambda,
            &linearize::ramp(speed),
        );
    }
    let (mut q, mut lambda) = linearize::steady_state(
        &with_gravity(0.0),
        spin,
        &start.q,
        &start.lambda,
        &linearize::ramp(speed),
    )?;
    for k in 1..=8 {
        (q, lambda) =
            linearize::steady_state(&with_gravity(k as f64 / 8.0), spin, &q, &lambda, &[speed])?;
    }
    Ok((q, lambda))
}

/// Whether the system can spin steadily about world z (the hub's axis): gravity along that
/// axis only (a planar system's lies in the plane of rotation), and no loads, which keep their
/// world direction while the system turns under them.
fn steady_at_speed(sys: &Mechanics) -> Result<(), EngineError> {
    let (across, loads) = match sys {
        Mechanics::Planar(s) => (
            s.gravity
                .filter(|g| g.norm() > 0.0)
                .map(|g| [g[0], g[1], 0.0]),
            s.loads
                .iter()
                .any(|l| l.force.norm() > 0.0 || l.torque != 0.0 || l.inputs.is_some()),
        ),
        Mechanics::Spatial(s, _) => (
            s.gravity
                .filter(|g| g[0].hypot(g[1]) > 1e-12 * g.norm())
                .map(|g| [g[0], g[1], g[2]]),
            !s.loads.is_empty(),
        ),
    };
    if let Some(g) = across {
        return Err(modes_error(format!(
            "gravity {g:?} m/s² has a part across the hub's axis (world z): it turns in the \
             co-rotating frame, so the spinning state is periodic, not steady. At speed, gravity \
             must lie along world z (a 3D scene); it is linearized at rest"
        )));
    }
    if loads {
        return Err(modes_error(
            "a load keeps its world direction while the scene turns under it, so the spinning \
             state is periodic, not steady: loads are linearized at rest only"
                .into(),
        ));
    }
    Ok(())
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
