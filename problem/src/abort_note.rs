//! summary.json when the process aborts: an allocation that fails (out of memory beyond what the
//! estimate of [`super::memory`] foresaw) ends the process with SIGABRT, which nothing can catch
//! to clean up. While a run goes on, a summary.json that says "failed" (with the steps written so
//! far) is kept ready in memory ([`AbortNote::prepare`], after every write of summary.json), and a
//! SIGABRT handler writes it over summary.json with nothing but open/write/close (no allocation,
//! no lock) before the process ends as it would have. Without it summary.json would say "running"
//! for ever.

use std::ffi::CString;
use std::os::unix::ffi::OsStrExt;
use std::path::Path;
use std::sync::atomic::{AtomicPtr, Ordering};
use std::sync::{Mutex, Once};

struct Note {
    path: CString,
    bytes: Vec<u8>,
}

/// The note the handler writes (null: none).
static NOTE: AtomicPtr<Note> = AtomicPtr::new(std::ptr::null_mut());
/// The note replaced last: kept alive one generation longer, in case the handler is reading it.
static RETIRED: Mutex<Option<Box<Note>>> = Mutex::new(None);

/// Write the current note over its file: called in the SIGABRT handler, so only
/// async-signal-safe calls.
fn write_note() {
    let p = NOTE.swap(std::ptr::null_mut(), Ordering::AcqRel);
    if p.is_null() {
        return;
    }
    // SAFETY: a note is freed only two generations after it was published (see `publish`), long
    // after a handler that took it has written it; open/write/close are async-signal-safe
    unsafe {
        let note = &*p;
        let fd = libc::open(note.path.as_ptr(), libc::O_WRONLY | libc::O_TRUNC | libc::O_NOFOLLOW | libc::O_NONBLOCK);
        if fd < 0 {
            return;
        }
        let mut done = 0;
        while done < note.bytes.len() {
            let n = libc::write(fd, note.bytes[done..].as_ptr().cast(), note.bytes.len() - done);
            if n <= 0 {
                break;
            }
            done += n as usize;
        }
        libc::close(fd);
    }
}

/// The SIGABRT action: write the note, then end the process as SIGABRT does by default (a
/// SIGABRT sent by another process would otherwise be ignored once handled).
fn on_abort() {
    write_note();
    // SAFETY: signal and raise are async-signal-safe
    unsafe {
        libc::signal(libc::SIGABRT, libc::SIG_DFL);
        libc::raise(libc::SIGABRT);
    }
}

fn publish(note: Option<Box<Note>>) {
    let new = note.map_or(std::ptr::null_mut(), Box::into_raw);
    let old = NOTE.swap(new, Ordering::AcqRel);
    // SAFETY: `old` came from Box::into_raw in an earlier publish (or is null)
    let old = (!old.is_null()).then(|| unsafe { Box::from_raw(old) });
    let mut retired = RETIRED.lock().unwrap_or_else(|p| p.into_inner());
    *retired = old;
}

/// The note of one run; dropping it withdraws the note (the run wrote its last summary.json).
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

    /// Keep `text` ready to be written over `path` if the process aborts.
    pub fn prepare(&self, path: &Path, text: String) {
        if let Ok(path) = CString::new(path.as_os_str().as_bytes()) {
            publish(Some(Box::new(Note { path, bytes: text.into_bytes() })));
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
