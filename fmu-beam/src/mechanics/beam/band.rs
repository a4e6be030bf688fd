//! Banded storage of a planar beam: its constant deformation matrices ([`Banded`]) and its
//! blocks of M, K_t and C_t as an arrow around a band ([`ArrowBand`]: the first `head` rows and
//! columns, the frame coordinates coupled with all, dense; the deformation coordinates, each
//! coupled only within the elements of its node, within a half bandwidth). A beam of n elements
//! then builds and fills O(n) entries instead of O(n²), and the iteration matrix can eliminate
//! the band in O(n) (`integrator/bordered_band.rs`).

use nalgebra::{DMatrix, DMatrixViewMut, DVector, DVectorView};
use std::ops::{Index, IndexMut};

/// Read for every entry outside the pattern.
static ZERO: f64 = 0.0;

/// An n × n block: dense head rows and columns, the tail within `width` of the diagonal.
#[derive(Debug, Clone, PartialEq)]
pub struct ArrowBand {
    n: usize,
    head: usize,
    width: usize,
    /// Rows 0..head over all n columns, row-major.
    rows: Vec<f64>,
    /// Rows head..n over columns 0..head, row-major.
    cols: Vec<f64>,
    /// Rows head..n over columns i - width ..= i + width (tail indices), row-major.
    band: Vec<f64>,
}

impl ArrowBand {
    /// Zeros over an n × n block with `head` dense rows and columns and a tail of half
    /// bandwidth `width`.
    pub fn zeros(n: usize, head: usize, width: usize) -> ArrowBand {
        let tail = n.saturating_sub(head);
        ArrowBand {
            n,
            head,
            width,
            rows: vec![0.0; head * n],
            cols: vec![0.0; tail * head],
            band: vec![0.0; tail * (2 * width + 1)],
        }
    }

    /// Order of the block.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of dense leading rows and columns.
    pub fn head(&self) -> usize {
        self.head
    }

    /// Half bandwidth of the tail.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Entries stored: the head's rows and columns and the tail's band.
    pub fn stored(&self) -> usize {
        self.rows.len() + self.cols.len() + self.band.len()
    }

    pub fn fill_zero(&mut self) {
        self.rows.fill(0.0);
        self.cols.fill(0.0);
        self.band.fill(0.0);
    }

    /// Where entry (i, j) is stored, if it lies in the pattern.
    #[inline]
    fn slot(&self, i: usize, j: usize) -> Option<(u8, usize)> {
        let (h, w) = (self.head, self.width);
        if i >= self.n || j >= self.n {
            None
        } else if i < h {
            Some((0, i * self.n + j))
        } else if j < h {
            Some((1, (i - h) * h + j))
        } else if i.abs_diff(j) <= w {
            Some((2, (i - h) * (2 * w + 1) + j + w - i))
        } else {
            None
        }
    }

    /// Entry (i, j), zero outside the pattern.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        match self.slot(i, j) {
            Some((0, k)) => self.rows[k],
            Some((1, k)) => self.cols[k],
            Some((_, k)) => self.band[k],
            None => 0.0,
        }
    }

    /// Visits (i, j, value) of every stored entry.
    pub fn for_each_entry(&self, mut visit: impl FnMut(usize, usize, f64)) {
        let (n, h, w) = (self.n, self.head, self.width);
        for i in 0..h {
            for j in 0..n {
                visit(i, j, self.rows[i * n + j]);
            }
        }
        for i in h..n {
            for j in 0..h {
                visit(i, j, self.cols[(i - h) * h + j]);
            }
            for j in i.saturating_sub(w).max(h)..(i + w + 1).min(n) {
                visit(i, j, self.band[(i - h) * (2 * w + 1) + j + w - i]);
            }
        }
    }

    /// y = α A x + β y over slices of length n.
    /// Without a work vector (it runs in every Newton iteration): `for_each_entry` visits the
    /// rows in order, so each row's sum is done before the next row begins.
    pub fn gemv(&self, alpha: f64, x: &[f64], beta: f64, y: &mut [f64]) {
        let (mut row, mut sum) = (0, 0.0);
        self.for_each_entry(|i, j, a| {
            while row < i {
                y[row] = alpha * sum + beta * y[row];
                (row, sum) = (row + 1, 0.0);
            }
            sum += a * x[j];
        });
        while row < self.n {
            y[row] = alpha * sum + beta * y[row];
            (row, sum) = (row + 1, 0.0);
        }
    }

    /// Writes the block into a dense view (zeros off the pattern).
    pub fn write_dense(&self, mut out: DMatrixViewMut<f64>) {
        out.fill(0.0);
        self.for_each_entry(|i, j, a| out[(i, j)] = a);
    }

    /// A handle through which a body writes the block as it would a dense view.
    pub fn as_mut(&mut self) -> BandMut<'_> {
        BandMut(self)
    }
}

impl Index<(usize, usize)> for ArrowBand {
    type Output = f64;
    #[inline]
    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        match self.slot(i, j) {
            Some((0, k)) => &self.rows[k],
            Some((1, k)) => &self.cols[k],
            Some((_, k)) => &self.band[k],
            None => &ZERO,
        }
    }
}

impl IndexMut<(usize, usize)> for ArrowBand {
    #[inline]
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut f64 {
        match self.slot(i, j) {
            Some((0, k)) => &mut self.rows[k],
            Some((1, k)) => &mut self.cols[k],
            Some((_, k)) => &mut self.band[k],
            None => panic!(
                "entry ({i}, {j}) is outside the arrow band (order {}, head {}, half bandwidth {})",
                self.n, self.head, self.width
            ),
        }
    }
}

/// A square matrix stored within a half bandwidth of its diagonal: a beam's constant
/// deformation matrices (m_ff, W, K_ff, D_ff), each element coupling only its own coordinates,
/// in O(n) instead of O(n²).
#[derive(Debug, Clone, PartialEq)]
pub struct Banded {
    n: usize,
    width: usize,
    /// Row i over columns i − width ..= i + width, row-major.
    data: Vec<f64>,
}

impl Banded {
    pub fn zeros(n: usize, width: usize) -> Banded {
        Banded {
            n,
            width,
            data: vec![0.0; n * (2 * width + 1)],
        }
    }

    /// The dense matrix `d`, all of it (half bandwidth n − 1).
    pub fn from_dense(d: &DMatrix<f64>) -> Banded {
        let n = d.nrows();
        let mut b = Banded::zeros(n, n.saturating_sub(1));
        for j in 0..n {
            for i in 0..n {
                b[(i, j)] = d[(i, j)];
            }
        }
        b
    }

    pub fn nrows(&self) -> usize {
        self.n
    }

    /// Half bandwidth.
    pub fn width(&self) -> usize {
        self.width
    }

    pub fn to_dense(&self) -> DMatrix<f64> {
        DMatrix::from_fn(self.n, self.n, |i, j| self[(i, j)])
    }

    /// The matrix times x.
    pub fn scaled(&self, x: f64) -> Banded {
        Banded {
            data: self.data.iter().map(|a| a * x).collect(),
            ..self.clone()
        }
    }

    /// The product with a vector, column by column.
    pub fn mul_vec(&self, x: &DVectorView<f64>) -> DVector<f64> {
        let mut y = DVector::zeros(self.n);
        for j in 0..self.n {
            for i in j.saturating_sub(self.width)..(j + self.width + 1).min(self.n) {
                y[i] += self[(i, j)] * x[j];
            }
        }
        y
    }

    /// Row k over the columns `cols`, all within the half bandwidth of k (the loops that run
    /// in every Newton iteration: a slice instead of a checked lookup per entry).
    #[inline]
    pub fn row(&self, k: usize, cols: std::ops::Range<usize>) -> &[f64] {
        let w = self.width;
        assert!(
            cols.start + w >= k && cols.end <= (k + w + 1).min(self.n),
            "columns {cols:?} are outside the band of row {k} (half bandwidth {w})"
        );
        // entry (k, j) is at k (2w + 1) + j + w − k = 2 w k + w + j
        &self.data[2 * w * k + w + cols.start..2 * w * k + w + cols.end]
    }

    /// Column k over the rows `rows`, all within the half bandwidth of k, in order.
    #[inline]
    pub fn column(&self, k: usize, rows: std::ops::Range<usize>) -> impl Iterator<Item = f64> + '_ {
        let w = self.width;
        assert!(
            rows.start + w >= k && rows.end <= (k + w + 1).min(self.n),
            "rows {rows:?} are outside the band of column {k} (half bandwidth {w})"
        );
        rows.map(move |l| self.data[2 * w * l + w + k])
    }

    #[inline]
    fn slot(&self, i: usize, j: usize) -> Option<usize> {
        (i < self.n && j < self.n && i.abs_diff(j) <= self.width)
            .then(|| i * (2 * self.width + 1) + j + self.width - i)
    }
}

impl Index<(usize, usize)> for Banded {
    type Output = f64;
    #[inline]
    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        self.slot(i, j).map_or(&ZERO, |k| &self.data[k])
    }
}

impl IndexMut<(usize, usize)> for Banded {
    #[inline]
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut f64 {
        match self.slot(i, j) {
            Some(k) => &mut self.data[k],
            None => panic!(
                "entry ({i}, {j}) is outside the band (order {}, half bandwidth {})",
                self.n, self.width
            ),
        }
    }
}

/// What a body writes its blocks of M, K_t and C_t through: a dense view or an arrow band.
pub trait BlockMut: IndexMut<(usize, usize), Output = f64> {
    /// Sets every stored entry to zero.
    fn set_zero(&mut self);
}

impl BlockMut for DMatrixViewMut<'_, f64> {
    fn set_zero(&mut self) {
        self.fill(0.0);
    }
}

/// A mutable borrow of an [`ArrowBand`] that writes like a dense view.
#[derive(Debug)]
pub struct BandMut<'a>(&'a mut ArrowBand);

impl Index<(usize, usize)> for BandMut<'_> {
    type Output = f64;
    #[inline]
    fn index(&self, ij: (usize, usize)) -> &f64 {
        &self.0[ij]
    }
}

impl IndexMut<(usize, usize)> for BandMut<'_> {
    #[inline]
    fn index_mut(&mut self, ij: (usize, usize)) -> &mut f64 {
        &mut self.0[ij]
    }
}

impl BlockMut for BandMut<'_> {
    fn set_zero(&mut self) {
        self.0.fill_zero();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_multiply_and_expand_like_the_dense_matrix() {
        let mut a = ArrowBand::zeros(8, 3, 2);
        let mut d = DMatrix::zeros(8, 8);
        let mut x = 1.0;
        for i in 0..8_usize {
            for j in 0..8 {
                if i < 3 || j < 3 || i.abs_diff(j) <= 2 {
                    x += 0.37;
                    a[(i, j)] = x;
                    d[(i, j)] = x;
                }
            }
        }
        assert_eq!(a[(3, 7)], 0.0);
        assert_eq!(a.get(7, 3), 0.0);
        let mut e = DMatrix::zeros(8, 8);
        a.write_dense(e.view_mut((0, 0), (8, 8)));
        assert_eq!(e, d);
        let v = DVector::from_fn(8, |i, _| 1.0 / (1.0 + i as f64));
        let mut y = vec![1.0; 8];
        a.gemv(2.0, v.as_slice(), 0.5, &mut y);
        let expect = &d * &v * 2.0 + DVector::from_element(8, 0.5);
        for i in 0..8 {
            assert!((y[i] - expect[i]).abs() < 1e-12 * expect[i].abs());
        }
    }

    #[test]
    fn rows_and_columns_within_the_band_are_its_entries() {
        let (n, w) = (7, 2);
        let mut b = Banded::zeros(n, w);
        for i in 0..n {
            for j in i.saturating_sub(w)..(i + w + 1).min(n) {
                b[(i, j)] = 1.0 + 10.0 * i as f64 + j as f64;
            }
        }
        for k in 0..n {
            let cols = k.saturating_sub(w)..(k + w + 1).min(n);
            let row: Vec<f64> = cols.clone().map(|j| b[(k, j)]).collect();
            assert_eq!(b.row(k, cols.clone()), row.as_slice());
            let col: Vec<f64> = cols.clone().map(|l| b[(l, k)]).collect();
            assert_eq!(b.column(k, cols.clone()).collect::<Vec<_>>(), col);
            assert!(b.row(k, k..k).is_empty());
        }
    }

    #[test]
    #[should_panic(expected = "outside the band of row 1")]
    fn a_row_past_the_band_panics_rather_than_read_the_next_row() {
        Banded::zeros(7, 2).row(1, 0..5); // columns 0..=3 are in its band, 4 is not
    }

    #[test]
    #[should_panic(expected = "outside the arrow band")]
    fn a_write_outside_the_pattern_panics() {
        let mut a = ArrowBand::zeros(8, 3, 1);
        a.as_mut()[(3, 6)] += 1.0;
    }
}
