//! `[[output.thickness_probe]]`: the displacement and the six stresses through the thickness of a
//! laminate at one point of the plate, written for every written step as
//! `thickness_<name>_<step>.csv` with the columns `x3, layer, u1, u2, u3, s11, s22, s33, s12, s13,
//! s23` (`layer` counts from 0 at the bottom; `points_per_layer` rows per layer, evenly spaced, its
//! faces included, so an interface has one row for each of its two layers).
//!
//! The stresses are the second Piola-Kirchhoff stresses in the plate's axes by each layer's 3D law
//! from the element's strains at the four Gauss points, extrapolated bilinearly to the point (the
//! in-plane position inside its element); the displacement is the element's interpolation there.
//! At an interface the transverse stresses of the two layers differ by what the model has not
//! converged (docs/verification.md measures it against Pagano's exact solution).

use super::mesh::MeshData;
use super::plate_model::Plate;
use super::probe::CellLocator;
use super::problem::{Problem, DEFAULT_POINTS_PER_LAYER};
use stamp::element::Element;
use stamp::io::write_string_atomically;
use stamp::model::Model;
use stamp::{Result, StampError};
use std::path::{Path, PathBuf};

struct Item {
    name: String,
    cell: usize,
    xi: [f64; 2],
    points: usize,
}

/// The thickness probes of a run.
pub struct ThicknessProbes {
    items: Vec<Item>,
}

impl ThicknessProbes {
    /// Locate every probe's point in the mesh (an error names the probe whose point is outside).
    pub fn new(p: &Problem, mesh: &MeshData) -> Result<ThicknessProbes> {
        let probes = &p.spec.output.thickness_probe;
        if probes.is_empty() {
            return Ok(ThicknessProbes { items: Vec::new() });
        }
        let locator = CellLocator::new(&mesh.mesh);
        let mut items = Vec::new();
        for (i, s) in probes.iter().enumerate() {
            let spec = s.get_ref();
            let (cell, xi) = locator
                .locate(spec.at)
                .ok_or_else(|| p.error_at(s.span(), &format!("output.thickness_probe[{i}].at"), format!("the point {:?} is not on the plate (the mesh)", spec.at)))?;
            items.push(Item { name: spec.name.clone(), cell, xi, points: spec.points_per_layer.unwrap_or(DEFAULT_POINTS_PER_LAYER) });
        }
        Ok(ThicknessProbes { items })
    }

    /// Write the CSV of every probe for `step`; returns the files written.
    pub fn write_step(&self, dir: &Path, step: usize, model: &Model<Plate>, u: &[f64]) -> Result<Vec<PathBuf>> {
        let mut files = Vec::new();
        for item in &self.items {
            let text = csv(item, model, u).ok_or_else(|| StampError::Input { file: String::new(), message: "a thickness probe needs a laminate".into() })?;
            let path = dir.join(format!("thickness_{}_{step:04}.csv", item.name));
            write_string_atomically(&path, &text)?;
            files.push(path);
        }
        Ok(files)
    }
}

/// The rows of one probe.
fn csv(item: &Item, model: &Model<Plate>, u: &[f64]) -> Option<String> {
    let plate = &model.element;
    let (lam, per_layer) = plate.laminate()?;
    let dpn = plate.dofs_per_node();
    let nodes = plate.element_nodes(item.cell);
    let local: Vec<f64> = nodes.iter().flat_map(|&n| u[dpn * n..dpn * (n + 1)].iter().copied()).collect();
    let (shape, _) = stamp::mesh::bilinear(item.xi[0], item.xi[1]);
    // the Gauss points' values extrapolated: the bilinear functions of the points (+-1/sqrt 3)
    let r3 = 3f64.sqrt();
    let (at_gauss, _) = stamp::mesh::bilinear(r3 * item.xi[0], r3 * item.xi[1]);
    let mut ws = plate.new_workspace();
    let b = lam.boundaries();
    let zs: Vec<f64> = (0..per_layer).map(|s| -1.0 + 2.0 * s as f64 / (per_layer - 1) as f64).collect();
    let mut out = String::from("x3,layer,u1,u2,u3,s11,s22,s33,s12,s13,s23\n");
    for k in 0..lam.plies.len() {
        let slots = lam.ply_slots(per_layer, k);
        for j in 0..item.points {
            let x3 = if j + 1 == item.points { b[k + 1] } else { b[k] + (b[k + 1] - b[k]) * j as f64 / (item.points - 1) as f64 };
            let (l, _) = stamp_elements::multi_surface::lagrange(&zs, 2.0 * (x3 - 0.5 * (b[k] + b[k + 1])) / (b[k + 1] - b[k]));
            let disp: [f64; 3] =
                std::array::from_fn(|i| (0..4).map(|a| shape[a] * slots.iter().zip(&l).map(|(&sl, &ls)| ls * local[dpn * a + 3 * sl + i]).sum::<f64>()).sum());
            let g = plate.layer_stresses(item.cell, k, x3, &local, &mut ws)?;
            let st = |c: usize| (0..4).map(|q| at_gauss[q] * g[q][c]).sum::<f64>();
            out.push_str(&format!(
                "{:e},{k},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}\n",
                x3,
                disp[0],
                disp[1],
                disp[2],
                st(0),
                st(1),
                st(2),
                st(5),
                st(4),
                st(3)
            ));
        }
    }
    Some(out)
}
