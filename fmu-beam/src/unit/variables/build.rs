//! The variables of a scene, in value-reference order: parameters (world, solver, beams,
//! joints' starts, drives, rigid bodies, loads), inputs, then outputs (beams, shapes, joints, bodies, energy, solver, input loads'
//! frames), each kind by its own function; only the variables of effects that are on.
//!
//! Over 600 lines on purpose: every variable a unit can offer, one function per kind in value-
//! reference order; the list reads best whole.

use super::{
    Binding, Causality, Initial, LawOf, LawParam, OutputKind, ParamTarget, VarType, Variability,
    Variable,
};
use crate::scene::Scene;
use crate::unit::effects::Effects;

/// Every variable of `scene` computing `effects`, without their dependencies.
pub(super) fn variables(scene: &Scene, effects: &Effects) -> Vec<Variable> {
    let mut t = Builder { vars: Vec::new() };
    world_parameters(&mut t, scene, effects);
    solver_parameters(&mut t, scene);
    beam_parameters(&mut t, scene, effects);
    joint_parameters(&mut t, scene);
    drive_parameters(&mut t, scene);
    body_parameters(&mut t, scene);
    load_parameters(&mut t, scene);
    inputs(&mut t, scene);
    beam_outputs(&mut t, scene, effects);
    shape_outputs(&mut t, scene, effects);
    joint_outputs(&mut t, scene);
    body_outputs(&mut t, scene);
    energy_outputs(&mut t, effects);
    solver_outputs(&mut t);
    load_frame_outputs(&mut t, scene);
    t.vars
}

/// The shear modulus and the section constants given directly of a 3D beam (a section from a
/// shape or a matrix file has none to set).
fn spatial_section_params(t: &mut Builder, b: &crate::scene::BeamSpec, i: usize, rigid: bool) {
    use ParamTarget as T;
    let n = &b.name;
    let mut param = |name: &str, target, unit, v: f64, desc: &str| {
        t.push(
            format!("{n}.{name}"),
            VarType::Real,
            Causality::Parameter,
            Variability::Fixed,
            Some(unit),
            desc,
            Some(v),
            Binding::Parameter(target),
        );
    };
    if b.matrix_text.is_some() {
        return;
    }
    if !rigid {
        param(
            "G",
            T::BeamG(i),
            "Pa",
            b.material.g.unwrap_or(0.0),
            "Shear modulus",
        );
    }
    let s = &b.section;
    if s.shape.is_some() {
        return;
    }
    param(
        "A",
        T::BeamArea(i),
        "m2",
        s.area.unwrap_or(0.0),
        "Section area",
    );
    if rigid {
        return;
    }
    for (name, target, value, desc) in [
        (
            "Iy",
            T::BeamIy(i),
            s.iy,
            "Second moment of area Iy (bending in the local x-z plane)",
        ),
        (
            "Iz",
            T::BeamIz(i),
            s.iz,
            "Second moment of area Iz (bending in the local x-y plane)",
        ),
        (
            "It",
            T::BeamTorsion(i),
            s.torsion_constant,
            "Saint-Venant torsion constant",
        ),
    ] {
        param(name, target, "m4", value.unwrap_or(0.0), desc);
    }
}

struct Builder {
    vars: Vec<Variable>,
}

impl Builder {
    /// A real parameter bound to `target`, with its start value `v`.
    #[allow(clippy::too_many_arguments)]
    fn real_param(
        &mut self,
        name: String,
        target: ParamTarget,
        unit: &'static str,
        v: f64,
        variability: Variability,
        desc: &str,
    ) {
        self.push(
            name,
            VarType::Real,
            Causality::Parameter,
            variability,
            Some(unit),
            desc,
            Some(v),
            Binding::Parameter(target),
        );
    }

    fn push(
        &mut self,
        name: String,
        ty: VarType,
        causality: Causality,
        variability: Variability,
        unit: Option<&'static str>,
        description: &str,
        start: Option<f64>,
        binding: Binding,
    ) {
        let initial = match causality {
            Causality::Parameter => Some(Initial::Exact),
            Causality::CalculatedParameter | Causality::Output => Some(Initial::Calculated),
            Causality::Input => None,
        };
        let unit = unit.filter(|u| *u != "1");
        self.vars.push(Variable {
            name,
            vr: self.vars.len() as u32,
            ty,
            causality,
            variability,
            initial,
            unit,
            description: description.to_string(),
            start,
            binding,
            dependencies: Vec::new(),
        });
    }

    fn output(
        &mut self,
        name: String,
        ty: VarType,
        unit: Option<&'static str>,
        desc: &str,
        kind: OutputKind,
    ) {
        let variability = if ty == VarType::Real {
            Variability::Continuous
        } else {
            Variability::Discrete
        };
        self.push(
            name,
            ty,
            Causality::Output,
            variability,
            unit,
            desc,
            None,
            Binding::Output(kind),
        );
    }
}

/// The motion interface of a motion drive reading input `slot` (named `name`): its rate and
/// acceleration as inputs of their own, and its reaction consistent with them, so that a master
/// coupling in motion causality reads the interface's effective inertia as
/// d(reaction)/d(acceleration) (fmi2GetDirectionalDerivative). Nothing for other inputs.
fn motion_interface(t: &mut Builder, scene: &Scene, slot: usize, name: &str) {
    use crate::scene::{DriveKind, JointKind};
    let Some((j, joint)) = scene.joints.iter().enumerate().find(|(_, j)| {
        j.drive
            .as_ref()
            .is_some_and(|d| d.kind == DriveKind::Motion && d.law.law == "input")
            && name.starts_with(&format!("{}.drive.", j.name))
    }) else {
        return;
    };
    let n = &joint.name;
    let (rate, units, effort) = if joint.kind == JointKind::Prismatic {
        ("velocity", ["m/s", "m/s2", "N"], "force")
    } else {
        ("speed", ["rad/s", "rad/s2", "N.m"], "torque")
    };
    for (order, what, unit) in [(1u8, rate, units[0]), (2, "acceleration", units[1])] {
        t.push(
            format!("{n}.drive.{what}"),
            VarType::Real,
            Causality::Input,
            Variability::Continuous,
            Some(unit),
            &format!(
                "Drive of joint {n}: the prescribed motion's {what}, the time derivative of \
                 order {order} of {name} over the next step (the value fmi2SetRealInputDerivatives \
                 sets; setting {name} resets it to 0, so set it after {name})"
            ),
            Some(0.0),
            Binding::InputDerivative { slot, order },
        );
    }
    t.output(
        format!("{n}.drive.reaction"),
        VarType::Real,
        Some(units[2]),
        &format!(
            "Reaction {effort} of the drive of joint {n} on frame 1, consistent with the state and \
             the inputs as set now (direct feedthrough of {n}.drive.acceleration: its derivative \
             is the interface's effective inertia); {n}.{effort} is the last step's"
        ),
        OutputKind::DriveReaction(j),
    );
}

/// The world axes of the scene's outputs.
fn axes(scene: &Scene) -> &'static [&'static str] {
    if scene.is_3d() {
        &["x", "y", "z"]
    } else {
        &["x", "y"]
    }
}

/// The gravity field, when gravity is on.
fn world_parameters(t: &mut Builder, scene: &Scene, effects: &Effects) {
    use ParamTarget as T;
    use Variability as V;
    let g = scene.world.gravity;
    if effects.gravity {
        t.real_param(
            "world.gravity.x".into(),
            T::GravityX,
            "m/s2",
            g[0],
            V::Fixed,
            "Gravity, world x",
        );
        t.real_param(
            "world.gravity.y".into(),
            T::GravityY,
            "m/s2",
            g[1],
            V::Fixed,
            "Gravity, world y",
        );
        if scene.is_3d() {
            t.real_param(
                "world.gravity.z".into(),
                T::GravityZ,
                "m/s2",
                g[2],
                V::Fixed,
                "Gravity, world z",
            );
        }
    }
}

/// The solver settings, tunable between communication steps.
fn solver_parameters(t: &mut Builder, scene: &Scene) {
    use Binding::Parameter as P;
    use Causality as C;
    use ParamTarget as T;
    use Variability as V;
    let s = &scene.solver;
    t.push(
        "solver.adaptive".into(),
        VarType::Boolean,
        C::Parameter,
        V::Tunable,
        None,
        "Local error control (true) or a fixed internal step of solver.max_step (false)",
        Some(if s.adaptive { 1.0 } else { 0.0 }),
        P(T::SolverAdaptive),
    );
    t.real_param(
        "solver.tolerance".into(),
        T::SolverTolerance,
        "1",
        s.tolerance,
        V::Tunable,
        "Relative tolerance of the error control and of the Newton iteration",
    );
    t.real_param(
        "solver.max_step".into(),
        T::SolverMaxStep,
        "s",
        s.max_step,
        V::Tunable,
        "Largest internal step; the fixed step when solver.adaptive is false",
    );
    t.real_param(
        "solver.rho_inf".into(),
        T::SolverRhoInf,
        "1",
        s.rho_inf,
        V::Tunable,
        "Generalized-alpha spectral radius at infinity (1: no numerical damping)",
    );
    t.push(
        "solver.step_budget".into(),
        VarType::Integer,
        C::Parameter,
        V::Tunable,
        None,
        "Internal steps one communication step may take before it ends in fmi2Discard",
        Some(s.step_budget as f64),
        P(T::SolverStepBudget),
    );
}

/// Each beam's material, section, damping and initial-state parameters (only those of the effects that are on).
fn beam_parameters(t: &mut Builder, scene: &Scene, effects: &Effects) {
    use Binding::Output as O;
    use Causality as C;
    use OutputKind as K;
    use ParamTarget as T;
    use Variability as V;
    for (i, (b, fx)) in scene.beams.iter().zip(&effects.beams).enumerate() {
        let n = &b.name;
        t.real_param(
            format!("{n}.length"),
            T::BeamLength(i),
            "m",
            b.length,
            V::Fixed,
            "Undeformed length",
        );
        t.real_param(
            format!("{n}.rho"),
            T::BeamRho(i),
            "kg/m3",
            b.material.rho,
            V::Fixed,
            "Density",
        );
        let matrices = b.matrix_text.is_some();
        if !fx.rigid && !matrices {
            t.real_param(
                format!("{n}.E"),
                T::BeamE(i),
                "Pa",
                b.material.e,
                V::Fixed,
                "Young's modulus",
            );
        }
        if scene.is_3d() {
            spatial_section_params(t, b, i, fx.rigid);
        } else if b.section.shape.is_none() {
            t.real_param(
                format!("{n}.A"),
                T::BeamArea(i),
                "m2",
                b.section.area.unwrap_or(0.0),
                V::Fixed,
                "Section area",
            );
            t.real_param(
                format!("{n}.J"),
                T::BeamSecondMoment(i),
                "m4",
                b.section.second_moment.unwrap_or(0.0),
                V::Fixed,
                "Second moment of area, in-plane bending",
            );
        } else {
            t.push(
                format!("{n}.A"),
                VarType::Real,
                C::CalculatedParameter,
                V::Fixed,
                Some("m2"),
                "Section area, from the section shape",
                None,
                O(K::SectionArea(i)),
            );
            t.push(
                format!("{n}.J"),
                VarType::Real,
                C::CalculatedParameter,
                V::Fixed,
                Some("m4"),
                "Second moment of area, from the section shape",
                None,
                O(K::SectionSecondMoment(i)),
            );
        }
        if fx.rigid {
            continue;
        }
        if fx.options.damping {
            t.real_param(
                format!("{n}.rayleigh.alpha"),
                T::BeamRayleighAlpha(i),
                "1/s",
                b.rayleigh.alpha,
                V::Fixed,
                "Rayleigh damping, mass-proportional",
            );
            t.real_param(
                format!("{n}.rayleigh.beta"),
                T::BeamRayleighBeta(i),
                "s",
                b.rayleigh.beta,
                V::Fixed,
                "Rayleigh damping, stiffness-proportional",
            );
        }
        if scene.is_3d() {
            continue;
        }
        t.real_param(
            format!("{n}.initial.tip_displacement"),
            T::BeamTipDisplacement(i),
            "m",
            b.initial.tip_displacement,
            V::Fixed,
            "Initial static transverse tip displacement",
        );
    }
}

/// Each joint's start, where the scene gives it: `<joint>.initial.position`, `.speed`.
fn joint_parameters(t: &mut Builder, scene: &Scene) {
    use ParamTarget as T;
    for (i, j) in scene.joints.iter().enumerate() {
        let Some(start) = &j.initial else { continue };
        let (what, units) = if j.kind == crate::scene::JointKind::Prismatic {
            ("position along the axis", ["m", "m/s"])
        } else {
            ("angle", ["rad", "rad/s"])
        };
        if let Some(v) = start.position {
            t.real_param(
                format!("{}.initial.position", j.name),
                T::JointInitialPosition(i),
                units[0],
                v,
                Variability::Fixed,
                &format!("Joint {what} at the start (the bodies are placed to meet it)"),
            );
        }
        if let Some(v) = start.speed {
            t.real_param(
                format!("{}.initial.speed", j.name),
                T::JointInitialSpeed(i),
                units[1],
                v,
                Variability::Fixed,
                &format!("Rate of the joint {what} at the start"),
            );
        }
    }
}

/// Each drive's law parameters (a law read from an input has only its input).
fn drive_parameters(t: &mut Builder, scene: &Scene) {
    for (i, j) in scene.joints.iter().enumerate() {
        let Some(d) = &j.drive else { continue };
        let unit = match (j.kind, d.kind) {
            (crate::scene::JointKind::Prismatic, crate::scene::DriveKind::Motion) => "m",
            (crate::scene::JointKind::Prismatic, crate::scene::DriveKind::Effort) => "N",
            (_, crate::scene::DriveKind::Motion) => "rad",
            (_, crate::scene::DriveKind::Effort) => "N.m",
        };
        if d.law.law != "input" {
            law_parameters(
                t,
                &format!("{}.drive", j.name),
                &d.law,
                LawOf::Drive(i),
                unit,
            );
        }
    }
}

/// The numbers of a time law as parameters `<prefix>.value`, `.omega`, …, a table's rows as
/// `<prefix>.table.t[k]` and `<prefix>.table.value[k]` (a table of at most
/// [`crate::scene::TABLE_PARAMETER_ROWS`] rows); `unit` is the unit of its values.
fn law_parameters(
    t: &mut Builder,
    prefix: &str,
    law: &crate::scene::LawSpec,
    of: LawOf,
    unit: &'static str,
) {
    use LawParam as L;
    use ParamTarget::Law;
    let fixed = Variability::Fixed;
    let what = match of {
        LawOf::Drive(_) => "Drive law",
        LawOf::LoadScale(_) => "Load scale law",
    };
    for (field, p, u, v, desc) in [
        ("value", L::Value, unit, law.value, "value or final value"),
        (
            "omega",
            L::Omega,
            "rad/s",
            law.omega,
            "spin-up's final angular speed",
        ),
        (
            "ramp_time",
            L::RampTime,
            "s",
            law.ramp_time,
            "spin-up's ramp duration T",
        ),
        (
            "time_constant",
            L::TimeConstant,
            "s",
            law.time_constant,
            "exponential's time constant",
        ),
        (
            "until",
            L::Until,
            "s",
            law.until,
            "the law is zero after this time",
        ),
    ] {
        if let Some(v) = v {
            t.real_param(
                format!("{prefix}.{field}"),
                Law(of, p),
                u,
                v,
                fixed,
                &format!("{what}: {desc}"),
            );
        }
    }
    let rows = law
        .table
        .iter()
        .filter(|t| t.len() <= crate::scene::TABLE_PARAMETER_ROWS)
        .flatten();
    for (k, row) in rows.enumerate() {
        t.real_param(
            format!("{prefix}.table.t[{}]", k + 1),
            Law(of, L::TableTime(k)),
            "s",
            row[0],
            fixed,
            &format!("{what}: time of table row {}", k + 1),
        );
        t.real_param(
            format!("{prefix}.table.value[{}]", k + 1),
            Law(of, L::TableValue(k)),
            unit,
            row[1],
            fixed,
            &format!("{what}: value of table row {}", k + 1),
        );
    }
}

/// Each rigid body's mass, moments of inertia about its centre of mass and centre of mass.
fn body_parameters(t: &mut Builder, scene: &Scene) {
    use ParamTarget as T;
    let fixed = Variability::Fixed;
    let xyz = axes(scene);
    for (i, b) in scene.bodies.iter().enumerate() {
        let n = &b.name;
        t.real_param(
            format!("{n}.mass"),
            T::BodyMass(i),
            "kg",
            b.mass,
            fixed,
            "Mass",
        );
        if scene.is_3d() {
            for (k, c) in xyz.iter().enumerate() {
                t.real_param(
                    format!("{n}.inertia.{c}"),
                    T::BodyInertia(i, k),
                    "kg.m2",
                    b.inertia[k],
                    fixed,
                    &format!("Principal moment of inertia about the centre of mass, body axis {c}"),
                );
            }
        } else {
            t.real_param(
                format!("{n}.inertia"),
                T::BodyInertia(i, 2),
                "kg.m2",
                b.inertia[2],
                fixed,
                "Moment of inertia about the centre of mass (about z)",
            );
        }
        for (k, c) in xyz.iter().enumerate() {
            t.real_param(
                format!("{n}.com.{c}"),
                T::BodyCom(i, k),
                "m",
                b.com[k],
                fixed,
                &format!("Centre of mass in the body frame, body axis {c}"),
            );
        }
    }
}

/// Each load's force and torque (named as the inputs of a load with `input = true` are) and
/// its scale law's numbers; a load read from inputs has only its inputs. The components the
/// running system holds are tunable (a change between steps is met as an input's jump is);
/// a 3D scene that runs as planar keeps its out-of-plane ones fixed, and a law stays fixed.
fn load_parameters(t: &mut Builder, scene: &Scene) {
    use ParamTarget as T;
    let fixed = Variability::Fixed;
    let runs_planar = !scene.is_3d() || scene.planar_reduction().is_ok();
    let variability = |target: T| {
        let part = match target {
            T::LoadForce(_, k) => k,
            T::LoadTorque(_, k) => 3 + k,
            _ => return fixed,
        };
        if !runs_planar || matches!(part, 0 | 1 | 5) {
            Variability::Tunable
        } else {
            fixed
        }
    };
    for (i, l) in scene.loads.iter().enumerate().filter(|(_, l)| !l.input) {
        let n = &l.name;
        let (f, m) = (l.force, l.torque);
        let force = "Force, world axes";
        let torque = "Torque, world axes";
        let planar = [
            ("fx", T::LoadForce(i, 0), "N", f[0], force),
            ("fy", T::LoadForce(i, 1), "N", f[1], force),
            ("torque", T::LoadTorque(i, 2), "N.m", m[2], "Torque about z"),
        ];
        let spatial = [
            ("fx", T::LoadForce(i, 0), "N", f[0], force),
            ("fy", T::LoadForce(i, 1), "N", f[1], force),
            ("fz", T::LoadForce(i, 2), "N", f[2], force),
            ("tx", T::LoadTorque(i, 0), "N.m", m[0], torque),
            ("ty", T::LoadTorque(i, 1), "N.m", m[1], torque),
            ("tz", T::LoadTorque(i, 2), "N.m", m[2], torque),
        ];
        let parts: &[_] = if scene.is_3d() { &spatial } else { &planar };
        for &(what, target, unit, v, desc) in parts {
            t.real_param(
                format!("{n}.{what}"),
                target,
                unit,
                v,
                variability(target),
                &format!("Load on {}: {desc} ({what})", l.frame),
            );
        }
        if let Some(scale) = &l.scale {
            law_parameters(t, &format!("{n}.scale"), scale, LawOf::LoadScale(i), "1");
        }
    }
}

/// The inputs (drives and loads given by the master), each with its motion interface.
fn inputs(t: &mut Builder, scene: &Scene) {
    use Causality as C;
    use Variability as V;
    for (slot, input) in crate::mechanics::from_scene::input_slots(scene)
        .into_iter()
        .enumerate()
    {
        t.push(
            input.name.clone(),
            VarType::Real,
            C::Input,
            V::Continuous,
            Some(input.unit),
            &input.description,
            Some(input.start),
            Binding::Input(slot),
        );
        motion_interface(t, scene, slot, &input.name);
    }
}

/// Each beam's tip and mid outputs (a rigid beam has no deflection or twist).
fn beam_outputs(t: &mut Builder, scene: &Scene, effects: &Effects) {
    use OutputKind as K;
    for (i, (b, fx)) in scene.beams.iter().zip(&effects.beams).enumerate() {
        for o in scene.beam_outputs(b) {
            if fx.rigid && (o.contains("deflection") || o == "tip.twist") {
                continue; // a rigid beam does not deflect
            }
            let (kind, unit, desc) = match o {
                "tip.deflection" => (
                    K::TipDeflection(i),
                    "m",
                    "Transverse displacement of flange b from the tangent at flange a",
                ),
                "tip.x" => (K::TipX(i), "m", "World x of flange b"),
                "tip.y" => (K::TipY(i), "m", "World y of flange b"),
                "tip.z" => (K::TipZ(i), "m", "World z of flange b"),
                "tip.deflection_y" => (K::TipDeflectionY(i), "m",
                    "Displacement of flange b along the root frame's y axis, from the root axis"),
                "tip.deflection_z" => (K::TipDeflectionZ(i), "m",
                    "Displacement of flange b along the root frame's z axis, from the root axis"),
                "tip.twist" => (K::TipTwist(i), "rad",
                    "Rotation of flange b about the beam axis, relative to the root frame"),
                "mid.deflection" => (K::MidDeflection(i), "m",
                    "Transverse displacement at mid-span from the root axis (the chord for a pinned frame)"),
                _ => (K::TipPhi(i), "rad", "World rotation of flange b"),
            };
            t.output(
                format!("{}.{o}", b.name),
                VarType::Real,
                Some(unit),
                desc,
                kind,
            );
        }
    }
}

/// Each beam's shape points and the axis its deflections are measured from.
fn shape_outputs(t: &mut Builder, scene: &Scene, effects: &Effects) {
    use OutputKind as K;
    let xyz = axes(scene);
    for (i, (b, fx)) in scene.beams.iter().zip(&effects.beams).enumerate() {
        let points = crate::unit::shape::stations(b, fx.rigid).len();
        if points == 0 {
            continue;
        }
        for (axis, c) in xyz.iter().enumerate() {
            for point in 0..points {
                t.output(
                    format!("{}.shape.{c}[{}]", b.name, point + 1),
                    VarType::Real,
                    Some("m"),
                    &format!(
                        "World {c} of point {} of {points} of the deformed centre line, equally \
                         spaced from flange a to flange b along the undeformed axis",
                        point + 1
                    ),
                    K::Shape {
                        beam: i,
                        point,
                        axis,
                    },
                );
            }
        }
        for (axis, c) in xyz.iter().enumerate() {
            t.output(
                format!("{}.axis.{c}", b.name),
                VarType::Real,
                None,
                &format!(
                    "World {c} of the unit direction the deflections are measured from (the \
                     root frame's axis; for a planar pinned frame the chord)"
                ),
                K::BeamAxis(i, axis),
            );
        }
    }
}

/// Each joint's position, then each revolute or prismatic joint's coordinate, rate and effort.
fn joint_outputs(t: &mut Builder, scene: &Scene) {
    use OutputKind as K;
    let xyz = axes(scene);
    for (i, j) in scene.joints.iter().enumerate() {
        for (axis, c) in xyz.iter().enumerate() {
            t.output(
                format!("{}.{c}", j.name),
                VarType::Real,
                Some("m"),
                &format!(
                    "World {c} of the joint's second frame (where a revolute, spherical or \
                     weld joint is; the sliding frame of a prismatic joint)"
                ),
                K::JointPosition { joint: i, axis },
            );
        }
    }
    for (i, j) in scene.joints.iter().enumerate() {
        let n = &j.name;
        match j.kind {
            crate::scene::JointKind::Revolute => {
                t.output(
                    format!("{n}.angle"),
                    VarType::Real,
                    Some("rad"),
                    "Joint angle, frame 1 relative to frame 0",
                    K::JointCoordinate(i),
                );
                t.output(
                    format!("{n}.speed"),
                    VarType::Real,
                    Some("rad/s"),
                    "Joint angular speed",
                    K::JointRate(i),
                );
                t.output(format!("{n}.torque"), VarType::Real, Some("N.m"),
                    "Torque of the joint's drive on frame 1 (the reaction of a motion drive; 0 without drive)", K::JointEffort(i));
            }
            crate::scene::JointKind::Prismatic => {
                t.output(
                    format!("{n}.position"),
                    VarType::Real,
                    Some("m"),
                    "Position of frame 1 along the axis of frame 0",
                    K::JointCoordinate(i),
                );
                t.output(
                    format!("{n}.velocity"),
                    VarType::Real,
                    Some("m/s"),
                    "Sliding velocity",
                    K::JointRate(i),
                );
                t.output(format!("{n}.force"), VarType::Real, Some("N"),
                    "Force of the joint's drive on frame 1 along the axis (the reaction of a motion drive; 0 without drive)", K::JointEffort(i));
            }
            crate::scene::JointKind::Weld | crate::scene::JointKind::Spherical => {}
        }
    }
}

/// Each rigid body's frame.
fn body_outputs(t: &mut Builder, scene: &Scene) {
    let xyz = axes(scene);
    use OutputKind as K;
    for (i, b) in scene.bodies.iter().enumerate() {
        let n = &b.name;
        t.output(
            format!("{n}.x"),
            VarType::Real,
            Some("m"),
            "World x of the body frame",
            K::BodyX(i),
        );
        t.output(
            format!("{n}.y"),
            VarType::Real,
            Some("m"),
            "World y of the body frame",
            K::BodyY(i),
        );
        if scene.is_3d() {
            t.output(
                format!("{n}.z"),
                VarType::Real,
                Some("m"),
                "World z of the body frame",
                K::BodyZ(i),
            );
            for row in 0..3 {
                for col in 0..3 {
                    t.output(
                        format!("{n}.R[{},{}]", row + 1, col + 1),
                        VarType::Real,
                        None,
                        &format!(
                            "Rotation of the body frame: world {} component of body axis {}",
                            xyz[row], xyz[col]
                        ),
                        K::BodyRotation { body: i, row, col },
                    );
                }
            }
            continue;
        }
        t.output(
            format!("{n}.phi"),
            VarType::Real,
            Some("rad"),
            "World angle of the body frame",
            K::BodyPhi(i),
        );
    }
}

/// The energy balance (no strain energy without deformation, no potential without gravity).
fn energy_outputs(t: &mut Builder, effects: &Effects) {
    use OutputKind as K;
    for (name, kind, desc) in [
        (
            "energy.work",
            K::EnergyWork,
            "Work done by drives and loads since the start",
        ),
        ("energy.kinetic", K::EnergyKinetic, "Kinetic energy"),
        ("energy.strain", K::EnergyStrain, "Strain energy"),
        (
            "energy.potential",
            K::EnergyPotential,
            "Potential energy of gravity",
        ),
        (
            "energy.total",
            K::EnergyTotal,
            "Kinetic + strain + potential energy",
        ),
    ] {
        let strain = kind == K::EnergyStrain && effects.beams.iter().all(|b| b.rigid);
        if strain || (kind == K::EnergyPotential && !effects.gravity) {
            continue; // no deformation, or no gravity field
        }
        t.output(name.into(), VarType::Real, Some("J"), desc, kind);
    }
}

/// The solver's counters, constraint drift and next event time.
fn solver_outputs(t: &mut Builder) {
    use Binding::Output as O;
    use Causality as C;
    use OutputKind as K;
    use Variability as V;
    t.output(
        "solver.constraint_residual".into(),
        VarType::Real,
        None,
        "Largest residual of the joint equations |g(q, t)| (m or rad) at the end of the last internal step: the constraint drift",
        K::ConstraintResidual,
    );
    for (name, kind, desc) in [
        (
            "solver.steps",
            K::SolverSteps,
            "Accepted internal steps since initialization",
        ),
        (
            "solver.newton_iterations",
            K::SolverNewtonIterations,
            "Newton iterations since initialization",
        ),
        (
            "solver.jacobians",
            K::SolverJacobians,
            "Iteration-matrix factorizations since initialization",
        ),
        (
            "solver.rejected_steps",
            K::SolverRejectedSteps,
            "Rejected internal steps since initialization",
        ),
        (
            "solver.split_steps",
            K::SolverSplitSteps,
            "Fixed steps cut shorter than solver.max_step since initialization (to land on a \
             drive law's jump or on a communication point of a unit with inputs, or after a \
             failed Newton iteration); 0 with error control",
        ),
    ] {
        t.output(name.into(), VarType::Integer, None, desc, kind);
    }
    t.push(
        "solver.next_event_time".into(),
        VarType::Real,
        C::Output,
        V::Discrete,
        Some("s"),
        "Time of the next jump of a drive or load law after the current time, where the unit \
         lands and restarts (a master coupling units mechanically lands there too); \
         1.7976931348623157e308 when none",
        None,
        O(K::NextEventTime),
    );
}

/// The frames of input loads: what a master joining this unit mechanically reads.
fn load_frame_outputs(t: &mut Builder, scene: &Scene) {
    use OutputKind as K;
    // the frames of input loads: what a master joining this unit mechanically reads
    for (i, l) in scene.loads.iter().enumerate().filter(|(_, l)| l.input) {
        for (suffix, what, unit, desc) in
            crate::unit::interface::frame_outputs(if scene.is_3d() { 3 } else { 2 })
        {
            t.output(
                format!("{}.{suffix}", l.name),
                VarType::Real,
                Some(unit),
                desc,
                K::LoadFrame(i, what),
            );
        }
    }
}
