//! A [`System3`] from a 3D scene (`dimensions = 3`) that does not reduce to a planar one: beams
//! (substructures, frozen inertia, matrix files, rigid bars), rigid bodies, joints with their
//! axes, drives, loads (constant, scaled by a law, or FMU inputs) and gravity.
//!
//! Orientation at t = 0: a beam's local x is its `axis` (default from `angle` in the x–y
//! plane), its local z the `normal` (default world z); a rigid body's frame is the world's
//! turned by `angle` about z. A joint's two frames get the same world rotation W at t = 0:
//! z along the axis of a revolute joint, x along the axis of a prismatic one, the identity for
//! weld and spherical joints (the joint convention of `multibody3d/joint.rs`); on a body that is
//! the rotation offset Aᵀ W, with A the body's rotation at t = 0.

use super::input_slots;
use crate::mechanics::beam::spatial_beam::{
    InertiaModel, SpatialBeam, SpatialBeamProps, SpatialPointMap,
};
use crate::mechanics::beam::spatial_section::SpatialSection;
use crate::mechanics::beam::FloatingFrame;
use crate::mechanics::multibody::joint::Drive;
use crate::mechanics::multibody::joint::JointKind;
use crate::mechanics::multibody::law::TimeLaw;
use crate::mechanics::multibody3d::frame::Frame3;
use crate::mechanics::multibody3d::rigid_body::RigidBody3;
use crate::mechanics::multibody3d::system::{Load3, System3};
use crate::mechanics::multibody3d::Body3;
use crate::mechanics::Effects;
use crate::scene::matrix_file::{self, MatrixFile};
use crate::scene::{self, BeamSpec, InertiaSpec, LawSpec, Scene, SectionSpec};
use nalgebra::{DMatrix, Matrix3, Vector3};

/// Where the scene's parts are in the built system.
#[derive(Debug, Clone, Default)]
pub struct SceneIndex {
    /// Per scene beam: its root frame (flange a) and tip frame (flange b), frames of the
    /// system whose rotation at t = 0 is the beam's.
    pub beam_frames: Vec<(usize, usize)>,
    /// Per scene beam: its bodies in the system (substructures from flange a to flange b; one
    /// rigid body for a rigid bar).
    pub beam_bodies: Vec<std::ops::Range<usize>>,
    /// System joint index of each scene joint.
    pub joints: Vec<usize>,
    /// System body index of each scene body.
    pub bodies: Vec<usize>,
}

/// What a scene beam or body is in the system.
enum Owner {
    /// A flexible beam (its index in `System3::beams`).
    Beam(usize),
    /// A rigid body or bar (system body index).
    Rigid(usize),
}

/// The section constants of a 3D section entry.
pub fn spatial_section(s: &SectionSpec) -> SpatialSection {
    let v = |x: Option<f64>| x.unwrap_or(0.0);
    match s.shape.as_deref() {
        Some("rectangle") => SpatialSection::rectangle(v(s.a), v(s.b)),
        Some("hollow_rectangle") => SpatialSection::hollow_rectangle(v(s.a), v(s.b), v(s.t)),
        Some("circle") => SpatialSection::circle(v(s.d)),
        Some("hollow_circle") => SpatialSection::hollow_circle(v(s.d), v(s.t)),
        _ => SpatialSection::given(v(s.area), v(s.iy), v(s.iz), v(s.torsion_constant)),
    }
}

/// Rotation (local → world) of a beam at t = 0: columns x = axis, y = z × x, z = normal.
pub fn beam_rotation(b: &BeamSpec) -> Matrix3<f64> {
    let x = b
        .axis
        .map_or(
            Vector3::new(b.angle.cos(), b.angle.sin(), 0.0),
            Vector3::from,
        )
        .normalize();
    let z = b.normal.map_or(Vector3::z(), Vector3::from).normalize();
    Matrix3::from_columns(&[x, z.cross(&x), z])
}

/// A rotation whose column `k` is the unit vector `d` (any completion).
fn along(d: Vector3<f64>, k: usize) -> Matrix3<f64> {
    let d = d.normalize();
    let helper = if d.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = helper.cross(&d).normalize();
    let e2 = d.cross(&e1);
    // right-handed with d in column k: (d, e1, e2) cyclically
    let mut cols = [Vector3::zeros(); 3];
    cols[k] = d;
    cols[(k + 1) % 3] = e1;
    cols[(k + 2) % 3] = e2;
    Matrix3::from_columns(&cols)
}

fn props(b: &BeamSpec, elements: usize, damping: bool) -> SpatialBeamProps {
    SpatialBeamProps {
        length: b.length,
        elements,
        frame: b.frame.into(),
        rho: b.material.rho,
        e: b.material.e,
        g: b.material.g.unwrap_or(b.material.e),
        section: spatial_section(&b.section),
        rayleigh_alpha: if damping { b.rayleigh.alpha } else { 0.0 },
        rayleigh_beta: if damping { b.rayleigh.beta } else { 0.0 },
        inertia: match b.inertia {
            InertiaSpec::Full => InertiaModel::Full,
            InertiaSpec::Frozen => InertiaModel::Frozen,
        },
    }
}

/// A rigid bar with the mass and inertia of the undeformed beam, frames `a` and `b`.
fn rigid_bar(b: &BeamSpec) -> RigidBody3 {
    let beam = SpatialBeam::new(&b.name, &props(b, 1, false));
    let tip = Vector3::new(b.length, 0.0, 0.0);
    RigidBody3::of_beam(
        &beam,
        vec![
            ("a".into(), Vector3::zeros(), Matrix3::identity()),
            ("b".into(), tip, Matrix3::identity()),
        ],
    )
}

/// The system of a validated 3D scene computing `effects`, and where its parts are.
pub fn from_scene(scene: &Scene, effects: &Effects) -> (System3, SceneIndex) {
    let gravity = effects.gravity.then(|| Vector3::from(scene.world.gravity));
    let mut sys = System3::new(gravity);
    let mut index = SceneIndex::default();
    // scene beam and body name → owner, and the owner's rotation at t = 0
    let mut owners: Vec<(String, Owner, Matrix3<f64>)> = Vec::new();
    for (b, fx) in scene.beams.iter().zip(&effects.beams) {
        let rot = beam_rotation(b);
        let at = Vector3::from(b.position);
        if fx.rigid {
            let body = sys.add_rigid(rigid_bar(b), at, rot);
            owners.push((b.name.clone(), Owner::Rigid(body), rot));
            index.beam_bodies.push(body..body + 1);
            continue;
        }
        let g = if let Some(text) = &b.matrix_text {
            let file = b.matrix_file.clone().unwrap_or_default();
            let m = matrix_file::parse(text, &file).expect("validated matrix file");
            let (alpha, beta) = if fx.options.damping {
                (b.rayleigh.alpha, b.rayleigh.beta)
            } else {
                (0.0, 0.0)
            };
            sys.add_beam_body(
                matrix_file_beam(&m, &b.name, b.frame.into(), alpha, beta),
                at,
                rot,
            )
        } else {
            let (elements, frames) = Scene::beam_layout(b);
            sys.add_beam(
                &b.name,
                &props(b, elements, fx.options.damping),
                frames,
                at,
                rot,
            )
        };
        for body in sys.beams[g].bodies.clone() {
            if let Body3::Beam(frame) = &mut sys.bodies[body] {
                frame.set_geometric_stiffening(fx.options.geometric_stiffening);
            }
        }
        owners.push((b.name.clone(), Owner::Beam(g), rot));
        index.beam_bodies.push(sys.beams[g].bodies.clone());
    }
    for spec in &scene.bodies {
        let rot = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), spec.angle).into_inner();
        let [ixx, iyy, izz] = spec.inertia;
        let mut frames = vec![
            ("origin".to_string(), Vector3::zeros(), Matrix3::identity()),
            (
                "com".to_string(),
                Vector3::from(spec.com),
                Matrix3::identity(),
            ),
        ];
        frames.extend(
            spec.frames
                .iter()
                .map(|(n, p)| (n.clone(), Vector3::from(p.0), Matrix3::identity())),
        );
        let body = sys.add_rigid(
            RigidBody3 {
                name: spec.name.clone(),
                mass: spec.mass,
                com: Vector3::from(spec.com),
                inertia: Matrix3::from_diagonal(&Vector3::new(ixx, iyy, izz)),
                frames,
            },
            Vector3::from(spec.position),
            rot,
        );
        index.bodies.push(body);
        owners.push((spec.name.clone(), Owner::Rigid(body), rot));
    }
    // a frame named in the scene, with world rotation `w` at t = 0
    let frame = |sys: &mut System3, name: &str, w: Matrix3<f64>| -> usize {
        if name == "world" {
            return sys.world_frame(Vector3::zeros(), w);
        }
        let (owner, part) = name.split_once('.').expect("validated frame name");
        let (_, o, rot) = owners
            .iter()
            .find(|(n, _, _)| n == owner)
            .expect("validated frame owner");
        let offset = rot.transpose() * w;
        match o {
            Owner::Beam(g) => sys.beam_frame(*g, part == "b", offset),
            Owner::Rigid(body) => {
                let Some(Body3::Rigid(r)) = sys.bodies.get(*body) else {
                    unreachable!("rigid owner")
                };
                let (s0, _) = r.frame(part).expect("validated body frame");
                let map = SpatialPointMap {
                    s0,
                    sp: DMatrix::zeros(3, 0),
                    sphi: DMatrix::zeros(3, 0),
                };
                sys.add_frame(Frame3::on_body(*body, map, offset))
            }
        }
    };
    for b in &scene.beams {
        let rot = beam_rotation(b);
        let root = frame(&mut sys, &format!("{}.a", b.name), rot);
        let tip = frame(&mut sys, &format!("{}.b", b.name), rot);
        index.beam_frames.push((root, tip));
    }
    let slots = input_slots(scene);
    let slot = |name: &str| slots.iter().position(|s| s.name == name);
    for j in &scene.joints {
        let first_rotation = if j.frames[0] == "world" {
            Matrix3::identity()
        } else {
            let owner = j.frames[0].split_once('.').map_or("", |x| x.0);
            owners
                .iter()
                .find(|(n, _, _)| n == owner)
                .map_or(Matrix3::identity(), |o| o.2)
        };
        let (kind, w) = match j.kind {
            scene::JointKind::Weld => (JointKind::Weld, Matrix3::identity()),
            scene::JointKind::Spherical => (JointKind::Spherical, Matrix3::identity()),
            scene::JointKind::Revolute => {
                let axis = j.axis.map_or(Vector3::z(), Vector3::from);
                (JointKind::Revolute, along(axis, 2))
            }
            scene::JointKind::Prismatic => {
                let (s, c) = j.axis_angle.sin_cos();
                let axis = j
                    .axis
                    .map_or(first_rotation * Vector3::new(c, s, 0.0), Vector3::from);
                (JointKind::Prismatic, along(axis, 0))
            }
        };
        let f0 = frame(&mut sys, &j.frames[0], w);
        let f1 = frame(&mut sys, &j.frames[1], w);
        let drive = Drive::of_joint(j, &slots);
        index
            .joints
            .push(sys.add_joint(&j.name, kind, f0, f1, drive));
    }
    for l in &scene.loads {
        let at = frame(&mut sys, &l.frame, Matrix3::identity());
        if !l.input {
            sys.add_load(Load3 {
                name: l.name.clone(),
                frame: at,
                force: Vector3::from(l.force),
                torque: Vector3::from(l.torque),
                law: l.scale.as_ref().map(|s| TimeLaw::from_spec(s, None)),
            });
            continue;
        }
        // an input load: one unit load per component, scaled by its input
        let input = LawSpec {
            law: "input".into(),
            value: None,
            time_constant: None,
            until: None,
            omega: None,
            ramp_time: None,
            table: None,
        };
        for (k, part) in ["fx", "fy", "fz", "tx", "ty", "tz"].iter().enumerate() {
            let mut unit = [Vector3::zeros(), Vector3::zeros()];
            unit[k / 3][k % 3] = 1.0;
            sys.add_load(Load3 {
                name: format!("{}.{part}", l.name),
                frame: at,
                force: unit[0],
                torque: unit[1],
                law: Some(TimeLaw::from_spec(
                    &input,
                    slot(&format!("{}.{part}", l.name)),
                )),
            });
        }
    }
    sys.inputs = vec![Default::default(); slots.len()];
    (sys, index)
}

/// The one-element beam of a matrix file's matrices in a floating frame of kind `frame`,
/// Rayleigh damping D = alpha m_ff + beta K_ff, frozen inertia (3D paper §6).
pub fn matrix_file_beam(
    m: &MatrixFile,
    name: &str,
    frame: FloatingFrame,
    alpha: f64,
    beta: f64,
) -> SpatialBeam {
    SpatialBeam::from_nodal_matrices(name, m.length, 1, frame, &m.mass, &m.stiffness, alpha, beta)
}
