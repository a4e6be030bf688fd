//! The effects of a scene that runs with the 3D element: gravity, flexibility, geometric
//! stiffening and Rayleigh damping can be switched (`crate::scene::SPATIAL_EFFECTS`); the
//! element's other terms (axial, quadratic velocity) are always on. Geometric stiffening
//! follows the planar rules: where a beam asks for it (`"scene"`, a list naming it), on every
//! flexible beam (`"all"`), or where `auto` finds spin near the first bending frequency or an
//! axial force that is a share of the buckling load (the weaker bending plane's, since
//! stiffening acts on both). No cost model (cost shares 0).

use super::*;
use crate::mechanics::from_scene::spatial::spatial_section;
use crate::unit::axial_load::AxialLoad;

/// First bending frequency (rad/s) of a 3D beam alone, in its weaker plane (min(I_y, I_z));
/// `None` for a beam from a matrix file (no section).
fn weakest_bending(b: &BeamSpec) -> Option<(f64, f64)> {
    if b.matrix_text.is_some() {
        return None;
    }
    let s = spatial_section(&b.section);
    let planar = BeamSpec {
        section: crate::scene::SectionSpec {
            shape: None,
            area: Some(s.area),
            second_moment: Some(s.iy.min(s.iz)),
            ..b.section.clone()
        },
        ..b.clone()
    };
    Some((first_bending_frequency(&planar), buckling_load(&planar)))
}

/// The effects of a 3D scene run with the 3D element (`why_3d`: why it is).
pub(super) fn resolve(scene: &Scene, why_3d: &str) -> Resolution {
    use crate::scene::EffectsSpec;
    // what the mode settles itself (None: auto decides)
    let (mode, listed): (&'static str, &[String]) = match &scene.effects {
        EffectsSpec::List(names) => ("list", names),
        EffectsSpec::Mode(m) if m == "auto" => ("auto", &[]),
        EffectsSpec::Mode(m) if m == "all" => ("all", &[]),
        EffectsSpec::Mode(_) => ("scene", &[]),
    };
    let on = |e: &str| match mode {
        "list" => Some(listed.iter().any(|n| n == e)),
        "all" | "scene" => Some(true),
        _ => None,
    };
    let reason = |auto: &str| match mode {
        "list" => "listed in `effects`".to_string(),
        "all" => "effects = \"all\": every effect".to_string(),
        "scene" => "effects = \"scene\" (the default): every term of the element".to_string(),
        _ => auto.to_string(),
    };
    let field = scene.world.gravity != [0.0; 3];
    let gravity = on("gravity").unwrap_or(field);
    let mut decisions = vec![
        Decision {
            effect: "formulation",
            subject: "scene".into(),
            setting: "spatial".into(),
            why: format!("the 3D element: {why_3d}"),
            cost_share: 0.0,
        },
        Decision {
            effect: "gravity",
            subject: "scene".into(),
            setting: on_off(gravity),
            why: reason(if field {
                "a gravity field"
            } else {
                "no gravity field"
            }),
            cost_share: 0.0,
        },
    ];
    // auto: the spin and (where a beam could need it) the axial forces of a rigid-body run
    let spin = spin_rate(scene);
    let axial = if mode == "auto"
        && scene
            .beams
            .iter()
            .any(|b| !b.rigid && !b.geometric_stiffening)
    {
        Some(crate::unit::axial_load::rigid_run_3d(scene))
    } else {
        None
    };
    let mut beams = Vec::new();
    for (i, b) in scene.beams.iter().enumerate() {
        let rigid = b.rigid || !on("flexibility").unwrap_or(true);
        let damped = b.rayleigh.alpha != 0.0 || b.rayleigh.beta != 0.0;
        let damping = on("rayleigh_damping").unwrap_or(damped);
        decisions.push(Decision {
            effect: "flexibility",
            subject: b.name.clone(),
            setting: on_off(!rigid),
            why: if b.rigid {
                "the scene makes the beam rigid (rigid = true)".into()
            } else {
                reason("auto never makes a flexible beam rigid")
            },
            cost_share: 0.0,
        });
        let (stiffening, stiffening_why) = match mode {
            "all" => (
                !rigid,
                "effects = \"all\": every effect, geometric stiffening included".into(),
            ),
            "auto" if b.geometric_stiffening => (true, "asked for by the beam".into()),
            "auto" => auto_stiffening(b, spin, axial.as_ref().map(|a| (a, i))),
            _ if !b.geometric_stiffening => (
                false,
                "the beam does not ask for it (geometric_stiffening = false); effects = \
                 \"all\" turns it on for every beam, \"auto\" where spin or axial force needs it"
                    .into(),
            ),
            "list" if !on("geometric_stiffening").unwrap_or(false) => {
                (false, "not listed in `effects`".into())
            }
            "list" => (true, "listed in `effects` and asked for by the beam".into()),
            _ => (
                true,
                "asked for by the beam (geometric_stiffening = true)".into(),
            ),
        };
        let stiffening = stiffening && !rigid;
        if !rigid {
            // the 3D element's terms that cannot be switched, listed so that `explain` shows
            // exactly what is on
            let always = |effect: &'static str, why: &str| Decision {
                effect,
                subject: b.name.clone(),
                setting: "on".into(),
                why: format!("the 3D element always computes {why}"),
                cost_share: 0.0,
            };
            decisions.push(always("axial", "axial deformation"));
            decisions.push(always(
                "quadratic_velocity",
                "the centrifugal and Coriolis terms",
            ));
            decisions.push(Decision {
                effect: "geometric_stiffening",
                subject: b.name.clone(),
                setting: on_off(stiffening),
                why: stiffening_why,
                cost_share: 0.0,
            });
            decisions.push(Decision {
                effect: "rayleigh_damping",
                subject: b.name.clone(),
                setting: on_off(damping),
                why: format!(
                    "{}: alpha = {}, beta = {}",
                    reason(if damped {
                        "damping coefficients given"
                    } else {
                        "both damping coefficients are zero"
                    }),
                    b.rayleigh.alpha,
                    b.rayleigh.beta
                ),
                cost_share: 0.0,
            });
        }
        beams.push(BeamEffects {
            rigid,
            options: BeamOptions {
                damping,
                geometric_stiffening: stiffening,
                ..BeamOptions::default()
            },
        });
    }
    Resolution {
        mode,
        effects: Effects { gravity, beams },
        decisions,
    }
}

/// `auto`'s stiffening of beam `b` (which does not ask for it) at the scene's `spin`, with the
/// rigid-body run's axial forces and the beam's index in them.
fn auto_stiffening(
    b: &BeamSpec,
    spin: f64,
    axial: Option<(&Result<Vec<AxialLoad>, String>, usize)>,
) -> (bool, String) {
    let Some((w1, buckling)) = weakest_bending(b) else {
        return (
            false,
            "a beam from a matrix file: no section to weigh its spin or axial force against; \
             geometric_stiffening = true turns it on"
                .into(),
        );
    };
    let none = Ok(Vec::new());
    let (run, i) = axial.unwrap_or((&none, 0));
    let force = run.as_ref().ok().and_then(|a| a.get(i).copied());
    match stiffening_reason(spin, w1, buckling, force) {
        Some(why) => (true, format!("{why} (weaker bending plane)")),
        None => (
            false,
            no_stiffening_reason(spin, w1, buckling, run, force) + " (weaker bending plane)",
        ),
    }
}
