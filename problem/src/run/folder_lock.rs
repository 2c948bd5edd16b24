//! One run at a time in an output folder: a run holds an advisory lock (`flock`, through
//! [`std::fs::File::try_lock`]) on the folder's [`LOCK_FILE`], which holds its pid. A second run
//! into the same folder while the first lives is refused with the first's pid; the lock dies with
//! its process (ended normally, by a signal or by kill -9), so a stale lock file is simply taken
//! over. The file itself stays in the folder (removing it would let two runs lock two different
//! files of the same name).
//!
//! Within one process the lock is shared by the thread that took it, and only by it: `stamp run
//! --refine` holds its folder for the whole run while the run on the problem's mesh claims the same
//! folder from the same thread ([`FolderLock::acquire`] again). Another thread of the process (two
//! Python threads solving into one folder) is refused, as another process is.

use stamp::{Result, StampError};
use std::collections::HashMap;
use std::fs::File;
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock, Weak};
use std::thread::ThreadId;

/// The lock file's name in the output folder.
pub const LOCK_FILE: &str = ".stamp-lock";

/// A held lock on an output folder; released when the last holder in this process drops it.
#[derive(Clone)]
pub struct FolderLock {
    _file: Arc<File>,
}

/// The folders this process holds, by canonical path: the lock and the thread that took it.
fn held() -> &'static Mutex<HashMap<PathBuf, (ThreadId, Weak<File>)>> {
    static HELD: OnceLock<Mutex<HashMap<PathBuf, (ThreadId, Weak<File>)>>> = OnceLock::new();
    HELD.get_or_init(|| Mutex::new(HashMap::new()))
}

/// Open `path` for reading and writing without following a link and without blocking on a FIFO;
/// refuse anything but a regular file (checked on the open file itself).
pub fn open_regular(path: &Path, create: bool) -> std::io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    let file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(create)
        .truncate(false)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(std::io::Error::other(format!("is not a regular file ({})", crate::run::regular::kind(&meta))));
    }
    Ok(file)
}

impl FolderLock {
    /// Lock the folder `dir` (which must exist) for this thread, or say which process holds it
    /// (this one, from another thread: another run of this process).
    pub fn acquire(dir: &Path) -> Result<FolderLock> {
        let key = dir.canonicalize().map_err(|e| StampError::io(dir, e))?;
        let mut map = held().lock().unwrap_or_else(|p| p.into_inner());
        if let Some((thread, file)) = map.get(&key).and_then(|(t, w)| Some((*t, w.upgrade()?))) {
            if thread == std::thread::current().id() {
                return Ok(FolderLock { _file: file });
            }
            let message = format!("the folder is in use: another run of this process (process {}, another thread) is writing into it; wait for it to end or choose another folder", std::process::id());
            return Err(StampError::io(dir, std::io::Error::new(std::io::ErrorKind::WouldBlock, message)));
        }
        let path = dir.join(LOCK_FILE);
        crate::run::regular::refuse_non_regular(&path)?;
        let mut file = open_regular(&path, true).map_err(|e| StampError::io(&path, e))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let mut text = String::new();
                let _ = file.read_to_string(&mut text);
                let pid = text.trim();
                let who = if pid.is_empty() || !pid.chars().all(|c| c.is_ascii_digit()) { "another process".to_string() } else { format!("process {pid}") };
                let message = format!("the folder is in use: another stamp run ({who}) is writing into it; wait for it to end, stop it, or choose another --out");
                return Err(StampError::io(dir, std::io::Error::new(std::io::ErrorKind::WouldBlock, message)));
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(StampError::io(&path, e)),
        }
        // ours now: say who holds it (a stale pid from a killed run is overwritten)
        let pid = format!("{}\n", std::process::id());
        let _ = file.set_len(0).and_then(|()| file.rewind()).and_then(|()| file.write_all(pid.as_bytes()));
        let file = Arc::new(file);
        map.insert(key, (std::thread::current().id(), Arc::downgrade(&file)));
        Ok(FolderLock { _file: file })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_thread_that_holds_a_folder_shares_it_and_another_thread_is_refused() {
        let d = std::env::temp_dir().join(format!("stamp-folder-lock-{}-threads", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let first = FolderLock::acquire(&d).unwrap();
        // the same thread again (stamp run --refine claims its folder twice)
        let again = FolderLock::acquire(&d).unwrap();
        let other = std::thread::scope(|s| s.spawn(|| FolderLock::acquire(&d).map(drop)).join().unwrap());
        let e = other.unwrap_err().to_string();
        assert!(e.contains("in use") && e.contains("another run of this process") && e.contains(&*d.to_string_lossy()), "{e}");
        drop((first, again));
        // released: another thread takes it
        std::thread::scope(|s| s.spawn(|| FolderLock::acquire(&d).map(drop)).join().unwrap()).unwrap();
        let _ = std::fs::remove_dir_all(&d);
    }
}
