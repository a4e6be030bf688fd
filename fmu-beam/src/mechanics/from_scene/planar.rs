//! The planar [`System`] of a validated scene: its beams (whole, substructured, rigid), rigid
//! bodies, frames, joints with their drives, loads and gravity, computing the resolved effects;
//! and where the scene places its bodies at t = 0 (with each beam's initial tip deflection).

use super::input_slots;
use crate::mechanics::beam::planar_beam::{rot, PlanarBeam, PointMap};
use crate::mechanics::beam::section::Section;
use crate::mechanics::multibody::body::Body;
use crate::mechanics::multibody::frame::Frame;
use crate::mechanics::multibody::joint::{Drive, Joint, JointKind};
use crate::mechanics::multibody::law::{InputValue, TimeLaw};
use crate::mechanics::multibody::rigid_body::RigidBody;
use crate::mechanics::multibody::system::{BeamGroup, Load, PlanarBeamData};
use crate::mechanics::multibody::System;
use crate::mechanics::Effects;
use crate::scene::{FrameKind, Scene};
use nalgebra::{DMatrix, DVector, Vector2};

impl System {
    /// Assembles the system of a validated scene computing the given effects (resolved from
    /// this scene, or from the packaged scene of which this one has other parameter values).
    pub fn build(scene: &Scene, effects: &Effects) -> System {
        let mut bodies = Vec::new();
        let mut beams = Vec::new();
        for (spec, fx) in scene.beams.iter().zip(&effects.beams) {
            let (_, k) = Scene::beam_layout(spec);
            let k = if fx.rigid { 1 } else { k };
            let first = bodies.len();
            let section = Section::from_spec(&spec.section);
            if fx.rigid {
                let mass = spec.material.rho * section.area * spec.length;
                bodies.push(Body::Rigid(RigidBody {
                    name: spec.name.clone(),
                    mass,
                    com: Vector2::new(spec.length / 2.0, 0.0),
                    inertia: mass * spec.length * spec.length / 12.0,
                    frames: vec![
                        ("a".into(), Vector2::zeros()),
                        ("b".into(), Vector2::new(spec.length, 0.0)),
                    ],
                    counts: Default::default(),
                    turn: Default::default(),
                }));
            } else {
                let ls = spec.length / k as f64;
                for i in 0..k {
                    let name = if k == 1 {
                        spec.name.clone()
                    } else {
                        format!("{}[{i}]", spec.name)
                    };
                    let b = PlanarBeam::part_of(spec, &name, ls, fx.options);
                    bodies.push(Body::Beam(Box::new(b)));
                }
            }
            let range = first..bodies.len();
            // mid-span: x = L/2 lies in substructure floor(k/2) (at its flange a when k is even)
            let idx = (range.len() / 2).min(range.len() - 1);
            let mid_body = first + idx;
            let local_x = spec.length / 2.0 - idx as f64 * spec.length / range.len() as f64;
            let mid_map = match &bodies[mid_body] {
                Body::Beam(b) => b.point_map(local_x),
                Body::Rigid(_) => PointMap {
                    s0: Vector2::new(local_x, 0.0),
                    sp: DMatrix::zeros(2, 0),
                    sphi: DVector::zeros(0),
                },
            };
            beams.push(BeamGroup {
                name: spec.name.clone(),
                bodies: range,
                length: spec.length,
                more: PlanarBeamData {
                    pinned: spec.frame == FrameKind::Pinned,
                    section,
                    mid: (mid_body, mid_map),
                    initial_tip: spec.initial.tip_displacement,
                },
            });
        }
        for spec in &scene.bodies {
            bodies.push(Body::Rigid(RigidBody {
                name: spec.name.clone(),
                mass: spec.mass,
                com: Vector2::new(spec.com[0], spec.com[1]),
                inertia: spec.inertia[2],
                frames: spec
                    .frames
                    .iter()
                    .map(|(n, p)| (n.clone(), Vector2::new(p.0[0], p.0[1])))
                    .collect(),
                counts: Default::default(),
                turn: Default::default(),
            }));
        }
        let mut offsets = Vec::with_capacity(bodies.len());
        let mut n = 0;
        for b in &bodies {
            offsets.push(n);
            n += b.ndof();
        }
        let mut sys = System {
            bodies,
            offsets,
            frames: Vec::new(),
            joints: Vec::new(),
            loads: Vec::new(),
            beams,
            gravity: effects
                .gravity
                .then(|| Vector2::new(scene.world.gravity[0], scene.world.gravity[1])),
            effects: effects.clone(),
            inputs: input_slots(scene)
                .iter()
                .map(|s| InputValue {
                    value: s.start,
                    ..Default::default()
                })
                .collect(),
            placed: DVector::zeros(0),
            n,
            m: 0,
        };
        sys.placed = placed_coordinates(&sys, scene);
        let q0 = sys.placed.clone();
        // substructure welds: flange b of each frame to flange a of the next
        let mut internal = Vec::new();
        for g in sys.beams.clone() {
            for i in g.bodies.start..g.bodies.end.saturating_sub(1) {
                if let (Body::Beam(b0), Body::Beam(b1)) = (&sys.bodies[i], &sys.bodies[i + 1]) {
                    let (m0, m1) = (b0.flange_b.clone(), b1.flange_a.clone());
                    let f0 = sys.add_frame(Frame::OnBody { body: i, map: m0 });
                    let f1 = sys.add_frame(Frame::OnBody {
                        body: i + 1,
                        map: m1,
                    });
                    internal.push((
                        format!("{}.substructure{}", g.name, i + 1 - g.bodies.start),
                        f0,
                        f1,
                    ));
                }
            }
        }
        let mut row = 0;
        for (name, f0, f1) in internal {
            let offset = sys.relative_angle(f0, f1, &q0);
            sys.joints.push(Joint {
                name,
                kind: JointKind::Weld,
                frames: [f0, f1],
                axis_angle: 0.0,
                angle_offset: offset,
                drive: None,
                row,
            });
            row += 3;
        }
        let slots = input_slots(scene);
        for j in &scene.joints {
            let f0 = sys.frame_by_name(&j.frames[0]);
            let f1 = sys.frame_by_name(&j.frames[1]);
            let drive = Drive::of_joint(j, &slots);
            let kind = JointKind::from(j.kind);
            let offset = sys.relative_angle(f0, f1, &q0);
            let count = Joint::rows_count(kind, drive.as_ref());
            sys.joints.push(Joint {
                name: j.name.clone(),
                kind,
                frames: [f0, f1],
                axis_angle: j.axis_angle,
                angle_offset: offset,
                drive,
                row,
            });
            row += count;
        }
        sys.m = row;
        for l in &scene.loads {
            let frame = sys.frame_by_name(&l.frame);
            let inputs = l
                .input
                .then(|| {
                    slots
                        .iter()
                        .position(|s| s.name == format!("{}.fx", l.name))
                })
                .flatten();
            sys.loads.push(Load {
                name: l.name.clone(),
                frame,
                force: Vector2::new(l.force[0], l.force[1]),
                torque: l.torque[2],
                inputs,
                scale: l.scale.as_ref().map(|s| TimeLaw::from_spec(s, None)),
            });
        }
        sys
    }

    /// Resolves a (validated) frame name of the scene.
    fn frame_by_name(&mut self, name: &str) -> usize {
        if name == "world" {
            return self.add_frame(Frame::World {
                position: Vector2::zeros(),
                angle: 0.0,
            });
        }
        let (owner, f) = name.split_once('.').unwrap_or((name, "origin"));
        let frame = if let Some(g) = self.beams.iter().find(|g| g.name == owner) {
            let body = if f == "a" {
                g.bodies.start
            } else {
                g.bodies.end - 1
            };
            let map = match &self.bodies[body] {
                Body::Beam(b) if f == "a" => b.flange_a.clone(),
                Body::Beam(b) => b.flange_b.clone(),
                Body::Rigid(r) => r.frame_map(f).expect("validated frame"),
            };
            Frame::OnBody { body, map }
        } else {
            let body = self
                .bodies
                .iter()
                .position(|b| b.name() == owner)
                .expect("validated body");
            let map = match &self.bodies[body] {
                Body::Rigid(r) => r.frame_map(f).expect("validated frame"),
                Body::Beam(b) => b.flange_a.clone(),
            };
            Frame::OnBody { body, map }
        };
        self.add_frame(frame)
    }
}

/// Coordinates of the scene's placement, before assembly: frames where the scene puts
/// them, substructures in a row along their beam, undeformed.
fn placed_coordinates(sys: &System, scene: &Scene) -> DVector<f64> {
    let mut q = DVector::zeros(sys.n);
    for (g, spec) in sys.beams.iter().zip(&scene.beams) {
        let k = g.bodies.len();
        let (ar, _) = rot(spec.angle);
        for (i, body) in g.bodies.clone().enumerate() {
            let o = sys.offsets[body];
            let p = Vector2::new(spec.position[0], spec.position[1])
                + ar * Vector2::new(i as f64 * spec.length / k as f64, 0.0);
            q[o] = p[0];
            q[o + 1] = p[1];
            q[o + 2] = spec.angle;
        }
    }
    let first_rigid = sys.beams.last().map_or(0, |g| g.bodies.end);
    for (i, spec) in scene.bodies.iter().enumerate() {
        let o = sys.offsets[first_rigid + i];
        q[o] = spec.position[0];
        q[o + 1] = spec.position[1];
        q[o + 2] = spec.angle;
    }
    q
}
