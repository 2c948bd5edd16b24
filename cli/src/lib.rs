//! The problems and reports behind the `stamp` command-line program.
pub mod bench;
pub mod paper;
pub mod run;
pub mod stdout;
