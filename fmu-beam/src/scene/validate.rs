//! Value rules of a scene. Each error names the file, the field and the rule.

use super::{
    BeamSpec, DriveKind, EffectsSpec, FrameKind, JointKind, LawSpec, RigidBodySpec, Scene,
    SectionSpec,
};
use crate::effects::EFFECTS;
use thiserror::Error;

/// Why a scene was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SceneError {
    #[error("{origin}: cannot read the scene: {message}")]
    Io { origin: String, message: String },
    #[error("{origin}: {message}")]
    Parse { origin: String, message: String },
    #[error("{origin}: field `{field}` = {value}: {rule}")]
    Invalid {
        origin: String,
        field: String,
        value: String,
        rule: String,
    },
}

pub(super) struct Checker<'a> {
    pub(super) origin: &'a str,
}

impl Checker<'_> {
    pub(super) fn fail(
        &self,
        field: &str,
        value: impl std::fmt::Display,
        rule: &str,
    ) -> SceneError {
        SceneError::Invalid {
            origin: self.origin.to_string(),
            field: field.to_string(),
            value: value.to_string(),
            rule: rule.to_string(),
        }
    }

    pub(super) fn finite(&self, field: &str, v: f64) -> Result<(), SceneError> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(self.fail(field, v, "must be a finite number"))
        }
    }

    pub(super) fn positive(&self, field: &str, v: f64) -> Result<(), SceneError> {
        self.finite(field, v)?;
        if v > 0.0 {
            Ok(())
        } else {
            Err(self.fail(field, v, "must be positive"))
        }
    }

    pub(super) fn non_negative(&self, field: &str, v: f64) -> Result<(), SceneError> {
        self.finite(field, v)?;
        if v >= 0.0 {
            Ok(())
        } else {
            Err(self.fail(field, v, "must not be negative"))
        }
    }
}

/// The smallest internal step a scene may ask for (s): below it t + h rounds to t at the times
/// a simulation reaches.
pub const MIN_STEP: f64 = 1e-9;

/// Characters allowed in names that become parts of FMI variable names.
pub(super) fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

impl Scene {
    pub(crate) fn validate(&self, origin: &str) -> Result<(), SceneError> {
        let ck = Checker { origin };
        if !is_identifier(&self.name) {
            return Err(ck.fail(
                "name",
                format!("{:?}", self.name),
                "must be an identifier (letters, digits, _; not starting with a digit)",
            ));
        }
        if !matches!(self.dimensions, 2 | 3) {
            return Err(ck.fail(
                "dimensions",
                self.dimensions,
                "must be 2 (planar) or 3 (spatial)",
            ));
        }
        for (i, g) in self.world.gravity.iter().enumerate() {
            ck.finite(&format!("world.gravity[{i}]"), *g)?;
        }
        let s = &self.solver;
        ck.positive("solver.tolerance", s.tolerance)?;
        if s.tolerance >= 1.0 {
            return Err(ck.fail("solver.tolerance", s.tolerance, "must be below 1"));
        }
        ck.positive("solver.max_step", s.max_step)?;
        if s.max_step < MIN_STEP {
            return Err(ck.fail(
                "solver.max_step",
                s.max_step,
                &format!("must be at least {MIN_STEP:e} s (a smaller step makes no progress)"),
            ));
        }
        ck.finite("solver.rho_inf", s.rho_inf)?;
        if !(0.0..=1.0).contains(&s.rho_inf) {
            return Err(ck.fail("solver.rho_inf", s.rho_inf, "must lie in [0, 1]"));
        }
        let e = &self.experiment;
        ck.finite("experiment.start_time", e.start_time)?;
        ck.finite("experiment.stop_time", e.stop_time)?;
        if e.stop_time <= e.start_time {
            return Err(ck.fail(
                "experiment.stop_time",
                e.stop_time,
                "must be after experiment.start_time",
            ));
        }
        ck.positive("experiment.step_size", e.step_size)?;

        if self.beams.is_empty() {
            return Err(ck.fail("beam", "[]", "a scene needs at least one [[beam]]"));
        }
        for (i, b) in self.beams.iter().enumerate() {
            validate_beam(&ck, b, i, self.is_3d())?;
            if self.beams[..i].iter().any(|o| o.name == b.name) {
                return Err(ck.fail(
                    &format!("beam[{i}].name"),
                    format!("{:?}", b.name),
                    "beam names must be unique",
                ));
            }
        }
        validate_effects(&ck, self)?;
        for (i, b) in self.bodies.iter().enumerate() {
            validate_body(&ck, b, i, self.is_3d())?;
        }
        let mut names: Vec<(&str, String)> = Vec::new();
        let all = self
            .beams
            .iter()
            .enumerate()
            .map(|(i, b)| (&b.name, format!("beam[{i}].name")))
            .chain(
                self.bodies
                    .iter()
                    .enumerate()
                    .map(|(i, b)| (&b.name, format!("body[{i}].name"))),
            )
            .chain(
                self.joints
                    .iter()
                    .enumerate()
                    .map(|(i, j)| (&j.name, format!("joint[{i}].name"))),
            )
            .chain(
                self.loads
                    .iter()
                    .enumerate()
                    .map(|(i, l)| (&l.name, format!("load[{i}].name"))),
            );
        for (name, field) in all {
            if !is_identifier(name) || name == "world" || name == "solver" || name == "energy" {
                return Err(ck.fail(
                    &field,
                    format!("{name:?}"),
                    "must be an identifier (letters, digits, _; not starting with a digit) other than world, solver, energy",
                ));
            }
            if names.iter().any(|(n, _)| *n == name.as_str()) {
                return Err(ck.fail(
                    &field,
                    format!("{name:?}"),
                    "names of beams, bodies, joints and loads must be unique",
                ));
            }
            names.push((name, field));
        }
        for (i, j) in self.joints.iter().enumerate() {
            let field = format!("joint[{i}]");
            for (k, f) in j.frames.iter().enumerate() {
                if !self.frame_exists(f) {
                    return Err(ck.fail(
                        &format!("{field}.frames[{k}]"),
                        format!("{f:?}"),
                        "must be `world`, `<beam>.a`, `<beam>.b` or `<body>.<frame>` of this scene",
                    ));
                }
            }
            if j.frames[0] == j.frames[1] {
                return Err(ck.fail(
                    &format!("{field}.frames"),
                    format!("{:?}", j.frames),
                    "a joint connects two different frames",
                ));
            }
            ck.finite(&format!("{field}.axis_angle"), j.axis_angle)?;
            if let Some(d) = &j.drive {
                if j.kind == JointKind::Weld {
                    return Err(ck.fail(
                        &format!("{field}.drive"),
                        format!("{:?}", d.kind),
                        "a weld joint has no motion to drive",
                    ));
                }
                validate_law(&ck, &d.law, &format!("{field}.drive"))?;
                if d.kind == DriveKind::Motion && matches!(d.law.law.as_str(), "exponential") {
                    return Err(ck.fail(
                        &format!("{field}.drive.law"),
                        "\"exponential\"",
                        "a motion drive needs a law with a continuous start (constant, spin_up, table, input)",
                    ));
                }
            }
        }
        for (i, l) in self.loads.iter().enumerate() {
            let field = format!("load[{i}]");
            if !self.frame_exists(&l.frame) {
                return Err(ck.fail(
                    &format!("{field}.frame"),
                    format!("{:?}", l.frame),
                    "must be `<beam>.a`, `<beam>.b` or `<body>.<frame>` of this scene",
                ));
            }
            if l.frame == "world" {
                return Err(ck.fail(
                    &format!("{field}.frame"),
                    "\"world\"",
                    "a load acts on a body",
                ));
            }
            for k in 0..3 {
                ck.finite(&format!("{field}.force[{k}]"), l.force[k])?;
                ck.finite(&format!("{field}.torque[{k}]"), l.torque[k])?;
            }
            if let Some(law) = &l.scale {
                validate_law(&ck, law, &format!("{field}.scale"))?;
                if l.input || law.law == "input" {
                    return Err(ck.fail(
                        &format!("{field}.scale"),
                        format!("{:?}", law.law),
                        "an input load, or an input law, cannot scale a load (use input = true)",
                    ));
                }
            }
        }
        super::space::validate_space(&ck, self)
    }

    fn frame_exists(&self, frame: &str) -> bool {
        if frame == "world" {
            return true;
        }
        match frame.split_once('.') {
            Some((beam, "a" | "b")) if self.beams.iter().any(|b| b.name == beam) => true,
            Some((body, f)) => self.bodies.iter().any(|b| {
                b.name == body && (f == "origin" || f == "com" || b.frames.contains_key(f))
            }),
            None => false,
        }
    }
}

/// `effects`: a known mode or a list of known, distinct effects that fit the beams.
fn validate_effects(ck: &Checker, scene: &Scene) -> Result<(), SceneError> {
    let names = match &scene.effects {
        EffectsSpec::Mode(m) if m == "all" || m == "auto" => return Ok(()),
        EffectsSpec::Mode(m) => {
            return Err(ck.fail(
                "effects",
                format!("{m:?}"),
                "must be \"all\", \"auto\" or a list of effects",
            ))
        }
        EffectsSpec::List(names) => names,
    };
    let known: Vec<&str> = EFFECTS.iter().map(|(n, _)| *n).collect();
    for (k, n) in names.iter().enumerate() {
        if !known.contains(&n.as_str()) {
            return Err(ck.fail(
                &format!("effects[{k}]"),
                format!("{n:?}"),
                &format!("is not an effect; the effects are {}", known.join(", ")),
            ));
        }
        if names[..k].contains(n) {
            return Err(ck.fail(
                &format!("effects[{k}]"),
                format!("{n:?}"),
                "is listed twice",
            ));
        }
    }
    let on = |e: &str| names.iter().any(|n| n == e);
    for (i, b) in scene.beams.iter().enumerate() {
        if !on("flexibility") && b.initial.tip_displacement != 0.0 {
            return Err(ck.fail(
                &format!("beam[{i}].initial.tip_displacement"),
                b.initial.tip_displacement,
                "needs the effect \"flexibility\" (a rigid beam cannot start deformed)",
            ));
        }
        if on("geometric_stiffening") && b.geometric_stiffening && !on("axial") {
            return Err(ck.fail(
                "effects",
                format!("{names:?}"),
                &format!(
                    "beam {} asks for geometric stiffening, which needs the effect \"axial\"",
                    b.name
                ),
            ));
        }
    }
    Ok(())
}

fn validate_beam(ck: &Checker, b: &BeamSpec, i: usize, three: bool) -> Result<(), SceneError> {
    let f = |name: &str| format!("beam[{i}].{name}");
    if !is_identifier(&b.name) {
        return Err(ck.fail(
            &f("name"),
            format!("{:?}", b.name),
            "must be an identifier (letters, digits, _; not starting with a digit)",
        ));
    }
    ck.positive(&f("length"), b.length)?;
    let count = |field: &str, n: usize, max: usize| -> Result<(), SceneError> {
        if n == 0 {
            return Err(ck.fail(&f(field), n, "must be at least 1"));
        }
        if n > max {
            return Err(ck.fail(&f(field), n, &format!("must be at most {max}")));
        }
        Ok(())
    };
    match (b.elements, b.substructures, b.elements_per_substructure) {
        (Some(n), None, None) => count("elements", n, 2000)?,
        (None, Some(k), Some(n)) => {
            count("substructures", k, 500)?;
            count("elements_per_substructure", n, 2000)?;
        }
        (None, None, _) => {
            return Err(ck.fail(
                &f("elements"),
                "missing",
                "give `elements`, or `substructures` with `elements_per_substructure`",
            ))
        }
        (None, Some(_), None) => {
            return Err(ck.fail(
                &f("elements_per_substructure"),
                "missing",
                "is required with `substructures`",
            ))
        }
        (Some(n), Some(_), _) | (Some(n), None, Some(_)) => {
            return Err(ck.fail(
                &f("elements"),
                n,
                "give either `elements` (one frame) or `substructures` with `elements_per_substructure`",
            ))
        }
    }
    if b.substructures.is_some() && b.initial.tip_displacement != 0.0 {
        return Err(ck.fail(
            &f("initial.tip_displacement"),
            b.initial.tip_displacement,
            "is only available for single-frame beams (`elements`)",
        ));
    }
    if b.rigid
        && (b.substructures.is_some()
            || b.geometric_stiffening
            || b.initial.tip_displacement != 0.0)
    {
        return Err(ck.fail(
            &f("rigid"),
            true,
            "a rigid beam has no substructures, stiffening or initial deformation",
        ));
    }
    if let Some(m) = b.modes {
        let (elements, _) = Scene::beam_layout(b);
        let nodal = 3 * elements; // the frame removes 3 of the 3 (N + 1) nodal coordinates
        if m == 0 || m > nodal || b.rigid {
            return Err(ck.fail(
                &f("modes"),
                m,
                &format!(
                    "must lie between 1 and the {nodal} deformation coordinates of a frame \
                     of a flexible beam"
                ),
            ));
        }
    }
    ck.positive(&f("material.rho"), b.material.rho)?;
    ck.positive(&f("material.E"), b.material.e)?;
    if let Some(g) = b.material.g {
        ck.positive(&f("material.G"), g)?;
    }
    if b.matrix_text.is_none() {
        validate_section(ck, &b.section, &f("section"), three)?;
    }
    ck.non_negative(&f("rayleigh.alpha"), b.rayleigh.alpha)?;
    ck.non_negative(&f("rayleigh.beta"), b.rayleigh.beta)?;
    for (k, p) in b.position.iter().enumerate() {
        ck.finite(&f(&format!("position[{k}]")), *p)?;
    }
    ck.finite(&f("angle"), b.angle)?;
    ck.finite(&f("initial.tip_displacement"), b.initial.tip_displacement)?;
    if b.initial.tip_displacement.abs() > 0.5 * b.length {
        return Err(ck.fail(
            &f("initial.tip_displacement"),
            b.initial.tip_displacement,
            "must be small against the length (at most half of it)",
        ));
    }
    if b.initial.tip_displacement != 0.0 && b.frame == FrameKind::Pinned {
        return Err(ck.fail(
            &f("initial.tip_displacement"),
            b.initial.tip_displacement,
            "needs frame = \"tangent\" (a pinned frame holds the tip on its axis)",
        ));
    }
    let outputs: &[&str] = if three {
        &super::BEAM_OUTPUTS_3D
    } else {
        &super::BEAM_OUTPUTS
    };
    for (k, o) in b.outputs.iter().enumerate() {
        if !outputs.contains(&o.as_str()) && o != super::SHAPE_OUTPUT {
            return Err(ck.fail(
                &f(&format!("outputs[{k}]")),
                format!("{o:?}"),
                &format!("must be one of {outputs:?} or {:?}", super::SHAPE_OUTPUT),
            ));
        }
    }
    if let Some(n) = b.shape_points {
        if n == 1 || n > crate::shape::MAX_POINTS {
            return Err(ck.fail(
                &f("shape_points"),
                n,
                &format!(
                    "must be 0 (no shape outputs) or 2 to {} (points from flange a to flange b)",
                    crate::shape::MAX_POINTS
                ),
            ));
        }
    }
    Ok(())
}

fn validate_section(
    ck: &Checker,
    s: &SectionSpec,
    field: &str,
    three: bool,
) -> Result<(), SceneError> {
    let f = |name: &str| format!("{field}.{name}");
    let given = |v: Option<f64>, name: &str| -> Result<f64, SceneError> {
        match v {
            Some(x) => {
                ck.positive(&f(name), x)?;
                Ok(x)
            }
            None => Err(ck.fail(&f(name), "missing", "is required for this section")),
        }
    };
    let unused = |v: Option<f64>, name: &str, why: &str| -> Result<(), SceneError> {
        match v {
            Some(x) => Err(ck.fail(&f(name), x, why)),
            None => Ok(()),
        }
    };
    let spatial = [(s.iy, "Iy"), (s.iz, "Iz"), (s.torsion_constant, "It")];
    if !three {
        for (v, n) in spatial {
            unused(
                v,
                n,
                "is for 3D scenes (dimensions = 3); a planar section has A and J",
            )?;
        }
    }
    match s.shape.as_deref() {
        None if three => {
            unused(
                s.second_moment,
                "J",
                "is the planar second moment; a 3D section gives Iy, Iz and It",
            )?;
            if spatial.iter().all(|(v, _)| v.is_none()) && s.area.is_none() {
                return Err(ck.fail(
                    field,
                    "missing",
                    "give `A`, `Iy`, `Iz` and `It`, or a `shape` (rectangle, circle, hollow_rectangle, hollow_circle) with its dimensions",
                ));
            }
            given(s.area, "A")?;
            for (v, n) in spatial {
                given(v, n)?;
            }
            for (v, n) in [(s.a, "a"), (s.b, "b"), (s.d, "d"), (s.t, "t")] {
                unused(
                    v,
                    n,
                    "belongs to a `shape`; with the constants given it is not used",
                )?;
            }
        }
        None => {
            if s.area.is_none() && s.second_moment.is_none() {
                return Err(ck.fail(
                    field,
                    "missing",
                    "give `A` and `J`, or a `shape` (rectangle, circle, hollow_rectangle, hollow_circle) with its dimensions",
                ));
            }
            given(s.area, "A")?;
            given(s.second_moment, "J")?;
            for (v, n) in [(s.a, "a"), (s.b, "b"), (s.d, "d"), (s.t, "t")] {
                unused(
                    v,
                    n,
                    "belongs to a `shape`; with `A` and `J` given it is not used",
                )?;
            }
        }
        Some(shape) => {
            for (v, n) in [(s.area, "A"), (s.second_moment, "J")]
                .into_iter()
                .chain(spatial)
            {
                unused(
                    v,
                    n,
                    "is computed from the `shape`; give either the shape or A and J",
                )?;
            }
            match shape {
                "rectangle" => {
                    given(s.a, "a")?;
                    given(s.b, "b")?;
                    unused(s.d, "d", "is not a dimension of a rectangle")?;
                    unused(s.t, "t", "is for hollow shapes")?;
                }
                "hollow_rectangle" => {
                    let a = given(s.a, "a")?;
                    let b = given(s.b, "b")?;
                    let t = given(s.t, "t")?;
                    unused(s.d, "d", "is not a dimension of a rectangle")?;
                    if 2.0 * t >= a.min(b) {
                        return Err(ck.fail(&f("t"), t, "must be less than half of min(a, b)"));
                    }
                }
                "circle" => {
                    given(s.d, "d")?;
                    unused(s.a, "a", "is not a dimension of a circle")?;
                    unused(s.b, "b", "is not a dimension of a circle")?;
                    unused(s.t, "t", "is for hollow shapes")?;
                }
                "hollow_circle" => {
                    let d = given(s.d, "d")?;
                    let t = given(s.t, "t")?;
                    unused(s.a, "a", "is not a dimension of a circle")?;
                    unused(s.b, "b", "is not a dimension of a circle")?;
                    if 2.0 * t >= d {
                        return Err(ck.fail(&f("t"), t, "must be less than half of d"));
                    }
                }
                other => {
                    return Err(ck.fail(
                        &f("shape"),
                        format!("{other:?}"),
                        "must be one of rectangle, circle, hollow_rectangle, hollow_circle",
                    ))
                }
            }
        }
    }
    Ok(())
}

fn validate_body(ck: &Checker, b: &RigidBodySpec, i: usize, three: bool) -> Result<(), SceneError> {
    let f = |name: &str| format!("body[{i}].{name}");
    ck.non_negative(&f("mass"), b.mass)?;
    for k in 0..3 {
        ck.non_negative(&f(&format!("inertia[{k}]")), b.inertia[k])?;
        ck.finite(&f(&format!("com[{k}]")), b.com[k])?;
        ck.finite(&f(&format!("position[{k}]")), b.position[k])?;
    }
    if three && b.mass > 0.0 && b.inertia.contains(&0.0) {
        return Err(ck.fail(
            &f("inertia"),
            format!("{:?}", b.inertia),
            "a 3D body with mass needs inertia = [Ixx, Iyy, Izz] (principal, body axes), each positive",
        ));
    }
    ck.finite(&f("angle"), b.angle)?;
    for (name, p) in &b.frames {
        if !is_identifier(name) || name == "a" || name == "b" {
            return Err(ck.fail(
                &f(&format!("frames.{name}")),
                format!("{name:?}"),
                "frame names are identifiers other than a and b",
            ));
        }
        for k in 0..3 {
            ck.finite(&f(&format!("frames.{name}[{k}]")), p.0[k])?;
        }
    }
    Ok(())
}

pub(super) fn validate_law(ck: &Checker, l: &LawSpec, field: &str) -> Result<(), SceneError> {
    let f = |name: &str| format!("{field}.{name}");
    let need = |v: Option<f64>, name: &str| -> Result<f64, SceneError> {
        let x = v.ok_or_else(|| {
            ck.fail(
                &f(name),
                "missing",
                &format!("is required by law \"{}\"", l.law),
            )
        })?;
        ck.finite(&f(name), x)?;
        Ok(x)
    };
    if let Some(u) = l.until {
        ck.non_negative(&f("until"), u)?;
    }
    match l.law.as_str() {
        "constant" => {
            need(l.value, "value")?;
        }
        "exponential" => {
            need(l.value, "value")?;
            ck.positive(&f("time_constant"), need(l.time_constant, "time_constant")?)?;
        }
        "spin_up" => {
            need(l.omega, "omega")?;
            ck.positive(&f("ramp_time"), need(l.ramp_time, "ramp_time")?)?;
        }
        "table" => {
            let t = l
                .table
                .as_ref()
                .ok_or_else(|| ck.fail(&f("table"), "missing", "is required by law \"table\""))?;
            if t.len() < 2 {
                return Err(ck.fail(&f("table"), t.len(), "needs at least two rows [t, value]"));
            }
            for (k, row) in t.iter().enumerate() {
                ck.finite(&f(&format!("table[{k}][0]")), row[0])?;
                ck.finite(&f(&format!("table[{k}][1]")), row[1])?;
                if k > 0 && row[0] <= t[k - 1][0] {
                    return Err(ck.fail(
                        &f(&format!("table[{k}][0]")),
                        row[0],
                        "times must increase",
                    ));
                }
            }
        }
        "input" => {
            if let Some(v) = l.value {
                ck.finite(&f("value"), v)?;
            }
        }
        other => {
            return Err(ck.fail(
                &f("law"),
                format!("{other:?}"),
                "must be one of constant, exponential, spin_up, table, input",
            ))
        }
    }
    Ok(())
}
