//! The rules that depend on a scene's `dimensions`: a planar scene lies in the world x–y plane
//! and uses no 3D field; a 3D scene's directions are usable, its sections complete, its
//! matrix files valid, and it asks for planar-only features only when its motion is planar
//! (then it runs with the planar element, [`Scene::planar_reduction`]).

use super::paths::Part;
use super::planar::unit;
use super::rules::{self as r, Rule};
use super::validate::{Checker, SceneError};
use super::{EffectsSpec, Formulation, InertiaSpec, JointKind, Scene};
use crate::scene::matrix_file;

/// Effects a scene run with the 3D element can switch (the others are planar-only).
pub const SPATIAL_EFFECTS: [&str; 4] = [
    "gravity",
    "flexibility",
    "geometric_stiffening",
    "rayleigh_damping",
];

pub(super) fn validate_space(ck: &Checker, s: &Scene) -> Result<(), SceneError> {
    if s.is_3d() {
        validate_3d(ck, s)
    } else {
        validate_planar(ck, s)
    }
}

fn validate_planar(ck: &Checker, s: &Scene) -> Result<(), SceneError> {
    let zero = |field: &str, v: f64, rule: &Rule| {
        if v == 0.0 {
            Ok(())
        } else {
            Err(ck.fail(rule, field, v))
        }
    };
    let none = |field: &str, v: bool, rule: &Rule| {
        if v {
            Err(ck.fail(rule, field, "given"))
        } else {
            Ok(())
        }
    };
    const PLANE: &Rule = &r::IN_PLANE;
    if s.formulation != Formulation::Auto {
        return Err(ck.fail(&r::SPATIAL_FORMULATION, "formulation", "\"spatial\""));
    }
    zero("world.gravity[2]", s.world.gravity[2], PLANE)?;
    for (i, b) in s.beams.iter().enumerate() {
        let path = s.path_of(Part::Beam, i);
        let f = |n: &str| format!("{path}.{n}");
        zero(&f("position[2]"), b.position[2], PLANE)?;
        none(&f("axis"), b.axis.is_some(), &r::ONLY_3D_FIELD)?;
        none(&f("normal"), b.normal.is_some(), &r::ONLY_3D_FIELD)?;
        none(
            &f("inertia"),
            b.inertia != InertiaSpec::Full,
            &r::FROZEN_INERTIA,
        )?;
        none(
            &f("matrix_file"),
            b.matrix_file.is_some() || b.matrix_text.is_some(),
            &r::ONLY_3D_FIELD,
        )?;
    }
    for (i, b) in s.bodies.iter().enumerate() {
        let path = s.path_of(Part::Body, i);
        let f = |n: &str| format!("{path}.{n}");
        zero(&f("position[2]"), b.position[2], PLANE)?;
        zero(&f("com[2]"), b.com[2], PLANE)?;
        for (name, p) in &b.frames {
            zero(&f(&format!("frames.{name}[2]")), p.0[2], PLANE)?;
        }
        for k in 0..2 {
            zero(
                &f(&format!("inertia[{k}]")),
                b.inertia[k],
                &r::PLANAR_INERTIA,
            )?;
        }
    }
    for (i, j) in s.joints.iter().enumerate() {
        let path = s.path_of(Part::Joint, i);
        let f = |n: &str| format!("{path}.{n}");
        none(&f("axis"), j.axis.is_some(), &r::ONLY_3D_FIELD)?;
        if j.kind == JointKind::Spherical {
            return Err(ck.fail(&r::SPHERICAL, &f("type"), "\"spherical\""));
        }
    }
    for (i, l) in s.loads.iter().enumerate() {
        let path = s.path_of(Part::Load, i);
        let f = |n: &str| format!("{path}.{n}");
        zero(&f("force[2]"), l.force[2], PLANE)?;
        for k in 0..2 {
            zero(&f(&format!("torque[{k}]")), l.torque[k], &r::PLANAR_TORQUE)?;
        }
    }
    Ok(())
}

/// A finite, non-zero direction.
fn direction(ck: &Checker, field: &str, v: [f64; 3]) -> Result<[f64; 3], SceneError> {
    for (k, x) in v.iter().enumerate() {
        ck.finite(&format!("{field}[{k}]"), *x)?;
    }
    unit(v).ok_or_else(|| ck.fail(&r::DIRECTION, field, format!("{v:?}")))
}

fn validate_3d(ck: &Checker, s: &Scene) -> Result<(), SceneError> {
    // why the planar element cannot be used, if it cannot
    let spatial = s.planar_reduction().err();
    let planar_only = |field: &str, value: String| -> Result<(), SceneError> {
        match &spatial {
            Some(why) => {
                Err(ck.fail_with(&r::PLANAR_ELEMENT_ONLY, field, value, &format!(" ({why})")))
            }
            None => Ok(()),
        }
    };
    for (i, b) in s.beams.iter().enumerate() {
        let path = s.path_of(Part::Beam, i);
        let f = |n: &str| format!("{path}.{n}");
        let axis = match b.axis {
            Some(a) => direction(ck, &f("axis"), a)?,
            None => [b.angle.cos(), b.angle.sin(), 0.0],
        };
        if let Some(n) = b.normal {
            let n = direction(ck, &f("normal"), n)?;
            let dot = axis[0] * n[0] + axis[1] * n[1] + axis[2] * n[2];
            if dot.abs() > 1e-9 {
                return Err(ck.fail(&r::NORMAL_TO_AXIS, &f("normal"), format!("{n:?}")));
            }
        } else if axis[2].abs() > 1e-9 {
            return Err(ck.fail(&r::NORMAL_REQUIRED, &f("normal"), "missing"));
        }
        if !b.rigid && b.matrix_text.is_none() && b.material.g.is_none() {
            return Err(ck.fail(&r::SHEAR_MODULUS, &f("material.G"), "missing"));
        }
        if b.modes.is_some() {
            planar_only(&f("modes"), format!("{:?}", b.modes))?;
        }
        if b.initial.tip_displacement != 0.0 {
            planar_only(
                &f("initial.tip_displacement"),
                b.initial.tip_displacement.to_string(),
            )?;
        }
        if let Some(text) = &b.matrix_text {
            let file = b
                .matrix_file
                .clone()
                .unwrap_or_else(|| "matrix_text".into());
            let m = matrix_file::parse(text, &file).map_err(|e| {
                ck.fail_with(
                    &r::MATRIX_FILE,
                    &f("matrix_file"),
                    format!("{file:?}"),
                    &format!(": {e}"),
                )
            })?;
            if b.rigid || b.elements != Some(1) {
                return Err(ck.fail(
                    &r::MATRIX_ONE_ELEMENT,
                    &f("matrix_file"),
                    format!("{file:?}"),
                ));
            }
            if (m.length - b.length).abs() > 1e-9 * b.length {
                return Err(ck.fail_with(
                    &r::MATRIX_LENGTH,
                    &f("length"),
                    b.length,
                    &format!(" {}", m.length),
                ));
            }
        }
    }
    for (i, j) in s.joints.iter().enumerate() {
        let path = s.path_of(Part::Joint, i);
        let f = |n: &str| format!("{path}.{n}");
        if let Some(a) = j.axis {
            direction(ck, &f("axis"), a)?;
        }
        if j.kind == JointKind::Spherical && j.drive.is_some() {
            return Err(ck.fail(&r::SPHERICAL_NO_DRIVE, &f("drive"), "given"));
        }
    }
    if let (Some(why), EffectsSpec::List(names)) = (&spatial, &s.effects) {
        for (k, n) in names.iter().enumerate() {
            if !SPATIAL_EFFECTS.contains(&n.as_str()) {
                return Err(ck.fail_with(
                    &r::SPATIAL_EFFECTS,
                    &format!("effects[{k}]"),
                    format!("{n:?}"),
                    &format!(" ({why})"),
                ));
            }
        }
    }
    Ok(())
}

impl Scene {
    /// A 3D scene's points and forces are written with 3 components: `[x, y]` is the planar
    /// form, and in a 3D scene it would put the point at z = 0 unasked. `table` is the scene's
    /// text as TOML.
    pub(super) fn check_components(
        &self,
        ck: &Checker,
        table: &toml::Table,
    ) -> Result<(), SceneError> {
        let two = |v: Option<&toml::Value>| {
            v.and_then(toml::Value::as_array)
                .is_some_and(|a| a.len() == 2)
        };
        let refuse = |field: String, v: Option<&toml::Value>| {
            let shown = v.map_or(String::new(), |v| v.to_string());
            Err(ck.fail(&r::SPATIAL_VECTOR, &field, shown))
        };
        let gravity = table.get("world").and_then(|w| w.get("gravity"));
        if two(gravity) {
            return refuse("world.gravity".into(), gravity);
        }
        let items = |key: &str| -> Vec<toml::Value> {
            table
                .get(key)
                .and_then(toml::Value::as_array)
                .cloned()
                .unwrap_or_default()
        };
        for (i, b) in items("beam").iter().enumerate() {
            if two(b.get("position")) {
                let path = self.path_of(Part::Beam, i);
                return refuse(format!("{path}.position"), b.get("position"));
            }
        }
        for (i, b) in items("body").iter().enumerate() {
            let path = self.path_of(Part::Body, i);
            for key in ["position", "com"] {
                if two(b.get(key)) {
                    return refuse(format!("{path}.{key}"), b.get(key));
                }
            }
            let frames = b.get("frames").and_then(toml::Value::as_table);
            for (name, p) in frames.into_iter().flatten() {
                if two(Some(p)) {
                    return refuse(format!("{path}.frames.{name}"), Some(p));
                }
            }
        }
        for (i, l) in items("load").iter().enumerate() {
            if two(l.get("force")) {
                let path = self.path_of(Part::Load, i);
                return refuse(format!("{path}.force"), l.get("force"));
            }
        }
        Ok(())
    }
}
