//! A parameter's value written into the scene the model is rebuilt from.

use crate::scene::{LawSpec, Scene};
use crate::unit::variables::{LawOf, LawParam, ParamTarget};

pub(super) fn apply(s: &mut Scene, t: ParamTarget, v: f64) {
    use ParamTarget as T;
    match t {
        T::GravityX => s.world.gravity[0] = v,
        T::GravityY => s.world.gravity[1] = v,
        T::GravityZ => s.world.gravity[2] = v,
        T::BeamG(i) => s.beams[i].material.g = Some(v),
        T::BeamIy(i) => s.beams[i].section.iy = Some(v),
        T::BeamIz(i) => s.beams[i].section.iz = Some(v),
        T::BeamTorsion(i) => s.beams[i].section.torsion_constant = Some(v),
        T::SolverAdaptive => s.solver.adaptive = v != 0.0,
        T::SolverTolerance => s.solver.tolerance = v,
        T::SolverMaxStep => s.solver.max_step = v,
        T::SolverRhoInf => s.solver.rho_inf = v,
        T::SolverStepBudget => s.solver.step_budget = v as u64,
        T::BeamLength(i) => s.beams[i].length = v,
        T::BeamRho(i) => s.beams[i].material.rho = v,
        T::BeamE(i) => s.beams[i].material.e = v,
        T::BeamArea(i) => s.beams[i].section.area = Some(v),
        T::BeamSecondMoment(i) => s.beams[i].section.second_moment = Some(v),
        T::BeamRayleighAlpha(i) => s.beams[i].rayleigh.alpha = v,
        T::BeamRayleighBeta(i) => s.beams[i].rayleigh.beta = v,
        T::BeamTipDisplacement(i) => s.beams[i].initial.tip_displacement = v,
        T::BodyMass(b) => s.bodies[b].mass = v,
        T::BodyInertia(b, k) => s.bodies[b].inertia[k] = v,
        T::BodyCom(b, k) => s.bodies[b].com[k] = v,
        T::LoadForce(l, k) => s.loads[l].force[k] = v,
        T::LoadTorque(l, k) => s.loads[l].torque[k] = v,
        T::Law(of, p) => set_law(law_mut(s, of), p, v),
        T::JointInitialPosition(j) => {
            s.joints[j].initial.get_or_insert_default().position = Some(v)
        }
        T::JointInitialSpeed(j) => s.joints[j].initial.get_or_insert_default().speed = Some(v),
    }
}

/// Writes `v` into the number `p` of a time law.
fn set_law(law: &mut LawSpec, p: LawParam, v: f64) {
    match p {
        LawParam::Value => law.value = Some(v),
        LawParam::Omega => law.omega = Some(v),
        LawParam::RampTime => law.ramp_time = Some(v),
        LawParam::TimeConstant => law.time_constant = Some(v),
        LawParam::Until => law.until = Some(v),
        LawParam::TableTime(k) => table_mut(law)[k][0] = v,
        LawParam::TableValue(k) => table_mut(law)[k][1] = v,
    }
}

fn table_mut(law: &mut LawSpec) -> &mut Vec<[f64; 2]> {
    law.table
        .as_mut()
        .expect("table parameters exist only for a table law")
}

fn law_mut(s: &mut Scene, of: LawOf) -> &mut LawSpec {
    match of {
        LawOf::Drive(j) => {
            &mut s.joints[j]
                .drive
                .as_mut()
                .expect("drive parameters exist only for drives")
                .law
        }
        LawOf::LoadScale(l) => s.loads[l]
            .scale
            .as_mut()
            .expect("scale parameters exist only for a scaled load"),
    }
}
