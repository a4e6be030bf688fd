//! A parameter's value written into the scene the model is rebuilt from.

use crate::scene::Scene;
use crate::unit::variables::ParamTarget;

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
        T::DriveValue(j) => law_mut(s, j).value = Some(v),
        T::DriveOmega(j) => law_mut(s, j).omega = Some(v),
        T::DriveRampTime(j) => law_mut(s, j).ramp_time = Some(v),
        T::DriveTimeConstant(j) => law_mut(s, j).time_constant = Some(v),
        T::DriveUntil(j) => law_mut(s, j).until = Some(v),
    }
}

pub(super) fn law_mut(s: &mut Scene, joint: usize) -> &mut crate::scene::LawSpec {
    &mut s.joints[joint]
        .drive
        .as_mut()
        .expect("drive parameters exist only for drives")
        .law
}
