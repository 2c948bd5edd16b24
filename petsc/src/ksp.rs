//! Krylov solvers and their preconditioners (KSP, PC).

use crate::error::{check, PetscError, Result};
use crate::ffi;
use crate::matrix::AijMatrix;
use crate::petsc::{pint, Petsc};
use crate::vector::DVec;
use std::ffi::{c_char, CStr, CString};

/// A KSP on PETSC_COMM_WORLD.
pub struct Ksp {
    raw: ffi::KSP,
    _petsc: Petsc,
}

unsafe impl Send for Ksp {}

/// What one solve did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SolveReport {
    pub iterations: usize,
    /// KSPConvergedReason (positive: converged).
    pub reason: i32,
}

fn cstring(s: &str) -> Result<CString> {
    CString::new(s).map_err(|_| PetscError::new(format!("{s:?} contains a NUL byte")))
}

fn string(p: *const c_char) -> String {
    if p.is_null() { String::new() } else { unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned() }
}

impl Ksp {
    pub fn new(petsc: &Petsc) -> Result<Ksp> {
        let mut raw = std::ptr::null_mut();
        check(unsafe { ffi::KSPCreate(ffi::PETSC_COMM_WORLD, &mut raw) })?;
        Ok(Ksp { raw, _petsc: petsc.clone() })
    }

    /// Solve with `a`, preconditioned by a preconditioner built from `p` (the same matrix, or
    /// another close to it). Set again after the values changed: the preconditioner is then
    /// rebuilt, its symbolic phase kept when the pattern is the same.
    pub fn set_operators(&mut self, a: &AijMatrix, p: &AijMatrix) -> Result<()> {
        check(unsafe { ffi::KSPSetOperators(self.raw, a.raw, p.raw) })
    }

    /// The Krylov method ("gmres", "cg", "preonly", ...).
    pub fn set_type(&mut self, t: &str) -> Result<()> {
        let c = cstring(t)?;
        check(unsafe { ffi::KSPSetType(self.raw, c.as_ptr()) })
    }

    /// Krylov vectors kept before GMRES restarts.
    pub fn set_gmres_restart(&mut self, restart: usize) -> Result<()> {
        check(unsafe { ffi::KSPGMRESSetRestart(self.raw, pint(restart)?) })
    }

    /// Precondition from the right (the residual the method judges is then the true one).
    pub fn set_right_preconditioning(&mut self) -> Result<()> {
        check(unsafe { ffi::KSPSetPCSide(self.raw, ffi::PCSide_PC_RIGHT) })
    }

    /// Converged when |r| <= max(rtol |b|, atol); at most `max_iterations`.
    pub fn set_tolerances(&mut self, rtol: f64, atol: f64, max_iterations: usize) -> Result<()> {
        check(unsafe { ffi::KSPSetTolerances(self.raw, rtol, atol, ffi::PETSC_DEFAULT as f64, pint(max_iterations)?) })
    }

    /// (rtol, atol, most iterations) in force.
    pub fn tolerances(&self) -> Result<(f64, f64, usize)> {
        let (mut r, mut a, mut d, mut m) = (0.0, 0.0, 0.0, 0);
        check(unsafe { ffi::KSPGetTolerances(self.raw, &mut r, &mut a, &mut d, &mut m) })?;
        Ok((r, a, m.max(0) as usize))
    }

    /// The preconditioner ("cholesky", "lu", "gamg", "hypre", ...).
    pub fn set_pc_type(&mut self, t: &str) -> Result<()> {
        let c = cstring(t)?;
        check(unsafe { ffi::PCSetType(self.pc()?, c.as_ptr()) })
    }

    /// The package of a factorisation preconditioner ("mumps", "superlu_dist", "petsc").
    pub fn set_factor_solver(&mut self, package: &str) -> Result<()> {
        let c = cstring(package)?;
        check(unsafe { ffi::PCFactorSetMatSolverType(self.pc()?, c.as_ptr()) })
    }

    fn pc(&self) -> Result<ffi::PC> {
        let mut pc = std::ptr::null_mut();
        check(unsafe { ffi::KSPGetPC(self.raw, &mut pc) })?;
        Ok(pc)
    }

    /// Read the options database (the `-ksp_*` and `-pc_*` options): what the user asks for
    /// overrides what was set before.
    pub fn set_from_options(&mut self) -> Result<()> {
        check(unsafe { ffi::KSPSetFromOptions(self.raw) })
    }

    /// Build the preconditioner (the factorisation) now.
    pub fn set_up(&mut self) -> Result<()> {
        check(unsafe { ffi::KSPSetUp(self.raw) })
    }

    /// Solve A x = b (collective). A solve that did not converge is an error naming PETSc's
    /// reason.
    pub fn solve(&mut self, b: &DVec, x: &mut DVec) -> Result<SolveReport> {
        check(unsafe { ffi::KSPSolve(self.raw, b.raw, x.raw) })?;
        let (mut its, mut reason) = (0, 0);
        check(unsafe { ffi::KSPGetIterationNumber(self.raw, &mut its) })?;
        check(unsafe { ffi::KSPGetConvergedReason(self.raw, &mut reason) })?;
        let report = SolveReport { iterations: its as usize, reason: reason as i32 };
        if report.reason < 0 {
            let mut s = std::ptr::null();
            unsafe { ffi::KSPGetConvergedReasonString(self.raw, &mut s) };
            let mut message = format!("the {} solve did not converge: {} after {} iterations", self.describe(), string(s), its);
            if report.reason == ffi::KSPConvergedReason_KSP_DIVERGED_PC_FAILED as i32 {
                message.push_str(&format!(" (the preconditioner: {})", self.pc_failure()));
            }
            return Err(PetscError { code: report.reason, message });
        }
        Ok(report)
    }

    /// x = M^-1 b with the preconditioner alone (collective; after [`Ksp::set_up`]): MUMPS's
    /// factor's solve, one multigrid cycle, ...
    pub fn apply_preconditioner(&self, b: &DVec, x: &mut DVec) -> Result<()> {
        let pc = self.pc()?;
        check(unsafe { ffi::PCApply(pc, b.raw, x.raw) })
    }

    /// Selected entries of the inverse of the factorisation preconditioner's matrix, computed
    /// by MUMPS (ICNTL(30)) into `requested`: its row j holds the entries (i, j) of the inverse
    /// at its pattern, every row on rank 0 (MatMumpsGetInverseTranspose). Collective; only with
    /// MUMPS's factor ([`Ksp::factor_solver`]). The solve controls it sets are restored after.
    pub fn inverse_entries(&self, requested: &mut AijMatrix) -> Result<()> {
        let mut f = std::ptr::null_mut();
        check(unsafe { ffi::PCFactorGetMatrix(self.pc()?, &mut f) })?;
        let mut saved = [0 as ffi::PetscInt; 3];
        for (k, icntl) in [20, 21, 30].into_iter().enumerate() {
            check(unsafe { ffi::MatMumpsGetIcntl(f, icntl, &mut saved[k]) })?;
        }
        let got = check(unsafe { ffi::MatMumpsGetInverseTranspose(f, requested.raw) });
        for (k, icntl) in [20, 21, 30].into_iter().enumerate() {
            check(unsafe { ffi::MatMumpsSetIcntl(f, icntl, saved[k]) })?;
        }
        got
    }

    /// Why the preconditioner failed on this rank, in PETSc's words and ours.
    fn pc_failure(&self) -> String {
        let mut r = ffi::PCFailedReason_PC_NOERROR;
        if let Ok(pc) = self.pc() {
            unsafe { ffi::PCGetFailedReason(pc, &mut r) };
        }
        match r {
            ffi::PCFailedReason_PC_SETUP_ERROR => "SETUP_ERROR".into(),
            ffi::PCFailedReason_PC_FACTOR_STRUCT_ZEROPIVOT => "FACTOR_STRUCT_ZEROPIVOT, a structurally zero pivot: the matrix is singular".into(),
            ffi::PCFailedReason_PC_FACTOR_NUMERIC_ZEROPIVOT => "FACTOR_NUMERIC_ZEROPIVOT, a zero pivot in the factorisation: the matrix is singular".into(),
            ffi::PCFailedReason_PC_FACTOR_OUTMEMORY => "FACTOR_OUTMEMORY, out of memory in the factorisation".into(),
            ffi::PCFailedReason_PC_FACTOR_OTHER => "FACTOR_OTHER, the factorisation failed".into(),
            ffi::PCFailedReason_PC_SUBPC_ERROR => "SUBPC_ERROR, an inner preconditioner failed".into(),
            ffi::PCFailedReason_PC_NOERROR => "failed on another rank".into(),
            other => format!("reason {other}"),
        }
    }

    /// The Krylov method's name.
    pub fn ksp_type(&self) -> String {
        let mut t = std::ptr::null();
        unsafe { ffi::KSPGetType(self.raw, &mut t) };
        string(t)
    }

    /// The preconditioner's name.
    pub fn pc_type(&self) -> String {
        let mut t = std::ptr::null();
        if let Ok(pc) = self.pc() {
            unsafe { ffi::PCGetType(pc, &mut t) };
        }
        string(t)
    }

    /// The factorisation package, if the preconditioner is a factorisation.
    pub fn factor_solver(&self) -> Option<String> {
        let pc = self.pc().ok()?;
        let t = self.pc_type();
        if !matches!(t.as_str(), "lu" | "cholesky" | "ilu" | "icc") {
            return None;
        }
        let mut s = std::ptr::null();
        unsafe { ffi::PCFactorGetMatSolverType(pc, &mut s) };
        let s = string(s);
        (!s.is_empty()).then_some(s)
    }

    /// "gmres + cholesky (mumps)": the method and preconditioner in use.
    pub fn describe(&self) -> String {
        match self.factor_solver() {
            Some(f) => format!("{} + {} ({f})", self.ksp_type(), self.pc_type()),
            None => format!("{} + {}", self.ksp_type(), self.pc_type()),
        }
    }
}

impl Drop for Ksp {
    fn drop(&mut self) {
        unsafe { ffi::KSPDestroy(&mut self.raw) };
    }
}
