//! The scaled iteration matrix of the Newton iteration,
//! [[d K_t + c_m M + c_c C_t, Gᵀ], [G, 0]], assembled from the system's body blocks and
//! constraint rows ([`crate::mechanics::multibody::sparsity`]) and factorized either dense (nalgebra's LU
//! with partial pivoting, of what is left once the coordinates that a constraint row fixes alone
//! are condensed out: `condensed.rs`) or sparse (faer's sparse LU: the fill-reducing column ordering and
//! symbolic analysis once per system, only the numeric factorization at each evaluation) or,
//! for a beam's banded block, bordered banded (`bordered_band.rs`: the band eliminated first,
//! the frame coordinates and multipliers last). [`LinearSolver::Auto`] chooses from the
//! system's size by [`prefers_sparse`], a rule read off the measurements of `fmu-harness
//! linear-solvers` (docs/linear_algebra.md), and the bordered band by [`prefers_bordered`].

use super::bordered_band::{BorderedBand, Refusal};
use super::condensed::Condensed;
use crate::mechanics::multibody::{Block, BlockDiagonal, Equations, JacobianRows, Point};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};
use nalgebra::{DMatrix, DVector, Dyn, LU};
use std::ops::Range;

/// How the iteration matrix is factorized.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinearSolver {
    /// Bordered band, dense or sparse, by the system's size and blocks (`prefers_bordered`,
    /// `prefers_sparse`).
    #[default]
    Auto,
    /// nalgebra's dense LU with partial pivoting, at every size.
    Dense,
    /// faer's sparse LU (ordering and symbolic analysis once per system), at every size.
    Sparse,
}

/// Systems with at least this many unknowns (n + m), of which no body holds more than
/// [`SPARSE_MAX_BLOCK_SHARE`], are factorized sparse under [`LinearSolver::Auto`]. Measured
/// (docs/linear_algebra.md): on chains of substructures the sparse LU costs 1.0 × the dense
/// one per factorization at n + m = 45–59 and 0.65–0.7 × at 63–83; per step 1.0 × and
/// 0.87–0.92 ×; below 40 the dense one is faster (1.1–1.7 ×).
pub const SPARSE_MIN_SIZE: usize = 60;
/// The largest share of the unknowns one body may hold for the sparse LU to be chosen: one
/// beam is one dense block, which the sparse LU factorizes no faster (C1 with 20–80 elements:
/// 1.0–1.1 × the dense time per step, 1.1–2.7 × per factorization).
pub const SPARSE_MAX_BLOCK_SHARE: f64 = 0.5;

/// The rule of [`LinearSolver::Auto`]: sparse for n + m ≥ [`SPARSE_MIN_SIZE`] unknowns of which
/// no body holds more than [`SPARSE_MAX_BLOCK_SHARE`].
pub fn prefers_sparse(unknowns: usize, largest_block: usize) -> bool {
    unknowns >= SPARSE_MIN_SIZE
        && (largest_block as f64) <= SPARSE_MAX_BLOCK_SHARE * unknowns as f64
}

/// The largest share of the dense LU's operations at which [`LinearSolver::Auto`] takes the
/// bordered banded LU (`bordered_band.rs`).
pub const BORDERED_MAX_SHARE: f64 = 0.2;

/// The rule of [`LinearSolver::Auto`] for a system with banded blocks: the bordered banded LU
/// when its operations are at most [`BORDERED_MAX_SHARE`] of the dense LU's.
pub fn prefers_bordered(unknowns: usize, band: usize, width: usize) -> bool {
    let dense = 2.0 / 3.0 * (unknowns as f64).powi(3);
    BorderedBand::operations(band, width, unknowns - band) <= BORDERED_MAX_SHARE * dense
}

/// The unknowns a bordered banded LU eliminates first (the tails of the banded blocks, past
/// their frame coordinates) and the largest half bandwidth; None without banded blocks.
fn band_split(blocks: &BlockDiagonal) -> Option<(Vec<Range<usize>>, usize)> {
    let mut width = 0;
    let tails: Vec<Range<usize>> = blocks
        .ranges
        .iter()
        .zip(&blocks.blocks)
        .filter_map(|(r, b)| match b {
            Block::Band(a) => {
                width = width.max(a.width());
                Some(r.start + a.head()..r.end)
            }
            Block::Dense(_) => None,
        })
        .collect();
    (!tails.is_empty()).then_some((tails, width))
}

/// Visits (i, j, entry) of block b of d K_t + c_m M + c_c C_t over its stored entries, column
/// by column.
fn for_each_scaled(
    mass: &Block,
    kt: &Block,
    ct: &Block,
    w: Scaling,
    with_tangents: bool,
    mut visit: impl FnMut(usize, usize, f64),
) {
    let scaled = |k: f64, m: f64, c: f64| {
        if with_tangents {
            k * w.d + m * w.cm + c * w.cc
        } else {
            m * w.cm
        }
    };
    if let (Block::Dense(m), Block::Dense(k), Block::Dense(c)) = (mass, kt, ct) {
        // dense blocks on their column slices, not through the block's index by kind
        let n = m.nrows().max(1);
        let columns = m.as_slice().chunks(n).zip(k.as_slice().chunks(n));
        for (j, ((mc, kc), cc)) in columns.zip(c.as_slice().chunks(n)).enumerate() {
            for (i, ((m, k), c)) in mc.iter().zip(kc).zip(cc).enumerate() {
                visit(i, j, scaled(*k, *m, *c));
            }
        }
        return;
    }
    mass.for_each_entry(|i, j, mm| {
        let x = if with_tangents {
            scaled(kt[(i, j)], mm, ct[(i, j)])
        } else {
            scaled(0.0, mm, 0.0)
        };
        visit(i, j, x);
    });
}

/// The coefficients of the blocks: d K_t + c_m M + c_c C_t. With `d` and `c_c` zero the
/// tangents are not evaluated ([[c_m M, Gᵀ], [G, 0]], the consistent accelerations).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scaling {
    pub d: f64,
    pub cm: f64,
    pub cc: f64,
}

impl Scaling {
    /// The mass matrix alone: [[M, Gᵀ], [G, 0]].
    pub const MASS: Scaling = Scaling {
        d: 0.0,
        cm: 1.0,
        cc: 0.0,
    };
}

/// The iteration matrix's workspace (sized once per system) and its factors.
#[derive(Debug, Clone)]
pub struct IterationMatrix {
    n: usize,
    m: usize,
    mass: BlockDiagonal,
    kt: BlockDiagonal,
    ct: BlockDiagonal,
    rows: JacobianRows,
    factors: Factors,
    factored: bool,
    /// The mass matrix's coefficient in the factorized matrix.
    cm: f64,
}

/// A dense matrix and its LU, where it is regular.
type DenseLu = (DMatrix<f64>, Option<LU<f64, Dyn, Dyn>>);

#[derive(Debug, Clone)]
enum Factors {
    /// The whole LU, or, where constraint rows fix coordinates alone and the system condenses
    /// ([`Equations::condenses`]), the LU of the rest (`condensed.rs`).
    Dense {
        jac: DMatrix<f64>,
        lu: Option<LU<f64, Dyn, Dyn>>,
        condensed: Option<Box<Condensed>>,
    },
    Sparse(Box<SparseLu>),
    /// The bordered banded LU, and the dense LU it falls back to where it refuses.
    Bordered {
        band: Box<BorderedBand>,
        dense: Option<Box<DenseLu>>,
        /// Why the last factorization fell back, if it did.
        refusal: Option<Refusal>,
        /// Factorizations that fell back to the dense LU.
        fallbacks: u64,
    },
}

impl IterationMatrix {
    /// The workspace for `sys`, dense or sparse as `choice` says.
    pub fn new<S: Equations + ?Sized>(sys: &S, choice: LinearSolver) -> IterationMatrix {
        let (n, m) = (sys.n(), sys.m());
        let mass = sys.block_diagonal();
        let rows = sys.jacobian_pattern();
        let largest = mass.ranges.iter().map(|r| r.len()).max().unwrap_or(0);
        let bordered = band_split(&mass).filter(|(tails, width)| {
            let band = tails.iter().map(|r| r.len()).sum();
            choice == LinearSolver::Auto && prefers_bordered(n + m, band, *width)
        });
        let sparse = match choice {
            LinearSolver::Auto => prefers_sparse(n + m, largest),
            LinearSolver::Dense => false,
            LinearSolver::Sparse => true,
        };
        let dense = || Factors::Dense {
            jac: DMatrix::zeros(n + m, n + m),
            lu: None,
            condensed: sys.condenses().then(Box::default),
        };
        let factors = if let Some((tails, width)) = bordered {
            Factors::Bordered {
                band: Box::new(BorderedBand::new(n + m, &tails, width)),
                dense: None,
                refusal: None,
                fallbacks: 0,
            }
        } else if sparse {
            // the symbolic analysis only fails when memory runs out: the dense LU then
            SparseLu::new(n, &mass, &rows).map_or_else(dense, |s| Factors::Sparse(Box::new(s)))
        } else {
            dense()
        };
        IterationMatrix {
            n,
            m,
            kt: mass.clone(),
            ct: mass.clone(),
            mass,
            rows,
            factors,
            factored: false,
            cm: 1.0,
        }
    }

    /// Whether the sparse LU factorizes it.
    pub fn is_sparse(&self) -> bool {
        matches!(self.factors, Factors::Sparse(_))
    }

    /// Whether the bordered banded LU factorizes it (falling back to the dense LU where it
    /// refuses).
    pub fn is_bordered(&self) -> bool {
        matches!(self.factors, Factors::Bordered { .. })
    }

    /// Factorizations the bordered banded LU refused and the dense LU did instead.
    pub fn fallbacks(&self) -> u64 {
        match &self.factors {
            Factors::Bordered { fallbacks, .. } => *fallbacks,
            _ => 0,
        }
    }

    /// Why the bordered banded LU refused the last factorization (the dense LU did it).
    pub fn refusal(&self) -> Option<Refusal> {
        match &self.factors {
            Factors::Bordered { refusal, .. } => *refusal,
            _ => None,
        }
    }

    /// Whether factors are ready for [`IterationMatrix::solve_mut`].
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Drops the factors.
    pub fn forget(&mut self) {
        self.factored = false;
        match &mut self.factors {
            Factors::Dense { lu, condensed, .. } => {
                *lu = None;
                if let Some(c) = condensed {
                    c.forget();
                }
            }
            Factors::Bordered { dense, .. } => {
                if let Some(d) = dense {
                    d.1 = None;
                }
            }
            Factors::Sparse(_) => {}
        }
    }

    /// Number of stored entries of the assembled matrix (the dense one stores all).
    pub fn nnz(&self) -> usize {
        match &self.factors {
            Factors::Dense { jac, .. } => jac.len(),
            Factors::Sparse(s) => s.values.len(),
            Factors::Bordered { band, .. } => band.stored(),
        }
    }

    /// The work units ([`super::work_units`]) of one evaluation and factorization: a quarter
    /// unit per stored entry of the dense and the bordered banded matrix, one per stored entry
    /// of the sparse one. The sparse LU's indexing and fill cost 3.6 × the dense one per entry
    /// (docs/linear_algebra.md: 83 unknowns, 1 251 entries, 42 µs against the dense 65 µs for
    /// 6 889); the banded one does fewer operations per entry than the dense one from about
    /// 20 unknowns on.
    pub fn factorization_units(&self) -> u64 {
        let entries = self.nnz() as u64;
        match &self.factors {
            Factors::Sparse(_) => entries,
            Factors::Dense { .. } | Factors::Bordered { .. } => entries / 4,
        }
    }

    /// Evaluates the matrix at a point (q, q', q'', λ, t) and factorizes it; false when
    /// singular.
    pub fn factorize<S: Equations + ?Sized>(&mut self, sys: &S, at: &Point, w: Scaling) -> bool {
        self.factored = false;
        let with_tangents = w.d != 0.0 || w.cc != 0.0;
        sys.mass_blocks(at.q, &mut self.mass);
        if with_tangents {
            sys.tangent_blocks(at, &mut self.kt, &mut self.ct);
        }
        sys.jacobian_rows(at.q, at.t, &mut self.rows);
        let n = self.n;
        self.cm = w.cm;
        let (mass, kt, ct, rows) = (&self.mass, &self.kt, &self.ct, &self.rows);
        self.factored = match &mut self.factors {
            Factors::Dense { jac, lu, condensed } => {
                assemble_dense(jac, (mass, kt, ct), rows, w, with_tangents, n);
                *lu = None;
                if let Some(ok) = condensed.as_mut().and_then(|c| c.factorize(jac, n)) {
                    ok
                } else {
                    let f = jac.clone().lu();
                    let ok = f.is_invertible();
                    *lu = ok.then_some(f);
                    ok
                }
            }
            Factors::Sparse(s) => {
                let mut p = s.block_positions.iter();
                for b in 0..mass.ranges.len() {
                    let (kt, mm, ct) = (&kt.blocks[b], &mass.blocks[b], &ct.blocks[b]);
                    for j in 0..mm.n() {
                        for i in 0..mm.n() {
                            let at = *p.next().expect("a position per block entry");
                            s.values[at] = if with_tangents {
                                kt[(i, j)] * w.d + mm[(i, j)] * w.cm + ct[(i, j)] * w.cc
                            } else {
                                mm[(i, j)] * w.cm
                            };
                        }
                    }
                }
                for (x, [a, b]) in rows.values().iter().zip(&s.g_positions) {
                    s.values[*a] = *x;
                    s.values[*b] = *x;
                }
                s.factorize()
            }
            Factors::Bordered {
                band,
                dense,
                refusal,
                fallbacks,
            } => {
                band.clear();
                for (b, r) in mass.ranges.iter().enumerate() {
                    let (mm, k, c) = (&mass.blocks[b], &kt.blocks[b], &ct.blocks[b]);
                    for_each_scaled(mm, k, c, w, with_tangents, |i, j, x| {
                        band.set(r.start + i, r.start + j, x)
                    });
                }
                let g = rows.values();
                rows.for_each_entry(|row, col, k| {
                    band.set(n + row, col, g[k]);
                    band.set(col, n + row, g[k]);
                });
                *refusal = band.factorize().err();
                if refusal.is_some() {
                    // the dense LU, as LinearSolver::Dense would factorize it
                    *fallbacks += 1;
                    let dim = n + rows.nrows();
                    let d = dense.get_or_insert_with(|| Box::new((DMatrix::zeros(dim, dim), None)));
                    assemble_dense(&mut d.0, (mass, kt, ct), rows, w, with_tangents, n);
                    let f = d.0.clone().lu();
                    let ok = f.is_invertible();
                    d.1 = ok.then_some(f);
                    ok
                } else {
                    true
                }
            }
        };
        self.factored
    }

    /// One pass of the scheme's filter on a position error `e` (n entries), in place: the
    /// solution x of [[S, Gᵀ], [G, 0]] [x; μ] = [c_m M e; G e], with the matrix's M and G at its
    /// point and `rhs` (n + m entries) as the workspace. A mode of frequency ω passes with the
    /// factor c_m / (c_m + d ω²); the part of `e` across the constraints (what a driven joint
    /// imposes) is kept. False when there are no factors or the solution is not finite.
    pub fn filter(&mut self, e: &mut DVector<f64>, rhs: &mut DVector<f64>) -> bool {
        let n = self.n;
        rhs.as_mut_slice().fill(0.0);
        for (r, b) in self.mass.ranges.iter().zip(&self.mass.blocks) {
            let x = &e.as_slice()[r.clone()];
            b.gemv(self.cm, x, 0.0, &mut rhs.as_mut_slice()[r.clone()]);
        }
        let g = self.rows.values();
        self.rows
            .for_each_entry(|row, col, k| rhs[n + row] += g[k] * e[col]);
        if !self.solve_mut(rhs) || !rhs.iter().all(|x| x.is_finite()) {
            return false;
        }
        e.copy_from(&rhs.rows(0, n));
        true
    }

    /// Solves in place with the factors; false when there are none or a finite right-hand
    /// side gives a solution that is not (a pivot that vanished in the sparse LU). A right-hand
    /// side that is not finite is the caller's to notice, as with the dense LU.
    pub fn solve_mut(&mut self, rhs: &mut DVector<f64>) -> bool {
        if !self.factored {
            return false;
        }
        debug_assert_eq!(rhs.len(), self.n + self.m);
        match &mut self.factors {
            Factors::Dense { lu, condensed, .. } => match lu {
                Some(lu) => lu.solve_mut(rhs),
                None => condensed.as_mut().is_some_and(|c| c.solve_mut(rhs)),
            },
            Factors::Sparse(s) => {
                // the slice's iterator, not nalgebra's strided one (every Newton iteration)
                let finite = all_finite(rhs);
                s.solve_mut(rhs.as_mut_slice());
                !finite || all_finite(rhs)
            }
            Factors::Bordered {
                band,
                dense,
                refusal,
                ..
            } => {
                if refusal.is_some() {
                    return dense
                        .as_ref()
                        .and_then(|d| d.1.as_ref())
                        .is_some_and(|lu| lu.solve_mut(rhs));
                }
                let finite = all_finite(rhs);
                band.solve_mut(rhs.as_mut_slice()) && (!finite || all_finite(rhs))
            }
        }
    }
}

fn all_finite(x: &DVector<f64>) -> bool {
    x.as_slice().iter().all(|x| x.is_finite())
}

/// Writes [[d K_t + c_m M + c_c C_t, Gᵀ], [G, 0]] into `jac` (zeros elsewhere).
fn assemble_dense(
    jac: &mut DMatrix<f64>,
    (mass, kt, ct): (&BlockDiagonal, &BlockDiagonal, &BlockDiagonal),
    rows: &JacobianRows,
    w: Scaling,
    with_tangents: bool,
    n: usize,
) {
    jac.as_mut_slice().fill(0.0);
    for (b, r) in mass.ranges.iter().enumerate() {
        let (mm, k, c) = (&mass.blocks[b], &kt.blocks[b], &ct.blocks[b]);
        for_each_scaled(mm, k, c, w, with_tangents, |i, j, x| {
            jac[(r.start + i, r.start + j)] = x
        });
    }
    let g = rows.values();
    rows.for_each_entry(|row, col, k| {
        jac[(n + row, col)] = g[k];
        jac[(col, n + row)] = g[k];
    });
}

/// faer's sparse LU over the fixed pattern of the iteration matrix.
struct SparseLu {
    dim: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    /// Position in `values` of each entry of the body blocks, block by block, column-major.
    block_positions: Vec<usize>,
    /// Positions of each stored entry of G (in [`JacobianRows::values`] order) and of its
    /// transpose.
    g_positions: Vec<[usize; 2]>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    scratch: StackReq,
    stack: MemBuffer,
}

impl SparseLu {
    /// The pattern (body blocks, G and Gᵀ) in compressed columns and its symbolic analysis;
    /// None when faer cannot allocate it.
    fn new(n: usize, blocks: &BlockDiagonal, rows: &JacobianRows) -> Option<SparseLu> {
        let dim = n + rows.nrows();
        // (column, row, source): source < nb is a block entry, else a G entry (even) or its
        // transpose (odd)
        let mut entries: Vec<(usize, usize, usize)> = Vec::new();
        let nb: usize = blocks.ranges.iter().map(|r| r.len() * r.len()).sum();
        for r in &blocks.ranges {
            for j in r.clone() {
                for i in r.clone() {
                    entries.push((j, i, entries.len()));
                }
            }
        }
        let mut k = 0;
        rows.for_each_entry(|row, col, _| {
            entries.push((col, n + row, nb + 2 * k));
            entries.push((n + row, col, nb + 2 * k + 1));
            k += 1;
        });
        entries.sort_unstable();
        let mut col_ptr = vec![0; dim + 1];
        let mut row_idx = Vec::with_capacity(entries.len());
        let mut block_positions = vec![0; nb];
        let mut g_positions = vec![[0; 2]; rows.nnz()];
        for (at, &(col, row, source)) in entries.iter().enumerate() {
            col_ptr[col + 1] += 1;
            row_idx.push(row);
            if source < nb {
                block_positions[source] = at;
            } else {
                g_positions[(source - nb) / 2][(source - nb) % 2] = at;
            }
        }
        for c in 0..dim {
            col_ptr[c + 1] += col_ptr[c];
        }
        let pattern = SymbolicSparseColMatRef::new_checked(dim, dim, &col_ptr, None, &row_idx);
        let symbolic = factorize_symbolic_lu(pattern, LuSymbolicParams::default()).ok()?;
        let scratch = StackReq::any_of(&[
            symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        Some(SparseLu {
            dim,
            values: vec![0.0; row_idx.len()],
            col_ptr,
            row_idx,
            block_positions,
            g_positions,
            symbolic,
            numeric: NumericLu::new(),
            scratch,
            stack: MemBuffer::try_new(scratch).ok()?,
        })
    }

    /// The numeric factorization of `values`; false when a column has no pivot left.
    fn factorize(&mut self) -> bool {
        let pattern = SymbolicSparseColMatRef::new_checked(
            self.dim,
            self.dim,
            &self.col_ptr,
            None,
            &self.row_idx,
        );
        let a = SparseColMatRef::new(pattern, &self.values);
        self.symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                a,
                Par::Seq,
                MemStack::new(&mut self.stack),
                Default::default(),
            )
            .is_ok()
    }

    fn solve_mut(&mut self, rhs: &mut [f64]) {
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, self.dim, 1),
            Par::Seq,
            MemStack::new(&mut self.stack),
        );
    }
}

impl Clone for SparseLu {
    fn clone(&self) -> SparseLu {
        SparseLu {
            dim: self.dim,
            col_ptr: self.col_ptr.clone(),
            row_idx: self.row_idx.clone(),
            values: self.values.clone(),
            block_positions: self.block_positions.clone(),
            g_positions: self.g_positions.clone(),
            symbolic: self.symbolic.clone(),
            numeric: self.numeric.clone(),
            scratch: self.scratch,
            stack: MemBuffer::new(self.scratch),
        }
    }
}

impl std::fmt::Debug for SparseLu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseLu")
            .field("dim", &self.dim)
            .field("nnz", &self.values.len())
            .finish_non_exhaustive()
    }
}
