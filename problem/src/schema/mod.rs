//! The problem file of `stamp run`: a TOML document read with serde, every table with
//! `deny_unknown_fields`. Range checks happen while deserialising, so that toml's error carries the
//! line and column of the offending value; checks that need the mesh (group names) use the spans kept
//! in [`Spanned`] values and report `file:line:column` themselves.
//!
//! See `meshes/paper-r100.toml` for a complete annotated example.

//!
//! A module per table of the file, each with its types and the checks serde cannot express:
//! [`mesh`], [`plate`], [`materials`], [`boundary`], [`loads`], [`punches`], [`solver`],
//! [`output`], [`units`]; the numbers they are made of in [`values`] (ranges in [`limits`]), and
//! the places in the file's text that errors point to in [`source`]. Every item is re-exported
//! here (`schema::PlateSpec`). The schema depends on nothing else of this crate: the modules that
//! build and run the model read it, not the reverse.

pub mod boundary;
pub mod limits;
pub mod loads;
pub mod materials;
pub mod mesh;
pub mod output;
pub mod plate;
pub mod punches;
pub mod solver;
pub mod source;
pub mod units;
pub mod values;

pub use boundary::*;
pub use loads::*;
pub use materials::*;
pub use mesh::*;
pub use output::*;
pub use plate::*;
pub use punches::*;
pub use solver::*;
pub use source::line_col_of;
pub use values::*;

use serde::Deserialize;
use source::{source_window, toml_message};
use stamp::{Result, StampError};
use std::path::{Path, PathBuf};
use toml::Spanned;

/// The whole problem file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProblemFile {
    /// Free text copied into summary.json.
    #[serde(default)]
    pub title: Option<String>,
    pub mesh: Spanned<MeshSpec>,
    pub plate: Spanned<PlateSpec>,
    /// Materials of the layers (`[[material]]`, see model/laminate_spec.rs).
    #[serde(default)]
    pub material: Vec<Spanned<MaterialSpec>>,
    #[serde(default)]
    pub boundary: Vec<Spanned<BoundarySpec>>,
    #[serde(default)]
    pub load: Vec<Spanned<LoadSpec>>,
    #[serde(default)]
    pub punch: Vec<Spanned<PunchSpec>>,
    #[serde(default)]
    pub solver: SolverSpec,
    #[serde(default)]
    pub output: OutputSpec,
    /// Unit names for labels (see [`units`]).
    #[serde(default)]
    pub units: Option<units::UnitsSpec>,
}

/// A parsed problem with its file name and source text (for line numbers).
#[derive(Debug)]
pub struct Problem {
    pub path: PathBuf,
    pub source: String,
    pub spec: ProblemFile,
    /// A mesh given in memory (the Python package's arrays, [`stamp::io::mesh_from_arrays`]) in
    /// place of `[mesh] file` or `rectangle`.
    pub given_mesh: Option<std::sync::Arc<stamp::io::GmshMesh>>,
    /// Built from a table in memory (the Python package's dict): errors name the keys alone, not
    /// lines of a TOML text the user never saw.
    pub from_table: bool,
}

/// A message of the problem file's text for a problem given as a table: without "line L,
/// column C: " and without the line shown under it, so that it names the key alone.
fn keys_only(message: &str) -> String {
    let first = message.split("\n  ").next().unwrap_or(message);
    let rest = first.strip_prefix("line ").and_then(|r| r.split_once(": ").filter(|(place, _)| place.contains("column")).map(|(_, rest)| rest));
    format!("in the table: {}", rest.unwrap_or(first))
}

impl Problem {
    /// Read and parse a problem file.
    /// Only a regular file of at most [`limits::MAX_FILE_BYTES`] is read: a FIFO, a device or a
    /// folder is refused from its metadata, before it is opened (opening a FIFO blocks).
    pub fn read(path: &Path) -> Result<Problem> {
        let meta = std::fs::metadata(path).map_err(|e| StampError::io(path, e))?;
        let input = |message: String| StampError::Input { file: path.display().to_string(), message };
        if !meta.is_file() {
            let kind = if meta.is_dir() { "a folder" } else { "not a regular file (a FIFO, socket or device)" };
            return Err(input(format!("is {kind}; a problem file must be a regular file")));
        }
        if meta.len() > limits::MAX_FILE_BYTES {
            return Err(input(format!("is {} bytes long; a problem file has at most {} bytes", meta.len(), limits::MAX_FILE_BYTES)));
        }
        let mut bytes = Vec::new();
        let file = std::fs::File::open(path).map_err(|e| StampError::io(path, e))?;
        // the file may have grown since: read no more than the limit allows
        std::io::Read::read_to_end(&mut std::io::Read::take(file, limits::MAX_FILE_BYTES + 1), &mut bytes).map_err(|e| StampError::io(path, e))?;
        if bytes.len() as u64 > limits::MAX_FILE_BYTES {
            return Err(input(format!("has more than {} bytes; a problem file has at most that many", limits::MAX_FILE_BYTES)));
        }
        let source = String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            let (line, _) = line_col_of(&String::from_utf8_lossy(&e.as_bytes()[..at]), at);
            input(format!("line {line}: not UTF-8 text (byte {at})"))
        })?;
        Problem::parse(path, source)
    }

    /// The problem of a table built in memory (the Python package's dict), with the same schema,
    /// checks and messages as a file: the table is written as TOML (the text errors point into,
    /// [`Problem::source`]) and parsed as a file named `path` would be, relative paths starting
    /// in the folder of `path`. `mesh`, if given, takes the place of `[mesh] file` or `rectangle`
    /// (the table's `mesh` then has neither).
    pub fn from_table(path: &Path, table: toml::Table, mesh: Option<stamp::io::GmshMesh>) -> Result<Problem> {
        let source = toml::to_string(&table).map_err(|e| StampError::Input { file: path.display().to_string(), message: format!("cannot be written as TOML: {e}") })?;
        Problem::parse_with_mesh(path, source, mesh.map(std::sync::Arc::new), true)
    }

    /// Parse problem text (`path` names it in errors and anchors relative paths).
    pub fn parse(path: &Path, source: String) -> Result<Problem> {
        Problem::parse_with_mesh(path, source, None, false)
    }

    fn parse_with_mesh(path: &Path, source: String, given_mesh: Option<std::sync::Arc<stamp::io::GmshMesh>>, from_table: bool) -> Result<Problem> {
        if source.trim_start().starts_with("$MeshFormat") {
            return Err(StampError::Input {
                file: path.display().to_string(),
                message: "this is a gmsh mesh, not a problem file: write a problem file (TOML) whose [mesh] file = names it".into(),
            });
        }
        let spec: ProblemFile = toml::from_str(&source).map_err(|e| {
            let message = toml_message(&source, &e);
            StampError::Input { file: path.display().to_string(), message: if from_table { keys_only(&message) } else { message } }
        })?;
        let p = Problem { path: path.to_path_buf(), source, spec, given_mesh, from_table };
        p.check()?;
        Ok(p)
    }

    /// "line L, column C" of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        line_col_of(&self.source, offset)
    }

    /// An input error located at `span`, naming `key`.
    pub fn error_at(&self, span: std::ops::Range<usize>, key: &str, message: impl std::fmt::Display) -> StampError {
        if self.from_table {
            return StampError::Input { file: self.path.display().to_string(), message: format!("in the table: {key}: {message}") };
        }
        let (line, col) = self.line_col(span.start);
        StampError::Input { file: self.path.display().to_string(), message: format!("line {line}, column {col}: {key}: {message}\n{}", source_window(&self.source, line, col)) }
    }

    /// An error in the expression `psi` at its 1-based character `column`: located in the file
    /// when the string is written without escapes (the column inside the string maps to the file),
    /// else at the string's start, naming the column inside it.
    pub fn psi_error(&self, psi: &Spanned<String>, column: usize, key: &str, message: &str) -> StampError {
        let span = psi.span();
        let raw = self.source.get(span.clone()).unwrap_or("");
        let text = psi.get_ref();
        let inner = raw.strip_prefix('"').and_then(|r| r.strip_suffix('"')).or_else(|| raw.strip_prefix('\'').and_then(|r| r.strip_suffix('\'')));
        if inner == Some(text.as_str()) && !text.contains('\n') {
            let offset: usize = text.chars().take(column - 1).map(char::len_utf8).sum();
            self.error_at(span.start + 1 + offset..span.end, key, message)
        } else {
            self.error_at(span, key, format!("column {column} of the expression: {message}"))
        }
    }

    /// The checks between keys that serde cannot express, table by table in the file's order (each
    /// in its table's module).
    fn check(&self) -> Result<()> {
        self.check_mesh()?;
        self.check_plate()?;
        self.check_boundary()?;
        self.check_loads()?;
        self.check_punches()?;
        self.check_solver()?;
        self.check_output()
    }

    /// The folder of the problem file (relative paths start there).
    pub fn dir(&self) -> PathBuf {
        self.path.parent().map(|p| if p.as_os_str().is_empty() { Path::new(".") } else { p }).unwrap_or(Path::new(".")).to_path_buf()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "[mesh]\nrectangle = { x = [0.0, 1.0], y = [0.0, 1.0], n = [2, 2] }\n\n[plate]\nthickness = 0.1\nE = 1.0\nnu = 0.3\n";

    fn table(text: &str) -> toml::Table {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn a_table_s_errors_name_its_keys_not_lines_of_its_toml() {
        let mut plate = toml::Table::new();
        plate.insert("nu".into(), toml::Value::Float(0.5));
        let mut t = toml::Table::new();
        t.insert("plate".into(), toml::Value::Table(plate));
        let e = Problem::from_table(Path::new("problem"), t.clone(), None).unwrap_err().to_string();
        assert!(e.contains("in the table: plate") && !e.contains("line ") && !e.contains(" | "), "{e}");
        // a type error of serde's, and an unknown key
        t["plate"].as_table_mut().unwrap().insert("nu".into(), toml::Value::String("x".into()));
        let e = Problem::from_table(Path::new("problem"), t.clone(), None).unwrap_err().to_string();
        assert!(e.contains("in the table: ") && !e.contains("column") && !e.contains(" | "), "{e}");
        // the same table as a file: its lines
        let e = Problem::parse(Path::new("p.toml"), "[plate]\nnu = 0.5\n".into()).unwrap_err().to_string();
        assert!(e.contains("line 2, column"), "{e}");
    }

    #[test]
    fn a_table_is_read_as_its_file_is() {
        let file = Problem::parse(Path::new("p.toml"), TEXT.into()).unwrap();
        let built = Problem::from_table(Path::new("p.toml"), table(TEXT), None).unwrap();
        assert_eq!(format!("{:?}", built.spec.plate.get_ref()), format!("{:?}", file.spec.plate.get_ref()));
        assert_eq!(format!("{:?}", built.spec.mesh.get_ref().rectangle), format!("{:?}", file.spec.mesh.get_ref().rectangle));
        // the same message, but for the line, which is the written table's
        let bad = TEXT.replace("nu = 0.3", "nu = 0.7");
        let from_file = Problem::parse(Path::new("p.toml"), bad.clone()).unwrap_err().to_string();
        let from_table = Problem::from_table(Path::new("p.toml"), table(&bad), None).unwrap_err().to_string();
        let what = |m: &str| m.split_once("plate.nu: ").map(|(_, w)| w.lines().next().unwrap().to_string()).unwrap();
        assert_eq!(what(&from_table), what(&from_file));
        assert_eq!(what(&from_file), "expected Poisson's ratio in (-1, 0.5), got 0.7");
    }

    #[test]
    fn a_given_mesh_takes_the_place_of_file_and_rectangle() {
        let nodes = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let mesh = || Some(stamp::io::mesh_from_arrays(Path::new("mesh"), &nodes, &[vec![0, 1, 2, 3]], &[]).unwrap());
        let given = TEXT.replace("rectangle = { x = [0.0, 1.0], y = [0.0, 1.0], n = [2, 2] }\n", "");
        let p = Problem::from_table(Path::new("p"), table(&given), mesh()).unwrap();
        assert_eq!(p.given_mesh.as_ref().unwrap().mesh.num_cells(), 1);
        let both = Problem::from_table(Path::new("p"), table(TEXT), mesh()).unwrap_err().to_string();
        assert!(both.contains("mesh: give the mesh as arrays (`nodes`, `cells`) or as `file` or `rectangle`, not both"), "{both}");
        let coarse = format!("{given}\n[solver]\npredictor = \"coarse\"\n");
        let e = Problem::from_table(Path::new("p"), table(&coarse), mesh()).unwrap_err().to_string();
        assert!(e.contains("solver.predictor: \"coarse\" needs a coarse mesh"), "{e}");
        // without the mesh the table is a file without a mesh
        let e = Problem::from_table(Path::new("p"), table(&given), None).unwrap_err().to_string();
        assert!(e.contains("give exactly one of `file` (a gmsh .msh) and `rectangle`"), "{e}");
    }
}
