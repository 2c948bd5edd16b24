//! A run never writes over its own input: a problem file, mesh, coarse mesh or STL die that lies in
//! the output folder (or in one of its `refined*/` folders) under a name stamp's outputs use
//! (summary.json, history.csv, *.vtu, *.pvd, pressure_/probe_/force_travel_ files, see
//! [`crate::run::out_dir::looks_like_output`]) would be overwritten, or removed by the next run: it is
//! refused before anything is written, naming the file and its key.

use crate::run::folder_lock::LOCK_FILE;
use crate::run::out_dir::{looks_like_output, MANIFEST};
use crate::schema::Problem;
use stamp::{Result, StampError};
use std::path::{Path, PathBuf};

/// The input files of `p`: (path, key naming it, where the key is in the problem file).
fn inputs(p: &Problem) -> Vec<(PathBuf, String, Option<std::ops::Range<usize>>)> {
    let mut out = vec![(p.path.clone(), "the problem file".to_string(), None)];
    let mesh = p.spec.mesh.get_ref();
    for (f, key) in [(&mesh.file, "mesh.file"), (&mesh.coarse_file, "mesh.coarse_file")] {
        if let Some(f) = f {
            out.push((p.dir().join(f.get_ref()), key.to_string(), Some(f.span())));
        }
    }
    for (i, punch) in p.spec.punch.iter().enumerate() {
        if let Some(f) = &punch.get_ref().file {
            out.push((p.dir().join(f.get_ref()), format!("punch[{i}].file"), Some(f.span())));
        }
    }
    out
}

/// Whether `folder` is `out` or one of its `refined`, `refined2`, ... folders.
fn is_output_folder(folder: &Path, out: &Path) -> bool {
    folder == out
        || (folder.parent() == Some(out)
            && folder.file_name().and_then(|n| n.to_str()).and_then(|n| n.strip_prefix("refined")).is_some_and(|rest| rest.chars().all(|c| c.is_ascii_digit())))
}

/// Err if an input file of `p` lies in the output folder `out_dir` (which exists) under a name
/// of stamp's outputs.
pub fn refuse_inputs_among_outputs(p: &Problem, out_dir: &Path) -> Result<()> {
    let Ok(out) = out_dir.canonicalize() else { return Ok(()) };
    for (path, key, span) in inputs(p) {
        let Ok(real) = path.canonicalize() else { continue };
        let (Some(folder), Some(name)) = (real.parent(), real.file_name().and_then(|n| n.to_str())) else { continue };
        if !(is_output_folder(folder, &out) && (looks_like_output(name) || name == MANIFEST || name == LOCK_FILE)) {
            continue;
        }
        let message = format!(
            "{} is in the output folder {} and named like one of stamp's outputs (summary.json, history.csv, *.vtu, *.pvd, pressure_*, probe_*, force_travel_*): \
             the run would write over it or remove it; rename or move it, or choose another --out",
            path.display(),
            out_dir.display()
        );
        return Err(match span {
            Some(span) => p.error_at(span, &key, message),
            None => StampError::Input { file: p.path.display().to_string(), message: format!("{key}: {message}") },
        });
    }
    Ok(())
}
