//! Linearized natural frequencies about the initial state: the eigenproblem
//! K φ = ω² M φ on the motions the joints leave free (null space of G).

use crate::error::EngineError;
use crate::integrator::{initial_state, Settings};
use crate::mechanics::multibody::equations::{Equations, Point};
use crate::mechanics::Mechanics;
use crate::scene::Scene;
use nalgebra::{DMatrix, DVector};

/// Natural frequencies (Hz), ascending, of the scene linearized about its initial
/// configuration at rest (deformation and loads as at t = 0). A 3D scene is linearized with
/// the element it runs with (planar when its motion is planar).
pub fn natural_frequencies(scene: &Scene) -> Result<Vec<f64>, EngineError> {
    let settings = Settings::from_scene(scene);
    // linearize about the undeformed equilibrium of the free motions
    let undeformed = Scene {
        beams: scene
            .beams
            .iter()
            .cloned()
            .map(|mut b| {
                b.initial.tip_displacement = 0.0;
                b
            })
            .collect(),
        ..scene.clone()
    };
    let effects = crate::unit::effects::resolve(scene).effects;
    crate::unit::memory::ensure_available(scene, "natural frequencies")?;
    let sys = Mechanics::build(scene, &effects);
    let st = initial_state(&sys, 0.0, &settings)?;
    let q = Mechanics::build(&undeformed, &effects).initial_coordinates()?;
    linearized(&sys, &q, &st.lambda)
}

/// Frequencies of K φ = ω² M φ at q (at rest) on the null space of G.
fn linearized<E: Equations>(
    sys: &E,
    q: &DVector<f64>,
    lambda: &DVector<f64>,
) -> Result<Vec<f64>, EngineError> {
    let (n, m) = (sys.n(), sys.m());
    let zero = DVector::zeros(n);
    let mut mm = DMatrix::zeros(n, n);
    let mut kt = DMatrix::zeros(n, n);
    let mut ct = DMatrix::zeros(n, n);
    let mut gm = DMatrix::zeros(m, n);
    sys.mass_matrix(q, &mut mm);
    let at = Point {
        q,
        v: &zero,
        a: &zero,
        lambda,
        t: 0.0,
    };
    sys.tangents(&at, &mut kt, &mut ct);
    sys.constraint_jacobian(q, 0.0, &mut gm);
    let basis = null_space(&gm, n);
    let mr = basis.transpose() * &mm * &basis;
    let kr = basis.transpose() * &kt * &basis;
    let mr = (&mr + mr.transpose()) * 0.5;
    let kr = (&kr + kr.transpose()) * 0.5;
    let chol = mr.cholesky().ok_or_else(|| EngineError::InitialState {
        message: "the mass matrix is not positive definite on the free motions".into(),
    })?;
    let linv = chol
        .l()
        .try_inverse()
        .ok_or_else(|| EngineError::InitialState {
            message: "singular mass matrix on the free motions".into(),
        })?;
    let a = &linv * kr * linv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let eig = a.symmetric_eigen();
    let mut f: Vec<f64> = eig
        .eigenvalues
        .iter()
        .map(|&l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
        .collect();
    f.sort_by(|a, b| a.total_cmp(b));
    Ok(f)
}

/// Orthonormal basis of the null space of G (n × (n - rank)).
fn null_space(gm: &DMatrix<f64>, n: usize) -> DMatrix<f64> {
    if gm.nrows() == 0 {
        return DMatrix::identity(n, n);
    }
    // Complete the row space with the SVD of the square matrix [G; 0].
    let mut sq = DMatrix::zeros(n, n);
    sq.view_mut((0, 0), (gm.nrows().min(n), n))
        .copy_from(&gm.rows(0, gm.nrows().min(n)));
    let svd = sq.svd(false, true);
    let vt = svd.v_t.expect("v_t requested");
    let smax = svd.singular_values.amax().max(1e-300);
    let cols: Vec<_> = (0..n)
        .filter(|&k| svd.singular_values[k] <= 1e-10 * smax)
        .map(|k| vt.row(k).transpose())
        .collect();
    DMatrix::from_columns(&cols)
}
