//! The assembled spatial system: bodies stacked in q (z = [R, p, q_f] each), the quaternion
//! norm rows first in g (one per body), then the joint rows. Built in code (the scene format
//! for 3D comes later): add bodies, frames, joints and loads, then integrate it with
//! [`crate::integrator`] through [`Equations`].
//!
//! Over 600 lines: the spatial system's residual, tangents, constraint rows and energy in one `impl
//! System3` whose methods share private helpers (its builder is `build.rs`); a split like the
//! planar `system/` is left for later.

use super::body::{Body3, FRAME};
use super::frame::Frame3;
use super::joint::{wrap, Joint3, Pose};
use super::quaternion::from_rotation;
use super::rigid_body::RigidBody3;
use crate::error::EngineError;
use crate::mechanics::beam::spatial_beam::{SpatialBeam, SpatialBeamProps};
use crate::mechanics::multibody::equations::{CoordinateKind, Equations, Point};
use crate::mechanics::multibody::joint::Drive;
use crate::mechanics::multibody::joint::JointKind;
use crate::mechanics::multibody::law::{InputValue, TimeLaw};
use crate::mechanics::multibody::sparsity::{BlockDiagonal, JacobianRows};
use crate::mechanics::multibody::system::BeamGroup;
use crate::mechanics::multibody::system::Energy;
use nalgebra::{DMatrix, DVector, DVectorView, Matrix3, Vector3};
use std::ops::Range;

/// Central-difference step of the constraint Jacobian and the joint and load gradients.
const EPS_CENTRAL: f64 = 1e-6;
/// Forward-difference step (relative) of the body tangents.
const EPS_FORWARD: f64 = 1e-7;
/// Step of the second directional difference of g along q' (times max |q'|).
const EPS_BIAS: f64 = 1e-3;

/// One column of a frame's Jacobian: (coordinate, ∂x/∂q_k, ∂θ/∂q_k).
pub type FrameColumn = (usize, Vector3<f64>, Vector3<f64>);

/// A world force and torque on a frame, scaled by an optional time law (1 without one).
#[derive(Debug, Clone)]
pub struct Load3 {
    /// The scene load's name; for an input load, one unit load per component, `<load>.fx` …
    /// `<load>.tz`.
    pub name: String,
    /// Index of the frame it acts on in the system's frames.
    pub frame: usize,
    /// Force, world axes (N).
    pub force: Vector3<f64>,
    /// Torque, world axes (N·m).
    pub torque: Vector3<f64>,
    /// The factor on force and torque: the scene's `scale`, or an input law (an input load).
    pub law: Option<TimeLaw>,
}

/// The assembled spatial system: bodies stacked in q (z = [R, p, q_f] each), frames, joints
/// and loads; the quaternions' norm rows come before the joints' rows in g(q).
#[derive(Debug, Clone)]
pub struct System3 {
    /// The bodies (beam substructures and rigid bodies), in the order of their coordinates in q.
    pub bodies: Vec<Body3>,
    /// Index of each body's first coordinate in q.
    pub offsets: Vec<usize>,
    /// The frames that joints and loads act on: fixed in the world or on bodies.
    pub frames: Vec<Frame3>,
    /// The joints, each with its first row among the joint rows.
    pub joints: Vec<Joint3>,
    /// The point loads.
    pub loads: Vec<Load3>,
    /// One group per beam, in the order added: its bodies (substructures) and length.
    pub beams: Vec<BeamGroup>,
    /// The gravity field (m/s², world axes), `None` when the effect is off (its terms are not
    /// evaluated).
    pub gravity: Option<Vector3<f64>>,
    /// Current values of the FMU inputs, by input slot.
    pub inputs: Vec<InputValue>,
    /// Coordinates of the placement (before assembly).
    initial: Vec<f64>,
    /// Joint rows (the norm rows come before them).
    joint_rows: usize,
}

impl System3 {
    /// An empty system in a gravity field (`None`: its terms are not evaluated).
    pub fn new(gravity: Option<Vector3<f64>>) -> System3 {
        System3 {
            bodies: Vec::new(),
            offsets: Vec::new(),
            frames: Vec::new(),
            joints: Vec::new(),
            loads: Vec::new(),
            beams: Vec::new(),
            gravity,
            inputs: Vec::new(),
            initial: Vec::new(),
            joint_rows: 0,
        }
    }

    fn add_body(&mut self, body: Body3, position: Vector3<f64>, rotation: &Matrix3<f64>) -> usize {
        self.offsets.push(self.initial.len());
        self.initial.extend(position.iter());
        self.initial.extend(from_rotation(rotation).iter());
        self.initial.extend(std::iter::repeat_n(0.0, body.nflex()));
        self.bodies.push(body);
        self.bodies.len() - 1
    }

    /// Adds a rigid body with its frame at `position`, rotated by `rotation` (body → world).
    pub fn add_rigid(
        &mut self,
        body: RigidBody3,
        position: Vector3<f64>,
        rotation: Matrix3<f64>,
    ) -> usize {
        self.add_body(Body3::Rigid(body), position, &rotation)
    }

    /// Adds a beam of `substructures` floating frames welded flange b to flange a (joints
    /// `<name>.substructure<i>`), flange a at `position`, axis along `rotation`'s x column.
    /// Returns the beam's index in `beams`.
    pub fn add_beam(
        &mut self,
        name: &str,
        props: &SpatialBeamProps,
        substructures: usize,
        position: Vector3<f64>,
        rotation: Matrix3<f64>,
    ) -> usize {
        let k = substructures.max(1);
        let part = props.length / k as f64;
        let first = self.bodies.len();
        for i in 0..k {
            let bname = if k == 1 {
                name.to_string()
            } else {
                format!("{name}.{i}")
            };
            let b = SpatialBeam::part_of(props, &bname, part);
            let p = position + rotation * Vector3::new(i as f64 * part, 0.0, 0.0);
            self.add_body(Body3::Beam(Box::new(b)), p, &rotation);
        }
        for i in 1..k {
            let fb = self.beam_flange(first + i - 1, true);
            let fa = self.beam_flange(first + i, false);
            self.add_joint(
                &format!("{name}.substructure{i}"),
                JointKind::Weld,
                fb,
                fa,
                None,
            );
        }
        self.beams.push(BeamGroup {
            name: name.to_string(),
            bodies: first..first + k,
            length: props.length,
            more: (),
        });
        self.beams.len() - 1
    }

    /// Adds one prebuilt beam body (from a matrix file, say) as a beam of one floating frame.
    /// Returns the beam's index in `beams`.
    pub fn add_beam_body(
        &mut self,
        beam: SpatialBeam,
        position: Vector3<f64>,
        rotation: Matrix3<f64>,
    ) -> usize {
        let first = self.bodies.len();
        let (name, length) = (beam.name.clone(), beam.length);
        self.add_body(Body3::Beam(Box::new(beam)), position, &rotation);
        self.beams.push(BeamGroup {
            name,
            bodies: first..first + 1,
            length,
            more: (),
        });
        self.beams.len() - 1
    }

    fn beam_flange(&mut self, body: usize, tip: bool) -> usize {
        let Body3::Beam(b) = &self.bodies[body] else {
            panic!("body {body} is not a beam");
        };
        let map = if tip {
            b.flange_b.clone()
        } else {
            b.flange_a.clone()
        };
        self.add_frame(Frame3::on_body(body, map, Matrix3::identity()))
    }

    /// Adds a frame; returns its index in `frames`.
    pub fn add_frame(&mut self, f: Frame3) -> usize {
        self.frames.push(f);
        self.frames.len() - 1
    }

    /// A frame fixed in the world.
    pub fn world_frame(&mut self, position: Vector3<f64>, rotation: Matrix3<f64>) -> usize {
        self.add_frame(Frame3::World { position, rotation })
    }

    /// Flange a (root) or flange b (tip) of beam `g`, rotated by `rotation`.
    pub fn beam_frame(&mut self, g: usize, tip: bool, rotation: Matrix3<f64>) -> usize {
        let grp = &self.beams[g];
        let body = if tip {
            grp.bodies.end - 1
        } else {
            grp.bodies.start
        };
        let f = self.beam_flange(body, tip);
        if let Frame3::OnBody { rotation: r, .. } = &mut self.frames[f] {
            *r = rotation;
        }
        f
    }

    /// The named frame of rigid body `body`.
    pub fn rigid_frame(&mut self, body: usize, name: &str) -> usize {
        let Body3::Rigid(r) = &self.bodies[body] else {
            panic!("body {body} is not rigid");
        };
        let (s0, rot) = r.frame(name).unwrap_or_else(|| panic!("no frame {name}"));
        let map = crate::mechanics::beam::spatial_beam::SpatialPointMap {
            s0,
            sp: DMatrix::zeros(3, 0),
            sphi: DMatrix::zeros(3, 0),
        };
        self.add_frame(Frame3::on_body(body, map, rot))
    }

    /// Adds a joint between frames f0 and f1 (axes of f0, see `multibody3d::joint`).
    pub fn add_joint(
        &mut self,
        name: &str,
        kind: JointKind,
        f0: usize,
        f1: usize,
        drive: Option<Drive>,
    ) -> usize {
        let j = Joint3 {
            name: name.to_string(),
            kind,
            frames: [f0, f1],
            drive,
            row: self.joint_rows,
        };
        self.joint_rows += j.len();
        self.joints.push(j);
        self.joints.len() - 1
    }

    /// Adds a point load.
    pub fn add_load(&mut self, load: Load3) {
        self.loads.push(load);
    }

    /// Sets the initial deformation coordinates q_f of body `body` (part of the placement
    /// before assembly, zero unless set), e.g. a static deflected shape.
    pub fn set_initial_deformation(&mut self, body: usize, qf: &[f64]) {
        let nf = self.bodies[body].nflex();
        assert_eq!(qf.len(), nf, "body {body} has {nf} deformation coordinates");
        let o = self.offsets[body] + FRAME;
        self.initial[o..o + nf].copy_from_slice(qf);
    }

    /// Coordinates of body `i`.
    pub fn body_coords<'a>(&self, i: usize, q: &'a DVector<f64>) -> DVectorView<'a, f64> {
        q.rows(self.offsets[i], self.bodies[i].ncoords())
    }

    /// First row of joint `j` in g.
    pub fn joint_row(&self, j: usize) -> usize {
        self.bodies.len() + self.joints[j].row
    }

    /// Pose of frame `f`.
    pub fn frame_pose(&self, f: usize, q: &DVector<f64>) -> Pose {
        let fr = &self.frames[f];
        fr.pose(fr.body().map(|b| self.body_coords(b, q)))
    }

    /// Indices in q on which the pose of frame `f` depends.
    fn frame_columns(&self, f: usize) -> Vec<usize> {
        let fr = &self.frames[f];
        fr.body()
            .map(|b| fr.active().iter().map(|k| self.offsets[b] + k).collect())
            .unwrap_or_default()
    }

    /// Indices in q on which joint `j` depends.
    fn joint_columns(&self, j: &Joint3) -> Vec<usize> {
        let mut c = self.frame_columns(j.frames[0]);
        for k in self.frame_columns(j.frames[1]) {
            if !c.contains(&k) {
                c.push(k);
            }
        }
        c
    }

    fn joint_values(&self, j: &Joint3, q: &DVector<f64>, t: f64, out: &mut [f64]) {
        let f0 = self.frame_pose(j.frames[0], q);
        let f1 = self.frame_pose(j.frames[1], q);
        j.rows(&f0, &f1, t, &self.inputs, out);
    }

    /// Joint coordinate of joint `j`: angle (rad, in (−π, π]) or slide (m).
    pub fn joint_coordinate(&self, j: usize, q: &DVector<f64>) -> f64 {
        let jt = &self.joints[j];
        jt.coordinate(
            &self.frame_pose(jt.frames[0], q),
            &self.frame_pose(jt.frames[1], q),
        )
    }

    /// Rate of joint `j`'s coordinate: ∂θ/∂q · q'.
    pub fn joint_rate(&self, j: usize, q: &DVector<f64>, v: &DVector<f64>) -> f64 {
        self.coordinate_gradient(j, q)
            .into_iter()
            .map(|(k, d)| d * v[k])
            .sum()
    }

    /// Effort of joint `j`'s drive on frame 1 along its coordinate: the effort law, or −λ of
    /// the motion row; 0 without a drive.
    pub fn joint_effort(&self, j: usize, lambda: &DVector<f64>, t: f64) -> f64 {
        let jt = &self.joints[j];
        if let Some(e) = jt.effort(t, &self.inputs) {
            e
        } else if jt.drive_acceleration(t, &self.inputs).is_some() {
            -lambda[self.joint_row(j) + jt.len() - 1]
        } else {
            0.0
        }
    }

    /// Pose of frame `f` and its derivatives over [`System3::frame_columns`] (same order).
    fn frame_pose_derivatives(
        &self,
        f: usize,
        q: &DVector<f64>,
        out: &mut Vec<(Vector3<f64>, Matrix3<f64>)>,
    ) -> Pose {
        let fr = &self.frames[f];
        fr.pose_derivatives(fr.body().map(|b| self.body_coords(b, q)), out)
    }

    /// ∂(joint coordinate)/∂q over the joint's columns (closed form; a column shared by both
    /// frames appears twice, the entries add).
    fn coordinate_gradient(&self, j: usize, q: &DVector<f64>) -> Vec<(usize, f64)> {
        let jt = &self.joints[j];
        let (mut d0, mut d1) = (Vec::new(), Vec::new());
        let p0 = self.frame_pose_derivatives(jt.frames[0], q, &mut d0);
        let p1 = self.frame_pose_derivatives(jt.frames[1], q, &mut d1);
        let zero = (Vector3::zeros(), Matrix3::zeros());
        let c0 = self.frame_columns(jt.frames[0]).into_iter().zip(&d0);
        let c1 = self.frame_columns(jt.frames[1]).into_iter().zip(&d1);
        c0.map(|(k, d)| {
            (
                k,
                jt.coordinate_acceleration(&p0, &p1, &zero, &zero, d, &zero),
            )
        })
        .chain(c1.map(|(k, d)| {
            (
                k,
                jt.coordinate_acceleration(&p0, &p1, &zero, &zero, &zero, d),
            )
        }))
        .collect()
    }

    /// ∂(joint coordinate)/∂q over the joint's columns by central differences: the reference
    /// of the closed form `System3::coordinate_gradient` in the tests.
    pub fn coordinate_gradient_differences(&self, j: usize, q: &DVector<f64>) -> Vec<(usize, f64)> {
        let jt = &self.joints[j];
        let mut qq = q.clone();
        self.joint_columns(jt)
            .into_iter()
            .map(|k| {
                let x = q[k];
                qq[k] = x + EPS_CENTRAL;
                let cp = self.joint_coordinate(j, &qq);
                qq[k] = x - EPS_CENTRAL;
                let cm = self.joint_coordinate(j, &qq);
                qq[k] = x;
                let d = if jt.kind == JointKind::Revolute {
                    wrap(cp - cm)
                } else {
                    cp - cm
                };
                (k, d / (2.0 * EPS_CENTRAL))
            })
            .collect()
    }

    /// The constraint Jacobian by central differences per joint column: the reference of the
    /// closed form ([`Equations::constraint_jacobian`]) in the tests.
    pub fn constraint_jacobian_differences(&self, q: &DVector<f64>, t: f64, gm: &mut DMatrix<f64>) {
        gm.fill(0.0);
        for (i, &o) in self.offsets.iter().enumerate() {
            for k in 0..4 {
                gm[(i, o + 3 + k)] = 2.0 * q[o + 3 + k];
            }
        }
        let nb = self.bodies.len();
        let mut qq = q.clone();
        let (mut gp, mut gn) = ([0.0; 6], [0.0; 6]);
        for j in &self.joints {
            let (r, l) = (nb + j.row, j.len());
            for k in self.joint_columns(j) {
                let x = q[k];
                qq[k] = x + EPS_CENTRAL;
                self.joint_values(j, &qq, t, &mut gp[..l]);
                qq[k] = x - EPS_CENTRAL;
                self.joint_values(j, &qq, t, &mut gn[..l]);
                qq[k] = x;
                for s in 0..l {
                    let mut d = gp[s] - gn[s];
                    if s == 5 && j.kind == JointKind::Revolute {
                        d = wrap(d);
                    }
                    gm[(r + s, k)] = d / (2.0 * EPS_CENTRAL);
                }
            }
        }
    }

    /// Generalized force of a world force and torque on frame `f`: Σ F·∂x/∂q_k + τ·∂θ/∂q_k,
    /// with ∂θ̃ = ∂A Aᵀ (its skew part).
    fn frame_force(
        &self,
        f: usize,
        q: &DVector<f64>,
        force: &Vector3<f64>,
        torque: &Vector3<f64>,
    ) -> Vec<(usize, f64)> {
        let (_, cols) = self.frame_jacobian(f, q);
        cols.into_iter()
            .map(|(k, dx, dth)| (k, force.dot(&dx) + torque.dot(&dth)))
            .collect()
    }

    /// Pose of frame `f` and, per coordinate k it depends on, (∂x/∂q_k, ∂θ/∂q_k): the world
    /// translation and rotation (axial part of ∂A_f A_fᵀ) per unit change of q_k, closed form
    /// ([`Frame3::pose_derivatives`]). Velocity J q', acceleration J q'' + bias.
    pub fn frame_jacobian(&self, f: usize, q: &DVector<f64>) -> (Pose, Vec<FrameColumn>) {
        let mut d = Vec::new();
        let pose = self.frame_pose_derivatives(f, q, &mut d);
        let a = pose.1;
        let cols = self
            .frame_columns(f)
            .into_iter()
            .zip(&d)
            .map(|(k, (dx, da))| {
                let w = da * a.transpose();
                let dth = Vector3::new(
                    w[(2, 1)] - w[(1, 2)],
                    w[(0, 2)] - w[(2, 0)],
                    w[(1, 0)] - w[(0, 1)],
                ) * 0.5;
                (k, *dx, dth)
            })
            .collect();
        (pose, cols)
    }

    /// ∂Q/∂u of input `slot`: the generalized force of one unit of that input at (q, t), from
    /// the input loads and effort drives that read it (Q is linear in the inputs), as
    /// (coordinate, value) pairs; entries of one coordinate add.
    pub fn input_force(&self, q: &DVector<f64>, t: f64, slot: usize) -> Vec<(usize, f64)> {
        use crate::mechanics::multibody::law::Law;
        let unit = InputValue::unit(self.inputs.len(), slot, t);
        let mut out = Vec::new();
        for l in &self.loads {
            let Some(law) = l.law.as_ref().filter(|law| law.law == Law::Input(slot)) else {
                continue;
            };
            let s = law.eval(t, &unit).0;
            out.extend(self.frame_force(l.frame, q, &(l.force * s), &(l.torque * s)));
        }
        for (j, jt) in self.joints.iter().enumerate() {
            let reads = jt.drive.as_ref().is_some_and(|d| {
                d.kind == crate::mechanics::multibody::joint::DriveKind::Effort
                    && d.law.law == Law::Input(slot)
            });
            let Some(e) = jt.effort(t, &unit).filter(|_| reads) else {
                continue;
            };
            out.extend(
                self.coordinate_gradient(j, q)
                    .into_iter()
                    .map(|(k, d)| (k, d * e)),
            );
        }
        out
    }

    /// The factor on load `l` at time t (1 without a law).
    pub fn load_scale(&self, l: &Load3, t: f64) -> f64 {
        l.law
            .as_ref()
            .map_or(1.0, |law| law.eval(t, &self.inputs).0)
    }

    /// Applied generalized forces of loads and effort drives.
    fn applied(&self, q: &DVector<f64>, t: f64) -> Vec<(usize, f64)> {
        let mut out = Vec::new();
        for l in &self.loads {
            let s = self.load_scale(l, t);
            out.extend(self.frame_force(l.frame, q, &(l.force * s), &(l.torque * s)));
        }
        for (j, jt) in self.joints.iter().enumerate() {
            if let Some(e) = jt.effort(t, &self.inputs) {
                out.extend(
                    self.coordinate_gradient(j, q)
                        .into_iter()
                        .map(|(k, d)| (k, d * e)),
                );
            }
        }
        out
    }

    /// Kinetic, strain and gravity energy.
    pub fn energy(&self, q: &DVector<f64>, v: &DVector<f64>) -> Energy {
        let g = self.gravity.unwrap_or_default();
        let mut e = Energy::default();
        for (i, b) in self.bodies.iter().enumerate() {
            let z = self.body_coords(i, q);
            e.kinetic += b.kinetic_energy(z, self.body_coords(i, v));
            e.strain += b.strain_energy(z);
            e.potential += b.gravity_energy(z, &g);
        }
        e
    }

    /// Pose of the tip (flange b of the last substructure) of beam `g`.
    pub fn beam_tip(&self, g: usize, q: &DVector<f64>) -> Pose {
        let last = self.beams[g].bodies.end - 1;
        let Body3::Beam(b) = &self.bodies[last] else {
            unreachable!("beam groups hold beams")
        };
        Frame3::on_body(last, b.flange_b.clone(), Matrix3::identity())
            .pose(Some(self.body_coords(last, q)))
    }

    /// The tip of beam `g` in the frame of its root flange (flange a: the tangent there,
    /// whatever the beam's frame; for a tangent frame, the frame of the first substructure):
    /// its y and z components are the tip deflections.
    pub fn beam_tip_local(&self, g: usize, q: &DVector<f64>) -> Vector3<f64> {
        let first = self.beams[g].bodies.start;
        let z = self.body_coords(first, q);
        let (r, a) = match &self.bodies[first] {
            Body3::Beam(b) => super::frame::map_pose(&b.flange_a, z),
            _ => {
                let (r, _, a) = super::body::frame_of(&z);
                (r, a)
            }
        };
        a.transpose() * (self.beam_tip(g, q).0 - r)
    }

    /// Largest quaternion norm error max |pᵀp − 1|.
    pub fn quaternion_drift(&self, q: &DVector<f64>) -> f64 {
        self.offsets
            .iter()
            .map(|&o| (q.rows(o + 3, 4).norm_squared() - 1.0).abs())
            .fold(0.0, f64::max)
    }
}

impl Equations for System3 {
    fn n(&self) -> usize {
        self.initial.len()
    }

    fn m(&self) -> usize {
        self.bodies.len() + self.joint_rows
    }

    fn length_scale(&self) -> f64 {
        self.bodies
            .iter()
            .map(Body3::length_scale)
            .fold(0.0, f64::max)
            .max(1e-3)
    }

    fn coordinate_kinds(&self) -> Vec<CoordinateKind> {
        let mut kinds = Vec::with_capacity(self.initial.len());
        for b in &self.bodies {
            for k in 0..b.ncoords() {
                kinds.push(CoordinateKind::of(b.is_massless(), b.is_angle(k)));
            }
        }
        kinds
    }

    fn frame_coordinates(&self) -> Vec<usize> {
        self.offsets.iter().flat_map(|&o| o..o + FRAME).collect()
    }

    /// The system's own placement (built in code; the scene is not read).
    fn initial_coordinates(&self) -> Result<DVector<f64>, EngineError> {
        Ok(DVector::from_vec(self.initial.clone()))
    }

    fn body_ranges(&self) -> Vec<Range<usize>> {
        self.bodies
            .iter()
            .zip(&self.offsets)
            .map(|(b, &o)| o..o + b.ncoords())
            .collect()
    }

    /// A norm row on its body; a joint's rows on the bodies of its two frames.
    fn row_bodies(&self) -> Vec<[Option<usize>; 2]> {
        let mut rows: Vec<[Option<usize>; 2]> =
            (0..self.bodies.len()).map(|i| [Some(i), None]).collect();
        for j in &self.joints {
            let bodies = j.frames.map(|f| self.frames[f].body());
            rows.extend(std::iter::repeat_n(bodies, j.len()));
        }
        rows
    }

    fn mass_blocks(&self, q: &DVector<f64>, m: &mut BlockDiagonal) {
        for (i, b) in self.bodies.iter().enumerate() {
            m.blocks[i]
                .dense_mut()
                .copy_from(&b.mass_matrix(self.body_coords(i, q)));
        }
    }

    fn body_residual(
        &self,
        q: &DVector<f64>,
        v: &DVector<f64>,
        a: &DVector<f64>,
        t: f64,
        r: &mut DVector<f64>,
    ) {
        let g = self.gravity.unwrap_or_default();
        // the bodies of beams with α damping, whose mass matrices the damping needs: each is
        // built from the inertia its residual computes anyway
        let mut damped = vec![false; self.bodies.len()];
        for (k, group) in self.beams.iter().enumerate() {
            if self.damps(k) {
                group.bodies.clone().for_each(|i| damped[i] = true);
            }
        }
        let mut masses: Vec<Option<DMatrix<f64>>> = vec![None; self.bodies.len()];
        for (i, b) in self.bodies.iter().enumerate() {
            let (o, n) = (self.offsets[i], b.ncoords());
            let (z, zd, zdd) = (
                self.body_coords(i, q),
                self.body_coords(i, v),
                self.body_coords(i, a),
            );
            let ri = if damped[i] {
                let (ri, mi) = b.residual_and_mass(z, zd, zdd, &g);
                masses[i] = Some(mi);
                ri
            } else {
                b.residual(z, zd, zdd, &g)
            };
            r.rows_mut(o, n).copy_from(&ri);
        }
        for g in 0..self.beams.len() {
            let mass = |i: usize| {
                masses[i]
                    .take()
                    .unwrap_or_else(|| self.bodies[i].mass_matrix(self.body_coords(i, q)))
            };
            if let Some(d) = self.beam_damping_with(g, q, mass) {
                d.add_force(v, r);
            }
        }
        for (k, f) in self.applied(q, t) {
            r[k] -= f;
        }
    }

    /// Per body, forward differences of its residual over its own coordinates and rates; the
    /// norm rows' 2λ I exactly. Joint and load geometric terms are left out (Newton converges
    /// without them at the step sizes the dynamics need).
    fn tangent_blocks(&self, at: &Point, kt: &mut BlockDiagonal, ct: &mut BlockDiagonal) {
        let Point {
            q, v, a, lambda, ..
        } = *at;
        kt.fill_zero();
        ct.fill_zero();
        let g = self.gravity.unwrap_or_default();
        for (i, b) in self.bodies.iter().enumerate() {
            let n = b.ncoords();
            let kb = kt.blocks[i].dense_mut();
            b.tangents(
                self.body_coords(i, q),
                self.body_coords(i, v),
                self.body_coords(i, a),
                &g,
                EPS_FORWARD,
                kb.view_mut((0, 0), (n, n)),
                ct.blocks[i].dense_mut().view_mut((0, 0), (n, n)),
            );
            for k in 0..4 {
                kb[(3 + k, 3 + k)] += 2.0 * lambda[i];
            }
        }
        for g in 0..self.beams.len() {
            if let Some(d) = self.beam_damping(g, q) {
                d.add_tangent(ct);
            }
        }
    }

    fn constraints(&self, q: &DVector<f64>, t: f64, g: &mut DVector<f64>) {
        for (i, &o) in self.offsets.iter().enumerate() {
            g[i] = q.rows(o + 3, 4).norm_squared() - 1.0;
        }
        let nb = self.bodies.len();
        for j in &self.joints {
            let r = nb + j.row;
            self.joint_values(j, q, t, &mut g.as_mut_slice()[r..r + j.len()]);
        }
    }

    /// Norm rows 2pᵀ; joint rows in closed form, each column the rows' derivative along the
    /// pose derivatives of one coordinate (`Joint3::rows_acceleration` at zero rates).
    fn jacobian_rows(&self, q: &DVector<f64>, _t: f64, gm: &mut JacobianRows) {
        gm.fill_zero();
        for (i, &o) in self.offsets.iter().enumerate() {
            for k in 0..4 {
                gm.add(i, o + 3 + k, 2.0 * q[o + 3 + k]);
            }
        }
        let nb = self.bodies.len();
        let zero = (Vector3::zeros(), Matrix3::zeros());
        let (mut d0, mut d1) = (Vec::new(), Vec::new());
        let mut col = [0.0; 6];
        for j in &self.joints {
            let (r, l) = (nb + j.row, j.len());
            let p0 = self.frame_pose_derivatives(j.frames[0], q, &mut d0);
            let p1 = self.frame_pose_derivatives(j.frames[1], q, &mut d1);
            for (side, d) in [&d0, &d1].into_iter().enumerate() {
                let f = &self.frames[j.frames[side]];
                let Some(b) = f.body() else { continue };
                for (&k, dk) in f.active().iter().zip(d) {
                    let (a0, a1) = if side == 0 { (dk, &zero) } else { (&zero, dk) };
                    j.rows_acceleration(&p0, &p1, &zero, &zero, a0, a1, &mut col[..l]);
                    let c = self.offsets[b] + k;
                    for s in 0..l {
                        gm.add(r + s, c, col[s]);
                    }
                }
            }
        }
    }

    /// Norm rows 2ṗᵀṗ; joint rows by the second difference of g along q' at fixed t, minus
    /// the drive law's second derivative on a motion row.
    fn accel_bias(&self, q: &DVector<f64>, v: &DVector<f64>, t: f64, out: &mut DVector<f64>) {
        for (i, &o) in self.offsets.iter().enumerate() {
            out[i] = 2.0 * v.rows(o + 3, 4).norm_squared();
        }
        let nb = self.bodies.len();
        let (mut g0, mut gp, mut gn) = ([0.0; 6], [0.0; 6], [0.0; 6]);
        for j in &self.joints {
            let (r, l) = (nb + j.row, j.len());
            let cols = self.joint_columns(j);
            let vmax = cols.iter().map(|&k| v[k].abs()).fold(0.0, f64::max);
            for s in 0..l {
                out[r + s] = 0.0;
            }
            if vmax > 0.0 {
                let h = EPS_BIAS / vmax;
                let (mut qp, mut qn) = (q.clone(), q.clone());
                for &k in &cols {
                    qp[k] += h * v[k];
                    qn[k] -= h * v[k];
                }
                self.joint_values(j, q, t, &mut g0[..l]);
                self.joint_values(j, &qp, t, &mut gp[..l]);
                self.joint_values(j, &qn, t, &mut gn[..l]);
                for s in 0..l {
                    let (mut a, mut b) = (gp[s] - g0[s], gn[s] - g0[s]);
                    if s == 5 && j.kind == JointKind::Revolute {
                        (a, b) = (wrap(a), wrap(b));
                    }
                    out[r + s] = (a + b) / (h * h);
                }
            }
            if let Some(sdd) = j.drive_acceleration(t, &self.inputs) {
                out[r + l - 1] -= sdd;
            }
        }
    }

    fn breakpoints(&self) -> Vec<f64> {
        let drives = self.joints.iter().filter_map(|j| j.drive.as_ref());
        let loads = self.loads.iter().filter_map(|l| l.law.as_ref());
        TimeLaw::breakpoints_of(drives.map(|d| &d.law).chain(loads))
    }

    fn joints_of_rows(&self, rows: &[usize]) -> Vec<String> {
        let nb = self.bodies.len();
        let mut names: Vec<String> = Vec::new();
        for &r in rows {
            let name = if r < nb {
                format!("{}.quaternion", self.bodies[r].name())
            } else if let Some(j) = self.joints.iter().rev().find(|j| j.row <= r - nb) {
                j.name.clone()
            } else {
                continue;
            };
            if !names.contains(&name) {
                names.push(name);
            }
        }
        names
    }

    /// Σ applied force × rate, plus −λ × joint rate of each motion drive.
    fn power(&self, q: &DVector<f64>, v: &DVector<f64>, lambda: &DVector<f64>, t: f64) -> f64 {
        let mut p: f64 = self.applied(q, t).into_iter().map(|(k, f)| f * v[k]).sum();
        for (j, jt) in self.joints.iter().enumerate() {
            if jt.drive_acceleration(t, &self.inputs).is_some() {
                let rate: f64 = self
                    .coordinate_gradient(j, q)
                    .into_iter()
                    .map(|(k, d)| d * v[k])
                    .sum();
                p -= lambda[self.joint_row(j) + jt.len() - 1] * rate;
            }
        }
        p
    }
}
