//! Mode shapes on named coordinates: the world displacement and rotation of each scene beam's
//! shape points (its nodes, or its `shape_points`: the points of the unit's
//! `<beam>.shape.x[i]` outputs, i from 1 at flange a) and of each rigid body's origin. A
//! motion δq of the system's coordinates maps to them linearly; the map is taken by central
//! differences of the points' poses, so that it holds for every element, frame and modal
//! truncation alike (a quaternion's or a modal coordinate's meaning needs no name).

use crate::mechanics::multibody3d::body::{frame_of, FRAME};
use crate::mechanics::multibody3d::quaternion::rotation_error;
use crate::mechanics::Mechanics;
use crate::scene::Scene;
use crate::unit::effects::Effects;
use crate::unit::shape::ShapeMaps;
use nalgebra::{DVector, Matrix3, Rotation3, Vector3};

/// Where a point is and how it is turned: a planar angle, or a 3D rotation matrix.
enum Pose {
    Planar([f64; 2], f64),
    Spatial(Vector3<f64>, Matrix3<f64>),
}

/// The named points of a built system.
pub struct Coordinates {
    /// Every scene beam's shape points (all of them, whatever its `outputs` list says).
    maps: ShapeMaps,
    /// The system body of each scene rigid body.
    bodies: Vec<usize>,
    /// One name per entry of a mapped shape: `<beam>.shape.x[i]`, `.y[i]`, (`.z[i]`), then
    /// `.phi[i]` (planar) or `.rx[i]`, `.ry[i]`, `.rz[i]` (3D); `<body>.x`, … likewise.
    pub names: Vec<String>,
}

impl Coordinates {
    /// The points of `scene` (the scene `sys` was built from, with its `effects`).
    pub fn new(scene: &Scene, effects: &Effects, sys: &Mechanics) -> Coordinates {
        let mut every = scene.clone();
        for b in &mut every.beams {
            b.outputs.clear();
        }
        let maps = ShapeMaps::build(&every, effects, sys);
        let three = matches!(sys, Mechanics::Spatial(..));
        let directions: &[&str] = if three {
            &["x", "y", "z", "rx", "ry", "rz"]
        } else {
            &["x", "y", "phi"]
        };
        let mut names = Vec::new();
        let points = |g: usize| match &maps {
            ShapeMaps::Planar(m) => m[g].len(),
            ShapeMaps::Spatial(m) => m[g].len(),
        };
        for (g, b) in scene.beams.iter().enumerate() {
            for i in 1..=points(g) {
                for d in directions {
                    names.push(format!("{}.shape.{d}[{i}]", b.name));
                }
            }
        }
        let bodies: Vec<usize> = match sys {
            Mechanics::Planar(s) => {
                let first = s.bodies.len() - scene.bodies.len();
                (0..scene.bodies.len()).map(|i| first + i).collect()
            }
            Mechanics::Spatial(_, index) => index.bodies.clone(),
        };
        for b in &scene.bodies {
            for d in directions {
                names.push(format!("{}.{d}", b.name));
            }
        }
        Coordinates {
            maps,
            bodies,
            names,
        }
    }

    /// The pose of every named point at q, in the order of [`Coordinates::names`].
    fn poses(&self, sys: &Mechanics, q: &DVector<f64>) -> Vec<Pose> {
        let mut out = Vec::new();
        match (&self.maps, sys) {
            (ShapeMaps::Planar(maps), Mechanics::Planar(s)) => {
                for (body, map) in maps.iter().flatten() {
                    let (p, angle) = s.bodies[*body].point(map, s.body_coords(*body, q));
                    out.push(Pose::Planar([p[0], p[1]], angle));
                }
                for &b in &self.bodies {
                    let z = s.body_coords(b, q);
                    out.push(Pose::Planar([z[0], z[1]], z[2]));
                }
            }
            (ShapeMaps::Spatial(maps), Mechanics::Spatial(s, _)) => {
                for (body, map) in maps.iter().flatten() {
                    let z = s.body_coords(*body, q);
                    let (r, _, a) = frame_of(&z);
                    let nf = map.sp.ncols();
                    let f = z.rows(FRAME, nf);
                    let p = r + a * (map.s0 + &map.sp * f);
                    let theta = &map.sphi * f;
                    let turn =
                        Rotation3::new(Vector3::new(theta[0], theta[1], theta[2])).into_inner();
                    out.push(Pose::Spatial(p, a * turn));
                }
                for &b in &self.bodies {
                    let z = s.body_coords(b, q);
                    let (r, _, a) = frame_of(&z);
                    out.push(Pose::Spatial(r, a));
                }
            }
            _ => {}
        }
        out
    }

    /// The named displacements and rotations of the motion `dq` about q (linear in `dq`):
    /// central differences over ±h·dq/|dq|∞, h a millionth of the system's length scale.
    pub fn map(
        &self,
        sys: &Mechanics,
        q: &DVector<f64>,
        dq: &DVector<f64>,
        scale: f64,
    ) -> Vec<f64> {
        let size = dq.amax();
        if size == 0.0 {
            return vec![0.0; self.names.len()];
        }
        let h = 1e-6 * scale;
        let step = dq * (h / size);
        let plus = self.poses(sys, &(q + &step));
        let minus = self.poses(sys, &(q - &step));
        let back = size / (2.0 * h);
        let mut out = Vec::with_capacity(self.names.len());
        for (p, m) in plus.iter().zip(&minus) {
            match (p, m) {
                (Pose::Planar(a, phi_a), Pose::Planar(b, phi_b)) => {
                    out.extend([(a[0] - b[0]) * back, (a[1] - b[1]) * back]);
                    out.push((phi_a - phi_b) * back);
                }
                (Pose::Spatial(a, ra), Pose::Spatial(b, rb)) => {
                    let d = (a - b) * back;
                    // the small rotation from the minus pose to the plus one, in world axes
                    let w = rb * rotation_error(rb, ra) * back;
                    out.extend([d[0], d[1], d[2], w[0], w[1], w[2]]);
                }
                _ => {}
            }
        }
        out
    }
}
