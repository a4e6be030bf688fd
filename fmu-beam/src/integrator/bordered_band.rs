//! A bordered banded LU: the iteration matrix with the beams' deformation coordinates (the
//! band blocks of `mechanics/beam/band.rs`) eliminated first and everything else (frame
//! coordinates, other bodies, multipliers: the border) last, as a dense Schur complement.
//! With the border small, a frame of n elements factorizes in O(n) where the dense LU takes
//! O(n³); the dense LU pivots on the frame's rows and fills the band, this order does not.
//!
//! [[B, E], [F, D]] = [[L_B U_B, 0], [F, I]] [[I, X], [0, S]], X = B⁻¹E, S = D − F X.
//! B is factorized with partial pivoting within its band (rows at most `width` below the
//! diagonal; the upper band widens by as much), S by nalgebra's dense LU.

use nalgebra::{DMatrix, Dyn, LU};
use std::ops::Range;

/// A pivot of B at most this fraction of its column's largest entry before elimination is
/// refused: so much cancellation that the factors would carry few correct digits.
pub const PIVOT_CANCELLATION: f64 = 1e-12;

/// Why a factorization was refused (the caller factorizes dense instead).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Refusal {
    /// Pivot `pivot` of column `column` of the band is tiny: its column held `column_max`
    /// before elimination, the band `band_max`.
    TinyPivot {
        column: usize,
        pivot: f64,
        column_max: f64,
        band_max: f64,
    },
    /// The Schur complement of order `order` is singular.
    SingularSchur { order: usize },
    /// An entry of the factors is not finite.
    NotFinite,
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Refusal::TinyPivot {
                column,
                pivot,
                column_max,
                band_max,
            } => write!(
                f,
                "band pivot {pivot:.3e} in column {column} (column max {column_max:.3e}, band \
                 max {band_max:.3e})"
            ),
            Refusal::SingularSchur { order } => {
                write!(f, "singular Schur complement of order {order}")
            }
            Refusal::NotFinite => write!(f, "factors not finite"),
        }
    }
}

/// Where an unknown goes: the k-th row of the band or of the border.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Place {
    Band(usize),
    Border(usize),
}

/// The workspace and factors over a fixed split of the unknowns.
#[derive(Debug, Clone)]
pub struct BorderedBand {
    place: Vec<Place>,
    /// Global index of each band row, and of each border row.
    band_rows: Vec<usize>,
    border_rows: Vec<usize>,
    /// Half bandwidth of B.
    width: usize,
    /// B by rows: row i over columns i − width ..= i + 2 width (the upper part widens by the
    /// row swaps of pivoting); after factorization L (below) and U.
    b: Vec<f64>,
    pivots: Vec<usize>,
    /// E by columns (nb each); after factorization X = B⁻¹E.
    e: Vec<f64>,
    /// F by rows (nb each).
    f: Vec<f64>,
    /// D; after factorization S = D − F X.
    d: DMatrix<f64>,
    /// Which columns of E and rows of F hold a nonzero.
    e_used: Vec<bool>,
    f_used: Vec<bool>,
    /// S's LU (None without a border).
    schur: Option<LU<f64, Dyn, Dyn>>,
    factored: bool,
}

impl BorderedBand {
    /// The split of `dim` unknowns: `bands` (global index ranges, in order, not overlapping)
    /// are eliminated first, B's half bandwidth is `width`.
    pub fn new(dim: usize, bands: &[Range<usize>], width: usize) -> BorderedBand {
        let mut place = vec![Place::Border(0); dim];
        let (mut band_rows, mut border_rows) = (Vec::new(), Vec::new());
        let mut in_band = vec![false; dim];
        for r in bands {
            in_band[r.clone()].fill(true);
        }
        for (i, p) in place.iter_mut().enumerate() {
            if in_band[i] {
                *p = Place::Band(band_rows.len());
                band_rows.push(i);
            } else {
                *p = Place::Border(border_rows.len());
                border_rows.push(i);
            }
        }
        let (nb, p) = (band_rows.len(), border_rows.len());
        BorderedBand {
            place,
            band_rows,
            border_rows,
            width,
            b: vec![0.0; nb * (3 * width + 1)],
            pivots: vec![0; nb],
            e: vec![0.0; nb * p],
            f: vec![0.0; p * nb],
            d: DMatrix::zeros(p, p),
            e_used: vec![false; p],
            f_used: vec![false; p],
            schur: None,
            factored: false,
        }
    }

    /// Stored entries.
    pub fn stored(&self) -> usize {
        self.b.len() + self.e.len() + self.f.len() + self.d.len()
    }

    /// Floating point operations of a factorization of `band` rows of half bandwidth `width`
    /// bordered by `border` rows: B's LU, X, S and S's LU.
    pub fn operations(band: usize, width: usize, border: usize) -> f64 {
        let (nb, w, p) = (band as f64, width as f64, border as f64);
        6.0 * nb * w * w + 6.0 * nb * w * p + 2.0 * nb * p * p + 2.0 / 3.0 * p * p * p
    }

    /// Sets every entry to zero.
    pub fn clear(&mut self) {
        self.b.fill(0.0);
        self.e.fill(0.0);
        self.f.fill(0.0);
        self.d.fill(0.0);
        self.schur = None;
        self.factored = false;
    }

    #[inline]
    fn ld(&self) -> usize {
        3 * self.width + 1
    }

    /// Where B's entry (i, j) (band indices) is stored; j − i within −width ..= 2 width.
    #[inline]
    fn at(&self, i: usize, j: usize) -> usize {
        i * self.ld() + j + self.width - i
    }

    /// Sets entry (i, j) of the matrix (global indices). Panics for an entry of B off its band.
    pub fn set(&mut self, i: usize, j: usize, x: f64) {
        let nb = self.band_rows.len();
        match (self.place[i], self.place[j]) {
            (Place::Band(r), Place::Band(c)) => {
                assert!(
                    r.abs_diff(c) <= self.width,
                    "entry ({i}, {j}) is {} off the band's diagonal, beyond its half bandwidth {}",
                    r.abs_diff(c),
                    self.width
                );
                let k = self.at(r, c);
                self.b[k] = x;
            }
            (Place::Band(r), Place::Border(c)) => self.e[c * nb + r] = x,
            (Place::Border(r), Place::Band(c)) => self.f[r * nb + c] = x,
            (Place::Border(r), Place::Border(c)) => self.d[(r, c)] = x,
        }
    }

    /// Factorizes the matrix set; refused (factors dropped) when a pivot of B is tiny, S is
    /// singular or the factors are not finite.
    pub fn factorize(&mut self) -> Result<(), Refusal> {
        self.schur = None;
        self.factored = false;
        let (nb, p, w) = (self.band_rows.len(), self.border_rows.len(), self.width);
        let band_max = self.b.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        for k in 0..nb {
            let last = (k + w).min(nb.saturating_sub(1));
            let column_max = (k.saturating_sub(w)..=last)
                .map(|i| self.b[self.at(i, k)].abs())
                .fold(0.0, f64::max);
            let (mut piv, mut best) = (k, self.b[self.at(k, k)].abs());
            for i in k + 1..=last {
                let x = self.b[self.at(i, k)].abs();
                if x > best {
                    (piv, best) = (i, x);
                }
            }
            // the column's entries above the diagonal are U's by now; what is below is what
            // elimination left: compare with the column before it
            if !best.is_finite()
                || best <= PIVOT_CANCELLATION * column_max
                || best <= f64::EPSILON * nb as f64 * band_max
            {
                return Err(Refusal::TinyPivot {
                    column: k,
                    pivot: best,
                    column_max,
                    band_max,
                });
            }
            self.pivots[k] = piv;
            let end = (k + 2 * w).min(nb - 1);
            if piv != k {
                for j in k..=end {
                    let (a, b) = (self.at(k, j), self.at(piv, j));
                    self.b.swap(a, b);
                }
            }
            let pivot = self.b[self.at(k, k)];
            for i in k + 1..=last {
                let ik = self.at(i, k);
                let l = self.b[ik] / pivot;
                self.b[ik] = l;
                if l != 0.0 {
                    for j in k + 1..=end {
                        let (ij, kj) = (self.at(i, j), self.at(k, j));
                        self.b[ij] -= l * self.b[kj];
                    }
                }
            }
        }
        for c in 0..p {
            let col = &self.e[c * nb..(c + 1) * nb];
            self.e_used[c] = col.iter().any(|&x| x != 0.0);
            self.f_used[c] = self.f[c * nb..(c + 1) * nb].iter().any(|&x| x != 0.0);
        }
        let mut e = std::mem::take(&mut self.e);
        for c in (0..p).filter(|&c| self.e_used[c]) {
            self.band_solve(&mut e[c * nb..(c + 1) * nb]);
        }
        self.e = e;
        for r in (0..p).filter(|&r| self.f_used[r]) {
            let fr = &self.f[r * nb..(r + 1) * nb];
            for c in (0..p).filter(|&c| self.e_used[c]) {
                let xc = &self.e[c * nb..(c + 1) * nb];
                let dot: f64 = fr.iter().zip(xc).map(|(a, b)| a * b).sum();
                self.d[(r, c)] -= dot;
            }
        }
        if !self
            .b
            .iter()
            .chain(&self.e)
            .chain(self.d.iter())
            .all(|x| x.is_finite())
        {
            return Err(Refusal::NotFinite);
        }
        if p > 0 {
            let lu = self.d.clone().lu();
            if !lu.is_invertible() {
                return Err(Refusal::SingularSchur { order: p });
            }
            self.schur = Some(lu);
        }
        self.factored = true;
        Ok(())
    }

    /// y ← B⁻¹ y with B's factors (nb entries).
    fn band_solve(&self, y: &mut [f64]) {
        let (nb, w) = (self.band_rows.len(), self.width);
        for k in 0..nb {
            let piv = self.pivots[k];
            if piv != k {
                y.swap(k, piv);
            }
            let yk = y[k];
            if yk != 0.0 {
                for i in k + 1..=(k + w).min(nb - 1) {
                    y[i] -= self.b[self.at(i, k)] * yk;
                }
            }
        }
        for k in (0..nb).rev() {
            let mut s = y[k];
            for j in k + 1..=(k + 2 * w).min(nb - 1) {
                s -= self.b[self.at(k, j)] * y[j];
            }
            y[k] = s / self.b[self.at(k, k)];
        }
    }

    /// Solves in place (global order); false without factors.
    pub fn solve_mut(&self, rhs: &mut [f64]) -> bool {
        if !self.factored {
            return false;
        }
        let nb = self.band_rows.len();
        let mut y: Vec<f64> = self.band_rows.iter().map(|&i| rhs[i]).collect();
        let mut z = nalgebra::DVector::from_iterator(
            self.border_rows.len(),
            self.border_rows.iter().map(|&i| rhs[i]),
        );
        self.band_solve(&mut y);
        for (r, zr) in z.iter_mut().enumerate() {
            if self.f_used[r] {
                let fr = &self.f[r * nb..(r + 1) * nb];
                *zr -= fr.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>();
            }
        }
        if self.schur.as_ref().is_some_and(|s| !s.solve_mut(&mut z)) {
            return false;
        }
        for (c, &zc) in z.iter().enumerate() {
            if self.e_used[c] && zc != 0.0 {
                let xc = &self.e[c * nb..(c + 1) * nb];
                for (yi, x) in y.iter_mut().zip(xc) {
                    *yi -= x * zc;
                }
            }
        }
        for (&i, v) in self.band_rows.iter().zip(&y) {
            rhs[i] = *v;
        }
        for (&i, v) in self.border_rows.iter().zip(z.iter()) {
            rhs[i] = *v;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    /// A pseudo-random number in (−1, 1) from a state.
    fn next(s: &mut u64) -> f64 {
        *s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }

    /// An arrow around a band: `head` dense rows and columns, then a band of `nb` rows (half
    /// bandwidth `w`), then `m` constraint rows over a few columns each and their transpose.
    fn arrow(
        seed: u64,
        head: usize,
        nb: usize,
        w: usize,
        m: usize,
    ) -> (DMatrix<f64>, Range<usize>) {
        let mut s = seed;
        let n = head + nb;
        let dim = n + m;
        let mut a = DMatrix::zeros(dim, dim);
        for i in 0..n {
            for j in 0..n {
                if i < head || j < head || i.abs_diff(j) <= w {
                    a[(i, j)] = next(&mut s);
                }
            }
            a[(i, i)] += 4.0 * (w + head) as f64 * if i % 2 == 0 { 1.0 } else { -1e3 };
        }
        for r in 0..m {
            let at = (r * 7) % nb;
            for c in [0, 2, head + at, head + (at + 1).min(nb - 1)] {
                let g = next(&mut s) + 2.0;
                a[(n + r, c)] = g;
                a[(c, n + r)] = g;
            }
        }
        (a, head..n)
    }

    fn bordered(a: &DMatrix<f64>, band: Range<usize>, w: usize) -> BorderedBand {
        let mut bb = BorderedBand::new(a.nrows(), &[band], w);
        for j in 0..a.ncols() {
            for i in 0..a.nrows() {
                if a[(i, j)] != 0.0 {
                    bb.set(i, j, a[(i, j)]);
                }
            }
        }
        bb
    }

    #[test]
    fn the_bordered_solve_equals_the_dense_lu_solve() {
        for (seed, head, nb, w, m) in [(1, 3, 40, 5, 2), (2, 3, 97, 2, 5), (3, 0, 30, 4, 0)] {
            let (a, band) = arrow(seed, head, nb, w, m);
            let mut bb = bordered(&a, band, w);
            bb.factorize().expect("a regular matrix factorizes");
            let mut s = seed + 100;
            let rhs = DVector::from_fn(a.nrows(), |_, _| next(&mut s));
            let dense = a.clone().lu().solve(&rhs).expect("regular");
            let mut x = rhs.clone();
            assert!(bb.solve_mut(x.as_mut_slice()));
            let err = (&x - &dense).amax() / dense.amax();
            assert!(err < 1e-12, "seed {seed}: relative difference {err:.2e}");
        }
    }

    #[test]
    fn a_band_that_cancels_is_refused() {
        let (mut a, band) = arrow(4, 3, 20, 3, 2);
        // rows 13 and 14 equal over the band's columns: B is singular, while the head columns
        // and the constraints keep the whole matrix regular (the dense LU solves it)
        for j in 10..=17 {
            let x = if j == 10 || j == 17 { 0.0 } else { a[(13, j)] };
            a[(13, j)] = x;
            a[(14, j)] = x;
        }
        assert!(a
            .clone()
            .lu()
            .solve(&DVector::from_element(a.nrows(), 1.0))
            .is_some());
        let mut bb = bordered(&a, band, 3);
        let refusal = bb.factorize().expect_err("a singular band is refused");
        assert!(matches!(refusal, Refusal::TinyPivot { .. }), "{refusal}");
        assert!(!bb.solve_mut(&mut vec![1.0; a.nrows()]));
    }

    #[test]
    fn a_singular_border_is_refused() {
        let (mut a, band) = arrow(5, 3, 20, 3, 1);
        let n = a.nrows();
        for j in 0..n {
            a[(n - 1, j)] = 0.0;
            a[(j, n - 1)] = 0.0;
        }
        let mut bb = bordered(&a, band, 3);
        assert_eq!(bb.factorize(), Err(Refusal::SingularSchur { order: 4 }));
    }
}
