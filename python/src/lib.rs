//! `stamp._stamp`: the native part of the Python package `stamp`, a thin shell around the
//! problem-file library [`stamp_problem`] (the same as the `stamp` program's). The Python layer
//! (`stamp/__init__.py`) checks the mesh arrays' shapes and types and documents the API.
//!
//! * a problem is read from a TOML file, or built from a dict: the dict is turned into the same
//!   TOML table ([`table`]) and goes through the same serde schema and checks;
//! * a solve runs with the GIL released; Ctrl-C sets the library's interrupt flag (its handler
//!   chains to Python's, [`stamp_problem::interrupt::install_chained`]), the solve stops after the
//!   Newton iteration in progress and Python's KeyboardInterrupt is raised;
//! * results: the library's outputs are written into a folder (a temporary one unless `out` is
//!   given) and the arrays are kept in memory ([`stamp_problem::kept`]).

mod result;
mod table;

use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use result::NativeResult;
use std::path::{Path, PathBuf};

create_exception!(stamp, StampError, PyValueError, "An error in a problem, its mesh or its solve, with the message `stamp run` prints (it names the key, the file and line, or the group).");

/// A library error as StampError, with the program's message.
pub(crate) fn to_py(e: stamp::StampError) -> PyErr {
    StampError::new_err(e.to_string())
}

/// A problem, read and checked (not yet built).
#[pyclass(frozen, name = "_Problem", module = "stamp._stamp")]
struct NativeProblem {
    problem: stamp_problem::Problem,
}

#[pymethods]
impl NativeProblem {
    /// The problem as TOML text (for a dict: the table it was turned into, which error messages
    /// point into).
    #[getter]
    fn toml(&self) -> String {
        self.problem.source.clone()
    }

    /// The path that names the problem in messages and output files.
    #[getter]
    fn path(&self) -> String {
        self.problem.path.display().to_string()
    }

    /// Build the problem and run `stamp check`'s checks: (summary text, warnings).
    fn check(&self, py: Python<'_>) -> PyResult<(String, Vec<String>)> {
        let p = &self.problem;
        py.detach(|| {
            let setup = stamp_problem::build::build(p)?;
            let report = stamp_problem::check::check(p, &setup)?;
            Ok((report.summary.to_string(), report.warnings.iter().map(|w| w.to_string()).collect()))
        })
        .map_err(to_py)
    }

    /// Build, check and solve; write the outputs into `out` (a temporary folder if None).
    #[pyo3(signature = (out=None, quiet=false))]
    fn solve(&self, py: Python<'_>, out: Option<PathBuf>, quiet: bool) -> PyResult<NativeResult> {
        let p = &self.problem;
        let (dir, temp) = match out {
            Some(o) => (o, None),
            None => {
                let t = tempfile::Builder::new().prefix("stamp-").tempdir().map_err(|e| to_py(stamp::StampError::io(&std::env::temp_dir(), e)))?;
                (t.path().to_path_buf(), Some(t))
            }
        };
        let flag = stamp_problem::interrupt::install_chained();
        stamp_problem::interrupt::clear();
        let opts = stamp_problem::solve::SolveOptions { quiet, keep: true, interrupt: flag, ..Default::default() };
        let outcome = py.detach(|| {
            let outcome = stamp_problem::solve_problem(p, &dir, &opts);
            let _ = stamp_problem::stdout::finish();
            outcome
        });
        let interrupted = stamp_problem::interrupt::received().is_some();
        stamp_problem::interrupt::clear();
        match outcome {
            Ok(outcome) => NativeResult::new(outcome, temp),
            Err(e @ stamp::StampError::Interrupted { .. }) => {
                // Python's own handler ran too (chained): what it raises comes first, a
                // KeyboardInterrupt with the library's message
                let by = if interrupted { " (Ctrl-C)" } else { "" };
                let message = format!("{e}{by}");
                match py.check_signals() {
                    Err(raised) if !raised.is_instance_of::<PyKeyboardInterrupt>(py) => Err(raised),
                    _ => Err(PyKeyboardInterrupt::new_err(message)),
                }
            }
            Err(e) => Err(to_py(e)),
        }
    }
}

/// Read a problem file.
#[pyfunction]
fn problem_from_toml(py: Python<'_>, path: PathBuf) -> PyResult<NativeProblem> {
    let problem = py.detach(|| stamp_problem::Problem::read(&path)).map_err(to_py)?;
    Ok(NativeProblem { problem })
}

/// A problem from a dict (without the mesh arrays) named `name`, with the mesh given as arrays if
/// `nodes` is given: `cells` (m, 3 or 4) and `groups` [(name, "nodes" | "segments" | "cells",
/// indices)], all int64 and checked for shape by the Python layer.
#[pyfunction]
#[pyo3(signature = (table, name, nodes=None, cells=None, groups=Vec::new()))]
fn problem_from_dict(
    table: &Bound<'_, PyDict>,
    name: PathBuf,
    nodes: Option<PyReadonlyArray2<'_, f64>>,
    cells: Option<PyReadonlyArray2<'_, i64>>,
    groups: Vec<(String, String, PyReadonlyArray1<'_, i64>)>,
) -> PyResult<NativeProblem> {
    let table = table::to_table(table)?;
    let mesh = match (nodes, cells) {
        (Some(nodes), Some(cells)) => Some(array_mesh(&nodes, &cells, &groups)?),
        (None, None) => None,
        _ => return Err(StampError::new_err("mesh: give both `nodes` and `cells`")),
    };
    let problem = stamp_problem::Problem::from_table(&name, table, mesh).map_err(to_py)?;
    Ok(NativeProblem { problem })
}

/// The arrays as the framework's array mesh.
fn array_mesh(nodes: &PyReadonlyArray2<'_, f64>, cells: &PyReadonlyArray2<'_, i64>, groups: &[(String, String, PyReadonlyArray1<'_, i64>)]) -> PyResult<stamp::io::GmshMesh> {
    let index = |v: i64, what: &str| usize::try_from(v).map_err(|_| StampError::new_err(format!("{what}: negative index {v} (indices are 0-based)")));
    let xy: Vec<[f64; 2]> = nodes.as_array().rows().into_iter().map(|r| [r[0], r[1]]).collect();
    let rows: Vec<Vec<usize>> = cells.as_array().rows().into_iter().map(|r| r.iter().map(|&v| index(v, "mesh.cells")).collect::<PyResult<Vec<_>>>()).collect::<PyResult<_>>()?;
    let mut list = Vec::with_capacity(groups.len());
    for (name, kind, values) in groups {
        let what = format!("mesh.groups.{name}.{kind}");
        let v: Vec<usize> = values.as_array().iter().map(|&i| index(i, &what)).collect::<PyResult<_>>()?;
        let items = match kind.as_str() {
            "nodes" => stamp::io::gmsh::GroupItems::Nodes(v),
            "cells" => stamp::io::gmsh::GroupItems::Cells(v),
            "segments" => stamp::io::gmsh::GroupItems::Segments(v.chunks_exact(2).map(|s| [s[0], s[1]]).collect()),
            k => return Err(StampError::new_err(format!("mesh.groups.{name}: unknown kind {k:?}"))),
        };
        list.push(stamp::io::gmsh::ArrayGroup { name: name.clone(), items });
    }
    stamp::io::mesh_from_arrays(Path::new("mesh"), &xy, &rows, &list).map_err(to_py)
}

#[pymodule]
fn _stamp(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("StampError", m.py().get_type::<StampError>())?;
    m.add_class::<NativeProblem>()?;
    m.add_class::<NativeResult>()?;
    m.add_function(wrap_pyfunction!(problem_from_toml, m)?)?;
    m.add_function(wrap_pyfunction!(problem_from_dict, m)?)?;
    Ok(())
}
