//! The assembled multibody system: bodies stacked in q, joint equations stacked in g.
//!
//! Residual of the equations of motion (what the integrator drives to zero):
//! r(q, q', q'', λ, t) = Σ_bodies r_body - Q_loads(q, t) + G(q)ᵀ λ,   g(q, t) = 0.

use super::body::Body;
use super::equations::{Point, Turning};
use super::frame::{self, Frame, FrameState};
use super::joint::{DriveKind, Joint, JointKind, Rows};
use super::law::{InputValue, TimeLaw};
use super::rigid_body::RigidBody;
use super::sparsity::{Block, BlockDiagonal, JacobianRows};
use crate::error::EngineError;
use crate::mechanics::beam::band::ArrowBand;
use crate::mechanics::beam::planar_beam::{rot, PlanarBeam, PointMap, THETA};
use crate::mechanics::beam::planar_beam::{TermCounts, FLEX};
use crate::mechanics::Effects;
use nalgebra::{DVector, DVectorView, Vector2};
use std::ops::Range;

mod damping;
mod readouts;

/// Energies of the system (J).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Energy {
    pub kinetic: f64,
    pub strain: f64,
    pub potential: f64,
}

impl Energy {
    pub fn total(&self) -> f64 {
        self.kinetic + self.strain + self.potential
    }
}

/// A point load: world force and torque on a frame, constant or from input slots.
#[derive(Debug, Clone)]
pub struct Load {
    pub name: String,
    pub frame: usize,
    pub force: Vector2<f64>,
    pub torque: f64,
    /// Input slots of fx, fy, torque.
    pub inputs: Option<usize>,
    /// A time law that scales the constant force and torque (a ramp, say).
    pub scale: Option<TimeLaw>,
}

/// A beam of a system, planar or spatial: one body, or k substructures welded tip to root,
/// consecutive among the system's bodies. `X` is what a system keeps more of it (the planar
/// one: [`PlanarBeamData`]; the spatial one nothing).
#[derive(Debug, Clone)]
pub struct BeamGroup<X = ()> {
    /// The beam's name (its substructures are `name[i]`).
    pub name: String,
    /// Its bodies, from flange a to flange b.
    pub bodies: Range<usize>,
    /// Its undeformed length (m).
    pub length: f64,
    /// What the system keeps more of the beam.
    pub more: X,
}

/// What the planar system keeps of a beam for its readouts and its initial shape.
#[derive(Debug, Clone)]
pub struct PlanarBeamData {
    /// A pinned floating frame: deflections are measured from the chord, not the root's axis.
    pub pinned: bool,
    /// Its section (for the outputs of stress).
    pub section: crate::mechanics::beam::section::Section,
    /// The material point at mid-span.
    pub mid: (usize, PointMap),
    /// Tip displacement (m) of the static shape the beam starts in; 0: undeformed.
    pub initial_tip: f64,
}

/// The assembled planar system: its bodies stacked in q, the frames that joints and loads act
/// on, the joints with their constraint rows, the loads, and the scene's beams.
#[derive(Debug, Clone)]
pub struct System {
    /// The bodies (beam substructures and rigid bodies), in the order of their coordinates in q.
    pub bodies: Vec<Body>,
    /// Index of each body's first coordinate in q.
    pub offsets: Vec<usize>,
    /// The frames that joints and loads act on: fixed in the world or material points of bodies.
    pub frames: Vec<Frame>,
    /// The joints, each with its first constraint row in g(q).
    pub joints: Vec<Joint>,
    /// The point loads.
    pub loads: Vec<Load>,
    /// One group per scene beam, in scene order: its bodies (substructures) and section.
    pub beams: Vec<BeamGroup<PlanarBeamData>>,
    /// The gravity field, `None` when the effect is off (its terms are not evaluated).
    pub gravity: Option<Vector2<f64>>,
    /// The resolved effects the system was built with.
    pub effects: Effects,
    /// Current values of the FMU inputs (slot order of `input_slots`).
    pub inputs: Vec<InputValue>,
    /// Coordinates of the bodies where they are placed at t = 0, undeformed (before assembly).
    pub placed: DVector<f64>,
    pub(crate) n: usize,
    pub(crate) m: usize,
}

impl System {
    pub(crate) fn relative_angle(&self, f0: usize, f1: usize, q: &DVector<f64>) -> f64 {
        self.frame_state(f1, q, None).phi - self.frame_state(f0, q, None).phi
    }

    /// Coordinates at t = 0 before assembly: the bodies where they are placed, each beam in
    /// the static shape of its initial tip displacement.
    pub fn initial_coordinates(&self) -> Result<DVector<f64>, EngineError> {
        let mut q = self.placed.clone();
        for g in &self.beams {
            if g.more.initial_tip == 0.0 {
                continue;
            }
            let body = g.bodies.start;
            let b = self.beam(body).ok_or_else(|| EngineError::InitialState {
                message: format!("beam '{}' is rigid: it has no initial deformation", g.name),
            })?;
            let shape = b.static_tip_shape(g.more.initial_tip).ok_or_else(|| {
                EngineError::InitialState {
                    message: format!(
                        "beam '{}': no static tip shape (is the tip held by the frame?)",
                        b.name
                    ),
                }
            })?;
            q.rows_mut(self.offsets[body] + 3, b.nflex())
                .copy_from(&shape);
        }
        Ok(q)
    }

    pub(crate) fn add_frame(&mut self, f: Frame) -> usize {
        self.frames.push(f);
        self.frames.len() - 1
    }

    /// The flexible beam that is body `i`, if it is one.
    pub fn beam(&self, i: usize) -> Option<&PlanarBeam> {
        match &self.bodies[i] {
            Body::Beam(b) => Some(b),
            Body::Rigid(_) => None,
        }
    }

    /// The unknowns that turn with the whole system: each body's (x, y) and angle, and the
    /// p₁ - p₀ rows of revolute and weld joints (the first two of each, along the world axes).
    pub fn turning(&self) -> Turning {
        let angles = self.offsets.iter().map(|&o| o + THETA).collect();
        let mut pairs: Vec<usize> = self.offsets.clone();
        for j in &self.joints {
            if matches!(
                j.kind,
                JointKind::Weld | JointKind::Revolute | JointKind::Spherical
            ) {
                pairs.push(self.n + j.row);
            }
        }
        Turning { angles, pairs }
    }

    /// Coordinates of body `i`.
    pub fn body_coords<'a>(&self, i: usize, q: &'a DVector<f64>) -> DVectorView<'a, f64> {
        q.rows(self.offsets[i], self.bodies[i].ndof())
    }

    /// Kinematics of frame `f` (at rest without rates).
    pub fn frame_state(
        &self,
        f: usize,
        q: &DVector<f64>,
        v: Option<&DVector<f64>>,
    ) -> FrameState<'_> {
        match &self.frames[f] {
            Frame::World { position, angle } => FrameState::world(*position, *angle),
            Frame::OnBody { body, map } => FrameState::on_body(
                *body,
                &self.bodies[*body],
                map,
                self.body_coords(*body, q),
                v.map(|v| self.body_coords(*body, v)),
            ),
        }
    }

    /// The rows of joint `j` at (q, q', t) (at rest without rates), handed to `visit` with the
    /// joint's two frame states. Built in place: returned in a tuple, the frame states were
    /// copied twice on every Newton iteration (memcpy 4.8 % of a small system's time).
    #[inline]
    pub fn with_joint_rows<R>(
        &self,
        j: &Joint,
        q: &DVector<f64>,
        v: Option<&DVector<f64>>,
        t: f64,
        visit: impl FnOnce(&FrameState, &FrameState, &Rows) -> R,
    ) -> R {
        let f0 = self.frame_state(j.frames[0], q, v);
        let f1 = self.frame_state(j.frames[1], q, v);
        let rows = j.rows(&f0, &f1, t, &self.inputs);
        visit(&f0, &f1, &rows)
    }

    /// Adds J_pᵀ w + J_φ c of frame `f` into row `row` of `out`.
    fn add_row_jacobian(
        &self,
        out: &mut JacobianRows,
        row: usize,
        f: &FrameState,
        w: Vector2<f64>,
        c: f64,
    ) {
        if let Some(b) = f.body {
            // the body's stored entries found once, not once per coordinate
            let body = out.row_from(row, self.offsets[b]);
            f.for_each_jacobian(w, c, |k, x| body[k] += x);
        }
    }

    /// Force and torque of load `l` at time t.
    pub fn load_value(&self, l: &Load, t: f64) -> (Vector2<f64>, f64) {
        if let Some(s) = &l.scale {
            let k = s.eval(t, &self.inputs).0;
            return (l.force * k, l.torque * k);
        }
        match l.inputs {
            Some(s) => (
                Vector2::new(self.input_at(s, t), self.input_at(s + 1, t)),
                self.input_at(s + 2, t),
            ),
            None => (l.force, l.torque),
        }
    }

    fn input_at(&self, slot: usize, t: f64) -> f64 {
        let u = self.inputs[slot];
        let dt = t - u.t0;
        u.value + u.der1 * dt + 0.5 * u.der2 * dt * dt
    }

    /// Subtracts the generalized force J_pᵀ w + J_φ c of frame `f` from the residual.
    fn add_generalized_force(&self, r: &mut DVector<f64>, f: &FrameState, w: Vector2<f64>, c: f64) {
        if let Some(b) = f.body {
            let o = self.offsets[b];
            f.for_each_jacobian(w, c, |k, x| r[o + k] -= x);
        }
    }

    fn add_force_tangent(
        &self,
        kt: &mut BlockDiagonal,
        frame: usize,
        q: &DVector<f64>,
        force: Vector2<f64>,
    ) {
        if let Frame::OnBody { body, map } = &self.frames[frame] {
            let b = &self.bodies[*body];
            let n = b.ndof();
            let z = self.body_coords(*body, q);
            match &mut kt.blocks[*body] {
                Block::Band(k) => frame::add_force_tangent(b, map, z, force, &mut k.as_mut()),
                Block::Dense(k) => {
                    frame::add_force_tangent(b, map, z, force, &mut k.view_mut((0, 0), (n, n)))
                }
            }
        }
    }

    /// Kinetic, strain and gravity energy.
    pub fn energy(&self, q: &DVector<f64>, v: &DVector<f64>) -> Energy {
        let mut e = Energy::default();
        for (i, b) in self.bodies.iter().enumerate() {
            let z = self.body_coords(i, q);
            e.kinetic += b.kinetic_energy(z, self.body_coords(i, v));
            e.strain += b.strain_energy(z);
            e.potential += b.gravity_energy(z, self.gravity);
        }
        e
    }

    /// Evaluations of each optional term, summed over the bodies.
    pub fn term_counts(&self) -> TermCounts {
        let total = TermCounts::default();
        for b in &self.bodies {
            total.add(b.counts());
        }
        total
    }

    /// ∂Q/∂u of input `slot`: the generalized force of one unit of that input at (q, q', t),
    /// from the input loads and effort drives that read it (Q is linear in the inputs), as
    /// (coordinate, value) pairs; entries of one coordinate add.
    pub fn input_force(
        &self,
        q: &DVector<f64>,
        v: &DVector<f64>,
        t: f64,
        slot: usize,
    ) -> Vec<(usize, f64)> {
        let mut out = Vec::new();
        let mut push = |f: &FrameState, w: Vector2<f64>, c: f64| {
            if let Some(b) = f.body {
                let o = self.offsets[b];
                f.for_each_jacobian(w, c, |k, x| out.push((o + k, x)));
            }
        };
        for l in &self.loads {
            let Some(s) = l.inputs.filter(|s| (*s..*s + 3).contains(&slot)) else {
                continue;
            };
            if l.scale.is_some() {
                continue; // a scaled load does not read its inputs
            }
            let fs = self.frame_state(l.frame, q, None);
            let (w, c) = match slot - s {
                0 => (Vector2::x(), 0.0),
                1 => (Vector2::y(), 0.0),
                _ => (Vector2::zeros(), 1.0),
            };
            push(&fs, w, c);
        }
        let unit = InputValue::unit(self.inputs.len(), slot, t);
        for j in &self.joints {
            let reads = j.drive.as_ref().is_some_and(|d| {
                d.kind == DriveKind::Effort && d.law.law == super::law::Law::Input(slot)
            });
            // the effort per unit input: 1, or 0 past the law's `until`
            let Some(e) = j.effort(t, &unit).filter(|_| reads) else {
                continue;
            };
            let f0 = self.frame_state(j.frames[0], q, Some(v));
            let f1 = self.frame_state(j.frames[1], q, Some(v));
            let c = j.coordinate(&f0, &f1);
            push(&f0, c.w0 * e, c.c0 * e);
            push(&f1, c.w1 * e, c.c1 * e);
        }
        out
    }

    /// The body a frame lies on (`None` for the world).
    pub fn frame_body(&self, frame: usize) -> Option<usize> {
        match &self.frames[frame] {
            Frame::OnBody { body, .. } => Some(*body),
            Frame::World { .. } => None,
        }
    }

    /// Index of the scene joint `name` in `joints`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }
}

impl super::equations::Equations for System {
    /// Number of coordinates.
    fn n(&self) -> usize {
        self.n
    }
    /// Number of constraint equations.
    fn m(&self) -> usize {
        self.m
    }
    /// The largest body length (m): the scale of position errors.
    fn length_scale(&self) -> f64 {
        self.bodies
            .iter()
            .map(Body::length_scale)
            .fold(0.0, f64::max)
            .max(1e-3)
    }
    fn coordinate_kinds(&self) -> Vec<super::equations::CoordinateKind> {
        use super::equations::CoordinateKind;
        let mut kinds = vec![CoordinateKind::Length; self.n];
        for (i, b) in self.bodies.iter().enumerate() {
            for k in 0..b.ndof() {
                kinds[self.offsets[i] + k] = CoordinateKind::of(b.is_massless(), b.is_angle(k));
            }
        }
        kinds
    }
    /// Indices in q of the frame coordinates (x, y, θ) of every body, not its deformation.
    fn frame_coordinates(&self) -> Vec<usize> {
        self.offsets.iter().flat_map(|&o| o..o + 3).collect()
    }
    fn initial_coordinates(&self) -> Result<DVector<f64>, EngineError> {
        System::initial_coordinates(self)
    }
    /// Coordinates of each body in q.
    fn body_ranges(&self) -> Vec<Range<usize>> {
        self.bodies
            .iter()
            .zip(&self.offsets)
            .map(|(b, &o)| o..o + b.ndof())
            .collect()
    }
    /// For each constraint row, the bodies of its joint's two frames.
    fn row_bodies(&self) -> Vec<[Option<usize>; 2]> {
        let mut rows = vec![[None, None]; self.m];
        for j in &self.joints {
            let body = |f: usize| match &self.frames[f] {
                Frame::World { .. } => None,
                Frame::OnBody { body, .. } => Some(*body),
            };
            let bodies = [body(j.frames[0]), body(j.frames[1])];
            let count = Joint::rows_count(j.kind, j.drive.as_ref());
            rows[j.row..j.row + count].fill(bodies);
        }
        rows
    }
    /// Mass matrix M(q) by body blocks, overwritten.
    fn mass_blocks(&self, q: &DVector<f64>, m: &mut BlockDiagonal) {
        m.fill_zero();
        for (i, b) in self.bodies.iter().enumerate() {
            let n = b.ndof();
            let z = self.body_coords(i, q);
            match (b, &mut m.blocks[i]) {
                (Body::Beam(beam), Block::Band(band)) => beam.mass_matrix(z, band.as_mut()),
                (_, block) => b.mass_matrix(z, block.dense_mut().view_mut((0, 0), (n, n))),
            }
        }
    }
    /// Dense blocks, but an arrow band for a beam whose deformation block is wider than its
    /// band (`beam/band.rs`) and whose damping adds no dense block (mass-proportional α).
    fn block_diagonal(&self) -> BlockDiagonal {
        let mut d = BlockDiagonal::zeros(&self.body_ranges());
        for (i, b) in self.bodies.iter().enumerate() {
            let Body::Beam(beam) = b else { continue };
            let dense_damping = beam.options.damping && beam.rayleigh_alpha != 0.0;
            match beam.band_width() {
                Some(w) if !dense_damping && 2 * w + 1 < beam.nflex() => {
                    d.blocks[i] = Block::Band(ArrowBand::zeros(beam.ndof(), FLEX, w));
                }
                _ => {}
            }
        }
        d
    }
    /// Residual r(q, q', q'', t) without the reactions: inertia + internal - applied, overwritten.
    fn body_residual(
        &self,
        q: &DVector<f64>,
        v: &DVector<f64>,
        a: &DVector<f64>,
        t: f64,
        r: &mut DVector<f64>,
    ) {
        r.as_mut_slice().fill(0.0);
        for (i, b) in self.bodies.iter().enumerate() {
            let o = self.offsets[i];
            let n = b.ndof();
            b.residual(
                self.body_coords(i, q),
                self.body_coords(i, v),
                self.body_coords(i, a),
                self.gravity,
                &mut r.as_mut_slice()[o..o + n],
            );
        }
        for g in 0..self.beams.len() {
            if let Some(d) = self.beam_damping(g, q) {
                d.add_force(v, r);
            }
        }
        for l in &self.loads {
            let fs = self.frame_state(l.frame, q, None);
            let (force, torque) = self.load_value(l, t);
            self.add_generalized_force(r, &fs, force, torque);
        }
        for j in &self.joints {
            if let Some(effort) = j.effort(t, &self.inputs) {
                let f0 = self.frame_state(j.frames[0], q, Some(v));
                let f1 = self.frame_state(j.frames[1], q, Some(v));
                let c = j.coordinate(&f0, &f1);
                self.add_generalized_force(r, &f0, c.w0 * effort, c.c0 * effort);
                self.add_generalized_force(r, &f1, c.w1 * effort, c.c1 * effort);
            }
        }
    }
    /// Tangents K_t = ∂(r + Gᵀλ)/∂q and C_t = ∂r/∂q' by body blocks, overwritten. The terms
    /// from the rotation of a prismatic axis and of effort drives are left out (Newton
    /// converges without them); a reaction or load only acts on its own body's block.
    fn tangent_blocks(&self, at: &Point, kt: &mut BlockDiagonal, ct: &mut BlockDiagonal) {
        let Point { q, v, a, lambda, t } = *at;
        kt.fill_zero();
        ct.fill_zero();
        for (i, b) in self.bodies.iter().enumerate() {
            let n = b.ndof();
            let (z, zd, zdd) = (
                self.body_coords(i, q),
                self.body_coords(i, v),
                self.body_coords(i, a),
            );
            match (b, &mut kt.blocks[i], &mut ct.blocks[i]) {
                (Body::Beam(beam), Block::Band(k), Block::Band(c)) => {
                    beam.tangents(z, zd, zdd, self.gravity, k.as_mut(), c.as_mut())
                }
                (_, k, c) => b.tangents(
                    z,
                    zd,
                    zdd,
                    self.gravity,
                    k.dense_mut().view_mut((0, 0), (n, n)),
                    c.dense_mut().view_mut((0, 0), (n, n)),
                ),
            }
        }
        for g in 0..self.beams.len() {
            if let Some(d) = self.beam_damping(g, q) {
                d.add_tangent(ct);
            }
        }
        for j in &self.joints {
            self.with_joint_rows(j, q, None, t, |_, _, rows| {
                for (k, r) in rows.iter().enumerate() {
                    if let Some(d) = r.force_dir {
                        let l = lambda[j.row + k];
                        self.add_force_tangent(kt, j.frames[1], q, d * l);
                        self.add_force_tangent(kt, j.frames[0], q, -d * l);
                    }
                }
            });
        }
        for l in &self.loads {
            let (force, _) = self.load_value(l, t);
            self.add_force_tangent(kt, l.frame, q, -force);
        }
    }
    /// Constraint residual g(q, t).
    fn constraints(&self, q: &DVector<f64>, t: f64, g: &mut DVector<f64>) {
        for j in &self.joints {
            self.with_joint_rows(j, q, None, t, |_, _, rows| {
                for (k, r) in rows.iter().enumerate() {
                    g[j.row + k] = r.g;
                }
            });
        }
    }
    /// Constraint Jacobian G = ∂g/∂q by rows, overwritten.
    fn jacobian_rows(&self, q: &DVector<f64>, t: f64, g: &mut JacobianRows) {
        g.fill_zero();
        for j in &self.joints {
            self.with_joint_rows(j, q, None, t, |f0, f1, rows| {
                for (k, r) in rows.iter().enumerate() {
                    self.add_row_jacobian(g, j.row + k, f0, r.w0, r.c0);
                    self.add_row_jacobian(g, j.row + k, f1, r.w1, r.c1);
                }
            });
        }
    }
    /// Constraint residual g(q, t) and Jacobian G by rows (overwritten) in one pass over the
    /// joints.
    fn constraints_and_rows(
        &self,
        q: &DVector<f64>,
        t: f64,
        g: &mut DVector<f64>,
        gm: &mut JacobianRows,
    ) {
        gm.fill_zero();
        for j in &self.joints {
            self.with_joint_rows(j, q, None, t, |f0, f1, rows| {
                for (k, r) in rows.iter().enumerate() {
                    g[j.row + k] = r.g;
                    self.add_row_jacobian(gm, j.row + k, f0, r.w0, r.c0);
                    self.add_row_jacobian(gm, j.row + k, f1, r.w1, r.c1);
                }
            });
        }
    }
    /// Acceleration bias: d²g/dt² = G q'' + bias.
    fn accel_bias(&self, q: &DVector<f64>, v: &DVector<f64>, t: f64, out: &mut DVector<f64>) {
        for j in &self.joints {
            self.with_joint_rows(j, q, Some(v), t, |_, _, rows| {
                for (k, r) in rows.iter().enumerate() {
                    out[j.row + k] = r.bias;
                }
            });
        }
    }
    /// Times where a drive law jumps, for the integrator to land on.
    fn breakpoints(&self) -> Vec<f64> {
        let drives = self.joints.iter().filter_map(|j| j.drive.as_ref());
        let loads = self.loads.iter().filter_map(|l| l.scale.as_ref());
        TimeLaw::breakpoints_of(drives.map(|d| &d.law).chain(loads))
    }
    /// Names of the joints whose equations are in the given constraint rows.
    fn joints_of_rows(&self, rows: &[usize]) -> Vec<String> {
        let mut names: Vec<String> = Vec::new();
        for &r in rows {
            if let Some(j) = self.joints.iter().rev().find(|j| j.row <= r) {
                if !names.contains(&j.name) {
                    names.push(j.name.clone());
                }
            }
        }
        names
    }
    /// Power of drives and loads (W): Σ effort × joint rate + Σ F·ṗ + τ φ̇.
    fn power(&self, q: &DVector<f64>, v: &DVector<f64>, lambda: &DVector<f64>, t: f64) -> f64 {
        let mut p = 0.0;
        for (j, jt) in self.joints.iter().enumerate() {
            if jt.drive.is_some() {
                p += self.joint_effort(j, lambda, t) * self.joint_coordinate(j, q, v).1;
            }
        }
        for l in &self.loads {
            let fs = self.frame_state(l.frame, q, Some(v));
            let (force, torque) = self.load_value(l, t);
            p += force.dot(&fs.pd) + torque * fs.phid;
        }
        p
    }
    fn turning(&self) -> Option<Turning> {
        Some(System::turning(self))
    }
    fn condenses(&self) -> bool {
        true
    }
}
