//! Shape outputs: where a unit's parts are, for a visualization tool or `fmu-harness animate`.
//!
//! Each beam offers the world positions of points of its deformed centre line
//! (`<beam>.shape.x[i]`, `.y[i]`, 3D `.z[i]`, i = 1 at flange a … n at flange b; by default its
//! nodes, or `shape_points = n` points equally spaced along the undeformed axis) and the unit
//! world direction its deflection outputs are measured from (`<beam>.axis.x/.y/.z`: the root
//! frame's axis, or the chord for a planar pinned frame), so that a viewer can magnify the
//! deformation without the rigid motion. The outputs are computed from the state when read
//! ([`ShapeMaps`] holds the point maps, built once per model): a step that nobody reads them
//! after costs nothing more.

use crate::mechanics::beam::planar_beam::PointMap;
use crate::mechanics::beam::spatial_beam::SpatialPointMap;
use crate::mechanics::multibody::body::Body;
use crate::mechanics::multibody3d::Body3;
use crate::mechanics::Mechanics;
use crate::scene::{BeamSpec, Scene, SHAPE_OUTPUT};
use crate::unit::effects::Effects;
use nalgebra::{DMatrix, DVector, Vector2, Vector3};

/// Distances from flange a, along the undeformed axis, of the shape points of a beam (rigid:
/// its two ends unless the scene asks for more); empty when the beam offers no shape.
pub fn stations(beam: &BeamSpec, rigid: bool) -> Vec<f64> {
    if !beam.outputs.is_empty() && !beam.outputs.iter().any(|o| o == SHAPE_OUTPUT) {
        return Vec::new();
    }
    let n = match beam.shape_points {
        Some(n) => n,
        None if rigid => 2,
        None => {
            let (elements, k) = Scene::beam_layout(beam);
            elements * k + 1
        }
    };
    if n < 2 {
        return Vec::new();
    }
    (0..n)
        .map(|i| beam.length * i as f64 / (n - 1) as f64)
        .collect()
}

/// The material points of the shape outputs, per scene beam: (system body, its point map).
#[derive(Debug, Clone)]
pub enum ShapeMaps {
    Planar(Vec<Vec<(usize, PointMap)>>),
    Spatial(Vec<Vec<(usize, SpatialPointMap)>>),
}

impl ShapeMaps {
    /// The maps of every scene beam's shape points in the built system.
    pub fn build(scene: &Scene, effects: &Effects, system: &Mechanics) -> ShapeMaps {
        // the body of a station x among equal parts of `part` length, and x on that body
        let locate = |x: f64, first: usize, parts: usize, part: f64| {
            let i = ((x / part).floor() as usize).min(parts - 1);
            (first + i, (x - i as f64 * part).clamp(0.0, part))
        };
        match system {
            Mechanics::Planar(sys) => ShapeMaps::Planar(
                scene
                    .beams
                    .iter()
                    .zip(&effects.beams)
                    .zip(&sys.beams)
                    .map(|((b, fx), grp)| {
                        let parts = grp.bodies.len();
                        let part = grp.length / parts as f64;
                        stations(b, fx.rigid)
                            .into_iter()
                            .map(|x| {
                                let (body, at) = locate(x, grp.bodies.start, parts, part);
                                let map = match &sys.bodies[body] {
                                    Body::Beam(beam) => beam.point_map(at),
                                    Body::Rigid(_) => PointMap {
                                        s0: Vector2::new(at, 0.0),
                                        sp: DMatrix::zeros(2, 0),
                                        sphi: DVector::zeros(0),
                                    },
                                };
                                (body, map)
                            })
                            .collect()
                    })
                    .collect(),
            ),
            Mechanics::Spatial(sys, index) => ShapeMaps::Spatial(
                scene
                    .beams
                    .iter()
                    .zip(&effects.beams)
                    .zip(&index.beam_bodies)
                    .map(|((b, fx), bodies)| {
                        let parts = bodies.len();
                        let part = b.length / parts as f64;
                        stations(b, fx.rigid)
                            .into_iter()
                            .map(|x| {
                                let (body, at) = locate(x, bodies.start, parts, part);
                                let map = match &sys.bodies[body] {
                                    Body3::Beam(beam) => beam.point_map(at),
                                    Body3::Rigid(_) => SpatialPointMap {
                                        s0: Vector3::new(at, 0.0, 0.0),
                                        sp: DMatrix::zeros(3, 0),
                                        sphi: DMatrix::zeros(3, 0),
                                    },
                                };
                                (body, map)
                            })
                            .collect()
                    })
                    .collect(),
            ),
        }
    }

    /// World position of shape point `k` (from 0) of scene beam `g` at coordinates q (a
    /// planar system's z is 0).
    pub fn point(&self, system: &Mechanics, q: &DVector<f64>, g: usize, k: usize) -> [f64; 3] {
        match (self, system) {
            (ShapeMaps::Planar(maps), Mechanics::Planar(sys)) => {
                let (body, map) = &maps[g][k];
                let p = sys.bodies[*body].point(map, sys.body_coords(*body, q)).0;
                [p[0], p[1], 0.0]
            }
            (ShapeMaps::Spatial(maps), Mechanics::Spatial(sys, _)) => {
                let (body, map) = &maps[g][k];
                let z = sys.body_coords(*body, q);
                let (r, _, a) = crate::mechanics::multibody3d::body::frame_of(&z);
                let f = z.rows(crate::mechanics::multibody3d::body::FRAME, map.sp.ncols());
                let p = r + a * (map.s0 + &map.sp * f);
                [p[0], p[1], p[2]]
            }
            _ => unreachable!("shape maps are built from the same system"),
        }
    }
}

/// The unit world direction from which the deflections of scene beam `g` are measured: the
/// root frame's axis (the chord to flange b for a planar pinned frame).
pub fn axis(system: &Mechanics, q: &DVector<f64>, g: usize) -> [f64; 3] {
    match system {
        Mechanics::Planar(sys) => {
            let a = sys.beam_axis(g, q).1;
            [a[0], a[1], 0.0]
        }
        Mechanics::Spatial(sys, index) => {
            let a = sys.frame_pose(index.beam_frames[g].0, q).1;
            [a[(0, 0)], a[(1, 0)], a[(2, 0)]]
        }
    }
}
