//! The one door from the scene format into the mechanics: the systems of a validated scene
//! ([`Mechanics::build`]; the planar one in `planar.rs`, the spatial one in `spatial.rs`) and
//! the mechanics' own types from the format's (a [`FloatingFrame`] from a [`FrameKind`], a
//! [`JointKind`] and a [`DriveKind`] from theirs, a [`Section`] from a [`SectionSpec`], a
//! [`PlanarBeam`] from a [`BeamSpec`], a [`TimeLaw`] from a [`LawSpec`], the FMU inputs a scene
//! offers). Nothing else in `mechanics/` reads the scene format (`fmu-beam/tests/layers.rs`).

pub(crate) mod planar;
pub(crate) mod spatial;

pub use spatial::{matrix_file_beam, SceneIndex};

use super::any_system::Mechanics;
use super::beam::planar_beam::{BeamOptions, PlanarBeam};
use super::beam::section::Section;
use super::beam::FloatingFrame;
use super::multibody::joint::{Drive, DriveKind, JointKind};
use super::multibody::law::{Law, TimeLaw};
use super::multibody::System;
use super::Effects;
use crate::scene::{self, BeamSpec, FrameKind, JointSpec, LawSpec, Scene, SectionSpec};

impl Mechanics {
    /// The system of a validated scene computing `effects` (resolved from the same scene): the
    /// planar one where the scene's motion stays in a plane ([`Scene::planar_reduction`]).
    pub fn build(scene: &Scene, effects: &Effects) -> Mechanics {
        match scene.planar_reduction() {
            Ok(planar) => Mechanics::Planar(System::build(&planar, effects)),
            Err(_) => {
                let (sys, index) = spatial::from_scene(scene, effects);
                Mechanics::Spatial(sys, index)
            }
        }
    }
}

impl From<scene::JointKind> for JointKind {
    fn from(k: scene::JointKind) -> JointKind {
        match k {
            scene::JointKind::Weld => JointKind::Weld,
            scene::JointKind::Revolute => JointKind::Revolute,
            scene::JointKind::Prismatic => JointKind::Prismatic,
            scene::JointKind::Spherical => JointKind::Spherical,
        }
    }
}

impl From<scene::DriveKind> for DriveKind {
    fn from(k: scene::DriveKind) -> DriveKind {
        match k {
            scene::DriveKind::Motion => DriveKind::Motion,
            scene::DriveKind::Effort => DriveKind::Effort,
        }
    }
}

impl TimeLaw {
    /// Builds a validated law; `slot` is the input slot for law "input".
    pub fn from_spec(spec: &LawSpec, slot: Option<usize>) -> TimeLaw {
        let v = spec.value.unwrap_or(0.0);
        let law = match spec.law.as_str() {
            "exponential" => Law::Exponential {
                value: v,
                tau: spec.time_constant.unwrap_or(1.0),
            },
            "spin_up" => Law::SpinUp {
                omega: spec.omega.unwrap_or(0.0),
                ramp: spec.ramp_time.unwrap_or(1.0),
            },
            "table" => Law::Table(spec.table.clone().unwrap_or_default()),
            "input" => Law::Input(slot.unwrap_or(0)),
            _ => Law::Constant(v),
        };
        TimeLaw::new(law, spec.until)
    }
}

impl Drive {
    /// The drive of a scene joint, if it has one; an `input` law reads the joint's input slot.
    pub fn of_joint(j: &JointSpec, slots: &[InputSlot]) -> Option<Drive> {
        j.drive.as_ref().map(|d| Drive {
            kind: d.kind.into(),
            law: TimeLaw::from_spec(
                &d.law,
                slots
                    .iter()
                    .position(|s| s.name.starts_with(&format!("{}.drive.", j.name))),
            ),
        })
    }
}

/// An FMU input of the scene, in slot order.
#[derive(Debug, Clone, PartialEq)]
pub struct InputSlot {
    pub name: String,
    pub unit: &'static str,
    pub start: f64,
    pub description: String,
}

/// The FMU inputs a scene offers: drives with law "input", then loads marked `input`.
pub fn input_slots(scene: &Scene) -> Vec<InputSlot> {
    let mut slots = Vec::new();
    for j in &scene.joints {
        if let Some(d) = j.drive.as_ref().filter(|d| d.law.law == "input") {
            let (what, unit) = match (j.kind, d.kind) {
                (scene::JointKind::Prismatic, scene::DriveKind::Motion) => ("position", "m"),
                (scene::JointKind::Prismatic, scene::DriveKind::Effort) => ("force", "N"),
                (_, scene::DriveKind::Motion) => ("angle", "rad"),
                (_, scene::DriveKind::Effort) => ("torque", "N.m"),
            };
            slots.push(InputSlot {
                name: format!("{}.drive.{what}", j.name),
                unit,
                start: d.law.value.unwrap_or(0.0),
                description: format!("Drive of joint {}: prescribed {what}", j.name),
            });
        }
    }
    for l in scene.loads.iter().filter(|l| l.input) {
        let planar = [
            ("fx", "N", l.force[0]),
            ("fy", "N", l.force[1]),
            ("torque", "N.m", l.torque[2]),
        ];
        let spatial = [
            ("fx", "N", l.force[0]),
            ("fy", "N", l.force[1]),
            ("fz", "N", l.force[2]),
            ("tx", "N.m", l.torque[0]),
            ("ty", "N.m", l.torque[1]),
            ("tz", "N.m", l.torque[2]),
        ];
        let parts: &[(&str, &'static str, f64)] = if scene.is_3d() { &spatial } else { &planar };
        for &(what, unit, start) in parts {
            slots.push(InputSlot {
                name: format!("{}.{what}", l.name),
                unit,
                start,
                description: format!("Load {} on {}: {what} (world axes)", l.name, l.frame),
            });
        }
    }
    slots
}

impl From<FrameKind> for FloatingFrame {
    fn from(k: FrameKind) -> FloatingFrame {
        match k {
            FrameKind::Tangent => FloatingFrame::Tangent,
            FrameKind::Pinned => FloatingFrame::Pinned,
        }
    }
}

impl Section {
    /// Resolves a validated section spec; `a` is the in-plane height, `b` the width.
    pub fn from_spec(s: &SectionSpec) -> Section {
        let g = |v: Option<f64>| v.unwrap_or(0.0);
        match s.shape.as_deref() {
            Some("rectangle") => Section::rectangle(g(s.a), g(s.b)),
            Some("hollow_rectangle") => Section::hollow_rectangle(g(s.a), g(s.b), g(s.t)),
            Some("circle") => Section::circle(g(s.d)),
            Some("hollow_circle") => Section::hollow_circle(g(s.d), g(s.t)),
            _ => Section {
                area: g(s.area),
                second_moment: g(s.second_moment),
            },
        }
    }
}

impl PlanarBeam {
    /// Builds the beam from its (validated) scene entry.
    /// (Every term on; geometric stiffening and modal truncation as the scene entry says.)
    pub fn from_spec(spec: &BeamSpec) -> PlanarBeam {
        let options = BeamOptions {
            geometric_stiffening: spec.geometric_stiffening,
            modes: spec.modes,
            ..BeamOptions::default()
        };
        PlanarBeam::part_of(spec, &spec.name, spec.length, options)
    }

    /// One floating frame of a (validated) scene beam: the whole beam, or one of its
    /// substructures, named `name`, of length `length`, computing the terms of `options`.
    pub fn part_of(spec: &BeamSpec, name: &str, length: f64, options: BeamOptions) -> PlanarBeam {
        PlanarBeam::with_options(
            name,
            length,
            Scene::beam_layout(spec).0,
            spec.frame.into(),
            spec.material.rho,
            spec.material.e,
            Section::from_spec(&spec.section),
            spec.rayleigh.alpha,
            spec.rayleigh.beta,
            options,
        )
    }
}
