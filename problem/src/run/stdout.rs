//! Printing to stdout without panicking: `stamp check P.toml | head -1` closes the pipe early and
//! `> /dev/full` fails every write, where `println!` would panic. [`outln!`](crate::outln) and
//! [`out!`](crate::out) write through [`print()`], which keeps the first failure and stops writing;
//! the program goes on (a run still writes its files and summary.json) and [`finish`] says at the
//! end how it went: a broken pipe is not an error (the reader had what it wanted, as with other
//! Unix tools), any other failure is.

use std::io::{ErrorKind, Write};
use std::sync::Mutex;

static FAILURE: Mutex<Option<std::io::Error>> = Mutex::new(None);

/// Write `text` to stdout and flush; after a failure nothing more is written.
pub fn print(text: &str) {
    let mut failure = FAILURE.lock().unwrap_or_else(|p| p.into_inner());
    if failure.is_some() {
        return;
    }
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        *failure = Some(e);
    }
}

/// How stdout went: Ok when every write went through or the reader closed the pipe early, else
/// the error of the first failed write.
pub fn finish() -> Result<(), std::io::Error> {
    match FAILURE.lock().unwrap_or_else(|p| p.into_inner()).take() {
        Some(e) if e.kind() != ErrorKind::BrokenPipe => Err(e),
        _ => Ok(()),
    }
}

/// `print!` to stdout through [`print()`]: never panics.
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => { $crate::run::stdout::print(&format!($($arg)*)) };
}

/// `println!` to stdout through [`print()`]: never panics.
#[macro_export]
macro_rules! outln {
    () => { $crate::run::stdout::print("\n") };
    ($($arg:tt)*) => { $crate::run::stdout::print(&format!("{}\n", format_args!($($arg)*))) };
}
