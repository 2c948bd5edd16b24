//! The files of its own that a run reads back from an output folder (the manifest, summary.json,
//! the lock) are read only if they are regular files: opening a FIFO would wait for a writer for
//! ever, a device could be anything. Such a file is refused with a message that names it.

use stamp::{Result, StampError};
use std::fs::Metadata;
use std::io::Read;
use std::os::unix::fs::FileTypeExt;
use std::path::Path;

/// What a file that is not a regular file is, in words ("a FIFO", "a folder", ...).
pub fn kind(meta: &Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        "a folder"
    } else if t.is_symlink() {
        "a symbolic link"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_block_device() || t.is_char_device() {
        "a device"
    } else if t.is_file() {
        "a regular file"
    } else {
        "not a regular file"
    }
}

/// Err if `path` exists and is not a regular file (a link is not followed): the message names the
/// file and what it is, and says what to do.
pub fn refuse_non_regular(path: &Path) -> Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) if !meta.is_file() => Err(not_regular(path, &meta)),
        _ => Ok(()),
    }
}

/// The error for `path`, which is not a regular file.
fn not_regular(path: &Path, meta: &Metadata) -> StampError {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let message = format!("cannot write {name} there: it is {}, not a regular file; remove it or choose another --out", kind(meta));
    StampError::io(path, std::io::Error::new(std::io::ErrorKind::InvalidInput, message))
}

/// The text of `path` if it is a regular file (not followed through a link, never waiting on a
/// FIFO); Ok(None) if there is no such file; Err if it is something else or cannot be read.
pub fn read_regular(path: &Path) -> Result<Option<String>> {
    use std::os::unix::fs::OpenOptionsExt;
    refuse_non_regular(path)?;
    let mut file = match std::fs::OpenOptions::new().read(true).custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK).open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(StampError::io(path, e)),
    };
    // checked again on the open file: it may have been replaced in between
    let meta = file.metadata().map_err(|e| StampError::io(path, e))?;
    if !meta.is_file() {
        return Err(not_regular(path, &meta));
    }
    let mut text = String::new();
    file.read_to_string(&mut text).map_err(|e| StampError::io(path, e))?;
    Ok(Some(text))
}
