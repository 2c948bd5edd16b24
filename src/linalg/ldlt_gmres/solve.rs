//! The solves with the LDL^T factor: direct with iterative refinement, or GMRES preconditioned by
//! it (the factor of an earlier matrix too, within a budget of iterations), many columns at once,
//! and the sparse forward halves.

use super::fallback::FALLBACK;
use super::matrix::{backward_error, multiply_rows};
use super::{LdltGmres, Mode, GMRES_MAX_ITERATIONS, GMRES_TOL};
use crate::error::{Result, StampError};
use crate::linalg::gmres::GmresReport;
use crate::linalg::linear_solver::{parallelism_for, LinearSolver};
use crate::linalg::supernodal_solve::{ForwardColumn, SparseForward, SupernodalSolve};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{LdltRef, SymbolicCholesky};
use faer::{Conj, MatMut, Par};
use std::time::Instant;

/// Backward error of a direct LDL^T solve accepted without refinement.
const ACCEPT: f64 = 1e-14;

/// Columns solved together by [`LdltGmres`]'s `solve_many_approx`.
const MANY_BLOCK: usize = 32;

impl LdltGmres {
    /// x = S^-1 x with the LDL^T factor: by the tree-parallel solve `supernodal` when given (on
    /// one thread if `par` is sequential; about 30 % faster than faer's there too), by faer's
    /// otherwise.
    fn ldlt_solve(symbolic: &SymbolicCholesky<usize>, supernodal: Option<&SupernodalSolve>, factor: &[f64], buffer: &mut MemBuffer, par: Par, x: &mut [f64]) {
        match supernodal {
            Some(fast) => fast.solve_in_place(symbolic, factor, x, par != Par::Seq),
            None => {
                let n = x.len();
                LdltRef::new(symbolic, factor).solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(x, n, 1), par, MemStack::new(buffer));
                crate::linalg::vector_state::clean_upper_vector_state();
            }
        }
    }

    /// The direct solve with iterative refinement; returns the backward error reached.
    fn direct_solve(&mut self, b: &mut [f64]) -> f64 {
        let par = parallelism_for(b.len(), self.par);
        let (sym, buffer) = (self.symbolic.as_ref().unwrap(), self.buffer.as_mut().unwrap());
        let fast = self.supernodal.as_ref();
        Self::ldlt_solve(sym, fast, &self.factor, buffer, par, b);
        let parallel = matches!(par, Par::Rayon(_));
        let mut error = backward_error(&self.col_ptr, &self.row_idx, &self.row_values, parallel, self.norm_inf, &self.rhs, b, &mut self.r);
        for _ in 0..2 {
            if !(error > ACCEPT) || !error.is_finite() {
                break;
            }
            Self::ldlt_solve(sym, fast, &self.factor, buffer, par, &mut self.r);
            for (x, d) in b.iter_mut().zip(&self.r) {
                *x += d;
            }
            self.stats.refinements += 1;
            error = backward_error(&self.col_ptr, &self.row_idx, &self.row_values, parallel, self.norm_inf, &self.rhs, b, &mut self.r);
        }
        error
    }

    /// GMRES on A preconditioned by the LDL^T of S.
    /// GMRES stops at a backward error of [`GMRES_TOL`] or at a relative residual `rtol`.
    fn preconditioned_solve(&mut self, b: &mut [f64], max_iterations: usize, rtol: f64) -> GmresReport {
        let par = parallelism_for(b.len(), self.par);
        let (sym, buffer) = (self.symbolic.as_ref().unwrap(), self.buffer.as_mut().unwrap());
        let fast = self.supernodal.as_ref();
        let (col_ptr, row_idx, row_values, factor) = (&self.col_ptr, &self.row_idx, &self.row_values, &self.factor);
        let parallel = matches!(par, Par::Rayon(_));
        // from x = 0: the first iteration finds the best multiple of S^-1 b, as good as starting
        // from S^-1 b and one preconditioner application cheaper
        b.iter_mut().for_each(|v| *v = 0.0);
        let report = self.gmres.solve(
            &self.rhs,
            b,
            GMRES_TOL,
            rtol,
            self.norm_inf,
            max_iterations,
            &mut |x, y| multiply_rows(col_ptr, row_idx, row_values, x, y, parallel),
            &mut |z: &mut [f64]| -> std::result::Result<(), ()> {
                Self::ldlt_solve(sym, fast, factor, buffer, par, z);
                Ok(())
            },
        );
        let report = report.unwrap_or(GmresReport { iterations: 0, backward_error: f64::INFINITY, converged: false });
        self.stats.gmres_iterations += report.iterations;
        report
    }

    /// Solve A x = b in place (see the module doc of [`super`]): to a backward error of
    /// [`GMRES_TOL`] or a relative residual `rtol` by GMRES, with refinement directly; by the LU
    /// where the LDL^T's solve is not accurate enough.
    pub(super) fn solve_to(&mut self, b: &mut [f64], rtol: f64) -> Result<()> {
        let rtol = rtol.max(0.0);
        self.check_factored()?;
        if self.mode == Mode::Lu {
            return self.lu.as_mut().unwrap().solve_in_place(b);
        }
        let t = Instant::now();
        self.rhs.clear();
        self.rhs.extend_from_slice(b);
        let ok = match self.mode {
            Mode::Direct => {
                let error = self.direct_solve(b);
                // what one preconditioned iteration would cost, for the budget of a stale solve
                self.iteration_seconds = t.elapsed().as_secs_f64();
                self.fresh_iterations = 1;
                error <= FALLBACK
            }
            _ => {
                // a stale factor may spend, over the iterations of the last fresh solve, at most
                // the iterations one factorisation costs
                let budget = if self.iteration_seconds > 0.0 { (self.factor_seconds / self.iteration_seconds).ceil() as usize } else { GMRES_MAX_ITERATIONS };
                let max_iterations = if self.stale { (self.fresh_iterations + budget.max(10)).min(GMRES_MAX_ITERATIONS) } else { GMRES_MAX_ITERATIONS };
                let ts = Instant::now();
                let report = self.preconditioned_solve(b, max_iterations, rtol);
                if report.iterations > 0 {
                    self.iteration_seconds = ts.elapsed().as_secs_f64() / report.iterations as f64;
                }
                if !self.stale {
                    self.fresh_iterations = report.iterations;
                } else if report.converged {
                    let extra = report.iterations.saturating_sub(self.fresh_iterations) as f64;
                    if extra * self.iteration_seconds > 0.5 * self.factor_seconds {
                        self.refactor_next = true;
                    }
                } else {
                    // the old factor is too far off: factorise this matrix and solve again
                    self.timings.solve += t.elapsed().as_secs_f64();
                    self.fresh_factorization(None)?;
                    b.copy_from_slice(&self.rhs);
                    return self.solve_to(b, rtol);
                }
                if !report.converged && std::env::var_os("STAMP_DEBUG").is_some() {
                    eprintln!("  GMRES: backward error {:.2e} after {} iterations (asked {rtol:.1e})", report.backward_error, report.iterations);
                }
                report.converged
            }
        };
        self.timings.solve += t.elapsed().as_secs_f64();
        self.timings.solves += 1;
        if !ok || b.iter().any(|x| !x.is_finite()) {
            return self.solve_by_lu(b);
        }
        Ok(())
    }

    /// The LDL^T factor (of A when it is symmetric, of its preconditioner otherwise) applied to
    /// all the columns at once, in blocks of `MANY_BLOCK` (32) (a block of columns reads the factor
    /// once); the LU where that took over.
    pub(super) fn solve_many(&mut self, b: &mut [f64], ncols: usize) -> Result<()> {
        if ncols == 0 {
            return Ok(());
        }
        self.check_factored()?;
        let n = b.len() / ncols;
        if self.mode == Mode::Lu {
            for col in b.chunks_mut(n) {
                self.lu.as_mut().unwrap().solve_in_place(col)?;
            }
            return Ok(());
        }
        let t = Instant::now();
        let sym = self.symbolic.as_ref().unwrap();
        let par = parallelism_for(n, self.par);
        let block = ncols.min(MANY_BLOCK);
        let scratch = sym.solve_in_place_scratch::<f64>(block, par);
        let mut buffer = MemBuffer::try_new(scratch).map_err(|_| StampError::LinearSolver("out of memory for the LDL^T solve's workspace".into()))?;
        for cols in b.chunks_mut(n * block) {
            let k = cols.len() / n;
            LdltRef::new(sym, &self.factor).solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(cols, n, k), par, MemStack::new(&mut buffer));
        }
        crate::linalg::vector_state::clean_upper_vector_state();
        self.timings.solve += t.elapsed().as_secs_f64();
        if b.iter().any(|x| !x.is_finite()) {
            return Err(StampError::LinearSolver("the solution has non-finite entries: the matrix is singular".into()));
        }
        Ok(())
    }

    /// With a supernodal factor large enough for the parallel solve (below that a whole solve is
    /// cheap); the factor of A when it is symmetric, of its preconditioner otherwise.
    pub(super) fn forward(&mut self, b: &[Vec<(usize, f64)>]) -> Result<Option<Vec<ForwardColumn>>> {
        if !self.factored || self.mode == Mode::Lu || self.supernodal.is_none() {
            return Ok(None);
        }
        let t = Instant::now();
        let sym = self.symbolic.as_ref().unwrap();
        if self.sparse_forward.is_none() {
            self.sparse_forward = SparseForward::new(sym);
        }
        let Some(forward) = self.sparse_forward.as_mut() else { return Ok(None) };
        let columns = b.iter().map(|g| forward.column(sym, &self.factor, g)).collect();
        self.timings.solve += t.elapsed().as_secs_f64();
        Ok(Some(columns))
    }

    /// A solve needs a successful factorisation first.
    fn check_factored(&self) -> Result<()> {
        if !self.factored {
            return Err(StampError::LinearSolver("solve called without a successful factorisation".into()));
        }
        Ok(())
    }
}
