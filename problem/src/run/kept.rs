//! The results of a run kept in memory (`SolveOptions::keep`, for the Python package): the mesh
//! that was solved and, for every step written (listed in summary.json), the .vtu's point and cell
//! arrays, each punch's contact pressure and the displacements of every surface.

use stamp::io::Field;

/// One written step.
#[derive(Debug, Clone)]
pub struct KeptStep {
    /// The load step's number (as in the file names and summary.json).
    pub step: usize,
    pub load_factor: f64,
    /// The .vtu's point arrays ([`crate::outputs::output::POINT_ARRAYS`]).
    pub point_fields: Vec<Field>,
    /// The .vtu's cell arrays ([`crate::outputs::output::cell_array_names`]: the resultants, and with layers the stresses).
    pub cell_fields: Vec<Field>,
    /// Per punch (in the order of [`Kept::punches`]), q_n at every node (0 off its candidates): the
    /// pressure column of its pressure_*.csv.
    pub contact_pressure: Vec<Vec<f64>>,
    /// The displacement of every surface at every node, bottom face to top face: node-major,
    /// `surfaces` 3-vectors per node.
    pub surface_displacements: Vec<[f64; 3]>,
}

/// A run's results.
#[derive(Debug, Clone, Default)]
pub struct Kept {
    /// The nodes (x1, x2) and 4-node cells of the mesh solved (triangles cut into quadrilaterals).
    pub nodes: Vec<[f64; 2]>,
    pub cells: Vec<[usize; 4]>,
    /// Surfaces through the thickness.
    pub surfaces: usize,
    /// The punches' names.
    pub punches: Vec<String>,
    pub steps: Vec<KeptStep>,
}

impl KeptStep {
    /// The step's results from what the run wrote for it.
    pub fn new(data: &crate::outputs::output::StepData, u: &[f64], layout: &crate::model::plate_model::Layout, nodes: usize) -> KeptStep {
        let contact_pressure = data
            .punch_rows
            .iter()
            .map(|rows| {
                let mut q = vec![0.0; nodes];
                for r in rows {
                    q[r.node] += r.q_n;
                }
                q
            })
            .collect();
        KeptStep {
            step: data.entry.step,
            load_factor: data.entry.load_factor,
            point_fields: data.point_fields.clone(),
            cell_fields: data.cell_fields.clone(),
            contact_pressure,
            surface_displacements: (0..nodes).flat_map(|n| layout.surface_displacements(u, n)).collect(),
        }
    }
}
