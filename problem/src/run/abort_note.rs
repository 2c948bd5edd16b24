//! summary.json when the process is ended before it can write it: an allocation that fails (out
//! of memory beyond what the estimate of [`crate::model::memory`] foresaw) ends the process with SIGABRT,
//! which nothing can catch to clean up, and under MPI a Ctrl-C makes mpirun send every rank
//! SIGTERM and, a second later, SIGKILL (Open MPI's default), too soon for a rank in the middle
//! of a factorisation to end its run. While a run goes on, the summary.json that would then be
//! true is kept ready in memory ([`AbortNote::prepare`], after every converged step and every
//! write of summary.json): "failed" (with the steps written so far) for SIGABRT, "interrupted" for
//! SIGINT and SIGTERM. The SIGABRT handler writes its note over summary.json with nothing but
//! open/write/close (no allocation, no lock) before the process ends as it would have; the
//! program's SIGINT and SIGTERM handlers ([`crate::run::interrupt`]) write theirs and let the run end
//! as usual (its final summary.json says the same, with the plots written). Without the notes
//! summary.json would say "running" for ever.

use std::ffi::CString;
use std::os::unix::ffi::OsStrExt;
use std::path::Path;
use std::sync::atomic::{AtomicI32, AtomicPtr, Ordering};
use std::sync::{Mutex, Once};

/// The signals with an "interrupted" note.
const INTERRUPTS: [i32; 2] = [libc::SIGINT, libc::SIGTERM];

struct Note {
    path: CString,
    /// Written at SIGABRT.
    failed: Vec<u8>,
    /// Written at SIGINT and SIGTERM, in the order of [`INTERRUPTS`].
    interrupted: [Vec<u8>; 2],
}

/// The note the handlers write (null: none).
static NOTE: AtomicPtr<Note> = AtomicPtr::new(std::ptr::null_mut());
/// The note replaced last: kept alive one generation longer, in case a handler is reading it.
static RETIRED: Mutex<Option<Box<Note>>> = Mutex::new(None);
/// The interrupting signal received (0: none): a note prepared after it is written at once.
static INTERRUPTED: AtomicI32 = AtomicI32::new(0);

/// Write `bytes` over `path`: only async-signal-safe calls (open/write/close).
fn write_over(path: &CString, bytes: &[u8]) {
    // SAFETY: open/write/close are async-signal-safe; the buffers outlive the calls
    unsafe {
        let fd = libc::open(path.as_ptr(), libc::O_WRONLY | libc::O_TRUNC | libc::O_NOFOLLOW | libc::O_NONBLOCK);
        if fd < 0 {
            return;
        }
        let mut done = 0;
        while done < bytes.len() {
            let n = libc::write(fd, bytes[done..].as_ptr().cast(), bytes.len() - done);
            if n <= 0 {
                break;
            }
            done += n as usize;
        }
        libc::close(fd);
    }
}

/// Write the current note's text for `signal` over its file: called in signal handlers, so only
/// async-signal-safe calls. SIGABRT takes the note (the process ends); an interrupt leaves it.
fn write_note(signal: i32) {
    let p = if signal == libc::SIGABRT { NOTE.swap(std::ptr::null_mut(), Ordering::AcqRel) } else { NOTE.load(Ordering::Acquire) };
    if p.is_null() {
        return;
    }
    // SAFETY: a note is freed only two generations after it was published (see `publish`), long
    // after a handler that took it has written it
    let note = unsafe { &*p };
    match INTERRUPTS.iter().position(|&s| s == signal) {
        Some(k) => write_over(&note.path, &note.interrupted[k]),
        None => write_over(&note.path, &note.failed),
    }
}

/// The SIGABRT action: write the note, then end the process as SIGABRT does by default (a
/// SIGABRT sent by another process would otherwise be ignored once handled).
fn on_abort() {
    write_note(libc::SIGABRT);
    // SAFETY: signal and raise are async-signal-safe
    unsafe {
        libc::signal(libc::SIGABRT, libc::SIG_DFL);
        libc::raise(libc::SIGABRT);
    }
}

/// The action of the program's SIGINT and SIGTERM handlers ([`crate::run::interrupt::install`]): write
/// the "interrupted" note over summary.json (async-signal-safe).
pub fn on_interrupt(signal: i32) {
    INTERRUPTED.store(signal, Ordering::Release);
    write_note(signal);
}

fn publish(note: Option<Box<Note>>) {
    let new = note.map_or(std::ptr::null_mut(), Box::into_raw);
    let old = NOTE.swap(new, Ordering::AcqRel);
    // SAFETY: `old` came from Box::into_raw in an earlier publish (or is null)
    let old = (!old.is_null()).then(|| unsafe { Box::from_raw(old) });
    let mut retired = RETIRED.lock().unwrap_or_else(|p| p.into_inner());
    *retired = old;
}

/// The notes of one run; dropping it withdraws them (the run wrote its last summary.json).
pub struct AbortNote(());

impl AbortNote {
    /// Install the SIGABRT handler (once per process) and start with no note.
    pub fn new() -> AbortNote {
        static INSTALL: Once = Once::new();
        INSTALL.call_once(|| {
            // SAFETY: the action only calls async-signal-safe functions (see write_note, on_abort)
            let _ = unsafe { signal_hook::low_level::register(signal_hook::consts::SIGABRT, on_abort) };
        });
        publish(None);
        AbortNote(())
    }

    /// Keep `failed` ready to be written over `path` if the process aborts, and
    /// `interrupted(signal)` if SIGINT or SIGTERM comes; if one came already (the run is
    /// ending), the interrupted text is written now.
    pub fn prepare(&self, path: &Path, failed: String, interrupted: impl Fn(i32) -> String) {
        if let Ok(path) = CString::new(path.as_os_str().as_bytes()) {
            let note = Note { path, failed: failed.into_bytes(), interrupted: INTERRUPTS.map(|s| interrupted(s).into_bytes()) };
            publish(Some(Box::new(note)));
            let signal = INTERRUPTED.load(Ordering::Acquire);
            if signal != 0 {
                write_note(signal);
            }
        }
    }

    /// Withdraw the note (before the final summary.json is written).
    pub fn withdraw(&self) {
        publish(None);
    }
}

impl Default for AbortNote {
    fn default() -> Self {
        AbortNote::new()
    }
}

impl Drop for AbortNote {
    fn drop(&mut self) {
        self.withdraw();
    }
}
