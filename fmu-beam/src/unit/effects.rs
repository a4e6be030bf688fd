//! Effects: which physical terms a scene's unit computes, and why.
//!
//! A scene's `effects` is `"scene"` (the default: every term of the model, geometric stiffening
//! for the beams that ask for it), `"all"` (every effect, geometric stiffening on every flexible
//! beam), a list of effect names (exactly those are on), or `"auto"` (decided here from the
//! scene: its gravity field, what its drives and loads excite, how fast its beams spin).
//! [`resolve`] turns that into [`Effects`] (what [`crate::mechanics::multibody::System`] builds) and a list
//! of [`Decision`]s with the reason for each and its estimated share of the cost of a step
//! (what `fmu-harness explain` prints and the FMU carries in `documentation/`). A term that is
//! off is not evaluated: the beam's [`BeamOptions`] switch its code path off.
//!
//! Over 600 lines: `auto`'s decisions, each with the reason it gives the user, read as one
//! policy (its cost model and its text are `effects/cost.rs` and `effects/explain.rs`).

use crate::mechanics::beam::planar_beam::BeamOptions;
use crate::mechanics::beam::section::Section;
pub use crate::mechanics::{BeamEffects, Effects};
use crate::scene::{BeamSpec, DriveKind, FrameKind, JointKind, LawSpec, Scene};
use std::collections::BTreeSet;
use std::f64::consts::PI;

pub use crate::scene::rules::EFFECTS;

mod cost;
mod explain;
mod spatial;

use cost::{coordinates, nodal_coordinates, shape_read_cost, step_cost};

/// Modes a beam keeps when `auto` finds its response quasi-static.
pub const AUTO_MODES: usize = 4;
/// `auto`: a beam whose first bending frequency is this many times above the excitation
/// bandwidth responds quasi-statically (a few modes carry it).
pub const QUASI_STATIC_RATIO: f64 = 10.0;
/// `auto`: spin above this fraction of the first bending frequency needs geometric stiffening
/// (the first frequency then rises by more than ≈ 5 %).
pub const SPIN_RATIO: f64 = 0.3;
/// `auto`: an axial force above this share of the buckling load needs geometric stiffening (it
/// changes the bending stiffness by about that share).
pub const AXIAL_SHARE: f64 = 0.01;

/// One resolved effect of one subject (the scene, or a beam), with its reason.
#[derive(Debug, Clone, PartialEq)]
pub struct Decision {
    /// The effect's name: one of [`EFFECTS`], or `formulation` (planar or spatial element).
    pub effect: &'static str,
    /// `scene` or the beam's name.
    pub subject: String,
    /// `on`, `off`, or a setting (`4 modes`, `5 x 4 elements`).
    pub setting: String,
    /// The reason, as `fmu-harness explain` prints it.
    pub why: String,
    /// Estimated share of a step's cost that this effect adds (0..1): the operation count with
    /// it, less the count without it, over the count with every resolved effect.
    pub cost_share: f64,
}

/// Everything `resolve` found.
#[derive(Debug, Clone, PartialEq)]
pub struct Resolution {
    /// `all`, `auto` or `list`.
    pub mode: &'static str,
    /// What the system is built to compute.
    pub effects: Effects,
    /// The decisions: the scene's first (a 3D scene's formulation, gravity), then each beam's.
    pub decisions: Vec<Decision>,
}

/// First bending natural frequency (rad/s) of a beam alone: clamped–free for a tangent frame,
/// pinned–pinned for a pinned one (Euler–Bernoulli closed forms).
pub fn first_bending_frequency(b: &BeamSpec) -> f64 {
    let sec = Section::from_spec(&b.section);
    let mu = b.material.rho * sec.area;
    let ej = b.material.e * sec.second_moment;
    let beta_l: f64 = match b.frame {
        FrameKind::Tangent => 1.875_104_068_711_961,
        FrameKind::Pinned => PI,
    };
    beta_l * beta_l * (ej / (mu * b.length.powi(4))).sqrt()
}

/// Euler's buckling load (N) of a beam pinned at both ends, π²EI/L²: the scale its axial force
/// is weighed against.
pub fn buckling_load(b: &BeamSpec) -> f64 {
    let sec = Section::from_spec(&b.section);
    PI * PI * b.material.e * sec.second_moment / (b.length * b.length)
}

/// First axial natural frequency (rad/s) of a beam alone, fixed at one end:
/// π/(2L) sqrt(E/ρ).
pub fn first_axial_frequency(b: &BeamSpec) -> f64 {
    PI / (2.0 * b.length) * (b.material.e / b.material.rho).sqrt()
}

/// Bandwidth (rad/s) a time law excites; infinite for a jump in the law or in its rate.
fn law_bandwidth(law: &LawSpec, kind: DriveKind, comm_step: f64) -> f64 {
    if law.until.is_some() {
        return f64::INFINITY; // the law drops to zero: a jump
    }
    match law.law.as_str() {
        "constant" => match kind {
            DriveKind::Motion => 0.0,
            DriveKind::Effort if law.value.unwrap_or(0.0) == 0.0 => 0.0,
            DriveKind::Effort => f64::INFINITY, // a step at t = 0
        },
        // the value is continuous but its rate jumps at t = 0 (a motion drive) or the effort
        // itself starts with a finite slope: take it as a jump for motion, 1/τ for effort
        "exponential" => match kind {
            DriveKind::Motion => f64::INFINITY,
            DriveKind::Effort => 1.0 / law.time_constant.unwrap_or(1.0),
        },
        "spin_up" => 2.0 * PI / law.ramp_time.unwrap_or(1.0),
        "table" => {
            let t = law.table.as_deref().unwrap_or(&[]);
            let dt = t
                .windows(2)
                .map(|w| w[1][0] - w[0][0])
                .fold(f64::INFINITY, f64::min);
            2.0 * PI / dt
        }
        // an input may change every communication step
        _ => PI / comm_step,
    }
}

/// Largest rate (rad/s) of a revolute motion drive's law.
fn law_max_rate(law: &LawSpec) -> f64 {
    match law.law.as_str() {
        "spin_up" => law.omega.unwrap_or(0.0).abs(),
        "exponential" => law.value.unwrap_or(0.0).abs() / law.time_constant.unwrap_or(1.0),
        "table" => law
            .table
            .as_deref()
            .unwrap_or(&[])
            .windows(2)
            .map(|w| ((w[1][1] - w[0][1]) / (w[1][0] - w[0][0])).abs())
            .fold(0.0, f64::max),
        _ => 0.0,
    }
}

/// The fastest spin (rad/s) of the scene: a revolute joint's fastest motion-drive law, or the
/// speed it starts at.
fn spin_rate(scene: &Scene) -> f64 {
    scene
        .joints
        .iter()
        .filter(|j| j.kind == JointKind::Revolute)
        .map(|j| {
            let driven = j
                .drive
                .as_ref()
                .filter(|d| d.kind == DriveKind::Motion)
                .map_or(0.0, |d| law_max_rate(&d.law));
            let start = j.initial.as_ref().and_then(|i| i.speed).unwrap_or(0.0);
            driven.max(start.abs())
        })
        .fold(0.0, f64::max)
}

/// `auto`'s reason for geometric stiffening of a flexible beam whose first bending frequency
/// is `w1` (rad/s) and buckling load `buckling` (N), at the scene's `spin` (rad/s) and with
/// the axial force of a rigid-body run (`None` when unknown); `None` when neither criterion
/// holds.
fn stiffening_reason(
    spin: f64,
    w1: f64,
    buckling: f64,
    axial_force: Option<crate::unit::axial_load::AxialLoad>,
) -> Option<String> {
    if spin >= SPIN_RATIO * w1 {
        return Some(format!(
            "spin up to {spin:.3} rad/s is {:.2} x the first bending frequency {w1:.3} rad/s \
             (>= {SPIN_RATIO}): centrifugal stiffening matters",
            spin / w1
        ));
    }
    axial_force
        .filter(|a| a.force >= AXIAL_SHARE * buckling)
        .map(|a| {
            format!(
                "a rigid-body run of the experiment puts an axial force of {:.3e} N on \
                 the beam (at t = {:.3} s), {:.1} % of its buckling load π²EI/L² = \
                 {buckling:.3e} N (>= {:.0} %): the geometric stiffness changes its \
                 bending stiffness by about as much",
                a.force,
                a.at,
                100.0 * a.force / buckling,
                100.0 * AXIAL_SHARE
            )
        })
}

/// `auto`'s reason for leaving geometric stiffening off (see [`stiffening_reason`]); `axial`
/// the rigid-body run's outcome.
fn no_stiffening_reason(
    spin: f64,
    w1: f64,
    buckling: f64,
    axial: &Result<Vec<crate::unit::axial_load::AxialLoad>, String>,
    axial_force: Option<crate::unit::axial_load::AxialLoad>,
) -> String {
    let load = match (axial, axial_force) {
        (_, Some(a)) => format!(
            "; the largest axial force of a rigid-body run, {:.3e} N, is {:.2} % of its \
             buckling load {buckling:.3e} N",
            a.force,
            100.0 * a.force / buckling
        ),
        (Err(e), _) => format!("; its axial force is not known (the rigid-body run failed: {e})"),
        _ => String::new(),
    };
    format!(
        "spin {spin:.3} rad/s is below {SPIN_RATIO} x the first bending frequency {w1:.3} \
         rad/s{load}"
    )
}

/// What excites the scene: the bandwidth (rad/s) and the source that sets it.
fn excitation(scene: &Scene) -> (f64, String) {
    let h = scene.experiment.step_size;
    let mut worst = (0.0, "nothing: no drive, load or gravity acts".to_string());
    let mut consider = |w: f64, what: String| {
        if w > worst.0 {
            worst = (w, what);
        }
    };
    if scene.world.gravity != [0.0; 3] {
        consider(
            f64::INFINITY,
            "gravity, switched on at t = 0 (a step)".into(),
        );
    }
    for j in &scene.joints {
        if let Some(d) = &j.drive {
            let w = law_bandwidth(&d.law, d.kind, h);
            consider(w, format!("the {} law of joint {}", d.law.law, j.name));
        }
    }
    for l in &scene.loads {
        if l.input {
            consider(PI / h, format!("load {} (an input)", l.name));
        } else if let Some(s) = &l.scale {
            let w = law_bandwidth(s, DriveKind::Effort, h);
            consider(w, format!("the {} law scaling load {}", s.law, l.name));
        } else if l.force != [0.0; 3] || l.torque != [0.0; 3] {
            consider(f64::INFINITY, format!("load {} (a step at t = 0)", l.name));
        }
    }
    worst
}

/// Names of the bodies and beams that never rotate: the world, and whatever a weld or a
/// prismatic joint holds to something that never rotates.
fn non_rotating(scene: &Scene) -> BTreeSet<String> {
    let owner = |f: &str| f.split_once('.').map_or(f, |(o, _)| o).to_string();
    let mut fixed = BTreeSet::from(["world".to_string()]);
    loop {
        let before = fixed.len();
        for j in &scene.joints {
            if !matches!(j.kind, JointKind::Weld | JointKind::Prismatic) {
                continue;
            }
            let (a, b) = (owner(&j.frames[0]), owner(&j.frames[1]));
            if fixed.contains(&a) {
                fixed.insert(b.clone());
            }
            if fixed.contains(&b) {
                fixed.insert(a);
            }
        }
        if fixed.len() == before {
            return fixed;
        }
    }
}

/// Resolves the effects of a validated scene. A 3D scene whose motion is planar resolves as
/// its planar reduction (and says so first); any other 3D scene as `spatial`.
pub fn resolve(scene: &Scene) -> Resolution {
    if scene.is_3d() {
        return match scene.planar_reduction() {
            Ok(planar) => {
                let mut r = resolve(&planar);
                r.decisions.insert(
                    0,
                    Decision {
                        effect: "formulation",
                        subject: "scene".into(),
                        setting: "planar".into(),
                        why: "the motion stays in the world x-y plane (gravity, axes, loads and                               positions have no out-of-plane part): the planar element gives                               the same solution with 3 instead of 6 coordinates per node" .into(),
                        cost_share: 0.0,
                    },
                );
                r
            }
            Err(why) => spatial::resolve(scene, &why),
        };
    }
    let all = || BeamOptions::default();
    match &scene.effects {
        crate::scene::EffectsSpec::List(names) => {
            let on = |e: &str| names.iter().any(|n| n == e);
            let effects = Effects {
                gravity: on("gravity"),
                beams: scene
                    .beams
                    .iter()
                    .map(|b| BeamEffects {
                        rigid: b.rigid || !on("flexibility"),
                        options: BeamOptions {
                            axial: on("axial"),
                            quadratic_velocity: on("quadratic_velocity"),
                            damping: on("rayleigh_damping"),
                            geometric_stiffening: b.geometric_stiffening
                                && on("geometric_stiffening"),
                            modes: b.modes,
                        },
                    })
                    .collect(),
            };
            finish(scene, "list", effects, |_, _| "listed in `effects`".into())
        }
        crate::scene::EffectsSpec::Mode(m) if m == "auto" => auto(scene),
        crate::scene::EffectsSpec::Mode(m) => {
            // "all": every effect, stiffening on every flexible beam; "scene": where asked
            let every = m == "all";
            let effects = Effects {
                gravity: true,
                beams: scene
                    .beams
                    .iter()
                    .map(|b| BeamEffects {
                        rigid: b.rigid,
                        options: BeamOptions {
                            geometric_stiffening: b.geometric_stiffening || (every && !b.rigid),
                            modes: b.modes,
                            ..all()
                        },
                    })
                    .collect(),
            };
            let mode = if every { "all" } else { "scene" };
            finish(scene, mode, effects, |effect, subject| {
                mode_reason(scene, every, effect, subject)
            })
        }
    }
}

/// Why `effects = "scene"` (`every` false) or `"all"` resolves `effect` of `subject` as it does.
fn mode_reason(scene: &Scene, every: bool, effect: &str, subject: &str) -> String {
    let mode = if every {
        "effects = \"all\": every effect"
    } else {
        "effects = \"scene\" (the default): every term of the element"
    };
    let beam = scene.beams.iter().find(|b| b.name == subject);
    match (effect, beam) {
        ("flexibility", Some(b)) if b.rigid => {
            "the scene makes the beam rigid (rigid = true)".into()
        }
        ("geometric_stiffening", Some(_)) if every => {
            format!("{mode}, geometric stiffening included")
        }
        ("geometric_stiffening", Some(b)) if b.geometric_stiffening => {
            "asked for by the beam (geometric_stiffening = true)".into()
        }
        ("geometric_stiffening", Some(_)) => "the beam does not ask for it (geometric_stiffening \
             = false); effects = \"all\" turns it on for every beam, \"auto\" where spin or \
             axial force needs it"
            .into(),
        ("rayleigh_damping", Some(b)) => format!(
            "{mode}: alpha = {}, beta = {}",
            b.rayleigh.alpha, b.rayleigh.beta
        ),
        _ => mode.into(),
    }
}

/// `effects = "auto"`: the rules of the module documentation, each decision with its reason.
fn auto(scene: &Scene) -> Resolution {
    let mut why: Vec<(&'static str, String, String)> = Vec::new();
    let gravity = scene.world.gravity != [0.0; 3];
    why.push((
        "gravity",
        "scene".into(),
        if gravity {
            format!("world.gravity = {:?} m/s2", scene.world.gravity)
        } else {
            "no gravity field".into()
        },
    ));
    let (bandwidth, source) = excitation(scene);
    let still = non_rotating(scene);
    let spin = spin_rate(scene);
    // the axial force of each beam, from a rigid-body run (only where a beam could need it)
    let axial = if scene
        .beams
        .iter()
        .any(|b| !b.rigid && !b.geometric_stiffening)
    {
        crate::unit::axial_load::rigid_run(scene)
    } else {
        Ok(vec![
            crate::unit::axial_load::AxialLoad {
                force: 0.0,
                at: 0.0
            };
            scene.beams.len()
        ])
    };
    let mut beams = Vec::new();
    for (i, b) in scene.beams.iter().enumerate() {
        let w1 = first_bending_frequency(b);
        let n = b.name.clone();
        let mut o = BeamOptions {
            geometric_stiffening: b.geometric_stiffening,
            modes: b.modes,
            ..BeamOptions::default()
        };
        // geometric stiffening: a beam (one frame or substructures) spinning near its first
        // frequency, or carrying an axial force that is a measurable share of its buckling load
        let buckling = buckling_load(b);
        let axial_force = axial.as_ref().ok().map(|a| a[i]);
        let reason = if b.rigid {
            None
        } else {
            stiffening_reason(spin, w1, buckling, axial_force)
        };
        if let Some(reason) = reason {
            o.geometric_stiffening = true;
            why.push(("geometric_stiffening", n.clone(), reason));
        } else if o.geometric_stiffening {
            why.push((
                "geometric_stiffening",
                n.clone(),
                "asked for by the beam".into(),
            ));
        } else {
            why.push((
                "geometric_stiffening",
                n.clone(),
                no_stiffening_reason(spin, w1, buckling, &axial, axial_force),
            ));
        }
        // axial deformation: where the stiffening needs the axial strain, or where the
        // excitation reaches the axial modes (a step does: measured on C2 and C3, dropping u
        // there moves the deflection by 0.3 to 0.7 %)
        let w_axial = first_axial_frequency(b);
        o.axial = o.geometric_stiffening || w_axial < QUASI_STATIC_RATIO * bandwidth;
        why.push((
            "axial",
            n.clone(),
            if o.geometric_stiffening {
                "geometric stiffening needs the axial strain".into()
            } else if o.axial {
                format!(
                    "the excitation bandwidth {bandwidth:.3} rad/s (set by {source}) lies \
                     within {QUASI_STATIC_RATIO} x of the first axial frequency {w_axial:.0} rad/s"
                )
            } else {
                format!(
                    "the first axial frequency {w_axial:.0} rad/s is {} the excitation \
                     bandwidth {bandwidth:.3} rad/s: the beam responds as inextensible",
                    if bandwidth > 0.0 {
                        format!("{:.0} x", w_axial / bandwidth)
                    } else {
                        "far above".into()
                    }
                )
            },
        ));
        // quadratic-velocity terms: off when the beam's frame never rotates
        let frame_still = b.substructures.is_none() && still.contains(&b.name);
        o.quadratic_velocity = !frame_still;
        why.push((
            "quadratic_velocity",
            n.clone(),
            if frame_still {
                "the beam is held to the world by welds or prismatic joints: its frame never \
                 rotates, so the terms are zero"
                    .into()
            } else {
                "the beam's frame rotates".into()
            },
        ));
        // Rayleigh damping: off without coefficients
        o.damping = b.rayleigh.alpha != 0.0 || b.rayleigh.beta != 0.0;
        why.push((
            "rayleigh_damping",
            n.clone(),
            if o.damping {
                format!("alpha = {}, beta = {}", b.rayleigh.alpha, b.rayleigh.beta)
            } else {
                "no damping coefficients".into()
            },
        ));
        // flexibility: a quasi-static response keeps a few modes
        let (elements, k) = Scene::beam_layout(b);
        let nodal = nodal_coordinates(b, elements, o.axial);
        let flex_why = if b.rigid {
            "the beam is rigid in the scene".to_string()
        } else if b.initial.tip_displacement != 0.0 {
            "the beam starts deformed: its free vibration is the point".into()
        } else if o.modes.is_some() {
            "modes asked for by the beam".into()
        } else if w1 >= QUASI_STATIC_RATIO * bandwidth && nodal > AUTO_MODES {
            o.modes = Some(AUTO_MODES);
            format!(
                "first bending frequency {w1:.3} rad/s is {} the excitation bandwidth \
                 {bandwidth:.3} rad/s (set by {source}): the response is quasi-static, the \
                 lowest {AUTO_MODES} modes of each frame carry it",
                if bandwidth > 0.0 {
                    format!("{:.0} x", w1 / bandwidth)
                } else {
                    "far above".into()
                }
            )
        } else {
            format!(
                "the excitation bandwidth {bandwidth:.3} rad/s (set by {source}) lies within \
                 {QUASI_STATIC_RATIO} x of the first bending frequency {w1:.3} rad/s{}",
                if k > 1 {
                    format!("; {k} substructures")
                } else {
                    String::new()
                }
            )
        };
        why.push(("flexibility", n.clone(), flex_why));
        beams.push(BeamEffects {
            rigid: b.rigid,
            options: o,
        });
    }
    let effects = Effects { gravity, beams };
    finish(scene, "auto", effects, |effect, subject| {
        why.iter()
            .find(|(e, s, _)| *e == effect && s == subject)
            .map(|(_, _, w)| w.clone())
            .unwrap_or_default()
    })
}

/// The decisions of resolved effects, with the cost of each one.
fn finish(
    scene: &Scene,
    mode: &'static str,
    effects: Effects,
    why: impl Fn(&str, &str) -> String,
) -> Resolution {
    let total = step_cost(scene, &effects);
    let share = |other: &Effects| ((total - step_cost(scene, other)) / total).abs();
    let mut decisions = Vec::new();
    let mut toggled = effects.clone();
    toggled.gravity = !effects.gravity;
    decisions.push(Decision {
        effect: "gravity",
        subject: "scene".into(),
        setting: on_off(effects.gravity),
        why: why("gravity", "scene"),
        cost_share: if effects.gravity {
            share(&toggled)
        } else {
            0.0
        },
    });
    for (i, (b, e)) in scene.beams.iter().zip(&effects.beams).enumerate() {
        let n = &b.name;
        let (elements, k) = Scene::beam_layout(b);
        let with = |f: &dyn Fn(&mut BeamEffects)| {
            let mut other = effects.clone();
            f(&mut other.beams[i]);
            share(&other)
        };
        let setting = if e.rigid {
            "rigid".to_string()
        } else {
            let layout = if k > 1 {
                format!("{k} x {elements} elements")
            } else {
                format!("{elements} elements")
            };
            match e.options.modes {
                Some(m) => format!("{layout}, {m} modes"),
                None => layout,
            }
        };
        decisions.push(Decision {
            effect: "flexibility",
            subject: n.clone(),
            setting,
            why: why("flexibility", n),
            cost_share: if e.rigid {
                0.0
            } else {
                with(&|x| x.rigid = true)
            },
        });
        if e.rigid {
            continue;
        }
        let o = e.options;
        type Toggle = fn(&mut BeamOptions);
        let rows: [(&'static str, bool, Toggle); 4] = [
            ("axial", o.axial, |x| x.axial = !x.axial),
            ("quadratic_velocity", o.quadratic_velocity, |x| {
                x.quadratic_velocity = !x.quadratic_velocity
            }),
            ("geometric_stiffening", o.geometric_stiffening, |x| {
                x.geometric_stiffening = !x.geometric_stiffening
            }),
            ("rayleigh_damping", o.damping, |x| x.damping = !x.damping),
        ];
        for (effect, on, toggle) in rows {
            decisions.push(Decision {
                effect,
                subject: n.clone(),
                setting: on_off(on),
                why: why(effect, n),
                cost_share: if on {
                    with(&|x| toggle(&mut x.options))
                } else {
                    0.0
                },
            });
        }
    }
    Resolution {
        mode,
        effects,
        decisions,
    }
}

fn on_off(on: bool) -> String {
    if on { "on" } else { "off" }.into()
}
