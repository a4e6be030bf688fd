//! An output's value from a built model's state at the communication point.

use super::Model;
use crate::mechanics::multibody::equations::Equations;
use crate::mechanics::multibody3d::System3;
use crate::mechanics::Mechanics;
use crate::unit::variables::OutputKind;

/// A 3D output of a planar model (a 3D scene reduced to the plane): nothing leaves the plane.
pub(super) fn planar_3d(
    sys: &crate::mechanics::multibody::System,
    q: &nalgebra::DVector<f64>,
    kind: OutputKind,
) -> f64 {
    use OutputKind as K;
    match kind {
        K::TipDeflectionY(g) => sys.beam_tip_deflection(g, q),
        _ => 0.0, // tip z, deflection along z, twist and body z
    }
}

/// An output of a spatial model.
pub(super) fn spatial_output(
    m: &Model,
    sys: &System3,
    index: &crate::mechanics::from_scene::SceneIndex,
    kind: OutputKind,
) -> f64 {
    use OutputKind as K;
    let st = &m.state;
    let (q, v) = (&st.q, &st.v);
    // the tip relative to the root frame: position, and rotation root → tip
    let local = |g: usize| {
        let (root, tip) = index.beam_frames[g];
        let (x0, a0) = sys.frame_pose(root, q);
        let (x1, a1) = sys.frame_pose(tip, q);
        (a0.transpose() * (x1 - x0), a0.transpose() * a1)
    };
    let tip = |g: usize| sys.frame_pose(index.beam_frames[g].1, q).0;
    let body = |b: usize| sys.offsets[m.body_index[b]];
    match kind {
        K::TipX(g) => tip(g)[0],
        K::TipY(g) => tip(g)[1],
        K::TipZ(g) => tip(g)[2],
        K::TipDeflectionY(g) | K::TipDeflection(g) => local(g).0[1],
        K::TipDeflectionZ(g) => local(g).0[2],
        // the rotation about the beam axis: exact for a pure twist, the axial part of the
        // relative rotation with bending
        K::TipTwist(g) => {
            let r = local(g).1;
            (r[(2, 1)] - r[(1, 2)]).atan2(r[(1, 1)] + r[(2, 2)])
        }
        K::JointCoordinate(j) => sys.joint_coordinate(m.joint_index[j], q),
        K::JointRate(j) => sys.joint_rate(m.joint_index[j], q, v),
        K::JointEffort(j) => sys.joint_effort(m.joint_index[j], &st.lambda, st.t),
        K::BodyX(b) => q[body(b)],
        K::BodyY(b) => q[body(b) + 1],
        K::BodyZ(b) => q[body(b) + 2],
        K::BodyRotation { body: b, row, col } => {
            let z = sys.body_coords(m.body_index[b], q);
            crate::mechanics::multibody3d::body::frame_of(&z).2[(row, col)]
        }
        K::JointPosition { joint, axis } => {
            let f = sys.joints[m.joint_index[joint]].frames[1];
            sys.frame_pose(f, q).0[axis]
        }
        K::EnergyKinetic => sys.energy(q, v).kinetic,
        K::EnergyStrain => sys.energy(q, v).strain,
        K::EnergyPotential => sys.energy(q, v).potential,
        K::EnergyTotal => sys.energy(q, v).total(),
        _ => common_output(m, kind),
    }
}

/// Outputs that do not depend on the kind of system.
pub(super) fn common_output(m: &Model, kind: OutputKind) -> f64 {
    use OutputKind as K;
    let st = &m.state;
    match kind {
        K::EnergyWork => st.work,
        K::SolverSteps => m.stats.steps as f64,
        K::SolverNewtonIterations => m.stats.newton_iterations as f64,
        K::SolverJacobians => m.stats.jacobians as f64,
        K::SolverRejectedSteps => m.stats.rejected as f64,
        K::SolverSplitSteps => m.stats.split as f64,
        // of the integrator's own state (an interpolated state between two steps carries the
        // interpolation's error too)
        K::ConstraintResidual => {
            let mut g = nalgebra::DVector::zeros(m.system.m());
            m.system.constraints(&m.front.q, m.front.t, &mut g);
            g.amax()
        }
        K::NextEventTime => m.origin + crate::unit::interface::next_event_time(&m.system, st.t),
        K::Shape { beam, point, axis } => m.shape.point(&m.system, &st.q, beam, point)[axis],
        K::BeamAxis(g, axis) => crate::unit::shape::axis(&m.system, &st.q, g)[axis],
        // no other output is offered by a scene whose system lacks it
        _ => f64::NAN,
    }
}

pub(super) fn output(m: &Model, kind: OutputKind) -> f64 {
    use OutputKind as K;
    let sys = match &m.system {
        Mechanics::Planar(sys) => sys,
        Mechanics::Spatial(sys, index) => return spatial_output(m, sys, index, kind),
    };
    let st = &m.state;
    let (q, v) = (&st.q, &st.v);
    match kind {
        K::TipDeflection(g) => sys.beam_tip_deflection(g, q),
        K::TipX(g) => sys.beam_tip(g, q).0[0],
        K::TipY(g) => sys.beam_tip(g, q).0[1],
        K::TipPhi(g) => sys.beam_tip(g, q).1,
        K::MidDeflection(g) => sys.beam_transverse(g, q, sys.beam_mid(g, q)),
        K::SectionArea(g) => beam_section(sys, g).area,
        K::SectionSecondMoment(g) => beam_section(sys, g).second_moment,
        K::JointCoordinate(j) => sys.joint_coordinate(m.joint_index[j], q, v).0,
        K::JointRate(j) => sys.joint_coordinate(m.joint_index[j], q, v).1,
        K::JointEffort(j) => sys.joint_effort(m.joint_index[j], &st.lambda, st.t),
        K::BodyX(b) => q[sys.offsets[m.body_index[b]]],
        K::BodyY(b) => q[sys.offsets[m.body_index[b]] + 1],
        K::BodyPhi(b) => q[sys.offsets[m.body_index[b]] + 2],
        // a 3D scene run in the plane: a rotation about z
        K::BodyRotation { body: b, row, col } => {
            let (s, c) = q[sys.offsets[m.body_index[b]] + 2].sin_cos();
            [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]][row][col]
        }
        K::JointPosition { joint, axis } => {
            let f = sys.joints[m.joint_index[joint]].frames[1];
            let p = sys.frame_state(f, q, None).p;
            [p[0], p[1], 0.0][axis]
        }
        K::EnergyKinetic => sys.energy(q, v).kinetic,
        K::EnergyStrain => sys.energy(q, v).strain,
        K::EnergyPotential => sys.energy(q, v).potential,
        K::EnergyTotal => sys.energy(q, v).total(),
        K::TipZ(_) | K::TipDeflectionY(_) | K::TipDeflectionZ(_) | K::TipTwist(_) | K::BodyZ(_) => {
            planar_3d(sys, q, kind)
        }
        _ => common_output(m, kind),
    }
}

pub(super) fn beam_section(
    sys: &crate::mechanics::multibody::System,
    g: usize,
) -> crate::mechanics::beam::section::Section {
    sys.beams[g].more.section
}
