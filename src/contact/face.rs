//! The contact face of an integrated (mortar-type) contact discretisation: the quadrature points of
//! the body's face that may touch the punch, and what each contact point (node) is made of.
//!
//! The constraint of node i is its weighted gap, the mean of Psi over the node's support weighted
//! by its shape function,
//!
//!   g_i = (1 / A_i) int N_i Psi(x(u)) dA,   A_i = int N_i dA,
//!
//! (the mortar method's weighted gap with the rigid analytic surface as master, its nodal
//! multiplier regularised with the lumped A_i), and the contact traction is the field
//! lambda_h = sum_i N_i lambda_i, so that the contact force on node j is
//!
//!   f_j = int N_j lambda_h grad Psi dA = sum_q w_q lambda_q N_j(q) grad Psi(x_q).
//!
//! A uniform pressure is then carried exactly by the consistent nodal forces int N_j p dA on any
//! mesh (the contact patch test), and the integral of the written pressure field over any region
//! is the contact force there. The penalty energy sum_i A_i (lambda_i^2 / (2 eps)) has this force
//! as its gradient, so the tangent is symmetric: eps / A_i a_i a_i^T (a_i = A_i dg_i/du) plus
//! int lambda_h N_j N_k H dA. Since a_i reaches every node of node i's cells, the tangent couples
//! the nodes of two cells that share a node: [`ContactFace::patch`] lists them for the sparse
//! pattern.
//!
//! The nodal collocation of the paper (eq. 3.8 at the nodes, tributary weights) is the same
//! formula with one quadrature point at each node (N_i(x_j) = delta_ij); [`super::ContactPair`]
//! keeps it as its own, cheaper path.
//!
//! The integrals use 2 x 2 Gauss points on each bilinear cell of the reference face: exact for a
//! quadric Psi (sphere, cylinder, plane) on a parallelogram cell, N_i Psi being at most cubic in
//! each cell coordinate.

use crate::error::{Result, StampError};
use crate::mesh::{bilinear, bilinear_jacobian};

/// A quadrature point of the face: the (up to four) contact points of its cell, their shape
/// functions there and its weight (reference area).
#[derive(Debug, Clone, Copy)]
pub struct FacePoint {
    /// Indices into the pair's contact points.
    pub points: [u32; 4],
    /// N_a at the quadrature point.
    pub shape: [f64; 4],
    /// Gauss weight times the Jacobian of the reference cell.
    pub weight: f64,
}

/// The quadrature of a contact face and, for every contact point, where it is integrated.
#[derive(Debug, Clone)]
pub struct ContactFace {
    /// The quadrature points, four per cell.
    pub quadrature: Vec<FacePoint>,
    /// For contact point i, its (quadrature point, local slot a) at `by_point[by_point_start[i]..by_point_start[i + 1]]`.
    by_point_start: Vec<usize>,
    by_point: Vec<(u32, u8)>,
    /// For contact point i, the contact points of its cells (itself included, sorted) at
    /// `patch[patch_start[i]..patch_start[i + 1]]`.
    patch_start: Vec<usize>,
    patch: Vec<u32>,
    /// A_i = int N_i dA of every contact point.
    pub area: Vec<f64>,
}

impl ContactFace {
    /// The face made of `cells` (four node indices each, counter-clockwise in the reference plane)
    /// whose nodes are contact points: `point_of_node[n]` is the contact point of node n (None: the
    /// node is no candidate; a cell with such a node is left out). `coords` are the nodes' reference
    /// in-plane coordinates. Every contact point must lie on some cell of the face.
    pub fn new(coords: &[[f64; 2]], cells: &[[usize; 4]], point_of_node: &[Option<usize>], num_points: usize) -> Result<ContactFace> {
        let g = 1.0 / 3f64.sqrt();
        let mut quadrature = Vec::with_capacity(4 * cells.len());
        for (c, cell) in cells.iter().enumerate() {
            let Some(pts) = cell.iter().map(|&n| point_of_node.get(n).copied().flatten()).collect::<Option<Vec<usize>>>() else { continue };
            let x: Vec<[f64; 2]> = cell.iter().map(|&n| coords[n]).collect();
            for &(s, t) in &[(-g, -g), (g, -g), (g, g), (-g, g)] {
                let (n, dn) = bilinear(s, t);
                let det = bilinear_jacobian(&x, &dn);
                if !(det > 0.0 && det.is_finite()) {
                    return Err(StampError::Mesh(format!("cell {c} of the contact face is degenerate or inverted (Jacobian {det:e})")));
                }
                quadrature.push(FacePoint { points: [0, 1, 2, 3].map(|a| pts[a] as u32), shape: n, weight: det });
            }
        }
        let mut count = vec![0usize; num_points];
        for q in &quadrature {
            for &p in &q.points {
                count[p as usize] += 1;
            }
        }
        if let Some(lone) = count.iter().position(|&c| c == 0) {
            return Err(StampError::Problem(format!("contact point {lone} lies on no cell of the contact face: an integrated contact needs the cells around every candidate node")));
        }
        let mut by_point_start = vec![0usize; num_points + 1];
        for i in 0..num_points {
            by_point_start[i + 1] = by_point_start[i] + count[i];
        }
        let mut fill = by_point_start.clone();
        let mut by_point = vec![(0u32, 0u8); by_point_start[num_points]];
        let mut area = vec![0.0; num_points];
        for (k, q) in quadrature.iter().enumerate() {
            for a in 0..4 {
                let p = q.points[a] as usize;
                by_point[fill[p]] = (k as u32, a as u8);
                fill[p] += 1;
                area[p] += q.weight * q.shape[a];
            }
        }
        let mut patch_start = vec![0usize; num_points + 1];
        let mut patch = Vec::new();
        for i in 0..num_points {
            let mut mine: Vec<u32> = by_point[by_point_start[i]..by_point_start[i + 1]].iter().flat_map(|&(q, _)| quadrature[q as usize].points).collect();
            mine.sort_unstable();
            mine.dedup();
            patch.extend_from_slice(&mine);
            patch_start[i + 1] = patch.len();
        }
        Ok(ContactFace { quadrature, by_point_start, by_point, patch_start, patch, area })
    }

    /// The (quadrature point, local slot) pairs of contact point i.
    pub fn of_point(&self, i: usize) -> &[(u32, u8)] {
        &self.by_point[self.by_point_start[i]..self.by_point_start[i + 1]]
    }

    /// The contact points whose displacements the weighted gap of point i depends on (its cells'
    /// points, sorted, itself included).
    pub fn patch(&self, i: usize) -> &[u32] {
        &self.patch[self.patch_start[i]..self.patch_start[i + 1]]
    }

    /// Number of contact points.
    pub fn num_points(&self) -> usize {
        self.area.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::QuadMesh as Mesh;

    #[test]
    fn areas_are_the_consistent_nodal_areas_and_patches_are_the_cells_points() {
        // a distorted 3 x 2 mesh: A_i = int N_i dA, the same as Mesh::nodal_areas
        let mut m = Mesh::rectangle(0.0, 3.0, 0.0, 2.0, 3, 2).unwrap();
        m.coords[5] = [1.3, 0.8];
        m.coords[6] = [2.1, 1.2];
        let all: Vec<Option<usize>> = (0..m.coords.len()).map(Some).collect();
        let f = ContactFace::new(&m.coords, &m.cells, &all, m.coords.len()).unwrap();
        let w = m.nodal_areas();
        for i in 0..w.len() {
            assert!((f.area[i] - w[i]).abs() < 1e-14, "node {i}: {} against {}", f.area[i], w[i]);
        }
        assert!((f.area.iter().sum::<f64>() - 6.0).abs() < 1e-12);
        // a corner node couples with its cell's four nodes, an interior node with nine
        assert_eq!(f.patch(0), &[0, 1, 4, 5]);
        assert_eq!(f.patch(5).len(), 9);
        assert_eq!(f.quadrature.len(), 24);
    }

    #[test]
    fn a_candidate_off_the_face_is_refused() {
        let m = Mesh::rectangle(0.0, 2.0, 0.0, 1.0, 2, 1).unwrap();
        // only the nodes of the first cell are candidates, plus node 2 of the second
        let mut p: Vec<Option<usize>> = vec![None; m.coords.len()];
        for (k, n) in [0usize, 1, 3, 4, 2].into_iter().enumerate() {
            p[n] = Some(k);
        }
        let e = ContactFace::new(&m.coords, &m.cells, &p, 5).unwrap_err();
        assert!(e.to_string().contains("contact point 4 lies on no cell"), "{e}");
    }
}
