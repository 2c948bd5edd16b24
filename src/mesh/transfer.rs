//! Moving a nodal field from one mesh of a region to another: the bilinear interpolant of the
//! coarse mesh's nodal values, evaluated at every node of the fine mesh ([`Prolongation`]). Exact
//! for a fine mesh that is a uniform refinement of the coarse one (every fine node lies on a
//! coarse cell, where the interpolant is the coarse finite-element field itself); for two
//! independent meshes of the same region it is the coarse field at the fine node, and a fine node
//! just outside the coarse mesh (a curved boundary meshed twice) takes the value at the point of
//! the cell whose reference coordinates it exceeds least, clamped to the cell's square (the
//! nearest point of the cell for a parallelogram; close to it for the cells a mesh generator
//! makes). [`Prolongation::farthest_outside`] says how far outside the farthest node lies.
//!
//! Used by [`crate::mesh::coarse_path`] to start the load steps of a fine mesh from the solution on a
//! coarse one.

use crate::mesh::{bilinear, bilinear_point, inverse_bilinear, QuadMesh};
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};

/// Interpolation weights of a fine mesh's nodes in a coarse mesh's cells: fine node j takes
/// `sum_a weights[j][a] * coarse[nodes[j][a]]`.
#[derive(Debug, Clone)]
pub struct Prolongation {
    nodes: Vec<[usize; 4]>,
    weights: Vec<[f64; 4]>,
    coarse_nodes: usize,
    /// The fine node farthest outside the coarse mesh and its distance from it (0 when every
    /// node lies on a coarse cell).
    farthest_outside: (usize, f64),
}

/// (s, t) of the point `p` in the bilinear cell `x` ([`inverse_bilinear`]; a point outside the
/// cell gives a value outside the square) and how far outside the square it lies; infinitely far
/// where the map cannot be inverted (a degenerate cell, a point far off).
fn local_coordinates(x: &[[f64; 2]; 4], p: [f64; 2]) -> ([f64; 2], f64) {
    match inverse_bilinear(x, p) {
        Some([s, t]) => ([s, t], (s.abs() - 1.0).max(0.0) + (t.abs() - 1.0).max(0.0)),
        None => ([0.0; 2], f64::INFINITY),
    }
}

impl Prolongation {
    /// The weights of every node of `fine` in the cells of `coarse` (both in the same x1-x2
    /// plane). Cells are found with an R*-tree over the coarse cells' boxes.
    pub fn between(coarse: &QuadMesh, fine: &QuadMesh) -> Prolongation {
        let boxes: Vec<GeomWithData<Rectangle<[f64; 2]>, usize>> = (0..coarse.num_cells())
            .map(|c| {
                let x = coarse.cell_coords(c);
                let lo = [x.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min), x.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min)];
                let hi = [x.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max), x.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max)];
                GeomWithData::new(Rectangle::from_corners(lo, hi), c)
            })
            .collect();
        let tree = RTree::bulk_load(boxes);
        let mut nodes = Vec::with_capacity(fine.num_nodes());
        let mut weights = Vec::with_capacity(fine.num_nodes());
        let mut farthest_outside = (0, 0.0f64);
        for (j, &p) in fine.coords.iter().enumerate() {
            // the cell whose square holds the point (the least outside it among the boxes that
            // hold it, or the nearest box when none does)
            let mut best: Option<(f64, usize, [f64; 2])> = None;
            let consider = |best: &mut Option<(f64, usize, [f64; 2])>, c: usize| {
                let (st, outside) = local_coordinates(&coarse.cell_coords(c), p);
                if best.is_none_or(|b| outside < b.0) {
                    *best = Some((outside, c, st));
                }
            };
            for b in tree.locate_in_envelope_intersecting(&AABB::from_point(p)) {
                consider(&mut best, b.data);
            }
            if best.is_none_or(|b| b.0 > 1e-9) {
                if let Some(b) = tree.nearest_neighbor(&p) {
                    consider(&mut best, b.data);
                }
            }
            let (outside, c, [s, t]) = best.expect("a coarse mesh has cells");
            let clamped = [s.clamp(-1.0, 1.0), t.clamp(-1.0, 1.0)];
            let (n, _) = bilinear(clamped[0], clamped[1]);
            if outside > 0.0 {
                // the distance from the point of the cell it was clamped to
                let q = bilinear_point(&coarse.cell_coords(c), clamped);
                let d = (q[0] - p[0]).hypot(q[1] - p[1]);
                if d > farthest_outside.1 {
                    farthest_outside = (j, d);
                }
            }
            nodes.push(coarse.cells[c]);
            weights.push(n);
        }
        Prolongation { nodes, weights, coarse_nodes: coarse.num_nodes(), farthest_outside }
    }

    /// The fine node farthest outside the coarse mesh (0-based) and its distance from the nearest
    /// coarse cell's point it takes its values from; distance 0 when every node lies on the
    /// coarse mesh. A curved boundary meshed twice leaves nodes a sagitta outside; a coarse mesh
    /// of another region leaves them far outside.
    pub fn farthest_outside(&self) -> (usize, f64) {
        self.farthest_outside
    }

    /// The fine vector of `components` values per node from the coarse one (node-major: node k's
    /// component i at k * components + i). Values past the nodal ones (the unknowns of a
    /// force-driven punch, say) are copied as they are.
    pub fn apply(&self, coarse: &[f64], components: usize, fine: &mut [f64]) {
        let nodal_fine = self.nodes.len() * components;
        let nodal_coarse = self.coarse_nodes * components;
        for (j, (nodes, w)) in self.nodes.iter().zip(&self.weights).enumerate() {
            for i in 0..components {
                fine[j * components + i] = (0..4).map(|a| w[a] * coarse[nodes[a] * components + i]).sum();
            }
        }
        for (f, c) in fine[nodal_fine..].iter_mut().zip(&coarse[nodal_coarse..]) {
            *f = *c;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bilinear field a + b x + c y + d x y is reproduced exactly on a uniform refinement of
    /// a distorted mesh (the refinement's nodes lie on the coarse cells, where the coarse
    /// interpolant is the field only on a parallelogram: here the field is linear, exact on any
    /// quadrilateral).
    #[test]
    fn linear_field_reproduced_on_the_refinement_of_a_distorted_mesh() {
        let mut coarse = QuadMesh::rectangle(0.0, 4.0, 0.0, 3.0, 4, 3).unwrap();
        // move the interior nodes off the grid
        for (k, x) in coarse.coords.iter_mut().enumerate() {
            if x[0] > 0.0 && x[0] < 4.0 && x[1] > 0.0 && x[1] < 3.0 {
                x[0] += 0.2 * ((k as f64) * 1.3).sin();
                x[1] += 0.2 * ((k as f64) * 0.7).cos();
            }
        }
        let fine = crate::mesh::refine::refine(&coarse).mesh;
        let field = |p: [f64; 2]| [1.0 + 2.0 * p[0] - 3.0 * p[1], -0.5 * p[0] + 0.25 * p[1]];
        let coarse_values: Vec<f64> = coarse.coords.iter().flat_map(|&p| field(p)).chain([7.0]).collect();
        let mut fine_values = vec![0.0; fine.num_nodes() * 2 + 1];
        Prolongation::between(&coarse, &fine).apply(&coarse_values, 2, &mut fine_values);
        for (j, &p) in fine.coords.iter().enumerate() {
            let want = field(p);
            for i in 0..2 {
                assert!((fine_values[2 * j + i] - want[i]).abs() < 1e-12, "node {j} at {p:?}: {} against {}", fine_values[2 * j + i], want[i]);
            }
        }
        // the extra unknown is copied
        assert_eq!(fine_values[fine.num_nodes() * 2], 7.0);
    }

    /// On two independent meshes of one square the bilinear coarse field x y is evaluated at the
    /// fine nodes: exact where the coarse cells are rectangles (x y is in their bilinear space),
    /// a fine node on a coarse node takes its value, a node outside the coarse mesh the nearest
    /// cell's edge value.
    #[test]
    fn bilinear_field_on_a_non_nested_mesh_and_outside() {
        let coarse = QuadMesh::rectangle(0.0, 2.0, 0.0, 2.0, 3, 3).unwrap();
        let mut fine = QuadMesh::rectangle(0.0, 2.0, 0.0, 2.0, 7, 5).unwrap();
        // one node pushed 0.1 outside the square, past x = 2
        let out = fine.coords.iter().position(|p| p[0] == 2.0 && p[1] > 0.5 && p[1] < 1.5).unwrap();
        fine.coords[out][0] = 2.1;
        let xy = |p: [f64; 2]| p[0] * p[1];
        let coarse_values: Vec<f64> = coarse.coords.iter().map(|&p| xy(p)).collect();
        let mut fine_values = vec![0.0; fine.num_nodes()];
        Prolongation::between(&coarse, &fine).apply(&coarse_values, 1, &mut fine_values);
        for (j, &p) in fine.coords.iter().enumerate() {
            let want = if j == out { xy([2.0, p[1]]) } else { xy(p) };
            assert!((fine_values[j] - want).abs() < 1e-12, "node {j} at {p:?}: {} against {want}", fine_values[j]);
        }
        let (node, distance) = Prolongation::between(&coarse, &fine).farthest_outside();
        assert_eq!(node, out);
        assert!((distance - 0.1).abs() < 1e-12, "{distance}");
        // every node inside (those on the boundary within round-off)
        assert!(Prolongation::between(&coarse, &QuadMesh::rectangle(0.0, 2.0, 0.0, 2.0, 7, 5).unwrap()).farthest_outside().1 < 1e-12);
    }
}
