//! Helpers shared by the `stamp run` tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The repository root (meshes/ lives there).
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// A fresh, empty temporary folder unique to this call: the process, a count of the calls, and
/// `name` (two tests running at once with the same name each get their own: the laminate's probe
/// runs of two tests once wrote into one folder and one test read the other's half-written run).
pub fn temp_dir(name: &str) -> PathBuf {
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let d = std::env::temp_dir().join(format!("stamp-test-{}-{call}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Write `text` to `dir`/`name` and return its path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// A run's summary.json, parsed.
pub fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

/// A shipped problem file (meshes/`shipped`) with some text replaced, written as `name`.toml to a
/// fresh folder with the mesh and STL files of meshes/ beside it.
pub fn variant(name: &str, shipped: &str, edits: &[(&str, &str)]) -> PathBuf {
    let dir = temp_dir(name);
    let mut text = std::fs::read_to_string(repo().join("meshes").join(shipped)).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{shipped} has no '{from}'");
        text = text.replacen(from, to, 1);
    }
    for entry in std::fs::read_dir(repo().join("meshes")).unwrap() {
        let path = entry.unwrap().path();
        if matches!(path.extension().and_then(|e| e.to_str()), Some("msh" | "stl")) {
            std::fs::copy(&path, dir.join(path.file_name().unwrap())).unwrap();
        }
    }
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// A cantilever strip (Table 1's first row): plane strain, clamped at x2 = 0, an end force F per
/// unit width at x2 = 100, no punch.
pub const CANTILEVER: &str = r#"title = "cantilever"
[mesh]
rectangle = { x = [0.0, 1.0], y = [0.0, 100.0], n = [1, 40] }

[plate]
thickness = 2.0
E = 2.0e4
nu = 0.3
kinematics = "linear"
plane_strain = true

[[boundary]]
group = "bottom"
fix = ["clamped"]

[[load]]
type = "line"
group = "top"
force = [0.0, 0.0, 0.05]
"#;
