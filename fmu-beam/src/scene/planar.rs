//! "Planar scenes stay planar": a 3D scene whose motion stays in the world x–y plane runs with
//! the planar element. [`Scene::planar_reduction`] decides it from the data alone (every
//! force, axis, position and gravity component that could move a point out of the plane is
//! zero) and gives the planar scene to run; the reduction is exact, not an approximation.

use super::{Formulation, InertiaSpec, JointKind, Scene, SectionSpec};

/// Unit vector along `v`, or None for a zero vector.
pub fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (n > 0.0 && n.is_finite()).then(|| [v[0] / n, v[1] / n, v[2] / n])
}

/// Is `v` the world z direction (to 1e-12)?
fn along_z(v: [f64; 3]) -> bool {
    unit(v).is_some_and(|u| (u[2] - 1.0).abs() <= 1e-12)
}

impl Scene {
    /// The planar scene that a 3D scene's motion reduces to, or why it does not: a planar
    /// scene reduces to itself. The reduction needs: `formulation = "auto"`; gravity, beam
    /// and body positions, forces and frame points in the x–y plane; beam axes in that plane
    /// with the section's local z along world z; revolute axes along +z; prismatic axes
    /// left to `axis_angle`; no spherical joint; torques about z only; no input load (its
    /// inputs include out-of-plane parts); full inertia, no matrix file.
    pub fn planar_reduction(&self) -> Result<Scene, String> {
        if !self.is_3d() {
            return Ok(self.clone());
        }
        if self.formulation == Formulation::Spatial {
            return Err("formulation = \"spatial\" asks for the 3D element".into());
        }
        let in_plane = |what: &str, v: [f64; 3]| {
            if v[2] == 0.0 {
                Ok(())
            } else {
                Err(format!("{what} has a z component"))
            }
        };
        in_plane("world.gravity", self.world.gravity)?;
        let mut s = self.clone();
        s.dimensions = 2;
        for b in &mut s.beams {
            let n = &b.name;
            in_plane(&format!("beam {n}: position"), b.position)?;
            if let Some(a) = b.axis {
                in_plane(&format!("beam {n}: axis"), a)?;
                b.angle = a[1].atan2(a[0]);
                b.axis = None;
            }
            if let Some(z) = b.normal {
                if !along_z(z) {
                    return Err(format!("beam {n}: its section's z axis is not world z"));
                }
                b.normal = None;
            }
            if b.inertia == InertiaSpec::Frozen {
                return Err(format!("beam {n}: frozen inertia is a 3D-only variant"));
            }
            if b.matrix_text.is_some() || b.matrix_file.is_some() {
                return Err(format!("beam {n}: a matrix-file beam is 3D only"));
            }
            b.section = planar_section(&b.section);
        }
        for b in &mut s.bodies {
            let n = &b.name;
            in_plane(&format!("body {n}: position"), b.position)?;
            in_plane(&format!("body {n}: com"), b.com)?;
            for (f, p) in &b.frames {
                in_plane(&format!("body {n}: frame {f}"), p.0)?;
            }
            b.inertia = [0.0, 0.0, b.inertia[2]];
        }
        for j in &mut s.joints {
            let n = &j.name;
            match j.kind {
                JointKind::Spherical => {
                    return Err(format!("joint {n}: a spherical joint is 3D"));
                }
                JointKind::Revolute => {
                    if let Some(a) = j.axis {
                        if !along_z(a) {
                            return Err(format!("joint {n}: its axis is not world +z"));
                        }
                    }
                }
                JointKind::Prismatic if j.axis.is_some() => {
                    return Err(format!(
                        "joint {n}: a 3D sliding axis (use axis_angle for a planar one)"
                    ));
                }
                _ => {}
            }
            j.axis = None;
        }
        for l in &s.loads {
            let n = &l.name;
            in_plane(&format!("load {n}: force"), l.force)?;
            if l.torque[0] != 0.0 || l.torque[1] != 0.0 {
                return Err(format!("load {n}: a torque about an in-plane axis"));
            }
            if l.input {
                return Err(format!("load {n}: 3D inputs can push out of the plane"));
            }
        }
        Ok(s)
    }
}

/// The planar section of a 3D one: a shape stays (its `a` is the height along y for both);
/// constants given directly keep A, with J = I_z (bending in the x–y plane).
fn planar_section(s: &SectionSpec) -> SectionSpec {
    if s.shape.is_some() {
        return SectionSpec {
            iy: None,
            iz: None,
            torsion_constant: None,
            ..s.clone()
        };
    }
    SectionSpec {
        area: s.area,
        second_moment: s.iz.or(s.second_moment),
        ..SectionSpec::default()
    }
}
