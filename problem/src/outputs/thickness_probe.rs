//! `[[output.thickness_probe]]`: the displacement and the six stresses through the thickness of a
//! laminate, or of a plate of three to five surfaces (one layer of its material), at one point of
//! the plate, written for every written step as `thickness_<name>_<step>.csv` with the columns
//! `x3, layer, u1, u2, u3, s11, s22, s33, s12, s13, s23` (`layer` counts from 0 at the bottom;
//! `points_per_layer` rows per layer, evenly spaced, its faces included, so an interface has one
//! row for each of its two layers).
//!
//! The displacement is the element's interpolation at the point. The stresses (second
//! Piola-Kirchhoff, in the plate's axes) are by default recovered (`stresses = "recovered"`,
//! outputs/recovered_stresses.rs: patch fits and 3D equilibrium through the thickness, the faces'
//! tractions from outputs/face_tractions.rs); with `stresses = "law"`, or a probe that names
//! `transverse_shear`, or where the mesh does not determine the fit, they are each layer's 3D law
//! from the element's strains at the four Gauss points, extrapolated bilinearly to the point (the
//! in-plane position inside its element), as follows.
//! A point on an edge or a node is held by several cells: their extrapolated values are averaged
//! with equal weights. A point on a symmetry plane (a boundary group fixed with `symmetry_x1` or
//! `symmetry_x2` whose nodes lie on one line x1 or x2 = const through the point) counts the
//! mirror images of its cells too, as the whole plate's probe would: the components odd under the
//! mirror (u1, s12, s13 for x1; u2, s12, s23 for x2) average to zero there. At an interface the
//! transverse stresses of the two layers differ by what the model has not converged
//! (docs/verification/laminates.md measures it against Pagano's exact solution).

use crate::model::mesh::MeshData;
use crate::model::plate_model::Plate;
use crate::model::build::PunchInfo;
use crate::outputs::equilibrium_shear::ShearRecovery;
use crate::outputs::face_tractions::FaceLoads;
use crate::outputs::recovered_stresses::{FaceTractions, StressRecovery};
use crate::outputs::probe::CellLocator;
use crate::schema::{Problem, DEFAULT_POINTS_PER_LAYER};
use stamp::element::Element;
use stamp::io::write_string_atomically;
use stamp::model::Model;
use stamp::{Result, StampError};
use std::path::{Path, PathBuf};

struct Item {
    name: String,
    /// The cells that hold the point, with its local coordinates in each.
    cells: Vec<(usize, [f64; 2])>,
    /// Whether the point lies on a symmetry plane of normal x1, x2.
    mirror: [bool; 2],
    points: usize,
    /// With `transverse_shear = "equilibrium"`: the in-plane stresses' recovery around the point.
    recovery: Option<ShearRecovery>,
    /// With recovered stresses: the fit around the point and the loads on its faces.
    recovered: Option<(StressRecovery, FaceLoads)>,
}

/// The thickness probes of a run.
pub struct ThicknessProbes {
    items: Vec<Item>,
    /// The probes that recover by default but whose mesh does not determine the fit (they read
    /// the law's stresses), one sentence each.
    pub warnings: Vec<String>,
}

impl ThicknessProbes {
    /// Locate every probe's point in the mesh (an error names the probe whose point is outside).
    pub fn new(p: &Problem, mesh: &MeshData) -> Result<ThicknessProbes> {
        let probes = &p.spec.output.thickness_probe;
        if probes.is_empty() {
            return Ok(ThicknessProbes { items: Vec::new(), warnings: Vec::new() });
        }
        let locator = CellLocator::new(&mesh.mesh);
        let mut items = Vec::new();
        let mut warnings = Vec::new();
        for (i, s) in probes.iter().enumerate() {
            let spec = s.get_ref();
            let cells = locator.locate_all(spec.at);
            if cells.is_empty() {
                return Err(p.error_at(s.span(), &format!("output.thickness_probe[{i}].at"), format!("the point {:?} is not on the plate (the mesh)", spec.at)));
            }
            let mirror = [0, 1].map(|d| on_symmetry_plane(p, mesh, spec.at, d));
            let recovery = if spec.transverse_shear.as_deref() == Some("equilibrium") {
                let holding: Vec<usize> = cells.iter().map(|c| c.0).collect();
                Some(ShearRecovery::new(&mesh.mesh, &holding, spec.at, &symmetry_planes(p, mesh)).ok_or_else(|| {
                    p.error_at(
                        s.span(),
                        &format!("output.thickness_probe[{i}].transverse_shear"),
                        format!("\"equilibrium\" fits the in-plane stresses of the cells around {:?}, but their centres do not span a quadratic in x1 and x2 (too few cells, or a strip one cell wide): use \"law\" or a finer mesh", spec.at),
                    )
                })?)
            } else {
                None
            };
            let recovered = if spec.recovered() {
                let holding: Vec<usize> = cells.iter().map(|c| c.0).collect();
                match StressRecovery::new(&mesh.mesh, &holding, spec.at, &symmetry_planes(p, mesh)) {
                    Some(fit) => Some((fit, FaceLoads::at(p, mesh, &cells, spec.at))),
                    None => {
                        let why = format!("the recovered stresses fit a cubic through the cells around {:?}, but their centres do not determine it (too few cells, or a strip one cell wide)", spec.at);
                        if spec.stresses.is_some() {
                            return Err(p.error_at(s.span(), &format!("output.thickness_probe[{i}].stresses"), format!("{why}: use stresses = \"law\" or a finer mesh")));
                        }
                        // the default: the law, said
                        warnings.push(format!("output.thickness_probe[{i}] ('{}'): {why}; it writes the 3D law's stresses (stresses = \"law\" says so and silences this)", spec.name));
                        None
                    }
                }
            } else {
                None
            };
            items.push(Item { name: spec.name.clone(), cells, mirror, points: spec.points_per_layer.unwrap_or(DEFAULT_POINTS_PER_LAYER), recovery, recovered });
        }
        Ok(ThicknessProbes { items, warnings })
    }

    /// Write the CSV of every probe for `step` (load factor `t`, the punches `punches` of the
    /// model); returns the files written and, per probe with recovered stresses, the top face's
    /// mismatch [s13, s23, s33] (see outputs/recovered_stresses.rs).
    pub fn write_step(&self, dir: &Path, step: usize, t: f64, model: &Model<Plate>, punches: &[PunchInfo], cells: &[[usize; 4]], u: &[f64]) -> Result<(Vec<PathBuf>, Vec<(String, [f64; 3])>)> {
        let mut files = Vec::new();
        let mut mismatches = Vec::new();
        for item in &self.items {
            let faces = item.recovered.as_ref().map(|(_, loads)| loads.tractions(t, model, punches, cells));
            let (text, mismatch) = csv(item, model, u, faces.as_ref()).ok_or_else(|| StampError::Input { file: String::new(), message: "a thickness probe needs a plate of three to five surfaces or layers".into() })?;
            let path = dir.join(format!("thickness_{}_{step:04}.csv", item.name));
            write_string_atomically(&path, &text)?;
            files.push(path);
            if let Some(m) = mismatch {
                mismatches.push((item.name.clone(), m));
            }
        }
        Ok((files, mismatches))
    }
}

/// The coordinates of the model's symmetry planes, by normal: [x1 of the planes of `symmetry_x1`
/// groups, x2 of those of `symmetry_x2`] (a group whose nodes share one coordinate).
fn symmetry_planes(p: &Problem, mesh: &MeshData) -> [Vec<f64>; 2] {
    let tol = 1e-9 * mesh.element_size();
    std::array::from_fn(|d| {
        let word = if d == 0 { "symmetry_x1" } else { "symmetry_x2" };
        let mut planes: Vec<f64> = Vec::new();
        for b in &p.spec.boundary {
            let b = b.get_ref();
            if !b.fix.iter().any(|f| f.word == word) {
                continue;
            }
            let Some(nodes) = mesh.nodes(b.group.get_ref()) else { continue };
            let Some(&first) = nodes.first() else { continue };
            let c = mesh.mesh.coords[first][d];
            if nodes.iter().all(|&n| (mesh.mesh.coords[n][d] - c).abs() <= tol) && !planes.iter().any(|q| (q - c).abs() <= tol) {
                planes.push(c);
            }
        }
        planes
    })
}

/// Whether `at` lies on a symmetry plane of normal x_(d+1): a boundary group fixed with
/// `symmetry_x1` (d = 0) or `symmetry_x2` (d = 1) whose nodes share one coordinate x_d, equal to
/// the point's, and span the point along the other axis.
fn on_symmetry_plane(p: &Problem, mesh: &MeshData, at: [f64; 2], d: usize) -> bool {
    let word = if d == 0 { "symmetry_x1" } else { "symmetry_x2" };
    let tol = 1e-9 * mesh.element_size();
    p.spec.boundary.iter().any(|b| {
        let b = b.get_ref();
        if !b.fix.iter().any(|f| f.word == word) {
            return false;
        }
        let Some(nodes) = mesh.nodes(b.group.get_ref()) else { return false };
        let xs: Vec<[f64; 2]> = nodes.iter().map(|&n| mesh.mesh.coords[n]).collect();
        let (lo, hi) = xs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| (l.min(x[1 - d]), h.max(x[1 - d])));
        !xs.is_empty() && xs.iter().all(|x| (x[d] - at[d]).abs() <= tol) && at[1 - d] >= lo - tol && at[1 - d] <= hi + tol
    })
}

/// The rows of one probe (with recovered stresses: the faces' tractions `faces`), and the
/// recovery's top-face mismatch.
fn csv(item: &Item, model: &Model<Plate>, u: &[f64], faces: Option<&FaceTractions>) -> Option<(String, Option<[f64; 3]>)> {
    let plate = &model.element;
    let (lam, per_layer, mid) = plate.stress_stack()?;
    let dpn = plate.dofs_per_node();
    let mut ws = plate.new_workspace();
    let b = lam.boundaries();
    let zs: Vec<f64> = (0..per_layer).map(|s| -1.0 + 2.0 * s as f64 / (per_layer - 1) as f64).collect();
    // the Gauss points' values extrapolated: the bilinear functions of the points (+-1/sqrt 3)
    let r3 = 3f64.sqrt();
    let places: Vec<(Vec<f64>, [f64; 4], [f64; 4])> = item
        .cells
        .iter()
        .map(|&(cell, xi)| {
            let local = plate.element_nodes(cell).iter().flat_map(|&n| u[dpn * n..dpn * (n + 1)].iter().copied()).collect();
            (local, stamp::mesh::bilinear(xi[0], xi[1]).0, stamp::mesh::bilinear(r3 * xi[0], r3 * xi[1]).0)
        })
        .collect();
    let weight = 1.0 / places.len() as f64;
    let mut heights: Vec<(usize, f64)> = Vec::new();
    for k in 0..lam.plies.len() {
        for j in 0..item.points {
            heights.push((k, if j + 1 == item.points { b[k + 1] } else { b[k] + (b[k + 1] - b[k]) * j as f64 / (item.points - 1) as f64 }));
        }
    }
    let column = match (&item.recovered, faces) {
        (Some((fit, _)), Some(f)) => Some(fit.column(plate, &lam, u, &heights, f)?),
        _ => None,
    };
    let mut out = String::from("x3,layer,u1,u2,u3,s11,s22,s33,s12,s13,s23\n");
    for (row_index, &(k, x3)) in heights.iter().enumerate() {
        let slots = lam.ply_slots(per_layer, k);
        let (l, _) = stamp_elements::multi_surface::lagrange(&zs, 2.0 * (x3 - 0.5 * (b[k] + b[k + 1])) / (b[k + 1] - b[k]));
        // [u1, u2, u3, s11, s22, s33, s12, s13, s23], the mean over the cells
        let mut row = [0.0; 9];
        for ((local, shape, at_gauss), &(cell, _)) in places.iter().zip(&item.cells) {
            for i in 0..3 {
                row[i] += weight * (0..4).map(|a| shape[a] * slots.iter().zip(&l).map(|(&sl, &ls)| ls * local[dpn * a + 3 * sl + i]).sum::<f64>()).sum::<f64>();
            }
            if column.is_none() {
                let g = plate.layer_stresses(cell, k, x3, local, &mut ws)?;
                for (r, c) in [(3, 0), (4, 1), (5, 2), (6, 5), (7, 4), (8, 3)] {
                    row[r] += weight * (0..4).map(|q| at_gauss[q] * g[q][c]).sum::<f64>();
                }
            }
        }
        if let Some(c) = &column {
            // [s11, s22, s33, s12, s13, s23]
            row[3..9].copy_from_slice(&c.rows[row_index]);
        }
        if let Some(r) = &item.recovery {
            let [s13, s23] = r.shear(plate, &lam, u, k, x3)?;
            row[7] = s13;
            row[8] = s23;
        }
        // a mirror image's odd components cancel the cell's
        if item.mirror[0] {
            for r in [0, 6, 7] {
                row[r] = 0.0;
            }
        }
        if item.mirror[1] {
            for r in [1, 6, 8] {
                row[r] = 0.0;
            }
        }
        out.push_str(&format!("{:e},{k}", x3 + mid));
        for v in row {
            out.push_str(&format!(",{v:e}"));
        }
        out.push('\n');
    }
    Some((out, column.map(|c| c.mismatch)))
}
