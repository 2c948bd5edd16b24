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

/// A CSV file of numbers (history.csv, a probe's): its header and its rows.
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(|s| s.to_string()).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap_or_else(|_| panic!("{}: {v:?}", path.display()))).collect()).collect();
    (header, rows)
}

/// A run's history.csv: its header and its rows, each as long as the header.
pub fn history(out: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let (header, rows) = read_csv(&out.join("history.csv"));
    assert!(rows.iter().all(|r| r.len() == header.len()), "history.csv: a row's length is not the header's");
    (header, rows)
}

/// The index of the column `name`.
pub fn col(header: &[String], name: &str) -> usize {
    header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

/// The values of the column `name`.
pub fn column(header: &[String], rows: &[Vec<f64>], name: &str) -> Vec<f64> {
    let c = col(header, name);
    rows.iter().map(|r| r[c]).collect()
}

/// `stamp run -q` on the problem `text` (written as p.toml into a fresh folder named after
/// `name`); the run must succeed. Returns its output folder.
pub fn run_text(name: &str, text: &str) -> PathBuf {
    let dir = temp_dir(name);
    let file = write(&dir, "p.toml", text);
    let out = dir.join("out");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_stamp")).args(["run", "-q", "--out", out.to_str().unwrap()]).arg(&file).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

/// The error of building the problem `text`, written as `<name>.toml` into a fresh folder named
/// `<folder>-<name>`: the problem must be refused, and the error must name the file.
pub fn build_error(folder: &str, name: &str, text: &str) -> String {
    use stamp_cli::run::{build::build, Problem};
    let dir = temp_dir(&format!("{folder}-{name}"));
    let path = write(&dir, &format!("{name}.toml"), text);
    let err = match Problem::read(&path).and_then(|p| build(&p).map(|_| ())) {
        Ok(()) => panic!("{name}: the problem was accepted:\n{text}"),
        Err(e) => e.to_string(),
    };
    assert!(err.contains(&format!("{name}.toml")), "{name}: the error does not name the file: {err}");
    err
}
