//! The numeric LDL^T of a matrix of the analysed pattern (A itself when it is symmetric, else the
//! given P or A's symmetric part) and the choice it makes: the direct solve for a symmetric A,
//! GMRES preconditioned by the factor otherwise, a factor kept from an earlier matrix (reuse), or
//! the LU where the factor fails.

use super::matrix::split_values;
use super::{LdltGmres, Mode, SYMMETRY_TOL};
use crate::error::{Result, StampError};
use crate::linalg::linear_solver::parallelism_for;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Par, Side};
use std::time::Instant;

impl LdltGmres {
    /// [`LinearSolver::factorize_preconditioned`](crate::linalg::linear_solver::LinearSolver::factorize_preconditioned):
    /// a new pattern analysed, one pass over A's values, then the LDL^T of A, P or A's symmetric
    /// part (or the factor of an earlier matrix kept, with reuse), the LU for a pattern that is not
    /// symmetric.
    pub(super) fn factorize_matrix(&mut self, a: SparseColMatRef<'_, usize, f64>, p: Option<SparseColMatRef<'_, usize, f64>>) -> Result<()> {
        self.factored = false;
        if a.nrows() != a.ncols() {
            return Err(StampError::LinearSolver(format!("a {} x {} matrix is not square", a.nrows(), a.ncols())));
        }
        if !self.same_pattern(a) {
            self.analyse(a)?;
        }
        self.r.resize(a.nrows(), 0.0);
        let Some(tr) = &self.transpose else {
            self.values.copy_from_slice(a.val());
            self.r.iter_mut().for_each(|v| *v = 0.0);
            for (k, v) in self.values.iter().enumerate() {
                self.r[self.row_idx[k]] += v.abs();
            }
            self.norm_inf = self.r.iter().fold(0.0f64, |m, x| m.max(*x));
            self.factorize_lu()?;
            self.factored = true;
            return Ok(());
        };
        let given = match p {
            Some(p) if self.use_preconditioner => {
                if !crate::linalg::sparse::same_pattern(p.symbolic(), a.symbolic()) {
                    return Err(StampError::LinearSolver("the preconditioner's pattern is not the matrix's".into()));
                }
                Some(p)
            }
            _ => None,
        };
        let par = parallelism_for(a.nrows(), self.par);
        let parallel = par != Par::Seq;
        // A given P factorised on one thread (FactorParallelism) leaves the other threads idle:
        // one of them takes A apart meanwhile (the pass below; at n = 400 in `stamp bench` about
        // 0.1 s per factorisation, hidden). Should A turn out symmetric, A itself is factorised
        // after. (Without reuse every factorisation is fresh.)
        if let (Some(p), true, false) = (given, parallel, self.reuse) {
            if self.factor_parallelism.next(par) == Par::Seq {
                self.factor_parallelism.choose(par);
                let (Some(sym), Some(buffer)) = (self.symbolic.as_ref(), self.buffer.as_mut()) else {
                    return Err(StampError::LinearSolver("no symbolic LDL^T for a symmetric pattern".into()));
                };
                let (col_ptr, row_idx, factor, row_values, r) = (&self.col_ptr, &self.row_idx, &mut self.factor, &mut self.row_values, &mut self.r);
                let t = Instant::now();
                let (ok, (worst, size)) = rayon::join(
                    || factorize_numeric(sym, buffer, factor, col_ptr, row_idx, p.val(), Par::Seq),
                    || split_values(col_ptr, tr, a.val(), row_values, None, r, false),
                );
                let seconds = t.elapsed().as_secs_f64();
                self.passed_over(worst, size);
                if self.symmetric {
                    // not the matrix to factorise after all (its time is not a measurement)
                    self.fresh_factorization(Some(a.val()))?;
                } else {
                    self.factorized(ok, seconds)?;
                }
                self.factored = true;
                return Ok(());
            }
        }
        // one pass over A: A by rows, its row sums, its asymmetry and size, and its symmetric
        // part unless a P will be factorised instead
        if given.is_none() || self.reuse {
            self.symmetric_values.resize(self.row_idx.len(), 0.0);
        }
        let sym = if given.is_some() { None } else { Some(self.symmetric_values.as_mut_slice()) };
        let (worst, size) = split_values(&self.col_ptr, tr, a.val(), &mut self.row_values, sym, &mut self.r, parallel);
        self.passed_over(worst, size);
        // the values to factorise: a symmetric A itself, else the given P, else the symmetric part
        // just written; kept when a factor may have to be renewed later (reuse), else read where
        // they lie (no copy: 0.4 GB at n = 400 in `stamp bench`)
        let mut values = match given {
            Some(_) if self.symmetric => Some(a.val()),
            Some(p) => Some(p.val()),
            None => None,
        };
        if let (Some(v), true) = (values, self.reuse) {
            self.symmetric_values.copy_from_slice(v);
            values = None;
        }
        if self.reuse && self.factor_valid && !self.refactor_next {
            self.mode = Mode::Preconditioned;
            self.stale = true;
            self.stats.reused += 1;
        } else {
            self.fresh_factorization(values)?;
        }
        self.factored = true;
        Ok(())
    }

    /// The LDL^T of `values` (in the pattern's slots; the lower triangle is read), or of the kept
    /// symmetric values; false on a zero pivot or a non-finite factor.
    fn factorize_ldlt(&mut self, values: Option<&[f64]>) -> bool {
        let n = self.col_ptr.len() - 1;
        let par = self.factor_parallelism.choose(parallelism_for(n, self.par));
        let (Some(sym), Some(buffer)) = (self.symbolic.as_ref(), self.buffer.as_mut()) else { return false };
        factorize_numeric(sym, buffer, &mut self.factor, &self.col_ptr, &self.row_idx, values.unwrap_or(&self.symmetric_values), par)
    }

    /// The LDL^T of the current matrix's symmetric part (or the LU where that fails).
    /// After the pass over A ([`split_values`], row sums in `r`): its infinity norm, and whether
    /// it is symmetric (largest asymmetry `worst`, largest entry `size`).
    fn passed_over(&mut self, worst: f64, size: f64) {
        self.norm_inf = self.r.iter().fold(0.0f64, |m, x| m.max(*x));
        self.symmetric = worst <= SYMMETRY_TOL * size;
    }

    /// `values` as in [`LdltGmres::factorize_ldlt`].
    pub(super) fn fresh_factorization(&mut self, values: Option<&[f64]>) -> Result<()> {
        let t = Instant::now();
        let ok = self.factorize_ldlt(values);
        self.factorized(ok, t.elapsed().as_secs_f64())
    }

    /// The bookkeeping after a numeric LDL^T that took `seconds` and succeeded if `ok` (the LU
    /// otherwise).
    fn factorized(&mut self, ok: bool, seconds: f64) -> Result<()> {
        self.factor_seconds = seconds;
        if ok {
            self.factor_parallelism.record(self.factor_seconds);
        }
        self.timings.factorization += self.factor_seconds;
        self.timings.factorizations += 1;
        self.refactor_next = false;
        self.stale = false;
        self.factor_valid = ok;
        if !ok {
            return self.factorize_lu();
        }
        if self.symmetric {
            self.mode = Mode::Direct;
            self.stats.direct += 1;
        } else {
            self.mode = Mode::Preconditioned;
            self.stats.preconditioned += 1;
        }
        Ok(())
    }
}

/// The numeric LDL^T of the matrix with `values` in the pattern (`col_ptr`, `row_idx`; the lower
/// triangle is read) into `factor`; false on a failure, a zero or a non-finite pivot.
fn factorize_numeric(sym: &SymbolicCholesky<usize>, buffer: &mut MemBuffer, factor: &mut [f64], col_ptr: &[usize], row_idx: &[usize], values: &[f64], par: Par) -> bool {
    let n = col_ptr.len() - 1;
    let pattern = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
    let s = SparseColMatRef::new(pattern, values);
    let ok = sym.factorize_numeric_ldlt(factor, s, Side::Lower, LdltRegularization::default(), par, MemStack::new(buffer), Default::default()).is_ok();
    crate::linalg::vector_state::clean_upper_vector_state();
    ok && pivots(sym, factor).all(|d| d.is_finite() && d != 0.0)
}

/// The pivots D of an LDL^T factor, in the factor's (permuted) order: faer keeps them on L's
/// unit diagonal, the first entry of each column of a simplicial factor and the diagonal of each
/// supernode's dense block. Finite nonzero pivots mean a usable factor: every entry l_ij of L
/// enters the pivot d_i = a_ii - sum_j l_ij^2 d_j, so a NaN or infinity anywhere in L (a zero
/// pivot divided by) reaches a pivot; checking the n pivots replaces a pass over the whole
/// factor (310 M entries at n = 400 in `stamp bench`) and also catches a zero last pivot.
pub(super) fn pivots<'a>(symbolic: &'a SymbolicCholesky<usize>, factor: &'a [f64]) -> Box<dyn Iterator<Item = f64> + 'a> {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => Box::new(s.col_ptr()[..s.ncols()].iter().map(move |&k| factor[k])),
        SymbolicCholeskyRaw::Supernodal(s) => Box::new((0..s.n_supernodes()).flat_map(move |k| {
            let (begin, end) = (s.supernode_begin()[k], s.supernode_end()[k]);
            let (first, last) = (s.col_ptr_for_val()[k], s.col_ptr_for_val()[k + 1]);
            let (ncols, nrows) = (end - begin, (last - first) / (end - begin));
            (0..ncols).map(move |j| factor[first + j * nrows + j])
        })),
    }
}
