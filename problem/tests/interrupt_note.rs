//! summary.json's notes (stamp_problem::abort_note): the "interrupted" note is written over
//! summary.json at the signal itself, so that a process killed right after (mpirun sends SIGKILL a
//! second after its SIGTERM) leaves a summary.json that says so; a summary.json written after the
//! signal is covered again at once; a withdrawn note writes nothing. A process of its own: the
//! signal is recorded for the whole process.

use stamp_problem::abort_note::{on_interrupt, AbortNote};

#[test]
fn the_interrupted_note_is_written_at_the_signal_and_after_every_later_write() {
    let dir = std::env::temp_dir().join(format!("stamp-interrupt-note-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("summary.json");
    let read = || std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, "running").unwrap();
    let note = AbortNote::new();
    note.prepare(&path, "failed".into(), |signal| format!("interrupted by {signal} after step 1"));
    assert_eq!(read(), "running", "nothing is written before a signal");
    on_interrupt(libc::SIGTERM);
    assert_eq!(read(), format!("interrupted by {} after step 1", libc::SIGTERM));
    // the step in progress converged and was written after the signal: covered again at once
    std::fs::write(&path, "running, step 2").unwrap();
    note.prepare(&path, "failed".into(), |signal| format!("interrupted by {signal} after step 2"));
    assert_eq!(read(), format!("interrupted by {} after step 2", libc::SIGTERM));
    // the final summary.json is the run's own
    note.withdraw();
    std::fs::write(&path, "interrupted, final").unwrap();
    on_interrupt(libc::SIGINT);
    assert_eq!(read(), "interrupted, final");
    let _ = std::fs::remove_dir_all(&dir);
}
