//! `mpirun -n P stamp ...` (the feature `petsc`): PETSc and MPI for the whole command, and the
//! rules that make P processes behave as one program.
//!
//! - PETSc is initialised at the start and finalised at the end ([`Ranks`]).
//! - With P > 1 each rank runs its rayon work on one thread: the ranks are the parallelism, and
//!   the replicated computation (stamp_problem::parallel) must give every rank the same numbers to
//!   the bit, which a reduction over a varying number of threads would not.
//! - Rank 0 writes the outputs and prints; the other ranks write no file at all
//!   (stamp_problem::parallel::writes_outputs) and have stdout and stderr on /dev/null, but run
//!   the same code otherwise, so that every rank makes the same collective calls in the same
//!   order.
//! - The outcome is agreed at the end: every rank exits with the error of the lowest rank that
//!   failed, printed once by rank 0. A rank that failed and finds the others still busy after
//!   [`ALONE_AFTER`] seconds (it failed alone, before the solve: its output folder could not be
//!   made, say, while the others wait for it in a collective call) prints its message and ends
//!   every rank (MPI_Abort); so does a panic on any rank. Failures during the solve are agreed
//!   where they happen (stamp_petsc::PetscSolver, and a failed write stops every rank after its
//!   step: stamp_problem::parallel::any_rank), so they end here together.

use stamp_petsc::Petsc;

/// Seconds a rank that failed waits for the others at the end before it ends the job.
pub const ALONE_AFTER: f64 = 20.0;

/// PETSc for the life of the command.
pub struct Ranks {
    petsc: Petsc,
    /// The original stderr (rank > 0 prints nothing else).
    stderr: i32,
}

impl Ranks {
    /// Initialise PETSc and MPI, and set the rules above.
    pub fn start() -> Result<Ranks, String> {
        let petsc = Petsc::initialize().map_err(|e| format!("cannot start PETSc and MPI: {e}"))?;
        let (rank, size) = (petsc.rank(), petsc.size());
        let mut stderr = 2;
        if size > 1 {
            let _ = rayon::ThreadPoolBuilder::new().num_threads(1).build_global();
            // the original stderr, for a panic's message
            let err = unsafe { libc::dup(2) };
            stderr = err;
            if rank > 0 {
                let null = std::fs::OpenOptions::new().write(true).open("/dev/null").map_err(|e| format!("/dev/null: {e}"))?;
                use std::os::fd::AsRawFd;
                unsafe {
                    libc::dup2(null.as_raw_fd(), 1);
                    libc::dup2(null.as_raw_fd(), 2);
                }
            }
            std::panic::set_hook(Box::new(move |info| {
                let text = format!("error: rank {rank} of {size} panicked: {info}\n");
                unsafe { libc::write(err, text.as_ptr().cast(), text.len()) };
                stamp_petsc::petsc::abort_world(101);
            }));
        }
        Ok(Ranks { petsc, stderr })
    }

    /// The command's outcome, the same on every rank (collective).
    /// [`end`](Self::end) follows once rank 0 has printed it.
    pub fn finish(&mut self, result: Result<(), String>) -> Result<(), String> {
        let (rank, size) = (self.petsc.rank(), self.petsc.size());
        let agreed = if size > 1 {
            let wait = result.is_err().then_some(ALONE_AFTER);
            match (self.petsc.barrier_within(wait), &result) {
                (Ok(true), _) => self.petsc.agree(result),
                (_, Err(e)) => {
                    let text = format!("error: rank {rank} of {size}: {e}\n(the other ranks did not stop within {ALONE_AFTER} s: ending them)\n");
                    unsafe { libc::write(self.stderr, text.as_ptr().cast(), text.len()) };
                    self.petsc.abort(1)
                }
                (Err(e), Ok(())) => Err(e.to_string()),
                (Ok(false), Ok(())) => Err("the ranks did not meet at the end".into()),
            }
        } else {
            result
        };
        agreed
    }

    /// The end of the command, after rank 0 printed its outcome: every rank waits for the others
    /// here, so that no rank exits (and mpirun, seeing its failure status, kills the job) before
    /// rank 0's message is out; then PETSc is finalised (the handle dropped).
    pub fn end(self) {
        if self.petsc.size() > 1 {
            let _ = self.petsc.barrier();
        }
        let _ = std::panic::take_hook();
    }
}
