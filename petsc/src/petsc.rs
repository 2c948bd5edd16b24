//! PetscInitialize once per process, PetscFinalize after the last handle; rank, size and the
//! collective helpers.

use crate::error::{check, check_mpi, PetscError, Result};
use crate::ffi;
use std::sync::{Arc, Mutex, Weak};

/// A handle on the initialised PETSc (and MPI) of this process. Cloning is cheap; every PETSc
/// object of this crate holds one, and PetscFinalize runs when the last is dropped. MPI cannot be
/// initialised twice in a process: after that, [`Petsc::initialize`] fails.
#[derive(Clone)]
pub struct Petsc {
    inner: Arc<Inner>,
}

struct Inner {
    rank: usize,
    size: usize,
}

/// The state of the process: never initialised, live (a weak reference to the handle), or
/// finalised.
enum State {
    Never,
    Live(Weak<Inner>),
    Finalized,
}

static STATE: Mutex<State> = Mutex::new(State::Never);

impl Drop for Inner {
    fn drop(&mut self) {
        if let Ok(mut s) = STATE.lock() {
            *s = State::Finalized;
        }
        unsafe { ffi::PetscFinalize() };
    }
}

impl Petsc {
    /// Initialise PETSc and MPI (PetscInitializeNoArguments: options come from the PETSC_OPTIONS
    /// environment variable and [`Petsc::insert_options`]), or return the live handle.
    pub fn initialize() -> Result<Petsc> {
        let mut state = STATE.lock().map_err(|_| PetscError::new("PETSc's state lock is poisoned"))?;
        match &*state {
            State::Live(w) => {
                if let Some(inner) = w.upgrade() {
                    return Ok(Petsc { inner });
                }
                return Err(PetscError::new("PETSc was finalised in this process and cannot be initialised again"));
            }
            State::Finalized => return Err(PetscError::new("PETSc was finalised in this process and cannot be initialised again")),
            State::Never => {}
        }
        check(unsafe { ffi::PetscInitializeNoArguments() })?;
        // errors come back as codes with their message (crate::error), not as printed tracebacks
        check(unsafe { ffi::PetscPushErrorHandler(Some(crate::error::handler), std::ptr::null_mut()) })?;
        let (mut rank, mut size) = (0i32, 0i32);
        check_mpi(unsafe { ffi::stamp_petsc_world_rank(&mut rank) }, "MPI_Comm_rank")?;
        check_mpi(unsafe { ffi::stamp_petsc_world_size(&mut size) }, "MPI_Comm_size")?;
        let inner = Arc::new(Inner { rank: rank as usize, size: size as usize });
        *state = State::Live(Arc::downgrade(&inner));
        Ok(Petsc { inner })
    }

    /// The live handle, if PETSc is initialised and not finalised (without initialising it).
    pub fn current() -> Option<Petsc> {
        match &*STATE.lock().ok()? {
            State::Live(w) => w.upgrade().map(|inner| Petsc { inner }),
            _ => None,
        }
    }

    /// This process's rank in PETSC_COMM_WORLD.
    pub fn rank(&self) -> usize {
        self.inner.rank
    }

    /// The number of processes.
    pub fn size(&self) -> usize {
        self.inner.size
    }

    /// PETSc's version, "3.18.5".
    pub fn version(&self) -> String {
        let (mut a, mut b, mut c) = (0, 0, 0);
        unsafe { ffi::PetscGetVersionNumber(&mut a, &mut b, &mut c, std::ptr::null_mut()) };
        format!("{a}.{b}.{c}")
    }

    /// Add options to PETSc's database as if given on the command line ("-ksp_type cg -pc_type
    /// gamg"); objects read them in their SetFromOptions.
    pub fn insert_options(&self, options: &str) -> Result<()> {
        let c = std::ffi::CString::new(options).map_err(|_| PetscError::new("PETSc options contain a NUL byte"))?;
        check(unsafe { ffi::PetscOptionsInsertString(std::ptr::null_mut(), c.as_ptr()) })
    }

    /// Elementwise maximum over the ranks, in place (collective).
    pub fn max_u64(&self, v: &mut [u64]) -> Result<()> {
        check_mpi(unsafe { ffi::stamp_petsc_allreduce_u64(v.as_mut_ptr(), len(v.len())?, 0) }, "MPI_Allreduce")
    }

    /// Elementwise minimum over the ranks, in place (collective).
    pub fn min_u64(&self, v: &mut [u64]) -> Result<()> {
        check_mpi(unsafe { ffi::stamp_petsc_allreduce_u64(v.as_mut_ptr(), len(v.len())?, 1) }, "MPI_Allreduce")
    }

    /// Elementwise sum over the ranks, in place (collective).
    pub fn sum_f64(&self, v: &mut [f64]) -> Result<()> {
        check_mpi(unsafe { ffi::stamp_petsc_allreduce_f64(v.as_mut_ptr(), len(v.len())?, 2) }, "MPI_Allreduce")
    }

    /// Elementwise maximum over the ranks, in place (collective).
    pub fn max_f64(&self, v: &mut [f64]) -> Result<()> {
        check_mpi(unsafe { ffi::stamp_petsc_allreduce_f64(v.as_mut_ptr(), len(v.len())?, 0) }, "MPI_Allreduce")
    }

    /// Rank `root`'s bytes on every rank (collective; the length must be the same everywhere).
    pub fn broadcast(&self, bytes: &mut [u8], root: usize) -> Result<()> {
        check_mpi(unsafe { ffi::stamp_petsc_bcast_bytes(bytes.as_mut_ptr().cast(), len(bytes.len())?, root as i32) }, "MPI_Bcast")
    }

    /// Rank `root`'s string on every rank (collective).
    pub fn broadcast_string(&self, s: &str, root: usize) -> Result<String> {
        let mut n = [if self.rank() == root { s.len() as u64 } else { 0 }];
        self.max_u64(&mut n)?;
        let mut bytes = if self.rank() == root { s.as_bytes().to_vec() } else { vec![0u8; n[0] as usize] };
        self.broadcast(&mut bytes, root)?;
        Ok(String::from_utf8_lossy(&bytes).into_owned())
    }

    /// Wait for every rank (collective).
    pub fn barrier(&self) -> Result<()> {
        check_mpi(unsafe { ffi::stamp_petsc_barrier() }, "MPI_Barrier")
    }

    /// Wait for every rank (collective), at most `seconds` (None: for ever); false on time-out:
    /// some rank did not come (it is busy in, or waiting at, another collective call), and the
    /// caller should [`abort`](Petsc::abort) rather than make another collective call.
    pub fn barrier_within(&self, seconds: Option<f64>) -> Result<bool> {
        let mut done = 0;
        check_mpi(unsafe { ffi::stamp_petsc_barrier_within(seconds.unwrap_or(-1.0), &mut done) }, "MPI_Ibarrier")?;
        Ok(done != 0)
    }

    /// Make every rank's outcome the same (collective): Ok on every rank if it was Ok on every
    /// rank, else on every rank the error of the lowest-numbered rank that failed, its message
    /// prefixed "rank r of P: " when not every rank failed. Each rank's own value is kept when all
    /// are Ok. Call it after any step that can fail on some ranks and not on others, so that the
    /// ranks go on, or stop, together instead of leaving some waiting in a collective call.
    pub fn agree<T, E: std::fmt::Display>(&self, local: std::result::Result<T, E>) -> std::result::Result<T, String> {
        let failed = local.is_err();
        let mut first = [if failed { self.rank() as u64 } else { u64::MAX }];
        let mut count = [failed as u64 as f64];
        let collective = self.min_u64(&mut first).and_then(|_| self.sum_f64(&mut count));
        if let Err(e) = collective {
            // MPI itself failed: nothing can be agreed any more
            return Err(format!("{e}"));
        }
        if first[0] == u64::MAX {
            return local.map_err(|e| e.to_string());
        }
        let root = first[0] as usize;
        let mine = match &local {
            Err(e) if self.rank() == root => e.to_string(),
            _ => String::new(),
        };
        let message = self.broadcast_string(&mine, root).unwrap_or_else(|e| e.to_string());
        if count[0] as usize == self.size() {
            Err(message)
        } else {
            Err(format!("rank {root} of {}: {message}", self.size()))
        }
    }

    /// End every rank of the job now (MPI_Abort), with `code`: for a failure that the other ranks
    /// cannot be told of in a collective call.
    pub fn abort(&self, code: i32) -> ! {
        abort_world(code)
    }
}

/// End every rank of the job now (MPI_Abort on PETSC_COMM_WORLD), without a handle (in a panic
/// hook, say, which must not keep PETSc alive).
pub fn abort_world(code: i32) -> ! {
    unsafe { ffi::stamp_petsc_abort(code) };
    std::process::exit(code)
}

/// A length as MPI's int.
fn len(n: usize) -> Result<i32> {
    i32::try_from(n).map_err(|_| PetscError::new(format!("{n} items exceed MPI's int count")))
}

/// An index or count as PETSc's PetscInt.
pub fn pint(n: usize) -> Result<ffi::PetscInt> {
    ffi::PetscInt::try_from(n).map_err(|_| PetscError::new(format!("{n} exceeds PETSc's integer range (PetscInt of {} bytes)", std::mem::size_of::<ffi::PetscInt>())))
}
