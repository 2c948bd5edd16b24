//! The commands of the `stamp` program: the paper's benchmark, the solver bench, and `stamp run` /
//! `stamp check` around the problem-file library [`stamp_problem`].
pub mod bench;
pub mod commands;
#[cfg(feature = "petsc")]
pub mod mpi;
pub mod paper;
/// The problem-file layer, under the name it had when it lived in this crate.
pub use stamp_problem as run;
pub use stamp_problem::{out, outln, stdout};
