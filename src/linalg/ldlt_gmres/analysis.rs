//! The symbolic phase of a new pattern: the fill-reducing ordering, the elimination structure,
//! the workspaces (computed once per pattern and reused by every numeric factorisation).

use super::matrix::transpose_positions;
use super::parallelism::FactorParallelism;
use super::{LdltGmres, Ordering, ND_MIN_UNKNOWNS};
use crate::error::{Result, StampError};
use crate::linalg::ordering;
use crate::linalg::supernodal_solve::SupernodalSolve;
use faer::dyn_stack::MemBuffer;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering};
use faer::sparse::SparseColMatRef;
use faer::Side;
use std::time::Instant;

impl LdltGmres {
    /// Ordering, elimination structure and workspaces for a new pattern.
    pub(super) fn analyse(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<()> {
        let t = Instant::now();
        let n = a.nrows();
        let nested = match self.ordering {
            Ordering::Amd => false,
            Ordering::NestedDissection => true,
            Ordering::Auto => n >= ND_MIN_UNKNOWNS,
        };
        // METIS runs on one thread: the copies of the pattern and its transpose positions (0.12 s
        // at n = 200 in `stamp bench`, against METIS's 0.23 s) are made beside it. A pattern that
        // turns out not symmetric has no LDL^T: its ordering goes unused (the LU orders its own).
        let (col_ptr, row_idx) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
        let (perm, (transpose, (col_ptr, row_idx))) = rayon::join(
            || if nested { ordering::nested_dissection(col_ptr, row_idx).ok() } else { None },
            || (transpose_positions(col_ptr, row_idx), (col_ptr.to_vec(), row_idx.to_vec())),
        );
        (self.col_ptr, self.row_idx, self.transpose) = (col_ptr, row_idx, transpose);
        let nnz = self.row_idx.len();
        // a symmetric pattern keeps A by rows only (the LU fallback rebuilds the columns)
        self.values = if self.transpose.is_some() { Vec::new() } else { vec![0.0; nnz] };
        // filled (and sized) only when the symmetric part is factorised or a factor may be renewed
        // later from kept values (reuse): a given P or a symmetric A is factorised where it lies
        self.symmetric_values = Vec::new();
        self.row_values = if self.transpose.is_some() { vec![0.0; nnz] } else { Vec::new() };
        self.symbolic = None;
        self.supernodal = None;
        self.sparse_forward = None;
        self.ordering_used = None;
        self.factor_valid = false;
        if self.transpose.is_some() {
            // a METIS failure leaves AMD
            let inverse = perm.as_deref().map(ordering::inverse);
            let order = match (&perm, &inverse) {
                (Some(p), Some(i)) => SymmetricOrdering::Custom(PermRef::new_checked(p, i, n)),
                _ => SymmetricOrdering::Amd,
            };
            let sym = factorize_symbolic_cholesky(a.symbolic(), Side::Lower, order, CholeskySymbolicParams::default())
                .map_err(|e| StampError::LinearSolver(format!("symbolic LDL^T failed: {e:?}")))?;
            self.ordering_used = Some(if perm.is_some() { Ordering::NestedDissection } else { Ordering::Amd });
            let scratch = sym.factorize_numeric_ldlt_scratch::<f64>(self.par, Default::default()).or(sym.solve_in_place_scratch::<f64>(1, self.par));
            self.buffer = Some(MemBuffer::try_new(scratch).map_err(|_| StampError::LinearSolver("out of memory for the LDL^T workspace".into()))?);
            // written, not only allocated: the pages are mapped here, not in the first
            // factorisation, whose time decides the parallelism (FactorParallelism); by all
            // threads, as the hypervisor maps fresh memory faster to two (512 MiB in a probe:
            // 0.18 s on one thread, 0.10 s on two when the host is quick)
            self.factor = vec![0.0; sym.len_val()];
            touch_pages(&mut self.factor);
            self.factor_parallelism = FactorParallelism::default();
            self.supernodal = Some(SupernodalSolve::new(&sym)).filter(SupernodalSolve::is_parallel);
            self.symbolic = Some(sym);
        }
        self.timings.symbolic += t.elapsed().as_secs_f64();
        Ok(())
    }

    pub(super) fn same_pattern(&self, a: SparseColMatRef<'_, usize, f64>) -> bool {
        !self.col_ptr.is_empty() && a.symbolic().col_ptr() == self.col_ptr.as_slice() && a.symbolic().row_idx() == self.row_idx.as_slice()
    }
}

/// Map the memory of a zero-filled `v` now, by all threads: one write of zero per 4 KiB page
/// (512 values), volatile since the allocation is zero already and a plain write of zero could
/// be elided. The values stay zero.
fn touch_pages(v: &mut [f64]) {
    use rayon::prelude::*;
    v.par_chunks_mut(1 << 16).for_each(|chunk| {
        for page in chunk.chunks_mut(512) {
            // SAFETY: `page` is a non-empty slice (chunks_mut never yields an empty one)
            unsafe { std::ptr::write_volatile(page.as_mut_ptr(), 0.0) };
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Touching the pages of a zero vector keeps it zero, at every length (chunks and pages cut
    /// anywhere, the empty vector included).
    #[test]
    fn touched_pages_stay_zero() {
        for len in [0, 1, 511, 512, 513, (1 << 16) + 7, 3 << 16] {
            let mut v = vec![0.0; len];
            touch_pages(&mut v);
            assert!(v.len() == len && v.iter().all(|&x| x == 0.0), "{len}");
        }
    }
}
