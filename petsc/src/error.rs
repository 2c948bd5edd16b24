//! PETSc's error codes as Rust errors with PETSc's message.
//!
//! [`crate::Petsc::initialize`] pushes `handler` as PETSc's error handler: instead of printing a
//! traceback it keeps the message of the error where it arose (`PETSC_ERROR_INITIAL`, with the
//! function, file and line), and PETSc returns the code up the stack. [`check`] turns a nonzero
//! code into a [`PetscError`] with that message (or PETSc's text for the code when none was kept).

use crate::ffi;
use std::ffi::{c_char, c_int, c_void, CStr};
use std::sync::Mutex;

/// A PETSc (or MPI) call that failed: its error code and PETSc's message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PetscError {
    pub code: i32,
    pub message: String,
}

impl std::fmt::Display for PetscError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "PETSc error {}: {}", self.code, self.message)
    }
}

impl std::error::Error for PetscError {}

impl From<PetscError> for stamp::error::StampError {
    fn from(e: PetscError) -> Self {
        stamp::error::StampError::LinearSolver(e.to_string())
    }
}

pub type Result<T> = std::result::Result<T, PetscError>;

impl PetscError {
    /// An error of this crate's own (a bad argument found before calling PETSc).
    pub fn new(message: impl Into<String>) -> Self {
        PetscError { code: -1, message: message.into() }
    }
}

/// The message of the last error PETSc raised, not yet taken.
static LAST_MESSAGE: Mutex<Option<String>> = Mutex::new(None);

fn cstr(p: *const c_char) -> String {
    if p.is_null() { String::new() } else { unsafe { CStr::from_ptr(p) }.to_string_lossy().trim().to_string() }
}

/// PETSc's error handler: keeps the first message of an error and returns its code.
pub(crate) unsafe extern "C" fn handler(
    _comm: ffi::MPI_Comm,
    line: c_int,
    func: *const c_char,
    file: *const c_char,
    n: ffi::PetscErrorCode,
    p: ffi::PetscErrorType,
    mess: *const c_char,
    _ctx: *mut c_void,
) -> ffi::PetscErrorCode {
    if p == ffi::PetscErrorType_PETSC_ERROR_INITIAL {
        let mut text = cstr(mess);
        if text.is_empty() {
            text = generic_message(n);
        }
        let at = format!("{} ({}:{})", cstr(func), cstr(file), line);
        if let Ok(mut last) = LAST_MESSAGE.lock() {
            *last = Some(format!("{text} [in {at}]"));
        }
    }
    n
}

/// PETSc's text for an error code.
fn generic_message(code: ffi::PetscErrorCode) -> String {
    let mut text: *const c_char = std::ptr::null();
    unsafe { ffi::PetscErrorMessage(code, &mut text, std::ptr::null_mut()) };
    let s = cstr(text);
    if s.is_empty() { format!("error code {code}") } else { s }
}

/// Ok for 0, else the error with PETSc's message.
pub fn check(code: ffi::PetscErrorCode) -> Result<()> {
    if code == 0 {
        return Ok(());
    }
    let kept = LAST_MESSAGE.lock().ok().and_then(|mut m| m.take());
    Err(PetscError { code, message: kept.unwrap_or_else(|| generic_message(code)) })
}

/// Ok for MPI_SUCCESS, else an error naming the MPI call.
pub fn check_mpi(code: i32, call: &str) -> Result<()> {
    if code == 0 { Ok(()) } else { Err(PetscError { code, message: format!("{call} failed (MPI error code {code})") }) }
}
