//! When the sparse LU takes over from the LDL^T (a zero pivot, a pattern that is not symmetric, a
//! solve that does not reach its tolerance), and when it is refused (its factors would not fit in
//! the memory available).

use super::{LdltGmres, Mode};
use crate::error::{Result, StampError};
use crate::linalg::linear_solver::{LinearSolver, SparseLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};

/// Backward error above which, after refinement, the matrix goes to the LU.
pub(super) const FALLBACK: f64 = 1e-10;
/// Bytes the sparse LU is taken to need per entry of the LDL^T factor of the same pattern: its
/// factors hold about ten times the entries (module doc), each a value and a row index.
const LU_BYTES_PER_LDLT_ENTRY: usize = 10 * 16;

impl LdltGmres {
    /// The sparse LU of the last matrix (its columns rebuilt from its rows where only those were
    /// kept), refused where it would not fit in the memory available.
    pub(super) fn factorize_lu(&mut self) -> Result<()> {
        let n = self.col_ptr.len() - 1;
        // the LU's factors are about ten times the LDL^T's: on a large plate more than the machine
        // has (at n = 400 in `stamp bench`, 50 GB against a 2.5 GB LDL^T factor), and a process
        // that outgrows it is killed with nothing said. Refused instead: Newton cuts the step back.
        if let Some(why) = lu_refusal(n, self.factor_len(), crate::memory::available_bytes().map(|b| b as usize)) {
            return Err(StampError::LinearSolver(why));
        }
        if let Some(tr) = &self.transpose {
            // A's columns from its rows: a_ij sits at the transposed position of a_ji
            self.values = tr.iter().map(|&k| self.row_values[k]).collect();
        }
        let lu = self.lu.get_or_insert_with(|| SparseLu::with_parallelism(self.par));
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        lu.factorize(SparseColMatRef::new(pattern, &self.values))?;
        self.mode = Mode::Lu;
        // a matrix the LDL^T could not serve: its factor is no preconditioner for the next one
        self.factor_valid = false;
        self.stats.lu_fallbacks += 1;
        Ok(())
    }

    /// The LU of the values of the matrix whose LDL^T solve was not accurate enough, and `b`
    /// solved by it again from the right-hand side kept in `rhs`.
    pub(super) fn solve_by_lu(&mut self, b: &mut [f64]) -> Result<()> {
        if std::env::var_os("STAMP_DEBUG").is_some() {
            eprintln!("  linear solve not accurate enough ({:?}): the LU takes over", self.mode);
        }
        // not accurate enough on this matrix: the LU of the same values
        self.factorize_lu()?;
        b.copy_from_slice(&self.rhs);
        self.lu.as_mut().unwrap().solve_in_place(b)
    }
}

/// Why the sparse LU of a matrix of `n` unknowns whose LDL^T factor holds `ldlt_entries` would
/// not fit in `available` bytes (None: it fits, or the memory is not known).
fn lu_refusal(n: usize, ldlt_entries: usize, available: Option<usize>) -> Option<String> {
    let need = ldlt_entries.saturating_mul(LU_BYTES_PER_LDLT_ENTRY);
    let available = available.filter(|&a| need > a)?;
    let gib = |b: usize| b as f64 / (1u64 << 30) as f64;
    Some(format!(
        "the LDL^T-preconditioned GMRES did not solve this matrix of {n} unknowns, and the sparse LU that would take over needs about {:.1} GiB, more than the {:.1} GiB available",
        gib(need),
        gib(available)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The LU is refused where ten times the LDL^T's entries exceed the memory available (the
    /// factor of n = 400 in `stamp bench`, 312 million entries, on a 24 GiB machine), allowed
    /// where they fit or the memory is not known.
    #[test]
    fn lu_refused_where_it_cannot_fit() {
        let gib = 1usize << 30;
        let why = lu_refusal(961_600, 312_000_000, Some(20 * gib)).expect("refused");
        assert!(why.contains("961600 unknowns") && why.contains("46.5 GiB") && why.contains("20.0 GiB available"), "{why}");
        assert_eq!(lu_refusal(60_400, 6_000_000, Some(20 * gib)), None);
        assert_eq!(lu_refusal(961_600, 312_000_000, None), None);
    }
}
