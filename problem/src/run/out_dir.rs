//! A run owns its output folder: before writing, `stamp run` removes the files the previous run
//! wrote there, and only those, so that a 2-step run after a 10-step run does not leave the older
//! steps' .vtu and .csv files beside its own. Other files in the folder are left alone.
//!
//! How the files are known: the manifest [`MANIFEST`] (JSON) in the folder. When a run claims the
//! folder ([`RunFolder::claim`]) it removes the files the manifest lists as `written`, then lists
//! what is left (with modification times) and records it as `before` with `status = "running"`.
//! When the run ends (the [`RunFolder`] is dropped, whatever the outcome) the files that are new or
//! were rewritten since the claim are the run's: they become the manifest's `written` list with
//! `status = "complete"`.
//!
//! A run that was killed leaves `status = "running"`: the next claim then removes only the files
//! that are not in `before` *and* are named like stamp's outputs (summary.json, *.vtu, *.pvd,
//! pressure_*, probe_*, force_travel_* .csv/.png/.svg, history.csv). A folder written before manifests existed (summary.json without a
//! manifest) loses what that summary.json names: summary.json, the steps' .vtu and .csv files,
//! the .pvd and the punches' pressure plots.
//!
//! A claim first locks the folder ([`FolderLock`]: a second run is refused while the first lives),
//! refuses a manifest or summary.json that is not a regular file ([`crate::run::regular`]), and
//! removes the temporary files (`.NAME.tmp-PID-N`) a killed run left in the middle of a write.

use crate::run::folder_lock::{FolderLock, LOCK_FILE};
use crate::run::regular::{read_regular, refuse_non_regular};
use serde::{Deserialize, Serialize};
use stamp::io::write_string_atomically;
use stamp::{Result, StampError};
use std::collections::BTreeMap;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// The manifest's file name.
pub const MANIFEST: &str = ".stamp-run";

#[derive(Debug, Serialize, Deserialize, Default)]
struct Manifest {
    /// "running" from the claim, "complete" when the run ended.
    status: String,
    /// Files the run wrote (complete runs).
    #[serde(default)]
    written: Vec<String>,
    /// Files in the folder when the run started (running runs).
    #[serde(default)]
    before: Vec<String>,
}

/// An output folder claimed by a run; dropping it records the files the run wrote.
pub struct RunFolder {
    dir: PathBuf,
    /// Regular files present after the claim, with their modification times.
    before: BTreeMap<OsString, Option<SystemTime>>,
    /// Files the claim removed (the previous run's).
    pub removed: Vec<String>,
    /// No other run writes into the folder while this one holds it.
    _lock: FolderLock,
}

/// Regular files of `dir` (not the manifest) with their modification times.
fn listing(dir: &Path) -> Result<BTreeMap<OsString, Option<SystemTime>>> {
    let mut out = BTreeMap::new();
    for entry in std::fs::read_dir(dir).map_err(|e| StampError::io(dir, e))? {
        let entry = entry.map_err(|e| StampError::io(dir, e))?;
        let Ok(meta) = entry.metadata() else { continue };
        if meta.is_file() && entry.file_name() != MANIFEST && entry.file_name() != LOCK_FILE && entry.file_name() != crate::run::reserve::RESERVE {
            out.insert(entry.file_name(), meta.modified().ok());
        }
    }
    Ok(out)
}

/// A bare file name (no path separators, not "." or ".."): the only names the manifest may remove.
fn plain_name(name: &str) -> bool {
    !name.is_empty() && name != "." && name != ".." && !name.contains('/') && !name.contains('\\') && name != MANIFEST && name != LOCK_FILE
}

/// Named like one of stamp's outputs.
pub fn looks_like_output(name: &str) -> bool {
    name == "summary.json"
        || name.ends_with(".vtu")
        || name.ends_with(".pvd")
        || name == "history.csv"
        || ((name.starts_with("pressure_") || name.starts_with("probe_") || name.starts_with("force_travel_"))
            && (name.ends_with(".csv") || name.ends_with(".png") || name.ends_with(".svg")))
}

/// The files a summary.json written without a manifest names.
fn legacy_outputs(dir: &Path) -> Result<Vec<String>> {
    let Some(text) = read_regular(&dir.join("summary.json"))? else { return Ok(Vec::new()) };
    let Ok(s) = serde_json::from_str::<serde_json::Value>(&text) else { return Ok(Vec::new()) };
    if !(s["steps"].is_array() && s["problem"].is_string()) {
        return Ok(Vec::new());
    }
    let mut names = vec!["summary.json".to_string()];
    for step in s["steps"].as_array().unwrap() {
        if let Some(v) = step["vtu"].as_str() {
            names.push(v.to_string());
        }
        for c in step["csv"].as_array().into_iter().flatten() {
            if let Some(c) = c.as_str() {
                names.push(c.to_string());
            }
        }
    }
    if let Some(stem) = Path::new(s["problem"].as_str().unwrap()).file_stem() {
        names.push(format!("{}.pvd", stem.to_string_lossy()));
    }
    for p in s["punches"].as_array().into_iter().flatten() {
        if let Some(n) = p["name"].as_str() {
            names.push(format!("pressure_{n}.png"));
            names.push(format!("pressure_{n}.svg"));
        }
    }
    Ok(names)
}

impl RunFolder {
    /// Create `dir` if needed, lock it (refused while another run holds it, see
    /// [`FolderLock`]), remove the previous run's files and mark the folder as in use.
    pub fn claim(dir: &Path) -> Result<RunFolder> {
        std::fs::create_dir_all(dir).map_err(|e| StampError::io(dir, e))?;
        let lock = FolderLock::acquire(dir)?;
        // the files of its own a run reads back or replaces: never a FIFO or a device
        for name in [MANIFEST, "summary.json"] {
            refuse_non_regular(&dir.join(name))?;
        }
        let mut removed = remove_previous_outputs(dir, true)?;
        removed.extend(remove_temporaries(dir)?);
        removed.extend(remove_refined_runs(dir)?);
        let before = listing(dir)?;
        let manifest = Manifest { status: "running".into(), written: Vec::new(), before: before.keys().filter_map(|k| k.to_str().map(String::from)).collect() };
        write_manifest(dir, &manifest)?;
        Ok(RunFolder { dir: dir.to_path_buf(), before, removed, _lock: lock })
    }

    /// The files written since the claim: new ones, and old ones rewritten.
    pub fn written(&self) -> Result<Vec<String>> {
        let now = listing(&self.dir)?;
        Ok(now
            .iter()
            .filter(|(k, t)| match self.before.get(*k) {
                None => true,
                Some(t0) => t0 != *t,
            })
            .filter_map(|(k, _)| k.to_str().map(String::from))
            .collect())
    }

    /// Record the files this run wrote (also done on drop).
    pub fn finish(&self) -> Result<()> {
        let written = self.written()?;
        write_manifest(&self.dir, &Manifest { status: "complete".into(), written, before: Vec::new() })
    }
}

/// Copy the files of a finished run (`files`, as [`super::RunOutcome::files`] lists them) into
/// `dir`, claimed as a run would claim it: the previous run's files there are removed first and
/// the manifest then lists these. Each file appears whole or not at all. Returns the new paths.
///
/// Into the folder the files already lie in (the same canonical path) nothing is copied and
/// nothing removed: the files' paths are returned as they are (claiming the folder would remove
/// the very files to copy). A run whose files lie partly in `dir` or below it (`--refine`'s
/// `refined/`) and partly elsewhere is refused.
pub fn copy_run(files: &[PathBuf], dir: &Path) -> Result<Vec<PathBuf>> {
    if let Ok(target) = dir.canonicalize() {
        let canonical = |f: &Path| f.canonicalize().map_err(|e| StampError::io(f, e));
        let mut inside = 0;
        for f in files {
            let c = canonical(f)?;
            if c.parent() == Some(target.as_path()) {
                inside += 1;
            } else if c.starts_with(&target) {
                inside = usize::MAX;
                break;
            }
        }
        if inside == files.len() && !files.is_empty() {
            return Ok(files.to_vec());
        }
        if inside > 0 {
            return Err(StampError::io(dir, std::io::Error::other("the run's files lie partly in this folder (or below it) and partly elsewhere: writing them into it would remove some of them first; choose another folder")));
        }
    }
    let folder = RunFolder::claim(dir)?;
    let mut copied = Vec::with_capacity(files.len());
    for from in files {
        let Some(name) = from.file_name() else { continue };
        let bytes = std::fs::read(from).map_err(|e| StampError::io(from, e))?;
        let to = dir.join(name);
        stamp::io::write_atomically(&to, |w| w.write_all(&bytes))?;
        copied.push(to);
    }
    folder.finish()?;
    Ok(copied)
}

/// Removes the files the previous run wrote in `dir` (see the module notes; `legacy`: also a
/// folder written before manifests existed) and returns their names.
fn remove_previous_outputs(dir: &Path, legacy: bool) -> Result<Vec<String>> {
    let previous: Vec<String> = match read_regular(&dir.join(MANIFEST))? {
        Some(text) => match serde_json::from_str::<Manifest>(&text) {
            Ok(m) if m.status == "complete" => m.written,
            Ok(m) => {
                // killed mid-run: stamp-named files that were not there before it
                let now = listing(dir)?;
                now.keys().filter_map(|k| k.to_str()).filter(|k| !m.before.iter().any(|b| b == k) && looks_like_output(k)).map(|k| k.to_string()).collect()
            }
            Err(_) => Vec::new(),
        },
        None if legacy => legacy_outputs(dir)?,
        None => Vec::new(),
    };
    let mut removed = Vec::new();
    for name in previous.iter().filter(|n| plain_name(n)) {
        let path = dir.join(name);
        if std::fs::symlink_metadata(&path).map(|m| m.is_file()).unwrap_or(false) {
            std::fs::remove_file(&path).map_err(|e| StampError::io(&path, e))?;
            removed.push(name.clone());
        }
    }
    Ok(removed)
}

/// Whether `name` is that of a temporary file of [`stamp::io::write_atomically`]:
/// `.<name>.tmp-<pid>-<n>`.
fn is_temporary(name: &str) -> bool {
    let Some(rest) = name.strip_prefix('.') else { return false };
    let Some((_, tail)) = rest.rsplit_once(".tmp-") else { return false };
    let mut parts = tail.split('-');
    let digits = |p: Option<&str>| p.is_some_and(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()));
    digits(parts.next()) && digits(parts.next()) && parts.next().is_none()
}

/// Removes the temporary files a killed run left in `dir` (regular files named like those of
/// [`stamp::io::write_atomically`]): with the folder locked, no other run is writing them.
fn remove_temporaries(dir: &Path) -> Result<Vec<String>> {
    let mut removed = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| StampError::io(dir, e))? {
        let entry = entry.map_err(|e| StampError::io(dir, e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let regular = entry.file_type().map(|t| t.is_file()).unwrap_or(false);
        if regular && is_temporary(&name) {
            std::fs::remove_file(entry.path()).map_err(|e| StampError::io(entry.path(), e))?;
            removed.push(name);
        }
    }
    Ok(removed)
}

/// Removes the finer runs a `stamp run --refine` left in `dir` (`refined/`, `refined2/`, ...:
/// sub-folders with a manifest): their files, their manifest, and the folder when nothing else is
/// in it. A later run without `--refine` (or with fewer levels) would otherwise leave results of
/// another run beside its own. Returns the removed files as `refined/name`.
fn remove_refined_runs(dir: &Path) -> Result<Vec<String>> {
    let mut removed = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| StampError::io(dir, e))? {
        let entry = entry.map_err(|e| StampError::io(dir, e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let is_refined_name = name.strip_prefix("refined").is_some_and(|rest| rest.chars().all(|c| c.is_ascii_digit()));
        let sub = entry.path();
        // a real folder (not a link) that a run claimed
        let is_dir = std::fs::symlink_metadata(&sub).map(|m| m.is_dir()).unwrap_or(false);
        if !is_refined_name || !is_dir || !sub.join(MANIFEST).is_file() {
            continue;
        }
        // refused while a run writes into it
        let lock = FolderLock::acquire(&sub)?;
        removed.extend(remove_previous_outputs(&sub, false)?.into_iter().chain(remove_temporaries(&sub)?).map(|f| format!("{name}/{f}")));
        std::fs::remove_file(sub.join(MANIFEST)).map_err(|e| StampError::io(&sub.join(MANIFEST), e))?;
        let _ = std::fs::remove_file(sub.join(LOCK_FILE));
        drop(lock);
        // only if empty: files the user put there stay, and so does the folder
        let _ = std::fs::remove_dir(&sub);
    }
    Ok(removed)
}

impl Drop for RunFolder {
    fn drop(&mut self) {
        if let Err(e) = self.finish() {
            eprintln!("warning: cannot record the files of this run in {}: {e}", stamp::show_path(&self.dir.join(MANIFEST)));
        }
    }
}

fn write_manifest(dir: &Path, m: &Manifest) -> Result<()> {
    let text = serde_json::to_string_pretty(m).map_err(|e| StampError::Problem(format!("cannot encode {MANIFEST}: {e}")))?;
    write_string_atomically(&dir.join(MANIFEST), &(text + "\n"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("stamp-out-dir-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    }

    #[test]
    fn a_run_removes_the_previous_runs_files_only() {
        let d = dir("runs");
        std::fs::write(d.join("notes.txt"), "mine").unwrap();
        {
            let _f = RunFolder::claim(&d).unwrap();
            for k in 1..=3 {
                std::fs::write(d.join(format!("a_{k:04}.vtu")), "x").unwrap();
            }
        }
        assert_eq!(names(&d), [".stamp-lock", ".stamp-run", "a_0001.vtu", "a_0002.vtu", "a_0003.vtu", "notes.txt"]);
        // a file the user adds afterwards, even named like an output, survives the next run
        std::fs::write(d.join("b_0009.vtu"), "mine").unwrap();
        {
            let f = RunFolder::claim(&d).unwrap();
            assert_eq!(f.removed, ["a_0001.vtu", "a_0002.vtu", "a_0003.vtu"]);
            std::fs::write(d.join("a_0001.vtu"), "y").unwrap();
        }
        assert_eq!(names(&d), [".stamp-lock", ".stamp-run", "a_0001.vtu", "b_0009.vtu", "notes.txt"]);
    }

    #[test]
    fn a_run_removes_the_finer_runs_of_a_previous_refine() {
        let d = dir("refined");
        // a --refine 2 run: the top folder and two finer runs, each claimed
        {
            let _top = RunFolder::claim(&d).unwrap();
            std::fs::write(d.join("summary.json"), "{}").unwrap();
            for sub in ["refined", "refined2"] {
                let f = RunFolder::claim(&d.join(sub)).unwrap();
                std::fs::write(d.join(sub).join("summary.json"), "{}").unwrap();
                std::fs::write(d.join(sub).join("p_0001.vtu"), "x").unwrap();
                f.finish().unwrap();
            }
        }
        // the user's own notes in one of them, and a folder of theirs named alike without a manifest
        std::fs::write(d.join("refined2").join("notes.txt"), "mine").unwrap();
        std::fs::create_dir_all(d.join("refined3")).unwrap();
        std::fs::write(d.join("refined3").join("p_0001.vtu"), "mine").unwrap();
        let f = RunFolder::claim(&d).unwrap();
        assert!(!d.join("refined").exists(), "refined/ left: {:?}", names(&d));
        assert_eq!(names(&d.join("refined2")), vec!["notes.txt"]);
        assert_eq!(names(&d.join("refined3")), vec!["p_0001.vtu"]);
        assert!(f.removed.contains(&"refined/p_0001.vtu".to_string()) && f.removed.contains(&"refined2/summary.json".to_string()), "{:?}", f.removed);
    }

    #[test]
    fn a_killed_run_loses_its_stamp_named_files() {
        let d = dir("killed");
        std::fs::write(d.join("notes.txt"), "mine").unwrap();
        let f = RunFolder::claim(&d).unwrap();
        std::fs::write(d.join("a_0001.vtu"), "x").unwrap();
        std::fs::write(d.join("summary.json"), "{}").unwrap();
        std::fs::write(d.join("later.txt"), "mine").unwrap();
        std::mem::forget(f); // as if killed: no final manifest
        let f = RunFolder::claim(&d).unwrap();
        assert_eq!(f.removed, ["a_0001.vtu", "summary.json"]);
        drop(f);
        assert_eq!(names(&d), [".stamp-lock", ".stamp-run", "later.txt", "notes.txt"]);
    }

    #[test]
    fn copying_a_run_into_its_own_folder_keeps_its_files() {
        let d = dir("copy-self");
        let files: Vec<PathBuf> = {
            let _f = RunFolder::claim(&d).unwrap();
            ["summary.json", "p_0001.vtu"].iter().map(|n| { std::fs::write(d.join(n), *n).unwrap(); d.join(n) }).collect()
        };
        // the same folder, named otherwise: nothing removed, nothing copied
        let same = d.join(".").join("..").join(d.file_name().unwrap());
        assert_eq!(copy_run(&files, &same).unwrap(), files);
        assert_eq!(names(&d), [".stamp-lock", ".stamp-run", "p_0001.vtu", "summary.json"]);
        assert_eq!(std::fs::read_to_string(d.join("p_0001.vtu")).unwrap(), "p_0001.vtu");
        // another folder: copied, the originals stay
        let other = d.join("copy");
        let copied = copy_run(&files, &other).unwrap();
        assert_eq!(copied, [other.join("summary.json"), other.join("p_0001.vtu")]);
        assert_eq!(std::fs::read_to_string(other.join("summary.json")).unwrap(), "summary.json");
        assert!(d.join("summary.json").exists());
        // files partly in the folder: refused, nothing removed
        let mixed = vec![files[0].clone(), other.join("p_0001.vtu")];
        assert!(copy_run(&mixed, &d).unwrap_err().to_string().contains("partly in this folder"));
        assert!(d.join("summary.json").exists() && d.join("p_0001.vtu").exists());
    }

    #[test]
    fn temporary_files_are_told_from_the_users() {
        for name in [".summary.json.tmp-123-0", ".p_0001.vtu.tmp-4-17", ".a.tmp-b.tmp-1-2"] {
            assert!(is_temporary(name), "{name}");
        }
        for name in ["summary.json.tmp-123-0", ".x.tmp-1", ".x.tmp-1-2-3", ".x.tmp-a-2", ".x.tmp--2", "notes.txt"] {
            assert!(!is_temporary(name), "{name}");
        }
    }

    #[test]
    fn a_folder_from_before_manifests_loses_what_its_summary_names() {
        let d = dir("legacy");
        let summary = r#"{"problem": "x/p.toml", "punches": [{"name": "s"}], "steps": [{"vtu": "p_0001.vtu", "csv": ["pressure_s_0001.csv"]}]}"#;
        for f in ["p_0001.vtu", "pressure_s_0001.csv", "p.pvd", "pressure_s.png", "p_0002.vtu", "notes.txt"] {
            std::fs::write(d.join(f), "x").unwrap();
        }
        std::fs::write(d.join("summary.json"), summary).unwrap();
        drop(RunFolder::claim(&d).unwrap());
        assert_eq!(names(&d), [".stamp-lock", ".stamp-run", "notes.txt", "p_0002.vtu"]);
    }
}
