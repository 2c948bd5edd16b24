//! Running the solve: [`solve`] (Newton-Raphson along the targets with a progress bar, writing
//! every step) on the processes of [`parallel`], ended cleanly by [`interrupt`] (with the notes
//! of [`abort_note`]), printing through [`stdout`]; and the output folder a run owns: [`out_dir`]
//! (removes the previous run's files, only those), locked by [`folder_lock`] against a second run,
//! with room for the last word ([`reserve`]), never over its own inputs ([`own_inputs`]), reading
//! back only regular files ([`regular`]); [`kept`]: the results kept in memory for the Python
//! package.

pub mod abort_note;
pub mod folder_lock;
pub mod interrupt;
pub mod kept;
pub mod out_dir;
pub mod own_inputs;
pub mod parallel;
pub mod regular;
pub mod reserve;
pub mod solve;
pub mod stdout;

pub use solve::{default_out_dir, solve_and_write, RunOutcome, SolveOptions};
