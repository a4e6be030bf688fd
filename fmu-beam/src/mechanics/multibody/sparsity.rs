//! The sparsity of a multibody system's matrices, fixed when the system is built: M, K_t and C_t
//! are block diagonal over the bodies' coordinates ([`BlockDiagonal`]; a beam's block may be an
//! arrow band, `beam/band.rs`), and each constraint row
//! depends on the coordinates of at most two bodies, the bodies of its joint's frames
//! ([`JacobianRows`]). Work on them is O(Σ block² + nnz(G)) instead of O(n²) and O(m n).

use crate::mechanics::beam::band::ArrowBand;
use nalgebra::{DMatrix, DVector};
use std::ops::{Index, Range};

/// One body's block: dense, or an arrow band (a beam's frame coordinates around the band of
/// its deformation coordinates).
#[derive(Debug, Clone, PartialEq)]
pub enum Block {
    Dense(DMatrix<f64>),
    Band(ArrowBand),
}

impl Block {
    /// Order of the block.
    pub fn n(&self) -> usize {
        match self {
            Block::Dense(d) => d.nrows(),
            Block::Band(b) => b.n(),
        }
    }

    /// Entries stored: n² dense, the arrow and band of a banded block.
    pub fn stored(&self) -> usize {
        match self {
            Block::Dense(d) => d.len(),
            Block::Band(b) => b.stored(),
        }
    }

    pub fn fill_zero(&mut self) {
        match self {
            Block::Dense(d) => d.as_mut_slice().fill(0.0),
            Block::Band(b) => b.fill_zero(),
        }
    }

    /// The dense matrix of a block that bodies fill densely (rigid bodies, 3D bodies);
    /// panics on a banded block.
    pub fn dense_mut(&mut self) -> &mut DMatrix<f64> {
        match self {
            Block::Dense(d) => d,
            Block::Band(b) => panic!(
                "a banded block (order {}, half bandwidth {}) written as a dense one",
                b.n(),
                b.width()
            ),
        }
    }

    /// Visits (i, j, value) of every stored entry.
    pub fn for_each_entry(&self, mut visit: impl FnMut(usize, usize, f64)) {
        match self {
            Block::Dense(d) => {
                for j in 0..d.ncols() {
                    for i in 0..d.nrows() {
                        visit(i, j, d[(i, j)]);
                    }
                }
            }
            Block::Band(b) => b.for_each_entry(visit),
        }
    }

    /// y = α B x + β y.
    pub fn gemv(&self, alpha: f64, x: &[f64], beta: f64, y: &mut [f64]) {
        match self {
            Block::Dense(d) => {
                let mut yv = nalgebra::DVectorViewMut::from_slice(y, d.nrows());
                yv.gemv(
                    alpha,
                    d,
                    &nalgebra::DVectorView::from_slice(x, d.ncols()),
                    beta,
                );
            }
            Block::Band(b) => b.gemv(alpha, x, beta, y),
        }
    }
}

impl Index<(usize, usize)> for Block {
    type Output = f64;
    fn index(&self, ij: (usize, usize)) -> &f64 {
        match self {
            Block::Dense(d) => &d[ij],
            Block::Band(b) => &b[ij],
        }
    }
}

/// A block-diagonal matrix: one block per body, over the body's coordinates in q.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockDiagonal {
    /// Coordinates of each block (consecutive, covering 0..n).
    pub ranges: Vec<Range<usize>>,
    pub blocks: Vec<Block>,
}

impl BlockDiagonal {
    /// Zero dense blocks over `ranges`.
    pub fn zeros(ranges: &[Range<usize>]) -> BlockDiagonal {
        BlockDiagonal {
            ranges: ranges.to_vec(),
            blocks: ranges
                .iter()
                .map(|r| Block::Dense(DMatrix::zeros(r.len(), r.len())))
                .collect(),
        }
    }

    pub fn fill_zero(&mut self) {
        for b in &mut self.blocks {
            b.fill_zero();
        }
    }

    /// Whether any block is banded.
    pub fn has_band(&self) -> bool {
        self.blocks.iter().any(|b| matches!(b, Block::Band(_)))
    }

    /// Writes the whole n × n matrix (zeros off the blocks) into `out`.
    pub fn to_dense(&self, out: &mut DMatrix<f64>) {
        out.fill(0.0);
        for (r, b) in self.ranges.iter().zip(&self.blocks) {
            b.for_each_entry(|i, j, x| out[(r.start + i, r.start + j)] = x);
        }
    }
}

/// Columns of one constraint row over one body: `len` columns from `col`, values from `at`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct Segment {
    col: usize,
    len: usize,
    at: usize,
}

/// The constraint Jacobian G (m × n) by rows: row i holds the columns of the (at most two)
/// bodies its joint's frames move with, stored densely over each body.
#[derive(Debug, Clone, PartialEq)]
pub struct JacobianRows {
    n: usize,
    segments: Vec<[Segment; 2]>,
    values: Vec<f64>,
}

impl JacobianRows {
    /// The pattern of a system: `ranges` the bodies' coordinates, `rows` the bodies each
    /// constraint row depends on (`None` for a world frame).
    pub fn new(n: usize, ranges: &[Range<usize>], rows: &[[Option<usize>; 2]]) -> JacobianRows {
        let mut at = 0;
        let segments = rows
            .iter()
            .map(|bodies| {
                let mut b: Vec<usize> = bodies.iter().flatten().copied().collect();
                b.sort_unstable();
                b.dedup();
                let mut s = [Segment::default(); 2];
                for (k, &body) in b.iter().enumerate() {
                    let r = &ranges[body];
                    s[k] = Segment {
                        col: r.start,
                        len: r.len(),
                        at,
                    };
                    at += r.len();
                }
                s
            })
            .collect();
        JacobianRows {
            n,
            segments,
            values: vec![0.0; at],
        }
    }

    /// Number of rows (m).
    pub fn nrows(&self) -> usize {
        self.segments.len()
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    pub fn fill_zero(&mut self) {
        self.values.fill(0.0);
    }

    /// Adds x to G[row, col]; `col` must lie on a body of the row's pattern.
    #[inline]
    pub fn add(&mut self, row: usize, col: usize, x: f64) {
        let k = self
            .index(row, col)
            .unwrap_or_else(|| panic!("G[{row}, {col}] is outside the constraint row's bodies"));
        self.values[k] += x;
    }

    /// The stored values of row `row` from column `col` to the end of the body's columns that
    /// hold it: entry k is G[row, col + k]. Panics where `col` is off the row's pattern.
    #[inline]
    pub fn row_from(&mut self, row: usize, col: usize) -> &mut [f64] {
        let s = self.segments[row]
            .iter()
            .find(|s| col >= s.col && col < s.col + s.len)
            .copied()
            .unwrap_or_else(|| panic!("G[{row}, {col}] is outside the constraint row's bodies"));
        &mut self.values[s.at + col - s.col..s.at + s.len]
    }

    /// Where G[row, col] is stored, if it lies in the pattern.
    fn index(&self, row: usize, col: usize) -> Option<usize> {
        self.segments[row]
            .iter()
            .find(|s| col >= s.col && col < s.col + s.len)
            .map(|s| s.at + col - s.col)
    }

    /// The stored values of row `row` over the columns `cols` of one body of its pattern
    /// (entry k is G[row, cols.start + k]); None where the row does not depend on that body.
    pub fn row_over(&self, row: usize, cols: &Range<usize>) -> Option<&[f64]> {
        self.segments[row]
            .iter()
            .find(|s| s.len > 0 && s.col == cols.start && s.len == cols.len())
            .map(|s| &self.values[s.at..s.at + s.len])
    }

    /// Visits (row, col, index of the stored value) of every stored entry, row by row.
    pub fn for_each_entry(&self, mut visit: impl FnMut(usize, usize, usize)) {
        for (row, segs) in self.segments.iter().enumerate() {
            for s in segs {
                for c in 0..s.len {
                    visit(row, s.col + c, s.at + c);
                }
            }
        }
    }

    /// The stored values, in the order [`JacobianRows::for_each_entry`] visits them.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// r += Gᵀ λ.
    pub fn add_transpose_times(&self, lambda: &DVector<f64>, r: &mut DVector<f64>) {
        for (row, segs) in self.segments.iter().enumerate() {
            let l = lambda[row];
            for s in segs {
                let g = &self.values[s.at..s.at + s.len];
                for (rc, x) in r.as_mut_slice()[s.col..s.col + s.len].iter_mut().zip(g) {
                    *rc += x * l;
                }
            }
        }
    }

    /// Writes the whole m × n matrix (zeros off the pattern) into `out`.
    pub fn to_dense(&self, out: &mut DMatrix<f64>) {
        assert_eq!(out.shape(), (self.nrows(), self.n));
        out.fill(0.0);
        self.for_each_entry(|row, col, k| out[(row, col)] = self.values[k]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_over_two_bodies_multiply_and_expand_like_the_dense_matrix() {
        let ranges = [0..2, 2..5, 5..6];
        let rows = [[None, Some(1)], [Some(0), Some(2)], [Some(2), Some(2)]];
        let mut g = JacobianRows::new(6, &ranges, &rows);
        assert_eq!(g.nnz(), 3 + 3 + 1);
        g.add(0, 3, 2.0);
        g.add(1, 0, -1.0);
        g.add(1, 5, 4.0);
        g.add(2, 5, 0.5);
        g.add(2, 5, 0.25);
        let mut d = DMatrix::zeros(3, 6);
        g.to_dense(&mut d);
        assert_eq!(d[(0, 3)], 2.0);
        assert_eq!(d[(1, 0)], -1.0);
        assert_eq!(d[(2, 5)], 0.75);
        let lambda = DVector::from_vec(vec![1.0, 2.0, 3.0]);
        let mut r = DVector::from_element(6, 1.0);
        g.add_transpose_times(&lambda, &mut r);
        let expected = DVector::from_element(6, 1.0) + d.transpose() * &lambda;
        assert_eq!(r, expected);
    }

    #[test]
    #[should_panic(expected = "outside")]
    fn an_entry_off_the_pattern_is_a_bug() {
        let mut g = JacobianRows::new(4, &[0..2, 2..4], &[[Some(0), None]]);
        g.add(0, 3, 1.0);
    }
}
