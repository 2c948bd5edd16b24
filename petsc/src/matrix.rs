//! Distributed sparse matrices (MPIAIJ) assembled by rows, and near-null spaces.

use crate::error::{check, PetscError, Result};
use crate::ffi;
use crate::petsc::{pint, Petsc};
use crate::vector::DVec;

/// The sparsity of this rank's rows [lo, hi) of an n x n matrix, compressed by rows: the columns
/// of row lo + i are `cols[row_ptr[i]..row_ptr[i + 1]]`, ascending.
#[derive(Debug, Clone, PartialEq)]
pub struct RowPattern {
    pub lo: usize,
    pub hi: usize,
    pub n: usize,
    pub row_ptr: Vec<usize>,
    pub cols: Vec<ffi::PetscInt>,
}

impl RowPattern {
    /// Check the shape: row_ptr of hi - lo + 1 nondecreasing offsets ending at cols.len(), columns
    /// in 0..n ascending within each row.
    pub fn validate(&self) -> Result<()> {
        let rows = self.hi.checked_sub(self.lo).ok_or_else(|| PetscError::new(format!("row range {}..{} is reversed", self.lo, self.hi)))?;
        if self.hi > self.n || self.row_ptr.len() != rows + 1 || self.row_ptr[0] != 0 || *self.row_ptr.last().unwrap() != self.cols.len() {
            return Err(PetscError::new(format!("row pattern of rows {}..{} of {}: {} offsets for {} entries", self.lo, self.hi, self.n, self.row_ptr.len(), self.cols.len())));
        }
        for i in 0..rows {
            let (a, b) = (self.row_ptr[i], self.row_ptr[i + 1]);
            if a > b {
                return Err(PetscError::new(format!("row {}: offsets decrease", self.lo + i)));
            }
            let row = &self.cols[a..b];
            if row.iter().any(|&c| c < 0 || c as usize >= self.n) || row.windows(2).any(|w| w[0] >= w[1]) {
                return Err(PetscError::new(format!("row {}: columns out of 0..{} or not ascending", self.lo + i, self.n)));
            }
        }
        Ok(())
    }

    /// Entries of each row in the diagonal block (columns lo..hi) and off it: MPIAIJ's exact
    /// preallocation.
    fn preallocation(&self) -> (Vec<ffi::PetscInt>, Vec<ffi::PetscInt>) {
        let rows = self.hi - self.lo;
        let (mut d, mut o) = (vec![0; rows], vec![0; rows]);
        for i in 0..rows {
            for &c in &self.cols[self.row_ptr[i]..self.row_ptr[i + 1]] {
                if (c as usize) >= self.lo && (c as usize) < self.hi {
                    d[i] += 1;
                } else {
                    o[i] += 1;
                }
            }
        }
        (d, o)
    }
}

/// An n x n AIJ matrix distributed by rows (MPIAIJ; SeqAIJ on one rank), preallocated exactly
/// for a [`RowPattern`]: assembling values outside it is an error.
pub struct AijMatrix {
    pub(crate) raw: ffi::Mat,
    pattern: RowPattern,
    _petsc: Petsc,
}

unsafe impl Send for AijMatrix {}

impl AijMatrix {
    /// An empty matrix of this pattern (collective: every rank passes its own rows, the ranges
    /// in rank order and covering 0..n).
    pub fn new(petsc: &Petsc, pattern: RowPattern) -> Result<AijMatrix> {
        pattern.validate()?;
        let (d, o) = pattern.preallocation();
        let local = pint(pattern.hi - pattern.lo)?;
        let n = pint(pattern.n)?;
        let mut raw = std::ptr::null_mut();
        check(unsafe { ffi::MatCreateAIJ(ffi::PETSC_COMM_WORLD, local, local, n, n, 0, d.as_ptr(), 0, o.as_ptr(), &mut raw) })?;
        let m = AijMatrix { raw, pattern, _petsc: petsc.clone() };
        let (lo, hi) = m.ownership_range()?;
        if (lo, hi) != (m.pattern.lo, m.pattern.hi) {
            return Err(PetscError::new(format!("PETSc gave rows {lo}..{hi} to this rank, the pattern has {}..{}", m.pattern.lo, m.pattern.hi)));
        }
        // an entry outside the preallocated pattern is an error, not a slow reallocation
        check(unsafe { ffi::MatSetOption(m.raw, ffi::MatOption_MAT_NEW_NONZERO_ALLOCATION_ERR, ffi::PetscBool_PETSC_TRUE) })?;
        Ok(m)
    }

    pub fn pattern(&self) -> &RowPattern {
        &self.pattern
    }

    /// The rows of this rank, [lo, hi).
    pub fn ownership_range(&self) -> Result<(usize, usize)> {
        let (mut lo, mut hi) = (0, 0);
        check(unsafe { ffi::MatGetOwnershipRange(self.raw, &mut lo, &mut hi) })?;
        Ok((lo as usize, hi as usize))
    }

    /// Set every entry of this rank's rows, `values` in the pattern's order, and assemble
    /// (collective).
    pub fn set_values(&mut self, values: &[f64]) -> Result<()> {
        let p = &self.pattern;
        if values.len() != p.cols.len() {
            return Err(PetscError::new(format!("{} values for a pattern of {} entries", values.len(), p.cols.len())));
        }
        for i in 0..p.hi - p.lo {
            let (a, b) = (p.row_ptr[i], p.row_ptr[i + 1]);
            let row = pint(p.lo + i)?;
            check(unsafe { ffi::MatSetValues(self.raw, 1, &row, pint(b - a)?, p.cols[a..b].as_ptr(), values[a..b].as_ptr(), ffi::InsertMode_INSERT_VALUES) })?;
        }
        check(unsafe { ffi::MatAssemblyBegin(self.raw, ffi::MatAssemblyType_MAT_FINAL_ASSEMBLY) })?;
        check(unsafe { ffi::MatAssemblyEnd(self.raw, ffi::MatAssemblyType_MAT_FINAL_ASSEMBLY) })
    }

    /// Set the matrix to the sum over the ranks of each rank's share, and assemble
    /// (collective): `own(k)`, this rank's share of entry k of its own rows (in the pattern's
    /// order); `foreign`,
    /// the entries it holds in other ranks' rows, (row, column, value), which PETSc sends at the
    /// assembly. Every entry must lie in the pattern (the preallocation is the pattern's): the
    /// nonzero structure stays, so a factorisation keeps its symbolic phase.
    pub fn set_sum(&mut self, own: impl Fn(usize) -> f64, foreign: &[(ffi::PetscInt, ffi::PetscInt, f64)]) -> Result<()> {
        let p = &self.pattern;
        check(unsafe { ffi::MatZeroEntries(self.raw) })?;
        let mut row_values = Vec::new();
        for i in 0..p.hi - p.lo {
            let (a, b) = (p.row_ptr[i], p.row_ptr[i + 1]);
            let row = pint(p.lo + i)?;
            row_values.clear();
            row_values.extend((a..b).map(&own));
            check(unsafe { ffi::MatSetValues(self.raw, 1, &row, pint(b - a)?, p.cols[a..b].as_ptr(), row_values.as_ptr(), ffi::InsertMode_ADD_VALUES) })?;
        }
        for &(i, j, v) in foreign {
            check(unsafe { ffi::MatSetValues(self.raw, 1, &i, 1, &j, &v, ffi::InsertMode_ADD_VALUES) })?;
        }
        check(unsafe { ffi::MatAssemblyBegin(self.raw, ffi::MatAssemblyType_MAT_FINAL_ASSEMBLY) })?;
        check(unsafe { ffi::MatAssemblyEnd(self.raw, ffi::MatAssemblyType_MAT_FINAL_ASSEMBLY) })
    }

    /// Tell PETSc the matrix is symmetric (MAT_SYMMETRIC, kept through value changes), and
    /// positive definite too when `spd` (MAT_SPD: MUMPS then factorises by Cholesky instead of
    /// LDL^T).
    pub fn set_symmetric(&mut self, spd: bool) -> Result<()> {
        let t = ffi::PetscBool_PETSC_TRUE;
        check(unsafe { ffi::MatSetOption(self.raw, ffi::MatOption_MAT_SYMMETRIC, t) })?;
        check(unsafe { ffi::MatSetOption(self.raw, ffi::MatOption_MAT_SYMMETRY_ETERNAL, t) })?;
        if spd {
            check(unsafe { ffi::MatSetOption(self.raw, ffi::MatOption_MAT_SPD, t) })?;
        }
        Ok(())
    }

    /// The values of this rank's row `row` (global), in the pattern's order.
    pub fn row_values(&self, row: usize, out: &mut Vec<f64>) -> Result<()> {
        let (mut n, mut cols, mut vals) = (0, std::ptr::null(), std::ptr::null());
        let r = pint(row)?;
        check(unsafe { ffi::MatGetRow(self.raw, r, &mut n, &mut cols, &mut vals) })?;
        out.clear();
        if n > 0 {
            out.extend_from_slice(unsafe { std::slice::from_raw_parts(vals, n as usize) });
        }
        check(unsafe { ffi::MatRestoreRow(self.raw, r, &mut n, &mut cols, &mut vals) })
    }

    /// y = A x (collective).
    pub fn mult(&self, x: &DVec, y: &mut DVec) -> Result<()> {
        check(unsafe { ffi::MatMult(self.raw, x.raw, y.raw) })
    }

    /// Give the matrix a near-null space (the rigid-body modes of an elastic body, say), which
    /// algebraic multigrid (GAMG) builds its coarse spaces from. `vectors` hold this rank's rows of
    /// each vector; they are orthonormalised here (collective).
    pub fn set_near_null_space(&mut self, petsc: &Petsc, vectors: &[Vec<f64>]) -> Result<()> {
        let rows = self.pattern.hi - self.pattern.lo;
        let basis = orthonormalise(petsc, vectors, rows)?;
        let mut vecs = Vec::with_capacity(basis.len());
        for b in &basis {
            let mut v = DVec::new(petsc, rows, self.pattern.n)?;
            v.with_local_mut(|x| x.copy_from_slice(b))?;
            vecs.push(v);
        }
        let raws: Vec<ffi::Vec> = vecs.iter().map(|v| v.raw).collect();
        let mut ns = std::ptr::null_mut();
        check(unsafe { ffi::MatNullSpaceCreate(ffi::PETSC_COMM_WORLD, ffi::PetscBool_PETSC_FALSE, pint(raws.len())?, raws.as_ptr(), &mut ns) })?;
        let set = check(unsafe { ffi::MatSetNearNullSpace(self.raw, ns) });
        // the matrix keeps its own reference
        unsafe { ffi::MatNullSpaceDestroy(&mut ns) };
        set
    }
}

impl Drop for AijMatrix {
    fn drop(&mut self) {
        unsafe { ffi::MatDestroy(&mut self.raw) };
    }
}

/// Modified Gram-Schmidt over distributed vectors (each rank's rows), dot products summed over the
/// ranks; vectors dependent on the earlier ones (relative norm below 1e-10) are dropped.
fn orthonormalise(petsc: &Petsc, vectors: &[Vec<f64>], rows: usize) -> Result<Vec<Vec<f64>>> {
    let mut basis: Vec<Vec<f64>> = Vec::new();
    for v in vectors {
        if v.len() != rows {
            return Err(PetscError::new(format!("a near-null vector has {} entries on this rank, which owns {rows} rows", v.len())));
        }
        let mut w = v.clone();
        let mut n0 = [w.iter().map(|x| x * x).sum::<f64>()];
        petsc.sum_f64(&mut n0)?;
        for b in &basis {
            let mut d = [w.iter().zip(b).map(|(x, y)| x * y).sum::<f64>()];
            petsc.sum_f64(&mut d)?;
            w.iter_mut().zip(b).for_each(|(x, y)| *x -= d[0] * y);
        }
        let mut n = [w.iter().map(|x| x * x).sum::<f64>()];
        petsc.sum_f64(&mut n)?;
        if n0[0] > 0.0 && n[0] > 1e-20 * n0[0] {
            let s = 1.0 / n[0].sqrt();
            w.iter_mut().for_each(|x| *x *= s);
            basis.push(w);
        }
    }
    Ok(basis)
}
