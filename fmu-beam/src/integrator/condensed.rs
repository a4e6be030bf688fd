//! The dense iteration matrix with its fixed coordinates condensed out before the LU.
//!
//! A constraint row whose only entry is in one coordinate's column fixes that coordinate alone:
//! a revolute joint to the world at a body's own origin (x, y), a prismatic joint to the world
//! through it (the offset across the line, the angle), a driven hub's angle. Its multiplier then
//! acts on that coordinate's row alone (the matrix holds G and Gᵀ), and the pair (coordinate,
//! multiplier) leaves the system exactly: the row gives the coordinate's correction, the
//! coordinate's own row the multiplier's after the rest is solved. The rest is one LU smaller by
//! two unknowns per pair; the slider-crank with a rigid crank and a rod of 2 elements solves 15
//! instead of 23 (its crank pivot and its slider fix four coordinates).
//!
//! The solution is the one of the whole matrix (the pairs are its first pivots, 2 × 2 blocks
//! [[s, g], [g, 0]] with g ≠ 0); the arithmetic differs in its rounding only.

use nalgebra::{DMatrix, DVector, Dyn, LU};

/// A coordinate fixed by a constraint row alone, and the entries that tie them.
#[derive(Debug, Clone, Copy)]
struct Pair {
    /// The coordinate's column (and row) in the matrix.
    coordinate: usize,
    /// The constraint's row (and its multiplier's column), n + j.
    row: usize,
    /// The constraint row's one entry, at the coordinate's column.
    fixes: f64,
    /// The multiplier's one entry, at the coordinate's row.
    reacts: f64,
}

/// The factors of a dense iteration matrix with its fixed coordinates condensed out (its
/// workspace kept from one factorization to the next).
#[derive(Debug, Clone, Default)]
pub(super) struct Condensed {
    pairs: Vec<Pair>,
    /// The unknowns left, in the matrix's order.
    kept: Vec<usize>,
    /// Each pair's coordinate column over the kept rows (pair by pair).
    columns: Vec<f64>,
    /// Each pair's coordinate row over the kept columns (pair by pair).
    rows: Vec<f64>,
    /// Each pair's coordinate row over the pairs' coordinate columns (pair by pair).
    among: Vec<f64>,
    /// The LU of the kept rows and columns; None where nothing is kept or before factors.
    lu: Option<LU<f64, Dyn, Dyn>>,
    /// Whether the factors are the last matrix's.
    factored: bool,
    /// Workspace: which unknowns a pair takes, the kept unknowns, the fixed coordinates' and
    /// the multipliers' corrections.
    taken: Vec<bool>,
    kept_x: DVector<f64>,
    fixed_x: Vec<f64>,
    multipliers: Vec<f64>,
}

impl Condensed {
    /// Finds the pairs of `jac` (n coordinates, then the constraint rows) and factorizes the
    /// rest: None where no constraint row fixes a coordinate alone (the whole matrix's LU is
    /// the caller's then), else whether the whole matrix is regular.
    pub(super) fn factorize(&mut self, jac: &DMatrix<f64>, n: usize) -> Option<bool> {
        self.factored = false;
        self.lu = None;
        let dim = jac.nrows();
        // column-major: entry (i, j) at j·dim + i
        let a = jac.as_slice();
        self.taken.clear();
        self.taken.resize(dim, false);
        self.pairs.clear();
        for row in n..dim {
            let mut entries = (0..dim).filter(|&c| a[c * dim + row] != 0.0);
            let (Some(coordinate), None) = (entries.next(), entries.next()) else {
                continue;
            };
            let column = &a[row * dim..(row + 1) * dim];
            let only_there = column
                .iter()
                .enumerate()
                .all(|(r, x)| (*x != 0.0) == (r == coordinate));
            if coordinate >= n || self.taken[coordinate] || !only_there {
                continue;
            }
            self.taken[coordinate] = true;
            self.taken[row] = true;
            self.pairs.push(Pair {
                coordinate,
                row,
                fixes: a[coordinate * dim + row],
                reacts: column[coordinate],
            });
        }
        if self.pairs.is_empty() {
            return None;
        }
        self.kept.clear();
        self.kept.extend((0..dim).filter(|&k| !self.taken[k]));
        let (r, p) = (self.kept.len(), self.pairs.len());
        let (kept, pairs) = (&self.kept, &self.pairs);
        self.columns.clear();
        self.rows.clear();
        self.among.clear();
        for pair in pairs {
            let column = &a[pair.coordinate * dim..(pair.coordinate + 1) * dim];
            self.columns.extend(kept.iter().map(|&k| column[k]));
            self.rows
                .extend(kept.iter().map(|&k| a[k * dim + pair.coordinate]));
            self.among.extend(
                pairs
                    .iter()
                    .map(|o| a[o.coordinate * dim + pair.coordinate]),
            );
        }
        if r > 0 {
            let mut rest = DMatrix::zeros(r, r);
            for (out, &j) in rest.as_mut_slice().chunks_exact_mut(r).zip(kept) {
                let column = &a[j * dim..(j + 1) * dim];
                for (x, &i) in out.iter_mut().zip(kept) {
                    *x = column[i];
                }
            }
            let lu = rest.lu();
            if !lu.is_invertible() {
                return Some(false);
            }
            self.lu = Some(lu);
        }
        // the workspace of the kept unknowns, allocated again only where their number changes
        if self.kept_x.len() != r {
            self.kept_x = DVector::zeros(r);
        }
        self.fixed_x.resize(p, 0.0);
        self.multipliers.resize(p, 0.0);
        self.factored = true;
        Some(true)
    }

    /// Drops the factors.
    pub(super) fn forget(&mut self) {
        self.factored = false;
        self.lu = None;
    }

    /// Solves the whole matrix in place; false without factors.
    pub(super) fn solve_mut(&mut self, b: &mut DVector<f64>) -> bool {
        if !self.factored {
            return false;
        }
        let (r, p) = (self.kept.len(), self.pairs.len());
        let b = b.as_mut_slice();
        for (x, pair) in self.fixed_x.iter_mut().zip(&self.pairs) {
            *x = b[pair.row] / pair.fixes;
        }
        let y = self.kept_x.as_mut_slice();
        for (y, &k) in y.iter_mut().zip(&self.kept) {
            *y = b[k];
        }
        for (column, &x) in self.columns.chunks_exact(r.max(1)).zip(&self.fixed_x) {
            // a satisfied constraint moves nothing (the common case: its coordinate's
            // correction is 0)
            if x != 0.0 {
                for (y, a) in y.iter_mut().zip(column) {
                    *y -= a * x;
                }
            }
        }
        if let Some(lu) = &self.lu {
            if !lu.solve_mut(&mut self.kept_x) {
                return false;
            }
        }
        let y = self.kept_x.as_slice();
        for (k, pair) in self.pairs.iter().enumerate() {
            let row = &self.rows[k * r..(k + 1) * r];
            let mut rest: f64 = row.iter().zip(y).map(|(a, x)| a * x).sum();
            for (a, &x) in self.among[k * p..(k + 1) * p].iter().zip(&self.fixed_x) {
                if x != 0.0 {
                    rest += a * x;
                }
            }
            self.multipliers[k] = (b[pair.coordinate] - rest) / pair.reacts;
        }
        for (x, &k) in y.iter().zip(&self.kept) {
            b[k] = *x;
        }
        for ((pair, x), lambda) in self.pairs.iter().zip(&self.fixed_x).zip(&self.multipliers) {
            b[pair.coordinate] = *x;
            b[pair.row] = *lambda;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A matrix of the iteration matrix's shape: a symmetric coordinate block, rows that fix a
    /// coordinate alone and rows that tie several.
    fn kkt() -> (DMatrix<f64>, usize) {
        let n = 5;
        let s = DMatrix::from_fn(n, n, |i, j| {
            if i == j {
                4.0 + i as f64
            } else {
                0.3 / (1.0 + (i as f64 - j as f64).abs())
            }
        });
        // row 0 fixes coordinate 1 alone, row 1 ties 0, 1 and 3, row 2 fixes coordinate 4
        let g = DMatrix::from_row_slice(
            3,
            n,
            &[
                0.0, -1.0, 0.0, 0.0, 0.0, //
                1.0, 0.5, 0.0, -2.0, 0.0, //
                0.0, 0.0, 0.0, 0.0, 1.5,
            ],
        );
        let dim = n + 3;
        let mut k = DMatrix::zeros(dim, dim);
        k.view_mut((0, 0), (n, n)).copy_from(&s);
        k.view_mut((n, 0), (3, n)).copy_from(&g);
        k.view_mut((0, n), (n, 3)).copy_from(&g.transpose());
        (k, n)
    }

    #[test]
    fn the_condensed_solution_is_the_whole_matrix_one() {
        let (k, n) = kkt();
        let mut c = Condensed::default();
        assert_eq!(
            c.factorize(&k, n),
            Some(true),
            "two coordinates fixed alone"
        );
        assert_eq!(c.pairs.len(), 2);
        assert_eq!(c.kept.len(), 4);
        let b = DVector::from_fn(k.nrows(), |i, _| (i as f64 * 0.7).sin() + 0.1);
        let mut x = b.clone();
        assert!(c.solve_mut(&mut x));
        let whole = k.clone().lu().solve(&b).unwrap();
        assert!((&x - &whole).amax() < 1e-14, "{x} against {whole}");
        assert!((&k * &x - &b).amax() < 1e-14);
    }

    #[test]
    fn a_matrix_without_such_rows_is_left_whole() {
        let (mut k, n) = kkt();
        // row 0 also in column 2: it ties two coordinates
        k[(n, 2)] = 0.25;
        k[(2, n)] = 0.25;
        k[(n + 2, 3)] = 1.0;
        k[(3, n + 2)] = 1.0;
        let mut c = Condensed::default();
        assert_eq!(c.factorize(&k, n), None);
        let mut b = DVector::from_element(k.nrows(), 1.0);
        assert!(!c.solve_mut(&mut b), "no factors");
        assert_eq!(b, DVector::from_element(k.nrows(), 1.0));
    }

    #[test]
    fn a_singular_rest_is_reported_and_solves_nothing() {
        let (mut k, n) = kkt();
        // two constraints fixing coordinate 1 alone: the second is redundant
        k[(n + 1, 0)] = 0.0;
        k[(0, n + 1)] = 0.0;
        k[(n + 1, 3)] = 0.0;
        k[(3, n + 1)] = 0.0;
        k[(n + 1, 1)] = 2.0;
        k[(1, n + 1)] = 2.0;
        let mut c = Condensed::default();
        assert_eq!(
            c.factorize(&k, n),
            Some(false),
            "one pair taken, the rest singular"
        );
        let mut b = DVector::from_element(k.nrows(), 1.0);
        assert!(!c.solve_mut(&mut b));
    }
}
