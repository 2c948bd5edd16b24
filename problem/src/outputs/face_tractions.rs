//! What acts on the plate's faces at a probe's point, for the recovered stresses
//! (outputs/recovered_stresses.rs): the `[[load]]` pressures and surface loads whose group holds
//! the point (the mean over the cells that hold it: a point on a group's edge gets the mean of
//! both sides), times the load factor, and the recovered contact pressure of each punch
//! (`stamp::contact::recovered_pressure`, the .vtu's `contact_pressure_recovered`) interpolated
//! at the point on the face the punch touches. Contact is taken frictionless (no shear traction);
//! line, point and moment loads act on lines and points, not on a face's area, and are not counted.

use crate::model::build::PunchInfo;
use crate::model::mesh::MeshData;
use crate::model::plate_model::Plate;
use crate::outputs::recovered_stresses::FaceTractions;
use crate::schema::{LoadFace, LoadKind, Problem};
use stamp::model::Model;
use stamp_elements::plate::Face;

/// The area loads at one point (at load factor 1).
pub struct FaceLoads {
    /// Per face load: the share of the holding cells in its group, the face, and the traction
    /// (force per area on the plate) at the point.
    items: Vec<(f64, LoadFace, [f64; 3])>,
    /// The cells that hold the point, with its local coordinates in each.
    cells: Vec<(usize, [f64; 2])>,
}

impl FaceLoads {
    /// The loads of `p` at `at`, held by `cells`.
    pub fn at(p: &Problem, mesh: &MeshData, cells: &[(usize, [f64; 2])], at: [f64; 2]) -> FaceLoads {
        // the expressions' length scale (only their derivatives use it)
        let size = mesh.mesh.coords.iter().flat_map(|x| x.iter()).fold(0.0f64, |m, v| m.max(v.abs()));
        let mut items = Vec::new();
        for l in &p.spec.load {
            let ls = l.get_ref();
            if !matches!(ls.kind, LoadKind::Pressure | LoadKind::Surface) {
                continue;
            }
            let Some(group) = mesh.surfaces.get(ls.group.get_ref()) else { continue };
            let share = cells.iter().filter(|(c, _)| group.contains(c)).count() as f64 / cells.len() as f64;
            if share == 0.0 {
                continue;
            }
            let face = ls.face.unwrap_or_default();
            let traction = match (ls.kind, &ls.pressure, ls.force) {
                (LoadKind::Pressure, Some(spec), _) => {
                    let q = crate::model::pressure::pressure_function(spec.get_ref(), size)(at[0], at[1]);
                    // a pressure pushes on its face towards the plate
                    [0.0, 0.0, if face == LoadFace::Top { -q } else { q }]
                }
                (_, _, Some(f)) => f.0,
                _ => continue,
            };
            items.push((share, face, traction));
        }
        FaceLoads { items, cells: cells.to_vec() }
    }

    /// The tractions at load factor `t` with the punches' contact pressures of `model`.
    pub fn tractions(&self, t: f64, model: &Model<Plate>, punches: &[PunchInfo], mesh_cells: &[[usize; 4]]) -> FaceTractions {
        let mut f = FaceTractions::default();
        for &(share, face, tr) in &self.items {
            for i in 0..3 {
                match face {
                    LoadFace::Top => f.top[i] += share * t * tr[i],
                    LoadFace::Bottom => f.bottom[i] += share * t * tr[i],
                    LoadFace::Mid => {
                        f.top[i] += 0.5 * share * t * tr[i];
                        f.bottom[i] += 0.5 * share * t * tr[i];
                    }
                }
            }
        }
        let weight = 1.0 / self.cells.len() as f64;
        for (info, pair) in punches.iter().zip(&model.contacts) {
            // the pair's points are nodes; their recovered pressures, interpolated at the point
            let p_rec = stamp::contact::recovered_pressure(pair, mesh_cells, stamp::contact::RECOVERY).pressure;
            let mut at_node = std::collections::HashMap::new();
            for (pt, v) in pair.points.iter().zip(&p_rec) {
                *at_node.entry(pt.node).or_insert(0.0) += v;
            }
            let mut q = 0.0;
            for &(c, xi) in &self.cells {
                let (n, _) = stamp::mesh::bilinear(xi[0], xi[1]);
                q += weight * (0..4).map(|a| n[a] * at_node.get(&mesh_cells[c][a]).copied().unwrap_or(0.0)).sum::<f64>();
            }
            match info.face {
                Face::Top => f.top[2] -= q,
                Face::Bottom => f.bottom[2] += q,
            }
        }
        f
    }
}
