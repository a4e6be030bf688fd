//! The α part of Rayleigh damping, on a beam as a whole (`mechanics/multibody/beam_damping.rs`),
//! checked on its algebra at arbitrary deformed states, planar and spatial, tangent and pinned
//! frames, one frame and substructures: a rigid motion of the whole beam (about any point)
//! meets no damping force; any motion's damping power is −α Σ uᵀ M u ≤ 0; the C_t blocks are
//! the force's derivative; a single tangent frame gets the classical α m_ff q̇_f.

use crate::mechanics::multibody::beam_damping::BeamDamping;
use crate::mechanics::multibody::sparsity::BlockDiagonal;
use crate::mechanics::multibody::Equations;
use crate::mechanics::multibody3d::quaternion::{g_body, rotation};
use crate::mechanics::Mechanics;
use crate::unit::effects::resolve;
use crate::Scene;
use nalgebra::{DVector, Vector3, Vector4};

/// A deterministic pseudo-random sequence in [−1, 1].
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// A beam of `parts` frames (2 elements each), `frame` kind, α = 3, clamped; 2 or 3 dims.
fn system(dims: usize, parts: usize, frame: &str) -> Mechanics {
    let layout = if parts == 1 {
        "elements = 4".to_string()
    } else {
        format!("substructures = {parts}\nelements_per_substructure = 2")
    };
    let (head, section) = if dims == 2 {
        ("", "{ shape = \"rectangle\", a = 0.01, b = 0.02 }")
    } else {
        (
            "dimensions = 3\nformulation = \"spatial\"\n",
            "{ A = 2e-4, Iy = 1.7e-9, Iz = 6.7e-9, It = 5e-10 }",
        )
    };
    let text = format!(
        r#"name = "d"
{head}
[[beam]]
name = "beam"
length = 1.0
frame = "{frame}"
{layout}
material = {{ rho = 2700.0, E = 70e9, G = 26e9 }}
section = {section}
rayleigh = {{ alpha = 3.0 }}
"#
    );
    let s = Scene::from_toml_str(&text, "d").expect("valid");
    Mechanics::build(&s, &resolve(&s).effects)
}

/// The system's damping of beam 0 at q, and q itself: the placement, every coordinate moved
/// by up to 0.05 (quaternions normalized).
fn deformed(sys: &Mechanics, noise: &mut Noise) -> (DVector<f64>, BeamDamping) {
    let mut q = sys.initial_coordinates().unwrap();
    for x in q.iter_mut() {
        *x += 0.05 * noise.next();
    }
    match sys {
        Mechanics::Planar(p) => {
            let d = p.beam_damping(0, &q).expect("damped");
            (q, d)
        }
        Mechanics::Spatial(s, _) => {
            for &o in &s.offsets {
                let n = q.rows(o + 3, 4).norm();
                q.rows_mut(o + 3, 4).unscale_mut(n);
            }
            let d = s.beam_damping(0, &q).expect("damped");
            (q, d)
        }
    }
}

/// Rates of a rigid motion of every body at velocity `vel` of the point `c` and angular
/// velocity `w` (world; in the plane only w.z counts).
fn rigid_rates(
    sys: &Mechanics,
    q: &DVector<f64>,
    c: Vector3<f64>,
    vel: Vector3<f64>,
    w: Vector3<f64>,
) -> DVector<f64> {
    let mut v = DVector::zeros(q.len());
    match sys {
        Mechanics::Planar(p) => {
            for &o in &p.offsets {
                v[o] = vel.x - w.z * (q[o + 1] - c.y);
                v[o + 1] = vel.y + w.z * (q[o] - c.x);
                v[o + 2] = w.z;
            }
        }
        Mechanics::Spatial(s, _) => {
            for &o in &s.offsets {
                let r = Vector3::new(q[o], q[o + 1], q[o + 2]);
                let p = Vector4::new(q[o + 3], q[o + 4], q[o + 5], q[o + 6]);
                v.rows_mut(o, 3).copy_from(&(vel + w.cross(&(r - c))));
                let pd = g_body(&p).transpose() * rotation(&p).transpose() * w * 0.5;
                v.rows_mut(o + 3, 4).copy_from(&pd);
            }
        }
    }
    v
}

fn force(d: &BeamDamping, v: &DVector<f64>) -> DVector<f64> {
    let mut r = DVector::zeros(v.len());
    d.add_force(v, &mut r);
    r
}

fn cases() -> Vec<(usize, usize, &'static str)> {
    let mut c = Vec::new();
    for dims in [2, 3] {
        for parts in [1, 4] {
            for frame in ["tangent", "pinned"] {
                c.push((dims, parts, frame));
            }
        }
    }
    c
}

#[test]
fn a_rigid_motion_of_the_whole_beam_meets_no_damping() {
    let mut noise = Noise(7);
    for (dims, parts, frame) in cases() {
        let sys = system(dims, parts, frame);
        for _ in 0..3 {
            let (q, d) = deformed(&sys, &mut noise);
            let mut r3 = || Vector3::new(noise.next(), noise.next(), noise.next());
            let (c, vel, w) = (r3() * 2.0, r3(), r3() * 3.0);
            let w = if dims == 2 {
                Vector3::new(0.0, 0.0, w.z)
            } else {
                w
            };
            let v = rigid_rates(&sys, &q, c, vel, w);
            // the scale: the force of the same rates on the beam's own mass, α M v
            let mut scale = 0.0f64;
            for b in &d.bodies {
                let vb = v.rows(b.offset, b.mass.nrows());
                scale = scale.max((&b.mass * vb).amax() * d.alpha);
            }
            let f = force(&d, &v);
            println!(
                "{dims}D, {parts} frame(s), {frame}: rigid motion, force {:.1e} of α M v {scale:.1e}, \
                 dissipation {:.1e}",
                f.amax(),
                d.dissipation(&v)
            );
            assert!(
                f.amax() < 1e-9 * scale,
                "{dims}D {parts} {frame}: {}",
                f.amax()
            );
            assert!(d.dissipation(&v).abs() < 1e-12 * scale);
        }
    }
}

#[test]
fn the_damping_power_is_never_positive_and_its_tangent_is_exact() {
    let mut noise = Noise(11);
    for (dims, parts, frame) in cases() {
        let sys = system(dims, parts, frame);
        let ranges = sys.body_ranges();
        for _ in 0..3 {
            let (q, d) = deformed(&sys, &mut noise);
            let v = DVector::from_fn(q.len(), |_, _| noise.next());
            let f = force(&d, &v);
            // the damping power −vᵀf equals −2F = −α Σ uᵀ M u, and is ≤ 0
            let (power, dissipation) = (-v.dot(&f), d.dissipation(&v));
            assert!(dissipation > 0.0, "{dims}D {parts} {frame}: {dissipation}");
            assert!(
                (power + dissipation).abs() < 1e-12 * dissipation,
                "{dims}D {parts} {frame}: power {power} against −{dissipation}"
            );
            // C_t's body blocks: the force is linear in v, so a column is f(e_k)
            let mut ct = BlockDiagonal::zeros(&ranges);
            d.add_tangent(&mut ct);
            for (b, r) in ranges.iter().enumerate() {
                for k in r.clone() {
                    let col = force(&d, &DVector::from_fn(q.len(), |i, _| f64::from(i == k)));
                    for i in r.clone() {
                        let (a, e) = (ct.blocks[b][(i - r.start, k - r.start)], col[i]);
                        assert!(
                            (a - e).abs() < 1e-10 * (1.0 + e.abs()),
                            "{dims}D {parts} {frame}: C_t[{i}, {k}] = {a}, ∂f/∂v = {e}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn a_single_tangent_frame_gets_the_classical_floating_frame_damping() {
    let mut noise = Noise(5);
    for dims in [2, 3] {
        let sys = system(dims, 1, "tangent");
        let (q, d) = deformed(&sys, &mut noise);
        let v = DVector::from_fn(q.len(), |_, _| noise.next());
        let f = force(&d, &v);
        let (frame, mff) = match &sys {
            Mechanics::Planar(p) => (3, p.beam(0).unwrap().mff.to_dense()),
            Mechanics::Spatial(s, _) => match &s.bodies[0] {
                crate::mechanics::Body3::Beam(b) => (7, b.mff.clone()),
                _ => unreachable!(),
            },
        };
        let nf = mff.nrows();
        let classical = &mff * v.rows(frame, nf) * 3.0;
        assert!(
            f.rows(0, frame).amax() < 1e-9 * classical.amax(),
            "{dims}D: no force on the frame"
        );
        assert!(
            (f.rows(frame, nf) - &classical).amax() < 1e-9 * classical.amax(),
            "{dims}D: α m_ff q̇_f"
        );
    }
}
