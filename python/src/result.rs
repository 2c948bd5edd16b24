//! The results of a solve: the library's [`stamp_problem::RunOutcome`] with its arrays kept in
//! memory, handed to Python as numpy arrays; the written files stay in the run's folder (removed
//! with the result when it was a temporary one) and [`NativeResult::write`] copies them.

use crate::to_py;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::exceptions::{PyIndexError, PyKeyError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use stamp_problem::kept::{Kept, KeptStep};
use std::path::{Path, PathBuf};
use std::time::SystemTime;

#[pyclass(frozen, name = "_Result", module = "stamp._stamp")]
pub struct NativeResult {
    outcome: stamp_problem::RunOutcome,
    kept: Kept,
    summary: String,
    /// The temporary output folder, removed when the result is.
    _temp: Option<tempfile::TempDir>,
    /// Size and modification time of each of `outcome.files` after the solve: [`Self::write`]
    /// refuses files another run has since removed or rewritten.
    stamps: Vec<Option<(u64, Option<SystemTime>)>>,
}

fn stamp_of(path: &Path) -> Option<(u64, Option<SystemTime>)> {
    std::fs::metadata(path).ok().map(|m| (m.len(), m.modified().ok()))
}

impl NativeResult {
    pub fn new(mut outcome: stamp_problem::RunOutcome, temp: Option<tempfile::TempDir>) -> PyResult<NativeResult> {
        let summary = std::fs::read_to_string(&outcome.summary).map_err(|e| to_py(stamp::StampError::io(&outcome.summary, e)))?;
        let kept = outcome.kept.take().unwrap_or_default();
        let stamps = outcome.files.iter().map(|f| stamp_of(f)).collect();
        Ok(NativeResult { outcome, kept, summary, _temp: temp, stamps })
    }

    fn step(&self, i: usize) -> PyResult<&KeptStep> {
        self.kept.steps.get(i).ok_or_else(|| PyIndexError::new_err(format!("step index {i}: the run wrote {} steps", self.kept.steps.len())))
    }
}

/// A field (node- or cell-major, `components` per entry) as an (n,) or (n, components) array.
fn field_array<'py>(py: Python<'py>, f: &stamp::io::Field) -> PyResult<Bound<'py, PyAny>> {
    let flat = PyArray1::from_slice(py, &f.values);
    if f.components == 1 {
        Ok(flat.into_any())
    } else {
        Ok(flat.reshape([f.values.len() / f.components, f.components])?.into_any())
    }
}

#[pymethods]
impl NativeResult {
    /// summary.json's text.
    #[getter]
    fn summary_json(&self) -> &str {
        &self.summary
    }

    /// history.csv's text.
    #[getter]
    fn history_csv(&self) -> String {
        self.outcome.history.csv()
    }

    /// The folder the outputs were written into.
    #[getter]
    fn out_dir(&self) -> PathBuf {
        self.outcome.out_dir.clone()
    }

    /// (n, 2) float64.
    #[getter]
    fn nodes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let flat: Vec<f64> = self.kept.nodes.iter().flatten().copied().collect();
        flat.into_pyarray(py).reshape([self.kept.nodes.len(), 2]).expect("n x 2 values")
    }

    /// (m, 4) int64, 0-based.
    #[getter]
    fn cells<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<i64>> {
        let flat: Vec<i64> = self.kept.cells.iter().flatten().map(|&n| n as i64).collect();
        flat.into_pyarray(py).reshape([self.kept.cells.len(), 4]).expect("m x 4 values")
    }

    /// The punches' names.
    #[getter]
    fn punches(&self) -> Vec<String> {
        self.kept.punches.clone()
    }

    /// (step number, load factor) of every written step.
    #[getter]
    fn steps(&self) -> Vec<(usize, f64)> {
        self.kept.steps.iter().map(|s| (s.step, s.load_factor)).collect()
    }

    /// (n, surfaces, 3): the displacements of every surface, bottom to top, at written step `i`.
    fn displacement<'py>(&self, py: Python<'py>, i: usize) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let s = self.step(i)?;
        let flat: Vec<f64> = s.surface_displacements.iter().flatten().copied().collect();
        Ok(flat.into_pyarray(py).reshape([self.kept.nodes.len(), self.kept.surfaces, 3])?)
    }

    /// (n,): the contact pressure of punch `name` at written step `i`.
    fn contact_pressure<'py>(&self, py: Python<'py>, name: &str, i: usize) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let s = self.step(i)?;
        let k = self.kept.punches.iter().position(|p| p == name).ok_or_else(|| PyKeyError::new_err(format!("no punch named {name:?}; the punches are {:?}", self.kept.punches)))?;
        Ok(PyArray1::from_slice(py, &s.contact_pressure[k]))
    }

    /// The .vtu's cell arrays at written step `i`: name -> (m,) float64.
    fn cell_data<'py>(&self, py: Python<'py>, i: usize) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for f in &self.step(i)?.cell_fields {
            d.set_item(&f.name, field_array(py, f)?)?;
        }
        Ok(d)
    }

    /// The .vtu's point arrays at written step `i`: name -> (n,) or (n, 3) float64.
    fn point_data<'py>(&self, py: Python<'py>, i: usize) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for f in &self.step(i)?.point_fields {
            d.set_item(&f.name, field_array(py, f)?)?;
        }
        Ok(d)
    }

    /// Copy the output files into `dir` (claimed as `stamp run --out dir` would claim it); into
    /// the folder they lie in, nothing to do: their paths. Refused if another run has removed or
    /// rewritten them since the solve.
    fn write(&self, py: Python<'_>, dir: PathBuf) -> PyResult<Vec<PathBuf>> {
        let files = &self.outcome.files;
        for (f, s) in files.iter().zip(&self.stamps) {
            if s.is_none() || stamp_of(f) != *s {
                let why = "removed or rewritten since the solve (another run wrote into its folder?): the result's files are lost, its arrays are still here";
                return Err(to_py(stamp::StampError::io(f, std::io::Error::other(why))));
            }
        }
        py.detach(|| stamp_problem::out_dir::copy_run(files, &dir)).map_err(to_py)
    }
}
