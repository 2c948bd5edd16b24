//! Atomic file output: a reader (ParaView watching a directory, a crash in the middle of a write)
//! sees either the old file or the complete new one, never a partial file.
//!
//! The content goes to a temporary file in the same directory (so that the final rename stays on
//! one file system), is flushed and fsynced, then renamed over the target. If writing fails, the
//! temporary file is removed and any old file is left untouched.

use crate::error::{Result, StampError};
use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Characters of the target's name kept in the temporary name: a target whose name is close to
/// the file system's limit (255 bytes) must not fail because its temporary name is longer.
const TEMP_NAME_CHARS: usize = 64;

/// A temporary path next to `path`: ".<name>.tmp-<pid>-<n>" (hidden, unique within the process),
/// with at most [`TEMP_NAME_CHARS`] characters of the name.
fn temp_path(path: &Path) -> io::Result<PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the output path has no file name"))?;
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let short: String = name.to_string_lossy().chars().take(TEMP_NAME_CHARS).collect();
    let tmp = format!(".{short}.tmp-{}-{}", std::process::id(), n);
    Ok(path.with_file_name(tmp))
}

fn create_new(tmp: &Path) -> io::Result<File> {
    OpenOptions::new().write(true).create_new(true).open(tmp)
}

/// Writes `path` atomically: `write` gets a buffered writer to a temporary file in the same
/// directory; on success the file is flushed, fsynced and renamed to `path`. On any error the
/// temporary file is removed, an existing `path` is left as it was, and the error names `path`.
pub fn write_atomically<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let tmp = temp_path(path).map_err(|e| StampError::io(path, e))?;
    let file = create_new(&tmp).map_err(|e| StampError::io(path, e))?;
    // Removes the temporary file on every way out (error or panic in `write`) but success.
    let mut guard = TempGuard(Some(tmp.clone()));
    let mut w = BufWriter::new(file);
    let result = write(&mut w)
        .and_then(|()| w.into_inner().map_err(|e| e.into_error()))
        .and_then(|file| file.sync_all())
        .and_then(|()| std::fs::rename(&tmp, path));
    result.map_err(|e| StampError::io(path, e))?;
    guard.0 = None;
    // Make the rename itself durable (best effort: not every platform can open a directory).
    if let Some(dir) = path.parent() {
        let dir = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
    Ok(())
}

struct TempGuard(Option<PathBuf>);

impl Drop for TempGuard {
    fn drop(&mut self) {
        if let Some(p) = self.0.take() {
            let _ = std::fs::remove_file(p);
        }
    }
}

/// Writes a string to `path` atomically (see [`write_atomically`]).
pub fn write_string_atomically(path: &Path, contents: &str) -> Result<()> {
    write_atomically(path, |w| w.write_all(contents.as_bytes()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_name_near_the_file_system_limit_is_written() {
        let dir = std::env::temp_dir().join(format!("stamp-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // 250 bytes: the file fits (255 at most); ".<name>.tmp-<pid>-<n>" would not
        let path = dir.join("n".repeat(246) + ".csv");
        write_string_atomically(&path, "x").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "x");
        // a name beyond the limit fails with an error that names it, and leaves nothing behind
        let long = dir.join("n".repeat(300));
        let e = write_string_atomically(&long, "x").unwrap_err().to_string();
        assert!(e.contains("nnnn"), "{e}");
        let left: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(left.len(), 1, "{left:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
