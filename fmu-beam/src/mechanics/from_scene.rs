//! The mechanics' own option types from the scene format's: a [`FloatingFrame`] from a
//! [`FrameKind`], a [`Section`] from a [`SectionSpec`], a [`PlanarBeam`] from a [`BeamSpec`].
//! The element layer (`beam/`) knows nothing of the scene file; the systems' builders
//! (`multibody/system/build.rs`, `multibody3d/build.rs`) go through these.

use super::beam::planar_beam::{BeamOptions, PlanarBeam};
use super::beam::section::Section;
use super::beam::FloatingFrame;
use crate::scene::{BeamSpec, FrameKind, Scene, SectionSpec};

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
