//! The linear-solver layer: a trait for "factorise, then solve", and its implementation over
//! faer's sparse LU. The symbolic factorisation (fill-reducing ordering, elimination structure) is
//! computed once for the pattern and reused by every numeric factorisation; so is the memory of the
//! numeric factors.

use crate::linalg::supernodal_solve::ForwardColumn;
use crate::error::{Result, StampError};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu};
use faer::sparse::SparseColMatRef;
use faer::{Conj, MatMut, Par};
use std::time::Instant;

/// Seconds spent in each phase of the linear solves, cumulative.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct SolverTimings {
    pub symbolic: f64,
    pub factorization: f64,
    pub solve: f64,
    pub factorizations: usize,
    pub solves: usize,
}

/// Matrices with fewer rows are factorised on one thread.
pub const PARALLEL_MIN_ROWS: usize = 20_000;

/// The parallelism to use for a matrix of `rows` rows given the solver's setting `par`: sequential
/// below [`PARALLEL_MIN_ROWS`], where waking threads costs more than the factorisation.
pub fn parallelism_for(rows: usize, par: Par) -> Par {
    if rows < PARALLEL_MIN_ROWS { Par::Seq } else { par }
}

/// Factorise a sparse square matrix and solve with it.
pub trait LinearSolver: Send {
    /// Factorise `a`. Implementations may reuse anything computed for an earlier matrix with the same
    /// pattern.
    fn factorize(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<()>;
    /// Factorise `a`, given a symmetric matrix `p` of the same pattern close to it that an
    /// iterative solver may factorise as its preconditioner instead (only its lower triangle need
    /// be read). A direct solver ignores `p` (the default).
    fn factorize_preconditioned(&mut self, a: SparseColMatRef<'_, usize, f64>, p: Option<SparseColMatRef<'_, usize, f64>>) -> Result<()> {
        let _ = p;
        self.factorize(a)
    }
    /// Whether `factorize_preconditioned` makes use of `p` (so that it is worth building).
    fn uses_preconditioner(&self) -> bool {
        false
    }
    /// Solve A x = b in place with the last factorisation.
    fn solve_in_place(&mut self, b: &mut [f64]) -> Result<()>;
    /// Solve A x = b in place to a relative residual |b - A x| <= rtol |b| at least: an iterative
    /// solver may stop there (an inexact Newton method needs no more), a direct one solves as
    /// [`LinearSolver::solve_in_place`] does (the default).
    fn solve_in_place_to(&mut self, b: &mut [f64], rtol: f64) -> Result<()> {
        let _ = rtol;
        self.solve_in_place(b)
    }
    /// Solve A X = B in place for the `ncols` columns of `b` (column-major, each of A's size)
    /// with the last factorisation, to a preconditioner's accuracy: an iterative solver may apply
    /// its preconditioner alone, once for all the columns. For estimates (the contact points'
    /// compliance, [`crate::nonlinear`]); the default solves each column as
    /// [`LinearSolver::solve_in_place`] does.
    fn solve_many_approx(&mut self, b: &mut [f64], ncols: usize) -> Result<()> {
        if ncols == 0 {
            return Ok(());
        }
        let n = b.len() / ncols;
        for col in b.chunks_mut(n) {
            self.solve_in_place(col)?;
        }
        Ok(())
    }
    /// The forward halves of sparse right-hand sides (pairs of an index and a value) with a
    /// symmetric factor of the last matrix, to a preconditioner's accuracy: two of them give
    /// b^T A^-1 c ([`ForwardColumn::dot`]) at the cost of the factor's rows on their paths to
    /// the root. None where the solver has no such factor or it would not pay (the caller
    /// then solves whole columns, [`LinearSolver::solve_many_approx`]); the default.
    fn forward_columns(&mut self, b: &[Vec<(usize, f64)>]) -> Result<Option<Vec<ForwardColumn>>> {
        let _ = b;
        Ok(None)
    }
    /// The compliance a_i^T A^-1 b_j between sparse vectors (pairs of an index and a value), as
    /// a matrix of a's length by b's, to a preconditioner's accuracy, from selected entries of
    /// the inverse of a symmetric factor (MUMPS's ICNTL(30): the entries on the vectors' indices
    /// only, each at the cost of its paths in the elimination tree). None where the solver has
    /// none (the caller then solves whole columns); the default. Collective on several processes.
    fn compliance(&mut self, a: &[Vec<(usize, f64)>], b: &[Vec<(usize, f64)>]) -> Result<Option<nalgebra::DMatrix<f64>>> {
        let _ = (a, b);
        Ok(None)
    }
    /// Time spent so far.
    fn timings(&self) -> SolverTimings;
}

/// Sparse LU with partial pivoting (faer), symbolic phase computed once.
pub struct SparseLu {
    symbolic: Option<SymbolicLu<usize>>,
    numeric: NumericLu<usize, f64>,
    factored: bool,
    pattern_nnz: usize,
    timings: SolverTimings,
    par: Par,
    buffer: Option<MemBuffer>,
}

impl Default for SparseLu {
    fn default() -> Self {
        Self::new()
    }
}

impl SparseLu {
    /// A solver that uses faer's global parallelism setting.
    pub fn new() -> Self {
        SparseLu {
            symbolic: None,
            numeric: NumericLu::new(),
            factored: false,
            pattern_nnz: 0,
            timings: SolverTimings::default(),
            par: faer::get_global_parallelism(),
            buffer: None,
        }
    }

    /// Use a given parallelism for the factorisation and solves.
    pub fn with_parallelism(par: Par) -> Self {
        SparseLu { par, ..Self::new() }
    }
}

impl LinearSolver for SparseLu {
    fn factorize(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<()> {
        let nnz = a.symbolic().row_idx().len();
        if self.symbolic.is_none() || self.pattern_nnz != nnz {
            let t = Instant::now();
            let sym = factorize_symbolic_lu(a.symbolic(), LuSymbolicParams::default())
                .map_err(|e| StampError::LinearSolver(format!("symbolic LU failed: {e:?}")))?;
            let scratch = sym.factorize_numeric_lu_scratch::<f64>(self.par, Default::default())
                .or(sym.solve_in_place_scratch::<f64>(1, self.par));
            self.buffer = Some(MemBuffer::try_new(scratch).map_err(|_| StampError::LinearSolver("out of memory for LU workspace".into()))?);
            self.symbolic = Some(sym);
            self.pattern_nnz = nnz;
            self.timings.symbolic += t.elapsed().as_secs_f64();
        }
        let t = Instant::now();
        let par = parallelism_for(a.nrows(), self.par);
        let sym = self.symbolic.as_ref().unwrap();
        let stack = MemStack::new(self.buffer.as_mut().unwrap());
        self.factored = false;
        let result = sym.factorize_numeric_lu(&mut self.numeric, a, par, stack, Default::default());
        crate::linalg::vector_state::clean_upper_vector_state();
        result.map_err(|e| StampError::LinearSolver(format!("numeric LU failed (singular matrix?): {e:?}")))?;
        self.factored = true;
        self.timings.factorization += t.elapsed().as_secs_f64();
        self.timings.factorizations += 1;
        Ok(())
    }

    fn solve_in_place(&mut self, b: &mut [f64]) -> Result<()> {
        if !self.factored {
            return Err(StampError::LinearSolver("solve called without a successful factorisation".into()));
        }
        let t = Instant::now();
        let sym = self.symbolic.as_ref().unwrap();
        let lu = LuRef::new_unchecked(sym, &self.numeric);
        let n = b.len();
        let rhs = MatMut::from_column_major_slice_mut(b, n, 1);
        let par = parallelism_for(n, self.par);
        let stack = MemStack::new(self.buffer.as_mut().unwrap());
        lu.solve_in_place_with_conj(Conj::No, rhs, par, stack);
        crate::linalg::vector_state::clean_upper_vector_state();
        self.timings.solve += t.elapsed().as_secs_f64();
        self.timings.solves += 1;
        if b.iter().any(|x| !x.is_finite()) {
            return Err(StampError::LinearSolver("the solution has non-finite entries: the matrix is singular".into()));
        }
        Ok(())
    }

    fn timings(&self) -> SolverTimings {
        self.timings
    }
}
