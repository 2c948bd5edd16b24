//! Distributed vectors (VecMPI) and the gather of a distributed vector onto every rank.

use crate::error::{check, Result};
use crate::ffi;
use crate::petsc::{pint, Petsc};

/// A vector distributed by contiguous ranges of rows over PETSC_COMM_WORLD.
pub struct DVec {
    pub(crate) raw: ffi::Vec,
    _petsc: Petsc,
}

// SAFETY: the handle is used by one thread at a time (not Sync); PETSc has no thread affinity.
unsafe impl Send for DVec {}

impl DVec {
    /// A vector of `global` rows, `local` of them on this rank (collective; the locals add up to
    /// the global).
    pub fn new(petsc: &Petsc, local: usize, global: usize) -> Result<DVec> {
        let mut raw = std::ptr::null_mut();
        check(unsafe { ffi::VecCreateMPI(ffi::PETSC_COMM_WORLD, pint(local)?, pint(global)?, &mut raw) })?;
        Ok(DVec { raw, _petsc: petsc.clone() })
    }

    /// The rows of this rank, [lo, hi).
    pub fn ownership_range(&self) -> Result<(usize, usize)> {
        let (mut lo, mut hi) = (0, 0);
        check(unsafe { ffi::VecGetOwnershipRange(self.raw, &mut lo, &mut hi) })?;
        Ok((lo as usize, hi as usize))
    }

    /// This rank's entries, to write.
    pub fn with_local_mut<T>(&mut self, f: impl FnOnce(&mut [f64]) -> T) -> Result<T> {
        let (lo, hi) = self.ownership_range()?;
        let mut p = std::ptr::null_mut();
        check(unsafe { ffi::VecGetArray(self.raw, &mut p) })?;
        let out = f(unsafe { std::slice::from_raw_parts_mut(p, hi - lo) });
        check(unsafe { ffi::VecRestoreArray(self.raw, &mut p) })?;
        Ok(out)
    }

    /// This rank's entries, to read.
    pub fn with_local<T>(&self, f: impl FnOnce(&[f64]) -> T) -> Result<T> {
        let (lo, hi) = self.ownership_range()?;
        let mut p = std::ptr::null();
        check(unsafe { ffi::VecGetArrayRead(self.raw, &mut p) })?;
        let out = f(unsafe { std::slice::from_raw_parts(p, hi - lo) });
        check(unsafe { ffi::VecRestoreArrayRead(self.raw, &mut p) })?;
        Ok(out)
    }

    /// Set this rank's entries from a full-length (replicated) array: entries lo..hi of `full`.
    pub fn set_from_full(&mut self, full: &[f64]) -> Result<()> {
        let (lo, hi) = self.ownership_range()?;
        self.with_local_mut(|x| x.copy_from_slice(&full[lo..hi]))
    }

    /// The Euclidean norm (collective).
    pub fn norm2(&self) -> Result<f64> {
        let mut n = 0.0;
        check(unsafe { ffi::VecNorm(self.raw, ffi::NormType_NORM_2, &mut n) })?;
        Ok(n)
    }
}

impl Drop for DVec {
    fn drop(&mut self) {
        unsafe { ffi::VecDestroy(&mut self.raw) };
    }
}

/// Gathers a distributed vector into a full copy on every rank (VecScatterCreateToAll).
pub struct Gather {
    scatter: ffi::VecScatter,
    all: ffi::Vec,
    _petsc: Petsc,
}

unsafe impl Send for Gather {}

impl Gather {
    /// A gather for vectors laid out as `like` (collective).
    pub fn new(petsc: &Petsc, like: &DVec) -> Result<Gather> {
        let (mut scatter, mut all) = (std::ptr::null_mut(), std::ptr::null_mut());
        check(unsafe { ffi::VecScatterCreateToAll(like.raw, &mut scatter, &mut all) })?;
        Ok(Gather { scatter, all, _petsc: petsc.clone() })
    }

    /// Every entry of `x` into `out` (collective; `out` has the global length).
    pub fn gather(&mut self, x: &DVec, out: &mut [f64]) -> Result<()> {
        check(unsafe { ffi::VecScatterBegin(self.scatter, x.raw, self.all, ffi::InsertMode_INSERT_VALUES, ffi::ScatterMode_SCATTER_FORWARD) })?;
        check(unsafe { ffi::VecScatterEnd(self.scatter, x.raw, self.all, ffi::InsertMode_INSERT_VALUES, ffi::ScatterMode_SCATTER_FORWARD) })?;
        let mut p = std::ptr::null();
        check(unsafe { ffi::VecGetArrayRead(self.all, &mut p) })?;
        out.copy_from_slice(unsafe { std::slice::from_raw_parts(p, out.len()) });
        check(unsafe { ffi::VecRestoreArrayRead(self.all, &mut p) })
    }
}

impl Drop for Gather {
    fn drop(&mut self) {
        unsafe {
            ffi::VecScatterDestroy(&mut self.scatter);
            ffi::VecDestroy(&mut self.all);
        }
    }
}
