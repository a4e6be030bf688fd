//! The inertia each force or torque input acts on: J_eff = 1 / (bᵀ M̃⁻¹ b), with b = ∂Q/∂u the
//! input's generalized direction and M̃⁻¹ b the accelerations a unit input gives under the
//! joints ([[M, Gᵀ], [G, 0]] [q''; λ] = [b; 0]). It is what the input's own joint (or frame)
//! feels at once: a sampled loop that holds the input over a communication step h sees it, not
//! the inertia of the arm. Beside it the same figure with every beam held rigid (its
//! deformation coordinates locked): the inertia of the attached bodies as the mechanism presents
//! them to this input. A bare beam root, or a joint between two beam ends, has J_eff a tiny
//! share of that (the first element's ρAL³/105 against the arm's), and a loop tuned on the arm
//! over-corrects it at every step.
//!
//! A loop that holds the input over h and reads a speed (damping k_d) or a position (stiffness
//! k_p) of the same joint is stable on an inertia J alone only for k_d h / J < 2 and k_p h² / J
//! < 4 (the explicit Euler and central-difference limits of ẍ = −(k_d ẋ + k_p x)/J sampled at h).

use crate::integrator::GaState;
use crate::mechanics::multibody::equations::Equations;
use crate::mechanics::Mechanics;
use crate::unit::variables::{Binding, VariableTable};
use nalgebra::{DMatrix, DVector};

/// A drive input's effective inertia below this share of the rigid value is warned about at
/// initialization. A loop tuned on the rigid inertia J_r with closed-loop bandwidth ω_c and
/// damping ratio ζ has k_d ≈ 2ζ ω_c J_r; it over-corrects the input's own inertia when
/// k_d h / J_eff > 2, i.e. when J_eff / J_r < ζ ω_c h. At 1 % only a loop sampled slower than
/// ω_c h = 0.01 (ζ = 1) is safe: a missing rotor or hub, not a tuning matter (a bare beam root
/// is at 1e-4, the shipped arm with its 5 kg m² rotor at 0.13).
pub const SMALL_SHARE: f64 = 0.01;

/// Systems with more unknowns than this (n + m) are not measured: the dense factorization at
/// initialization would cost more than the warning is worth (≈ 0.3 s at 1500).
pub const MAX_UNKNOWNS: usize = 1500;

/// The inertia one force or torque input acts on.
#[derive(Debug, Clone, PartialEq)]
pub struct InputInertia {
    /// The input's variable name (`shoulder.drive.torque`).
    pub name: String,
    /// The input's slot in the system.
    pub slot: usize,
    /// A torque (kg m², N m, rad/s) rather than a force (kg, N, m/s).
    pub torque: bool,
    /// A joint's effort drive (`<joint>.drive.torque` or `.force`), the actuator a control loop
    /// sets; otherwise an input load, most often the cut of a co-simulation, where a joint
    /// between units acts on the small inertia of a beam's end by design.
    pub drive: bool,
    /// ∂Q/∂u: the input's generalized direction, as (coordinate, value); bᵀq' is the speed of
    /// the input's own joint or frame along it.
    pub direction: Vec<(usize, f64)>,
    /// 1 / (bᵀ M̃⁻¹ b) with every coordinate (kg m² or kg).
    pub effective: f64,
    /// The same with every beam's deformation locked (kg m² or kg); NaN when not measured.
    pub rigid: f64,
}

impl InputInertia {
    /// J_eff / J_rigid.
    pub fn share(&self) -> f64 {
        self.effective / self.rigid
    }

    /// Whether this input is a drive that acts on an inertia far below the attached bodies'
    /// ([`SMALL_SHARE`]); false where the rigid value is not measured.
    pub fn is_small(&self) -> bool {
        self.drive && self.share() < SMALL_SHARE
    }

    /// (inertia unit, effort unit, speed unit, what it acts on).
    pub fn units(&self) -> (&'static str, &'static str, &'static str) {
        if self.torque {
            ("kg m²", "N m", "rad/s")
        } else {
            ("kg", "N", "m/s")
        }
    }

    /// The speed of the input's own joint or frame along its direction, bᵀq'.
    pub fn speed(&self, v: &DVector<f64>) -> f64 {
        self.direction.iter().map(|&(k, x)| x * v[k]).sum()
    }

    /// What initialization says of an input on a small effective inertia (information).
    pub fn note(&self, h: f64) -> String {
        let (ju, eu, su) = self.units();
        let j = self.effective;
        format!(
            "input '{}' acts on an effective {} of {j:.3e} {ju}, {:.2e} % of the {:.4} {ju} the \
             attached bodies present when held rigid (1 / (bᵀ M̃⁻¹ b) from the unit's mass matrix \
             and joints): a loop that samples this joint every h and holds the input over h is \
             stable only for a damping gain below 2J/h and a stiffness below 4J/h², at h = \
             {h:.3e} s (the DefaultExperiment's step) {:.3e} {eu} s/{} and {:.3e} {eu}/{}; add \
             rotor or hub inertia at this input (on both sides of a joint between two parts), \
             reduce the communication step, or filter the input",
            self.name,
            if self.torque { "inertia" } else { "mass" },
            100.0 * self.share(),
            self.rigid,
            2.0 * j / h,
            su.trim_end_matches("/s"),
            4.0 * j / (h * h),
            su.trim_end_matches("/s"),
        )
    }
}

/// The effective inertia of every force or torque input of the system at state `st`; empty
/// where the system is too large to factorize densely ([`MAX_UNKNOWNS`]) or the matrix is
/// singular (an input on a body without mass that the joints do not hold).
pub fn input_inertias(sys: &Mechanics, st: &GaState, table: &VariableTable) -> Vec<InputInertia> {
    let (n, m) = (sys.n(), sys.m());
    // the inertias are filled in below
    let inputs: Vec<InputInertia> = table
        .variables
        .iter()
        .filter_map(|var| match var.binding {
            Binding::Input(slot) => {
                let direction: Vec<(usize, f64)> = input_force(sys, st, slot)
                    .into_iter()
                    .filter(|&(_, x)| x != 0.0)
                    .collect();
                (!direction.is_empty()).then(|| InputInertia {
                    name: var.name.clone(),
                    slot,
                    torque: var.unit == Some("N.m"),
                    drive: var.name.ends_with(".drive.torque")
                        || var.name.ends_with(".drive.force"),
                    direction,
                    effective: f64::NAN,
                    rigid: f64::NAN,
                })
            }
            _ => None,
        })
        .collect();
    if inputs.is_empty() || n + m > MAX_UNKNOWNS {
        return Vec::new();
    }
    let mut mm = DMatrix::zeros(n, n);
    sys.mass_matrix(&st.q, &mut mm);
    let mut gm = DMatrix::zeros(m, n);
    sys.constraint_jacobian(&st.q, st.t, &mut gm);
    let full = kkt(&mm, &gm).lu();
    // every beam held rigid: only the frame coordinates move
    let frames = sys.frame_coordinates();
    let mr = mm.select_rows(&frames).select_columns(&frames);
    let gr = gm.select_columns(&frames);
    let rigid = kkt(&mr, &gr).svd(true, true);
    let mut out = Vec::new();
    for mut input in inputs {
        let mut rhs = DVector::zeros(n + m);
        for &(k, x) in &input.direction {
            rhs[k] += x;
        }
        let Some(x) = full.solve(&rhs).filter(|x| x.iter().all(|v| v.is_finite())) else {
            continue;
        };
        let mobility: f64 = input.direction.iter().map(|&(k, b)| b * x[k]).sum();
        if mobility.is_nan() || mobility <= 0.0 {
            continue;
        }
        let mut rhs_r = DVector::zeros(frames.len() + m);
        for (i, &k) in frames.iter().enumerate() {
            rhs_r[i] = rhs[k];
        }
        let rigid_mobility = rigid
            .solve(&rhs_r, 1e-12 * rigid.singular_values.max())
            .ok()
            .map(|x| (0..frames.len()).map(|i| rhs_r[i] * x[i]).sum::<f64>())
            // held rigid, a direction the joints then lock has no finite inertia to compare
            .filter(|&mo| mo > 1e-12 * mobility && mo.is_finite());
        input.effective = 1.0 / mobility;
        input.rigid = rigid_mobility.map_or(f64::NAN, |mo| 1.0 / mo);
        out.push(input);
    }
    out
}

/// [[M, Gᵀ], [G, 0]].
fn kkt(mm: &DMatrix<f64>, gm: &DMatrix<f64>) -> DMatrix<f64> {
    let (n, m) = (mm.nrows(), gm.nrows());
    let mut a = DMatrix::zeros(n + m, n + m);
    a.view_mut((0, 0), (n, n)).copy_from(mm);
    a.view_mut((0, n), (n, m)).copy_from(&gm.transpose());
    a.view_mut((n, 0), (m, n)).copy_from(gm);
    a
}

/// ∂Q/∂u of input slot `slot` at the state's time, as (coordinate, value) pairs.
fn input_force(sys: &Mechanics, st: &GaState, slot: usize) -> Vec<(usize, f64)> {
    match sys {
        Mechanics::Planar(s) => s.input_force(&st.q, &st.v, st.t, slot),
        Mechanics::Spatial(s, _) => s.input_force(&st.q, st.t, slot),
    }
}
