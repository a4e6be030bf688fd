//! The scaled iteration matrix of the Newton iteration,
//! [[d K_t + c_m M + c_c C_t, Gᵀ], [G, 0]], assembled from the system's body blocks and
//! constraint rows ([`crate::mechanics::multibody::sparsity`]) and factorized either dense (nalgebra's LU
//! with partial pivoting) or sparse (faer's sparse LU: the fill-reducing column ordering and
//! symbolic analysis once per system, only the numeric factorization at each evaluation).
//! [`LinearSolver::Auto`] chooses from the system's size by [`prefers_sparse`], a rule read off
//! the measurements of `fmu-harness linear-solvers` (docs/linear_algebra.md).

use crate::mechanics::multibody::{BlockDiagonal, Equations, JacobianRows, Point};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};
use nalgebra::{DMatrix, DVector, Dyn, LU};

/// How the iteration matrix is factorized.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinearSolver {
    /// Dense or sparse, by the system's size (`prefers_sparse`).
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

#[derive(Debug, Clone)]
enum Factors {
    Dense {
        jac: DMatrix<f64>,
        lu: Option<LU<f64, Dyn, Dyn>>,
    },
    Sparse(Box<SparseLu>),
}

impl IterationMatrix {
    /// The workspace for `sys`, dense or sparse as `choice` says.
    pub fn new<S: Equations + ?Sized>(sys: &S, choice: LinearSolver) -> IterationMatrix {
        let (n, m) = (sys.n(), sys.m());
        let mass = sys.block_diagonal();
        let rows = sys.jacobian_pattern();
        let largest = mass.ranges.iter().map(|r| r.len()).max().unwrap_or(0);
        let sparse = match choice {
            LinearSolver::Auto => prefers_sparse(n + m, largest),
            LinearSolver::Dense => false,
            LinearSolver::Sparse => true,
        };
        let dense = || Factors::Dense {
            jac: DMatrix::zeros(n + m, n + m),
            lu: None,
        };
        let factors = if sparse {
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

    /// Whether factors are ready for [`IterationMatrix::solve_mut`].
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Drops the factors.
    pub fn forget(&mut self) {
        self.factored = false;
        if let Factors::Dense { lu, .. } = &mut self.factors {
            *lu = None;
        }
    }

    /// Number of stored entries of the assembled matrix (the dense one stores all).
    pub fn nnz(&self) -> usize {
        match &self.factors {
            Factors::Dense { jac, .. } => jac.len(),
            Factors::Sparse(s) => s.values.len(),
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
        let block = |kt: &DMatrix<f64>, mm: &DMatrix<f64>, ct: &DMatrix<f64>, i, j| {
            if with_tangents {
                kt[(i, j)] * w.d + mm[(i, j)] * w.cm + ct[(i, j)] * w.cc
            } else {
                mm[(i, j)] * w.cm
            }
        };
        let n = self.n;
        self.cm = w.cm;
        self.factored = match &mut self.factors {
            Factors::Dense { jac, lu } => {
                jac.fill(0.0);
                for (b, r) in self.mass.ranges.iter().enumerate() {
                    let (kt, mm, ct) =
                        (&self.kt.blocks[b], &self.mass.blocks[b], &self.ct.blocks[b]);
                    for j in 0..r.len() {
                        for i in 0..r.len() {
                            jac[(r.start + i, r.start + j)] = block(kt, mm, ct, i, j);
                        }
                    }
                }
                let g = self.rows.values();
                self.rows.for_each_entry(|row, col, k| {
                    jac[(n + row, col)] = g[k];
                    jac[(col, n + row)] = g[k];
                });
                let f = jac.clone().lu();
                let ok = f.is_invertible();
                *lu = ok.then_some(f);
                ok
            }
            Factors::Sparse(s) => {
                let mut p = s.block_positions.iter();
                for b in 0..self.mass.ranges.len() {
                    let (kt, mm, ct) =
                        (&self.kt.blocks[b], &self.mass.blocks[b], &self.ct.blocks[b]);
                    for j in 0..mm.ncols() {
                        for i in 0..mm.nrows() {
                            let at = *p.next().expect("a position per block entry");
                            s.values[at] = block(kt, mm, ct, i, j);
                        }
                    }
                }
                for (x, [a, b]) in self.rows.values().iter().zip(&s.g_positions) {
                    s.values[*a] = *x;
                    s.values[*b] = *x;
                }
                s.factorize()
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
        rhs.fill(0.0);
        for (r, b) in self.mass.ranges.iter().zip(&self.mass.blocks) {
            rhs.rows_mut(r.start, r.len())
                .gemv(self.cm, b, &e.rows(r.start, r.len()), 0.0);
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
            Factors::Dense { lu, .. } => lu.as_ref().is_some_and(|lu| lu.solve_mut(rhs)),
            Factors::Sparse(s) => {
                let finite = rhs.iter().all(|x| x.is_finite());
                s.solve_mut(rhs.as_mut_slice());
                !finite || rhs.iter().all(|x| x.is_finite())
            }
        }
    }
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
