//! The validation cases C1–C4 (CASES.md) as the study sweeps them: the formulations of each
//! case (scene variants: element count, substructures, rigid parts, modal truncation,
//! geometric stiffening), the integrator settings, the reference every formulation is compared
//! with, and the model whose effects are switched off one by one.

use super::Setting;
use fmu_beam::Scene;

/// One change of a case's scene, on the beam it names.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Edit {
    /// One floating frame of `n` elements.
    Elements(&'static str, usize),
    /// `k` substructures of `n` elements each.
    Substructures(&'static str, usize, usize),
    /// A rigid bar (without the geometric stiffness a flexible beam of the scene may carry).
    Rigid(&'static str),
    /// Keep the lowest `k` modes of each frame.
    Modes(&'static str, usize),
    /// Add the geometric stiffness of the axial force.
    Stiffening(&'static str),
    /// Without the geometric stiffness (a linear beam, whatever the shipped scene carries).
    Linear(&'static str),
    /// The deformation's frame through both ends (`frame = "pinned"`).
    Pinned(&'static str),
}

/// A formulation of a case: the case's scene with some edits.
#[derive(Debug, Clone)]
pub struct Formulation {
    pub name: &'static str,
    pub edits: Vec<Edit>,
    /// Integrator settings of this formulation, where they differ from the case's.
    pub settings: Option<Vec<Setting>>,
}

impl Formulation {
    fn new(name: &'static str, edits: &[Edit]) -> Formulation {
        Formulation {
            name,
            edits: edits.to_vec(),
            settings: None,
        }
    }

    fn only(mut self, settings: &[Setting]) -> Formulation {
        self.settings = Some(settings.to_vec());
        self
    }

    /// The case's scene with this formulation's edits.
    pub fn apply(&self, scene: &Scene) -> Scene {
        let mut s = scene.clone();
        for e in &self.edits {
            let name = match *e {
                Edit::Elements(b, ..)
                | Edit::Substructures(b, ..)
                | Edit::Rigid(b)
                | Edit::Modes(b, _)
                | Edit::Stiffening(b)
                | Edit::Linear(b)
                | Edit::Pinned(b) => b,
            };
            let b = s
                .beams
                .iter_mut()
                .find(|x| x.name == name)
                .unwrap_or_else(|| panic!("scene {} has no beam {name}", scene.name));
            match *e {
                Edit::Elements(_, n) => {
                    b.elements = Some(n);
                    b.substructures = None;
                    b.elements_per_substructure = None;
                }
                Edit::Substructures(_, k, n) => {
                    b.elements = None;
                    b.substructures = Some(k);
                    b.elements_per_substructure = Some(n);
                }
                Edit::Rigid(_) => {
                    // a rigid bar carries no geometric stiffness (the scene rules refuse both)
                    b.rigid = true;
                    b.geometric_stiffening = false;
                }
                Edit::Modes(_, k) => b.modes = Some(k),
                Edit::Stiffening(_) => b.geometric_stiffening = true,
                Edit::Linear(_) => b.geometric_stiffening = false,
                Edit::Pinned(_) => b.frame = fmu_beam::scene::FrameKind::Pinned,
            }
        }
        s
    }
}

/// What a case's errors are measured against.
#[derive(Debug, Clone)]
pub enum Reference {
    /// A closed form of the main output over time (`exact::*`), named in the report.
    Exact {
        what: &'static str,
        values: fn(&Scene, &[f64]) -> Vec<f64>,
    },
    /// A run of `formulation` at `setting`, untimed.
    Run {
        formulation: Formulation,
        setting: Setting,
    },
}

/// A second, exact yardstick for one formulation of a case (C2: the rigid pendulum).
#[derive(Debug, Clone)]
pub struct Check {
    pub formulation: &'static str,
    pub what: &'static str,
    pub values: fn(&Scene, &[f64]) -> Vec<f64>,
}

/// A validation case as the study runs it.
#[derive(Debug, Clone)]
pub struct Case {
    pub name: &'static str,
    pub title: &'static str,
    pub scene: &'static str,
    /// Outputs whose error is measured; the first is the main one (the plot, the effects).
    pub outputs: &'static [&'static str],
    pub stop: f64,
    pub comm: f64,
    pub formulations: Vec<Formulation>,
    pub settings: Vec<Setting>,
    pub reference: Reference,
    pub check: Option<Check>,
    /// The models whose effects are switched off in turn: (formulation, integrator setting).
    pub effects: Vec<(&'static str, Setting)>,
    /// What the report says about the choices (shortened runs, fewer settings).
    pub note: &'static str,
}

impl Case {
    pub fn formulation(&self, name: &str) -> &Formulation {
        self.formulations
            .iter()
            .find(|f| f.name == name)
            .unwrap_or_else(|| panic!("{}: no formulation {name}", self.name))
    }
}

use Edit::*;
use Setting::{FixedStep as H, Tolerance as Tol};

/// The cases of `make bench`.
pub fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "C1",
            title: "clamped beam, free vibration from a static tip displacement (2 s)",
            scene: "cantilever_free_vibration.toml",
            outputs: &["beam.tip.deflection"],
            stop: 2.0,
            comm: 1e-2,
            formulations: vec![
                Formulation::new("5 elements", &[Elements("beam", 5)]),
                Formulation::new("10 elements (paper)", &[Elements("beam", 10)]),
                Formulation::new("20 elements", &[Elements("beam", 20)]),
                Formulation::new("40 elements", &[Elements("beam", 40)]),
                Formulation::new(
                    "20 elements, 2 modes",
                    &[Elements("beam", 20), Modes("beam", 2)],
                ),
                Formulation::new(
                    "20 elements, 4 modes",
                    &[Elements("beam", 20), Modes("beam", 4)],
                ),
                Formulation::new(
                    "20 elements, 8 modes",
                    &[Elements("beam", 20), Modes("beam", 8)],
                ),
            ],
            settings: vec![
                H(4e-3),
                H(2e-3),
                H(1e-3),
                H(5e-4),
                H(2.5e-4),
                H(1.25e-4),
                H(6.25e-5),
                Tol(1e-4),
                Tol(1e-5),
                Tol(1e-6),
                Tol(1e-7),
                Tol(1e-8),
            ],
            reference: Reference::Exact {
                what: "the exact tip deflection of the continuous Euler–Bernoulli beam released \
                       from its static tip-load shape: δ Σₙ 12/(βₙL)⁴ cos(ωₙt), 4000 modes \
                       (`exact::clamped_beam_tip`); it holds every element count and truncation \
                       to the same yardstick, so the curves level off at their discretization \
                       error",
                values: super::exact::clamped_beam_tip,
            },
            check: None,
            effects: vec![("10 elements (paper)", H(5e-4))],
            note: "Below a fixed step of ≈ 2.5e-4 s an element count reaches its own floor \
                   (the FE frequencies lie above the exact ones, the integrator's period \
                   elongation below: at 2.5e-4 s they cancel for 10 elements, which is why its \
                   error rises again at smaller steps). Error control's tolerance scales with \
                   the beam length, 200 x the tip deflection, so it reaches ≈ 1e-3 only at \
                   tolerance 1e-6, at about 5 x the time of a fixed step of the same error.",
        },
        Case {
            name: "C2",
            title: "flexible pendulum released from horizontal (1 s)",
            scene: "flexible_pendulum.toml",
            outputs: &["hinge.angle", "beam.tip.deflection"],
            stop: 1.0,
            comm: 1e-2,
            formulations: vec![
                Formulation::new("single frame, 10 elements (paper)", &[Elements("beam", 10)]),
                Formulation::new("single frame, 20 elements", &[Elements("beam", 20)]),
                Formulation::new(
                    "5 x 2 substructures (paper)",
                    &[Substructures("beam", 5, 2)],
                ),
                Formulation::new("10 x 2 substructures", &[Substructures("beam", 10, 2)]),
                Formulation::new("rigid", &[Rigid("beam")]),
            ],
            settings: vec![
                H(1e-2),
                H(3e-3),
                H(1e-3),
                H(3e-4),
                Tol(1e-4),
                Tol(1e-5),
                Tol(1e-6),
                Tol(1e-7),
            ],
            reference: Reference::Run {
                formulation: Formulation::new(
                    "20 x 2 substructures",
                    &[Substructures("beam", 20, 2)],
                ),
                setting: H(2.5e-5),
            },
            check: Some(Check {
                formulation: "rigid",
                what:
                    "the exact rigid compound pendulum, α'' = −(3g/2L) cos α (RK4, step 1e-5 s), \
                       column `error vs exact rigid`; its period 4K(sin 45°)/√(3g/2L)",
                values: super::exact::rigid_pendulum_angle,
            }),
            effects: vec![("5 x 2 substructures (paper)", Tol(1e-6))],
            note: "",
        },
        Case {
            name: "C3",
            title: "elastic slider-crank, torque-driven (1.6 s)",
            scene: "slider_crank.toml",
            outputs: &["slider.position", "rod.mid.deflection"],
            stop: 1.6,
            comm: 1e-2,
            formulations: vec![
                Formulation::new(
                    "flexible crank 3, rod 8 (paper)",
                    &[Elements("crank", 3), Elements("rod", 8)],
                ),
                Formulation::new(
                    "flexible crank 3, rod 4",
                    &[Elements("crank", 3), Elements("rod", 4)],
                ),
                Formulation::new(
                    "rigid crank, rod 8 (paper)",
                    &[Rigid("crank"), Elements("rod", 8)],
                ),
                Formulation::new(
                    "rigid crank, rod 8, 4 modes",
                    &[Rigid("crank"), Elements("rod", 8), Modes("rod", 4)],
                ),
            ],
            settings: vec![
                H(1e-2),
                H(3e-3),
                H(1e-3),
                H(3e-4),
                Tol(1e-4),
                Tol(1e-5),
                Tol(1e-6),
            ],
            reference: Reference::Run {
                formulation: Formulation::new(
                    "flexible crank 6, rod 16",
                    &[Elements("crank", 6), Elements("rod", 16)],
                ),
                setting: H(2.5e-5),
            },
            check: None,
            effects: vec![("flexible crank 3, rod 8 (paper)", H(1e-3))],
            note: "",
        },
        Case {
            name: "C4",
            title: "spin-up to Ω = 10 rad/s in 15 s, tip deflection in the hub frame (20 s)",
            scene: "spin_up_omega10.toml",
            outputs: &["beam.tip.deflection"],
            stop: 20.0,
            comm: 1e-1,
            formulations: vec![
                Formulation::new(
                    "10 x 1 substructures (paper)",
                    &[Substructures("beam", 10, 1)],
                ),
                // error control takes ≈ 10 s per run here: fixed steps only
                Formulation::new("20 x 1 substructures", &[Substructures("beam", 20, 1)])
                    .only(&[H(1e-2), H(3e-3)]),
                Formulation::new(
                    "single frame, 10 elements + stiffening",
                    &[Elements("beam", 10), Stiffening("beam")],
                ),
                Formulation::new(
                    "single frame, 20 elements + stiffening",
                    &[Elements("beam", 20), Stiffening("beam")],
                ),
                Formulation::new(
                    "single frame, 10 elements, linear",
                    &[Elements("beam", 10), Linear("beam")],
                ),
            ],
            settings: vec![H(1e-2), H(3e-3), H(1e-3), Tol(1e-4), Tol(1e-5), Tol(1e-6)],
            reference: Reference::Run {
                formulation: Formulation::new(
                    "40 x 1 substructures",
                    &[Substructures("beam", 40, 1)],
                ),
                setting: H(1e-3),
            },
            check: None,
            effects: vec![
                ("10 x 1 substructures (paper)", H(1e-2)),
                ("single frame, 10 elements + stiffening", H(1e-2)),
            ],
            note: "The slowest case: the full 20 s and 3 repeats, but 20 x 1 substructures run \
                   at fixed steps 1e-2 and 3e-3 s only (error control takes ≈ 10 s a run there), \
                   and the reference at a fixed step of 1e-3 s (40 substructures, ≈ 16 s). The \
                   linear single frame runs away at 6.4 s at every setting (CASES.md: it must); \
                   its rows show the engine's message.",
        },
    ]
}
