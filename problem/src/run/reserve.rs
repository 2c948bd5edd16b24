//! Room for the last word: a run keeps disk space allocated to a hidden file of its output folder
//! ([`RESERVE`]), at least twice the size of its summary.json, and gives it back when the final
//! summary.json cannot be written, so that a disk that filled up during the run still gets a
//! summary.json that tells how the run ended instead of one that says "running" for ever. The file
//! is removed when the run ends.

use crate::run::folder_lock::open_regular;
use stamp::{Result, StampError};
use std::fs::File;
use std::os::fd::AsRawFd;
use std::path::{Path, PathBuf};

/// The reserve's file name in the output folder.
pub const RESERVE: &str = ".stamp-reserve";

/// The smallest reserve, in bytes.
pub const MIN_BYTES: u64 = 64 * 1024;

/// Space held for summary.json.
pub struct Reserve {
    path: PathBuf,
    file: Option<File>,
    bytes: u64,
}

/// Allocate `bytes` to `file` (blocks, not a sparse length).
fn allocate(file: &File, bytes: u64) -> std::io::Result<()> {
    // SAFETY: posix_fallocate on an open descriptor of ours; it only reads its arguments
    let rc = unsafe { libc::posix_fallocate(file.as_raw_fd(), 0, bytes as libc::off_t) };
    match rc {
        0 => Ok(()),
        e => Err(std::io::Error::from_raw_os_error(e)),
    }
}

impl Reserve {
    /// Hold [`MIN_BYTES`] in `dir`; refused when the folder does not have that much room (a file
    /// system that cannot allocate ahead gets no reserve).
    pub fn create(dir: &Path) -> Result<Reserve> {
        let path = dir.join(RESERVE);
        crate::run::regular::refuse_non_regular(&path)?;
        let file = open_regular(&path, true).map_err(|e| StampError::io(&path, e))?;
        if let Err(e) = allocate(&file, MIN_BYTES) {
            drop(file);
            let _ = std::fs::remove_file(&path);
            // a file system that cannot allocate ahead: no reserve (only a full one is refused)
            if !matches!(e.raw_os_error(), Some(libc::ENOSPC) | Some(libc::EDQUOT)) {
                return Ok(Reserve { path, file: None, bytes: 0 });
            }
            let message = format!("cannot set aside {} KiB for the run's summary.json: {e}; free some space or choose another --out", MIN_BYTES / 1024);
            return Err(StampError::io(dir, std::io::Error::new(e.kind(), message)));
        }
        Ok(Reserve { path, file: Some(file), bytes: MIN_BYTES })
    }

    /// Grow the reserve to twice `summary_bytes` (if it is smaller); a failure is left for the end.
    pub fn cover(&mut self, summary_bytes: usize) {
        let want = (2 * summary_bytes as u64).max(MIN_BYTES);
        if let (Some(file), true) = (&self.file, want > self.bytes) {
            if allocate(file, want).is_ok() {
                self.bytes = want;
            }
        }
    }

    /// Give the space back (the reserve is removed); true if there was any.
    pub fn release(&mut self) -> bool {
        match self.file.take() {
            Some(file) => {
                drop(file);
                std::fs::remove_file(&self.path).is_ok()
            }
            None => false,
        }
    }
}

impl Drop for Reserve {
    fn drop(&mut self) {
        self.release();
    }
}
