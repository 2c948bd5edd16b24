//! What an elastic-plastic plate writes besides an elastic one's: per surface the equivalent
//! plastic strain and the yield state (cell arrays of the .vtu), the thickness strain at the nodes
//! (a point array), and per step the largest plastic strain and the least thickness (history.csv,
//! summary.json).
//!
//! - `plastic_strain_surface<s>`: the equivalent plastic strain ep at surface s (from the bottom
//!   face up) at the element centre, the mean over its Gauss points of the converged states
//!   interpolated through the thickness (elements/src/multi_surface.rs `plastic_strain_at`);
//! - `yielding_surface<s>`: the share of the element's Gauss points at that surface that flowed
//!   plastically in the step (0 to 1);
//! - `thickness_strain`: ln(h / h0) at every node, h the distance between the face points
//!   (x3 = delta+ and delta-) of the node's fibre in the deformed plate: negative where the sheet
//!   thins.

use crate::model::plate_model::{Layout, Plate};
use stamp::element::Element;
use stamp::io::Field;
use stamp_elements::Face;

/// The surfaces' heights from the mid-plane (bottom face up), for a plastic plate.
fn surface_heights(plate: &Plate) -> Option<Vec<f64>> {
    if !plate.is_plastic() {
        return None;
    }
    let (lam, _, _) = plate.stress_stack()?;
    let h = lam.thickness();
    let n = plate.surfaces();
    Some((0..n).map(|s| -0.5 * h + h * s as f64 / (n - 1) as f64).collect())
}

/// The cell arrays of a plastic plate (none for an elastic one).
pub fn plastic_cell_fields(plate: &Plate, u: &[f64]) -> Vec<Field> {
    let Some(heights) = surface_heights(plate) else {
        return Vec::new();
    };
    let mut ws = plate.new_workspace();
    let dpn = plate.dofs_per_node();
    let ne = plate.num_elements();
    let mut ep = vec![Vec::with_capacity(ne); heights.len()];
    let mut yielding = vec![Vec::with_capacity(ne); heights.len()];
    let mut local = vec![0.0; 4 * dpn];
    for e in 0..ne {
        for (a, &n) in plate.element_nodes(e).iter().enumerate() {
            local[dpn * a..dpn * (a + 1)].copy_from_slice(&u[dpn * n..dpn * (n + 1)]);
        }
        for (s, &x3) in heights.iter().enumerate() {
            let g = plate.plastic_strain_at(e, x3, &local, &mut ws).unwrap_or([(0.0, false); 4]);
            ep[s].push(0.25 * g.iter().map(|p| p.0).sum::<f64>());
            yielding[s].push(0.25 * g.iter().filter(|p| p.1).count() as f64);
        }
    }
    let mut fields: Vec<Field> = ep.into_iter().enumerate().map(|(s, v)| Field::scalar(&format!("plastic_strain_surface{s}"), v)).collect();
    fields.extend(yielding.into_iter().enumerate().map(|(s, v)| Field::scalar(&format!("yielding_surface{s}"), v)));
    fields
}

/// ln(h / h0) at every node of a plate of thickness `h0` whose faces' displacements `layout` reads.
pub fn thickness_strain(layout: &Layout, u: &[f64], nodes: usize, h0: f64) -> Vec<f64> {
    (0..nodes)
        .map(|n| {
            let (b, t) = (layout.face_displacement(u, n, Face::Bottom), layout.face_displacement(u, n, Face::Top));
            let d = [t[0] - b[0], t[1] - b[1], h0 + t[2] - b[2]];
            ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() / h0).ln()
        })
        .collect()
}

/// The point arrays of a plastic plate: `thickness_strain` (none for an elastic one).
pub fn plastic_point_fields(plate: &Plate, u: &[f64], nodes: usize) -> Vec<Field> {
    let Some(heights) = surface_heights(plate) else {
        return Vec::new();
    };
    let h0 = heights[heights.len() - 1] - heights[0];
    vec![Field::scalar("thickness_strain", thickness_strain(&Layout::of(plate), u, nodes, h0))]
}

/// The largest equivalent plastic strain over the surfaces' element centres' Gauss points and the
/// least thickness over the nodes, for a plastic plate.
pub fn plastic_extremes(plate: &Plate, u: &[f64], nodes: usize) -> Option<(f64, f64)> {
    let heights = surface_heights(plate)?;
    let h0 = heights[heights.len() - 1] - heights[0];
    let mut ws = plate.new_workspace();
    let dpn = plate.dofs_per_node();
    let mut local = vec![0.0; 4 * dpn];
    let mut largest = 0.0f64;
    for e in 0..plate.num_elements() {
        for (a, &n) in plate.element_nodes(e).iter().enumerate() {
            local[dpn * a..dpn * (a + 1)].copy_from_slice(&u[dpn * n..dpn * (n + 1)]);
        }
        for &x3 in &heights {
            if let Some(g) = plate.plastic_strain_at(e, x3, &local, &mut ws) {
                largest = g.iter().fold(largest, |m, p| m.max(p.0));
            }
        }
    }
    let least = thickness_strain(&Layout::of(plate), u, nodes, h0).into_iter().fold(f64::INFINITY, f64::min);
    Some((largest, h0 * least.exp()))
}
