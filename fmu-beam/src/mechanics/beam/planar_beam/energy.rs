//! A planar beam's energies (kinetic, strain, gravity's potential): what the energy balances
//! and the tests read, apart from the equations of every Newton iteration.

use super::*;

impl PlanarBeam {
    /// Kinetic energy ½ żᵀ M ż (J).
    pub fn kinetic_energy<'a>(&self, z: impl Coords<'a>, zd: impl Coords<'a>) -> f64 {
        let n = self.ndof();
        let mut m = DMatrix::zeros(n, n);
        self.mass_matrix(z, m.view_mut((0, 0), (n, n)));
        let zd = zd.into();
        0.5 * zd.dot(&(&m * zd))
    }

    /// Strain energy ½ q_fᵀ K_ff q_f (J).
    pub fn strain_energy<'a>(&self, z: impl Coords<'a>) -> f64 {
        let z = z.into();
        let f = z.rows(FLEX, self.nflex());
        let extra = if self.geometric_stiffening {
            self.stiffening_energy(&z)
        } else {
            0.0
        };
        0.5 * f.dot(&self.kff.mul_vec(&f)) + extra
    }

    /// Potential energy of gravity -g·∫ρ r dV (J).
    pub fn gravity_energy<'a>(&self, z: impl Coords<'a>, gravity: Option<Vector2<f64>>) -> f64 {
        let Some(gravity) = gravity else { return 0.0 };
        let z = z.into();
        let f = z.rows(FLEX, self.nflex());
        let (ar, _) = rot(z[THETA]);
        let com = Vector2::new(z[0], z[1]) * self.mass + ar * self.first_moment(&f);
        -gravity.dot(&com)
    }
}
