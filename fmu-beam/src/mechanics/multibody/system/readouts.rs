//! What the unit reads off a planar [`System`]'s state: joint coordinates and efforts, beam
//! tips, roots, axes and deflections.

use super::*;

impl System {
    /// Joint coordinate (rad or m) and its rate.
    pub fn joint_coordinate(&self, j: usize, q: &DVector<f64>, v: &DVector<f64>) -> (f64, f64) {
        let jt = &self.joints[j];
        let f0 = self.frame_state(jt.frames[0], q, Some(v));
        let f1 = self.frame_state(jt.frames[1], q, Some(v));
        let c = jt.coordinate(&f0, &f1);
        let body_rate = |f: &FrameState, w, c| {
            f.body
                .map_or(0.0, |b| f.jacobian_dot(w, c, self.body_coords(b, v)))
        };
        (c.g, body_rate(&f0, c.w0, c.c0) + body_rate(&f1, c.w1, c.c1))
    }

    /// Torque (revolute) or force (prismatic) that the joint's drive applies across the joint:
    /// the effort law, or the reaction of a motion drive (-λ of its row); 0 without a drive.
    pub fn joint_effort(&self, j: usize, lambda: &DVector<f64>, t: f64) -> f64 {
        let jt = &self.joints[j];
        match jt.drive.as_ref().map(|d| d.kind) {
            Some(DriveKind::Effort) => jt.effort(t, &self.inputs).unwrap_or(0.0),
            Some(DriveKind::Motion) => {
                let row = jt.row + Joint::rows_count(jt.kind, jt.drive.as_ref()) - 1;
                -lambda[row]
            }
            None => 0.0,
        }
    }

    /// World position and angle of the tip (flange b) of beam group `g`, and of its root frame.
    pub fn beam_tip(&self, g: usize, q: &DVector<f64>) -> (Vector2<f64>, f64) {
        self.flange(self.beams[g].bodies.end - 1, true, q)
    }

    /// World position and angle of flange b (`tip`) or a of `body`, a beam or a rigid bar.
    pub(super) fn flange(&self, body: usize, tip: bool, q: &DVector<f64>) -> (Vector2<f64>, f64) {
        let z = self.body_coords(body, q);
        match &self.bodies[body] {
            Body::Beam(b) => b.point(if tip { &b.flange_b } else { &b.flange_a }, z),
            Body::Rigid(r) => r_point(r, if tip { "b" } else { "a" }, z),
        }
    }

    /// World position and angle of the root (flange a) of beam group `g`: the tangent there.
    pub fn beam_root(&self, g: usize, q: &DVector<f64>) -> (Vector2<f64>, f64) {
        self.flange(self.beams[g].bodies.start, false, q)
    }

    /// Transverse displacement of the tip (flange b) of beam group `g` from the tangent at its
    /// root (flange a), whatever the frame: for a tangent frame that tangent is the frame's
    /// axis; a pinned frame's axis is the chord, from which the tip does not deflect.
    pub fn beam_tip_deflection(&self, g: usize, q: &DVector<f64>) -> f64 {
        let (root, phi) = self.beam_root(g, q);
        let d = self.beam_tip(g, q).0 - root;
        let (s, c) = phi.sin_cos();
        c * d.y - s * d.x
    }

    /// Transverse displacement of a world point from the beam's root axis (or, for a pinned
    /// frame, from the chord flange a → flange b).
    pub fn beam_transverse(&self, g: usize, q: &DVector<f64>, p: Vector2<f64>) -> f64 {
        let (root, axis) = self.beam_axis(g, q);
        let d = p - root;
        axis.x * d.y - axis.y * d.x
    }

    /// The root (flange a) of beam group `g` and the unit world direction its deflections are
    /// measured from: the root frame's axis, or for a pinned frame the chord to flange b.
    pub fn beam_axis(&self, g: usize, q: &DVector<f64>) -> (Vector2<f64>, Vector2<f64>) {
        let grp = &self.beams[g];
        let z0 = self.body_coords(grp.bodies.start, q);
        let root = Vector2::new(z0[0], z0[1]);
        let axis = if grp.more.pinned {
            let (tip, _) = self.beam_tip(g, q);
            let d = tip - root;
            if d.norm() > 0.0 {
                d / d.norm()
            } else {
                Vector2::x()
            }
        } else {
            let (s, c) = z0[2].sin_cos();
            Vector2::new(c, s)
        };
        (root, axis)
    }

    /// World position of the beam's mid-span point.
    pub fn beam_mid(&self, g: usize, q: &DVector<f64>) -> Vector2<f64> {
        let (body, map) = &self.beams[g].more.mid;
        self.bodies[*body].point(map, self.body_coords(*body, q)).0
    }
}

pub(super) fn r_point(r: &RigidBody, frame: &str, z: DVectorView<f64>) -> (Vector2<f64>, f64) {
    let map = r
        .frame_map(frame)
        .unwrap_or_else(|| r.frame_map("origin").expect("origin"));
    let (ar, _) = rot(z[2]);
    (Vector2::new(z[0], z[1]) + ar * map.s0, z[2])
}
