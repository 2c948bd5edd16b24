//! Helpers shared by the `stamp run` tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The repository root (meshes/ lives there).
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// A fresh, empty temporary folder unique to this test process and `name`.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("stamp-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
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
