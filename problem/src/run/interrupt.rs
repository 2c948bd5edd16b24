//! Ctrl-C (SIGINT) and SIGTERM end a run cleanly: the handlers ([`install`], from the start of a
//! solve on) only set a flag, which Newton checks before every iteration
//! ([`stamp::nonlinear::NewtonRaphson::interrupt`]); the step in progress is abandoned, the
//! converged steps stay written, summary.json says "interrupted" and the program exits with
//! 128 + the signal's number (130, 143), as a shell reports a process ended by it. A second
//! signal while the first is being handled ends the program at once. The program's handlers also
//! write summary.json's "interrupted" note at once ([`crate::run::abort_note`]): a process may be
//! killed before it ends the run (mpirun sends SIGKILL a second after the SIGTERM it sends every
//! rank). Under MPI the ranks agree on the signal ([`crate::run::parallel::agreed_interrupt`], which
//! records it with [`note`] on the ranks it did not reach).

use signal_hook::consts::{SIGINT, SIGTERM};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

struct Flags {
    /// Set by either signal.
    any: Arc<AtomicBool>,
    /// The number of the signal received last.
    which: Arc<AtomicUsize>,
}

static FLAGS: OnceLock<Option<Flags>> = OnceLock::new();

/// Install the handlers (once per process; later calls do nothing) and return the flag they set
/// (None if they could not be installed: the signals then end the program as by default).
pub fn install() -> Option<Arc<AtomicBool>> {
    init(&[SIGINT, SIGTERM], true)
}

/// For a program with a SIGINT handler of its own (Python's, which raises KeyboardInterrupt): a
/// handler for SIGINT alone, which sets the flag and then calls the program's handler
/// (signal-hook chains to the handler it replaced), with no exit at a second signal, SIGTERM left
/// as it was. The flag stays set until [`clear`]: clear it before each solve. Once per process,
/// like [`install`] (whichever comes first decides).
pub fn install_chained() -> Option<Arc<AtomicBool>> {
    init(&[SIGINT], false)
}

/// Forget a signal received before (see [`install_chained`]).
pub fn clear() {
    if let Some(Some(flags)) = FLAGS.get() {
        flags.any.store(false, Ordering::Relaxed);
        flags.which.store(0, Ordering::Relaxed);
    }
}

fn init(signals: &[i32], exit_on_second: bool) -> Option<Arc<AtomicBool>> {
    let flags = FLAGS.get_or_init(|| {
        let flags = Flags { any: Arc::new(AtomicBool::new(false)), which: Arc::new(AtomicUsize::new(0)) };
        for &sig in signals {
            // the second signal, with the flag already set, exits at once (status 128 + sig)
            if exit_on_second {
                signal_hook::flag::register_conditional_shutdown(sig, 128 + sig, flags.any.clone()).ok()?;
            }
            signal_hook::flag::register_usize(sig, flags.which.clone(), sig as usize).ok()?;
            signal_hook::flag::register(sig, flags.any.clone()).ok()?;
            if exit_on_second {
                // SAFETY: the action only calls async-signal-safe functions (see abort_note.rs)
                unsafe { signal_hook::low_level::register(sig, move || crate::run::abort_note::on_interrupt(sig)) }.ok()?;
            }
        }
        Some(flags)
    });
    flags.as_ref().map(|f| f.any.clone())
}

/// Record `signal` as received (another rank of a distributed run received it, see
/// [`crate::run::parallel::agreed_interrupt`]): this process then ends as if it had, with the same
/// status. Nothing without the handlers.
pub fn note(signal: i32) {
    if let Some(Some(flags)) = FLAGS.get() {
        flags.which.store(signal as usize, Ordering::Relaxed);
        flags.any.store(true, Ordering::Relaxed);
    }
}

/// The signal received, if any (SIGINT or SIGTERM).
pub fn received() -> Option<i32> {
    let flags = FLAGS.get()?.as_ref()?;
    if !flags.any.load(Ordering::Relaxed) {
        return None;
    }
    match flags.which.load(Ordering::Relaxed) {
        0 => None,
        s => Some(s as i32),
    }
}

/// The name of a signal stamp handles.
pub fn name(signal: i32) -> &'static str {
    match signal {
        SIGINT => "SIGINT (Ctrl-C)",
        SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}

/// The exit status of a program ended by `signal`: 128 + its number.
pub fn exit_status(signal: i32) -> u8 {
    (128 + signal).clamp(0, 255) as u8
}
