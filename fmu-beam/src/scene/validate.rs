//! Value rules of a scene. Each error names the file, the field and the rule.

use super::paths::Part;
use super::rules::{self as r, Rule};
use super::{
    BeamSpec, DriveKind, EffectsSpec, FrameKind, JointKind, RigidBodySpec, Scene, SectionSpec,
    Short,
};
use thiserror::Error;

/// Why a scene was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SceneError {
    /// The scene file, or a beam's matrix file, cannot be read.
    #[error("{origin}: cannot read the scene: {message}")]
    Io {
        /// The scene file's path (and, for a matrix file, the field that names it).
        origin: String,
        /// The system's error.
        message: String,
    },
    /// A file the scene names is refused before it is read: outside the scene's directory, not
    /// a regular file, over its cap, not text.
    #[error("{origin}: field `{field}` = {file}: {rule}")]
    File {
        /// The scene file's path.
        origin: String,
        /// The field that names the file, such as `beam[0].matrix_file`.
        field: String,
        /// The name as the scene wrote it (quoted).
        file: String,
        /// The rule it breaks ([`super::files::FileRefusal`]).
        rule: String,
    },
    /// The text is not TOML, or not of the scene's shape (unknown field, wrong type, …).
    #[error("{origin}: {message}")]
    Parse {
        /// Where the text came from: a path, or what the caller named it.
        origin: String,
        /// The TOML parser's message, with its line and column (never the text there).
        message: String,
    },
    /// A value that breaks one of the scene's rules ([`Rule`]).
    #[error("{origin}: field `{field}` = {value}: {rule}")]
    Invalid {
        /// Where the scene came from: a path, or what the caller named it ("parameters" for
        /// values set on an instance).
        origin: String,
        /// The field's path in the scene, such as `beam[0].material.e`.
        field: String,
        /// The value refused, as written (a number in the field's unit).
        value: String,
        /// The rule's text, with the values that decided it when there are some.
        rule: String,
        /// The [`Rule::code`] of the rule (`rules::RULES`).
        code: &'static str,
    },
}

pub(super) struct Checker<'a> {
    pub(super) origin: &'a str,
}

impl Checker<'_> {
    /// The error of `rule` at `field`: its message's rule is the rule's text.
    pub(super) fn fail(
        &self,
        rule: &Rule,
        field: &str,
        value: impl std::fmt::Display,
    ) -> SceneError {
        self.fail_with(rule, field, value, "")
    }

    /// The same, the rule's text followed by `detail` (the values that decided it).
    pub(super) fn fail_with(
        &self,
        rule: &Rule,
        field: &str,
        value: impl std::fmt::Display,
        detail: &str,
    ) -> SceneError {
        SceneError::Invalid {
            origin: self.origin.to_string(),
            field: field.to_string(),
            value: super::limits::abbreviate(&value.to_string(), 80),
            rule: format!("{}{detail}", rule.text),
            code: rule.code,
        }
    }

    /// A finite number, within its quantity's range where it has one ([`r::RANGES`]).
    pub(super) fn finite(&self, field: &str, v: f64) -> Result<(), SceneError> {
        if !v.is_finite() {
            return Err(self.fail(&r::FINITE, field, Short(v)));
        }
        // within every range's bound: no rule to look up (most numbers of a scene; the lookup
        // matches the field against each range's patterns)
        if v.abs() <= r::LEAST_RANGE {
            return Ok(());
        }
        match r::range_of(field) {
            Some((rule, bound)) if v.abs() > *bound => Err(self.fail(rule, field, Short(v))),
            _ => Ok(()),
        }
    }

    pub(super) fn positive(&self, field: &str, v: f64) -> Result<(), SceneError> {
        self.finite(field, v)?;
        if v > 0.0 {
            Ok(())
        } else {
            Err(self.fail(&r::POSITIVE, field, Short(v)))
        }
    }

    pub(super) fn non_negative(&self, field: &str, v: f64) -> Result<(), SceneError> {
        self.finite(field, v)?;
        if v >= 0.0 {
            Ok(())
        } else {
            Err(self.fail(&r::NON_NEGATIVE, field, Short(v)))
        }
    }
}

/// The smallest internal step a scene may ask for (s): below it t + h rounds to t at the times
/// a simulation reaches.
pub const MIN_STEP: f64 = 1e-9;

/// The longest internal step a scene may ask for (s): no flexible multibody motion is resolved
/// by longer steps, and the integrator's rounding guards (a remainder of 1e-6 of a step is
/// covered by a Taylor step) are sized against it. (Up to 1e308 was accepted: at 1e6 s the
/// pendulum took no step and stayed at rest, at 1e5 s it stopped short, with fmi2OK.)
pub const MAX_STEP: f64 = 1.0;

/// The largest `solver.step_budget`: ten times the default, so that a doStep a master allowed
/// the most still ends within about a minute (the largest fmi2Integer, 2147483647 work units,
/// let a doStep of the pendulum run 151 s: issue 45's fuzz stage found it).
pub const MAX_STEP_BUDGET: u64 = 10 * super::DEFAULT_STEP_BUDGET;

/// Characters allowed in names that become parts of FMI variable names.
pub(super) fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

impl Scene {
    pub(crate) fn validate(&self, origin: &str) -> Result<(), SceneError> {
        let ck = Checker { origin };
        super::limits::parts(&ck, self)?;
        super::limits::name_fits(&ck, "name", &self.name)?;
        if !is_identifier(&self.name) {
            return Err(ck.fail(&r::SCENE_NAME, "name", format!("{:?}", self.name)));
        }
        super::limits::description(&ck, self)?;
        if !matches!(self.dimensions, 2 | 3) {
            return Err(ck.fail(&r::DIMENSIONS, "dimensions", self.dimensions));
        }
        for (i, g) in self.world.gravity.iter().enumerate() {
            ck.finite(&format!("world.gravity[{i}]"), *g)?;
        }
        let s = &self.solver;
        ck.positive("solver.tolerance", s.tolerance)?;
        if s.tolerance >= 1.0 {
            return Err(ck.fail(
                &r::TOLERANCE_BELOW_ONE,
                "solver.tolerance",
                Short(s.tolerance),
            ));
        }
        if s.tolerance < r::MIN_TOLERANCE {
            return Err(ck.fail(&r::TOLERANCE_FLOOR, "solver.tolerance", Short(s.tolerance)));
        }
        ck.positive("solver.max_step", s.max_step)?;
        if s.max_step < MIN_STEP {
            return Err(ck.fail(&r::MIN_STEP, "solver.max_step", s.max_step));
        }
        if s.max_step > MAX_STEP {
            return Err(ck.fail(&r::MAX_STEP, "solver.max_step", s.max_step));
        }
        if !(1..=MAX_STEP_BUDGET).contains(&s.step_budget) {
            return Err(ck.fail(&r::STEP_BUDGET, "solver.step_budget", s.step_budget));
        }
        ck.finite("solver.rho_inf", s.rho_inf)?;
        if !(0.0..=1.0).contains(&s.rho_inf) {
            return Err(ck.fail(&r::RHO_INF, "solver.rho_inf", s.rho_inf));
        }
        let e = &self.experiment;
        ck.finite("experiment.start_time", e.start_time)?;
        ck.finite("experiment.stop_time", e.stop_time)?;
        if e.stop_time <= e.start_time {
            return Err(ck.fail(&r::STOP_AFTER_START, "experiment.stop_time", e.stop_time));
        }
        ck.positive("experiment.step_size", e.step_size)?;

        if self.beams.is_empty() {
            return Err(ck.fail(&r::A_BEAM, "beam", "[]"));
        }
        for (i, b) in self.beams.iter().enumerate() {
            let path = self.path_of(Part::Beam, i);
            validate_beam(&ck, b, &path, self.is_3d())?;
            if self.beams[..i].iter().any(|o| o.name == b.name) {
                return Err(ck.fail(
                    &r::BEAM_NAMES_UNIQUE,
                    &format!("{path}.name"),
                    format!("{:?}", b.name),
                ));
            }
        }
        super::limits::size(&ck, self)?;
        validate_effects(&ck, self)?;
        super::accuracy::validate(&ck, self)?;
        for (i, b) in self.bodies.iter().enumerate() {
            validate_body(&ck, b, &self.path_of(Part::Body, i), self.is_3d())?;
        }
        let mut names: Vec<(&str, String)> = Vec::new();
        let all = self
            .beams
            .iter()
            .enumerate()
            .map(|(i, b)| (&b.name, format!("{}.name", self.path_of(Part::Beam, i))))
            .chain(
                self.bodies
                    .iter()
                    .enumerate()
                    .map(|(i, b)| (&b.name, format!("{}.name", self.path_of(Part::Body, i)))),
            )
            .chain(
                self.joints
                    .iter()
                    .enumerate()
                    .map(|(i, j)| (&j.name, format!("{}.name", self.path_of(Part::Joint, i)))),
            )
            .chain(
                self.loads
                    .iter()
                    .enumerate()
                    .map(|(i, l)| (&l.name, format!("{}.name", self.path_of(Part::Load, i)))),
            );
        for (name, field) in all {
            super::limits::name_fits(&ck, &field, name)?;
            if !is_identifier(name) || r::RESERVED_NAMES.contains(&name.as_str()) {
                return Err(ck.fail(&r::PART_NAME, &field, format!("{name:?}")));
            }
            if names.iter().any(|(n, _)| *n == name.as_str()) {
                return Err(ck.fail(&r::NAMES_UNIQUE, &field, format!("{name:?}")));
            }
            names.push((name, field));
        }
        for (i, j) in self.joints.iter().enumerate() {
            let field = self.path_of(Part::Joint, i);
            for (k, f) in j.frames.iter().enumerate() {
                if !self.frame_exists(f) {
                    return Err(ck.fail(
                        &r::JOINT_FRAME,
                        &format!("{field}.frames[{k}]"),
                        format!("{f:?}"),
                    ));
                }
            }
            if j.frames[0] == j.frames[1] {
                return Err(ck.fail(
                    &r::JOINT_FRAMES_DIFFER,
                    &format!("{field}.frames"),
                    format!("{:?}", j.frames),
                ));
            }
            ck.finite(&format!("{field}.axis_angle"), j.axis_angle)?;
            super::joint_start::validate_start(&ck, j, &field)?;
            if let Some(d) = &j.drive {
                if j.kind == JointKind::Weld {
                    return Err(ck.fail(
                        &r::WELD_NO_DRIVE,
                        &format!("{field}.drive"),
                        format!("{:?}", d.kind),
                    ));
                }
                super::laws::validate_law(&ck, &d.law, &format!("{field}.drive"))?;
                if d.kind == DriveKind::Motion && matches!(d.law.law.as_str(), "exponential") {
                    return Err(ck.fail(
                        &r::MOTION_CONTINUOUS,
                        &format!("{field}.drive.law"),
                        "\"exponential\"",
                    ));
                }
            }
        }
        for (i, l) in self.loads.iter().enumerate() {
            let field = self.path_of(Part::Load, i);
            if !self.frame_exists(&l.frame) {
                return Err(ck.fail(
                    &r::LOAD_FRAME,
                    &format!("{field}.frame"),
                    format!("{:?}", l.frame),
                ));
            }
            if l.frame == "world" {
                return Err(ck.fail(&r::LOAD_ON_BODY, &format!("{field}.frame"), "\"world\""));
            }
            for k in 0..3 {
                ck.finite(&format!("{field}.force[{k}]"), l.force[k])?;
                ck.finite(&format!("{field}.torque[{k}]"), l.torque[k])?;
            }
            if let Some(law) = &l.scale {
                super::laws::validate_law(&ck, law, &format!("{field}.scale"))?;
                if l.input || law.law == "input" {
                    return Err(ck.fail(
                        &r::SCALE_NOT_INPUT,
                        &format!("{field}.scale"),
                        format!("{:?}", law.law),
                    ));
                }
            }
        }
        super::space::validate_space(&ck, self)?;
        self.validate_placement(&ck)
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
        EffectsSpec::Mode(m) if ["scene", "all", "auto"].contains(&m.as_str()) => return Ok(()),
        EffectsSpec::Mode(m) => return Err(ck.fail(&r::EFFECTS_MODE, "effects", format!("{m:?}"))),
        EffectsSpec::List(names) => names,
    };
    for (k, n) in names.iter().enumerate() {
        if !r::EFFECT_NAMES.contains(&n.as_str()) {
            return Err(ck.fail(&r::EFFECT_KNOWN, &format!("effects[{k}]"), format!("{n:?}")));
        }
        if names[..k].contains(n) {
            return Err(ck.fail(&r::EFFECT_ONCE, &format!("effects[{k}]"), format!("{n:?}")));
        }
    }
    let on = |e: &str| names.iter().any(|n| n == e);
    // the 3D element always computes the axial strain
    let axial = on("axial") || (scene.is_3d() && scene.planar_reduction().is_err());
    for (i, b) in scene.beams.iter().enumerate() {
        if !on("flexibility") && b.initial.tip_displacement != 0.0 {
            return Err(ck.fail(
                &r::DEFORMED_NEEDS_FLEXIBILITY,
                &format!("{}.initial.tip_displacement", scene.path_of(Part::Beam, i)),
                b.initial.tip_displacement,
            ));
        }
        if on("geometric_stiffening") && b.geometric_stiffening && !axial {
            return Err(ck.fail_with(
                &r::STIFFENING_NEEDS_AXIAL,
                "effects",
                format!("{names:?}"),
                &format!(" (beam {})", b.name),
            ));
        }
    }
    Ok(())
}

fn validate_beam(ck: &Checker, b: &BeamSpec, path: &str, three: bool) -> Result<(), SceneError> {
    let f = |name: &str| format!("{path}.{name}");
    super::limits::name_fits(ck, &f("name"), &b.name)?;
    if !is_identifier(&b.name) {
        return Err(ck.fail(&r::SCENE_NAME, &f("name"), format!("{:?}", b.name)));
    }
    ck.positive(&f("length"), b.length)?;
    let count = |field: &str, n: usize, max: (usize, &Rule)| -> Result<(), SceneError> {
        if n == 0 {
            return Err(ck.fail(&r::AT_LEAST_ONE, &f(field), n));
        }
        if n > max.0 {
            return Err(ck.fail(max.1, &f(field), n));
        }
        Ok(())
    };
    const ELEMENTS: (usize, &Rule) = (2000, &r::ELEMENTS_MAX);
    match (b.elements, b.substructures, b.elements_per_substructure) {
        (Some(n), None, None) => count("elements", n, ELEMENTS)?,
        (None, Some(k), Some(n)) => {
            count("substructures", k, (500, &r::SUBSTRUCTURES_MAX))?;
            count("elements_per_substructure", n, ELEMENTS)?;
            let all = k.saturating_mul(n);
            if all > r::MAX_BEAM_ELEMENTS {
                return Err(ck.fail(
                    &r::BEAM_ELEMENTS_MAX,
                    &f("substructures"),
                    format!("{k} × {n} = {all}"),
                ));
            }
        }
        (None, None, _) => return Err(ck.fail(&r::LAYOUT_MISSING, &f("elements"), "missing")),
        (None, Some(_), None) => {
            return Err(ck.fail(
                &r::LAYOUT_PER_SUBSTRUCTURE,
                &f("elements_per_substructure"),
                "missing",
            ))
        }
        (Some(n), Some(_), _) | (Some(n), None, Some(_)) => {
            return Err(ck.fail(&r::LAYOUT_EITHER, &f("elements"), n))
        }
    }
    if b.substructures.is_some() && b.initial.tip_displacement != 0.0 {
        return Err(ck.fail(
            &r::DEFORMED_SINGLE_FRAME,
            &f("initial.tip_displacement"),
            b.initial.tip_displacement,
        ));
    }
    if b.rigid
        && (b.substructures.is_some()
            || b.geometric_stiffening
            || b.initial.tip_displacement != 0.0)
    {
        return Err(ck.fail(&r::RIGID_PLAIN, &f("rigid"), true));
    }
    if let Some(m) = b.modes {
        let (elements, _) = Scene::beam_layout(b);
        let nodal = 3 * elements; // the frame removes 3 of the 3 (N + 1) nodal coordinates
        if m == 0 || m > nodal || b.rigid {
            return Err(ck.fail_with(&r::MODES_RANGE, &f("modes"), m, &format!(": {nodal} here")));
        }
    }
    ck.positive(&f("material.rho"), b.material.rho)?;
    if b.material.rho < r::MIN_DENSITY {
        return Err(ck.fail(&r::DENSITY_FLOOR, &f("material.rho"), Short(b.material.rho)));
    }
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
            &r::DEFORMATION_SMALL,
            &f("initial.tip_displacement"),
            b.initial.tip_displacement,
        ));
    }
    if b.initial.tip_displacement != 0.0 && b.frame == FrameKind::Pinned {
        return Err(ck.fail(
            &r::DEFORMED_TANGENT,
            &f("initial.tip_displacement"),
            b.initial.tip_displacement,
        ));
    }
    let (outputs, rule): (&[&str], _) = if three {
        (&super::BEAM_OUTPUT_NAMES_3D, &r::BEAM_OUTPUT_3D)
    } else {
        (&super::BEAM_OUTPUT_NAMES, &r::BEAM_OUTPUT)
    };
    for (k, o) in b.outputs.iter().enumerate() {
        if !outputs.contains(&o.as_str()) {
            return Err(ck.fail(rule, &f(&format!("outputs[{k}]")), format!("{o:?}")));
        }
    }
    if let Some(n) = b.shape_points {
        if n == 1 || n > super::MAX_POINTS {
            return Err(ck.fail(&r::SHAPE_POINTS, &f("shape_points"), n));
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
            None => Err(ck.fail(&r::SECTION_VALUE_MISSING, &f(name), "missing")),
        }
    };
    let unused = |v: Option<f64>, name: &str, rule: &Rule| -> Result<(), SceneError> {
        match v {
            Some(x) => Err(ck.fail(rule, &f(name), x)),
            None => Ok(()),
        }
    };
    let spatial = [(s.iy, "Iy"), (s.iz, "Iz"), (s.torsion_constant, "It")];
    if !three {
        for (v, n) in spatial {
            unused(v, n, &r::SECTION_3D_CONSTANTS)?;
        }
    }
    let dimensions = [(s.a, "a"), (s.b, "b"), (s.d, "d"), (s.t, "t")];
    match s.shape.as_deref() {
        None if three => {
            unused(s.second_moment, "J", &r::SECTION_PLANAR_J)?;
            if spatial.iter().all(|(v, _)| v.is_none()) && s.area.is_none() {
                return Err(ck.fail(&r::SECTION_MISSING_3D, field, "missing"));
            }
            given(s.area, "A")?;
            for (v, n) in spatial {
                given(v, n)?;
            }
            for (v, n) in dimensions {
                unused(v, n, &r::SHAPE_DIMENSION_UNUSED)?;
            }
        }
        None => {
            if s.area.is_none() && s.second_moment.is_none() {
                return Err(ck.fail(&r::SECTION_MISSING, field, "missing"));
            }
            given(s.area, "A")?;
            given(s.second_moment, "J")?;
            for (v, n) in dimensions {
                unused(v, n, &r::SHAPE_DIMENSION_UNUSED)?;
            }
        }
        Some(shape) => {
            for (v, n) in [(s.area, "A"), (s.second_moment, "J")]
                .into_iter()
                .chain(spatial)
            {
                unused(v, n, &r::CONSTANT_FROM_SHAPE)?;
            }
            match shape {
                "rectangle" => {
                    given(s.a, "a")?;
                    given(s.b, "b")?;
                    unused(s.d, "d", &r::NOT_OF_RECTANGLE)?;
                    unused(s.t, "t", &r::HOLLOW_ONLY)?;
                }
                "hollow_rectangle" => {
                    let a = given(s.a, "a")?;
                    let b = given(s.b, "b")?;
                    let t = given(s.t, "t")?;
                    unused(s.d, "d", &r::NOT_OF_RECTANGLE)?;
                    if 2.0 * t >= a.min(b) {
                        return Err(ck.fail(&r::WALL_OF_RECTANGLE, &f("t"), t));
                    }
                }
                "circle" => {
                    given(s.d, "d")?;
                    unused(s.a, "a", &r::NOT_OF_CIRCLE)?;
                    unused(s.b, "b", &r::NOT_OF_CIRCLE)?;
                    unused(s.t, "t", &r::HOLLOW_ONLY)?;
                }
                "hollow_circle" => {
                    let d = given(s.d, "d")?;
                    let t = given(s.t, "t")?;
                    unused(s.a, "a", &r::NOT_OF_CIRCLE)?;
                    unused(s.b, "b", &r::NOT_OF_CIRCLE)?;
                    if 2.0 * t >= d {
                        return Err(ck.fail(&r::WALL_OF_CIRCLE, &f("t"), t));
                    }
                }
                other => return Err(ck.fail(&r::SHAPE, &f("shape"), format!("{other:?}"))),
            }
        }
    }
    Ok(())
}

fn validate_body(
    ck: &Checker,
    b: &RigidBodySpec,
    path: &str,
    three: bool,
) -> Result<(), SceneError> {
    let f = |name: &str| format!("{path}.{name}");
    ck.non_negative(&f("mass"), b.mass)?;
    for k in 0..3 {
        ck.non_negative(&f(&format!("inertia[{k}]")), b.inertia[k])?;
        ck.finite(&f(&format!("com[{k}]")), b.com[k])?;
        ck.finite(&f(&format!("position[{k}]")), b.position[k])?;
    }
    if three && b.mass > 0.0 && b.inertia.contains(&0.0) {
        return Err(ck.fail(
            &r::BODY_INERTIA_3D,
            &f("inertia"),
            format!("{:?}", b.inertia),
        ));
    }
    ck.finite(&f("angle"), b.angle)?;
    for (name, p) in &b.frames {
        let field = f(&format!("frames.{}", super::limits::abbreviate(name, 80)));
        super::limits::name_fits(ck, &field, name)?;
        if !is_identifier(name) || name == "a" || name == "b" {
            return Err(ck.fail(&r::FRAME_NAME, &field, format!("{name:?}")));
        }
        for k in 0..3 {
            ck.finite(&format!("{field}[{k}]"), p.0[k])?;
        }
    }
    Ok(())
}
