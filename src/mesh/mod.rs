//! Plane quadrilateral meshes: node coordinates in the reference plane (x1, x2), four-node cells
//! numbered counter-clockwise, and named groups of nodes and cells (gmsh physical groups, or groups a
//! program defines). The mesh knows nothing about what is solved on it. Beside it: [`check`]
//! (defects of a mesh), [`refine`] (every cell into four), [`transfer`] (a field from one mesh onto
//! another by point location) and [`coarse_path`] (a coarse mesh's solution along the load path,
//! the coarse predictor's).

pub mod check;
pub mod coarse_path;
pub mod refine;
pub mod transfer;

use crate::error::{Result, StampError};
use std::collections::BTreeMap;

/// A mesh of four-node quadrilaterals in the plane.
#[derive(Debug, Clone, Default)]
pub struct QuadMesh {
    /// Reference coordinates (x1, x2) of the nodes.
    pub coords: Vec<[f64; 2]>,
    /// Node indices of each cell, counter-clockwise.
    pub cells: Vec<[usize; 4]>,
    /// Named node groups (a gmsh physical point, curve or surface gives the nodes it holds).
    pub node_groups: BTreeMap<String, Vec<usize>>,
    /// Named cell groups (gmsh physical surfaces).
    pub cell_groups: BTreeMap<String, Vec<usize>>,
}

/// Signed area of a quadrilateral by the shoelace formula (positive when counter-clockwise).
pub fn quad_signed_area(x: &[[f64; 2]; 4]) -> f64 {
    let mut a = 0.0;
    for i in 0..4 {
        let j = (i + 1) % 4;
        a += x[i][0] * x[j][1] - x[j][0] * x[i][1];
    }
    0.5 * a
}

/// The Jacobian determinant of the bilinear map at the four corners, divided by the area's
/// quarter (1 for a parallelogram). A corner value <= 0 means the cell is inverted or degenerate.
pub fn quad_corner_jacobians(x: &[[f64; 2]; 4]) -> [f64; 4] {
    let mut out = [0.0; 4];
    for i in 0..4 {
        let prev = x[(i + 3) % 4];
        let next = x[(i + 1) % 4];
        let c = x[i];
        let a = [next[0] - c[0], next[1] - c[1]];
        let b = [prev[0] - c[0], prev[1] - c[1]];
        out[i] = a[0] * b[1] - a[1] * b[0];
    }
    out
}

impl QuadMesh {
    /// Build a mesh and validate it.
    pub fn new(coords: Vec<[f64; 2]>, cells: Vec<[usize; 4]>) -> Result<Self> {
        let mesh = QuadMesh { coords, cells, ..Default::default() };
        mesh.validate()?;
        Ok(mesh)
    }

    /// Number of nodes.
    pub fn num_nodes(&self) -> usize {
        self.coords.len()
    }

    /// Number of cells.
    pub fn num_cells(&self) -> usize {
        self.cells.len()
    }

    /// Corner coordinates of cell `c`.
    pub fn cell_coords(&self, c: usize) -> [[f64; 2]; 4] {
        let n = self.cells[c];
        [self.coords[n[0]], self.coords[n[1]], self.coords[n[2]], self.coords[n[3]]]
    }

    /// Check that the mesh is usable: not empty, finite coordinates, node indices in range, no
    /// repeated node in a cell, and every cell convex and counter-clockwise (all four corner
    /// Jacobians positive).
    pub fn validate(&self) -> Result<()> {
        if self.coords.is_empty() || self.cells.is_empty() {
            return Err(StampError::Mesh(format!(
                "the mesh is empty ({} nodes, {} cells)",
                self.coords.len(),
                self.cells.len()
            )));
        }
        for (i, x) in self.coords.iter().enumerate() {
            if !x[0].is_finite() || !x[1].is_finite() {
                return Err(StampError::Mesh(format!("node {i} has a non-finite coordinate {x:?}")));
            }
        }
        for (c, cell) in self.cells.iter().enumerate() {
            for &n in cell {
                if n >= self.coords.len() {
                    return Err(StampError::Mesh(format!(
                        "cell {c} refers to node {n}, but the mesh has {} nodes",
                        self.coords.len()
                    )));
                }
            }
            for i in 0..4 {
                for j in i + 1..4 {
                    if cell[i] == cell[j] {
                        return Err(StampError::Mesh(format!(
                            "cell {c} is degenerate: node {} appears twice in {cell:?}",
                            cell[i]
                        )));
                    }
                }
            }
            let x = self.cell_coords(c);
            let area = quad_signed_area(&x);
            let scale = x.iter().map(|p| p[0].abs().max(p[1].abs())).fold(0.0, f64::max).max(1e-300);
            let jac = quad_corner_jacobians(&x);
            if area <= 1e-14 * scale * scale || jac.iter().any(|&j| j <= 0.0) {
                let kind = if area < 0.0 { "inverted (clockwise)" } else { "degenerate or non-convex" };
                return Err(StampError::Mesh(format!(
                    "cell {c} with nodes {cell:?} is {kind}: signed area {area:.3e}, corner Jacobians {jac:?}"
                )));
            }
        }
        Ok(())
    }

    /// Nodes of a named group, or an error that lists the names the mesh has.
    pub fn group_nodes(&self, name: &str) -> Result<&[usize]> {
        self.node_groups.get(name).map(|v| v.as_slice()).ok_or_else(|| {
            StampError::Problem(format!(
                "unknown node group '{name}'; the mesh has: {}",
                self.node_groups.keys().cloned().collect::<Vec<_>>().join(", ")
            ))
        })
    }

    /// Nodes whose coordinates satisfy a predicate (for programmatic boundary conditions).
    pub fn nodes_where(&self, pred: impl Fn([f64; 2]) -> bool) -> Vec<usize> {
        (0..self.coords.len()).filter(|&i| pred(self.coords[i])).collect()
    }

    /// Characteristic element size: the square root of the mean cell area.
    pub fn element_size(&self) -> f64 {
        let total: f64 = self.nodal_areas().iter().sum();
        (total / self.num_cells().max(1) as f64).sqrt()
    }

    /// Tributary (lumped) area of every node: each cell gives a quarter of its integral of the
    /// bilinear shape function of that node (exact for the bilinear element, one quarter of the area
    /// per node on a parallelogram).
    pub fn nodal_areas(&self) -> Vec<f64> {
        let mut w = vec![0.0; self.coords.len()];
        let g = 1.0 / 3f64.sqrt();
        for (c, cell) in self.cells.iter().enumerate() {
            let x = self.cell_coords(c);
            for &(s, t) in &[(-g, -g), (g, -g), (g, g), (-g, g)] {
                let (n, dn) = bilinear(s, t);
                let det = bilinear_jacobian(&x, &dn);
                for a in 0..4 {
                    w[cell[a]] += n[a] * det;
                }
            }
        }
        w
    }

    /// A structured rectangular mesh of nx by ny cells on [x0, x1] x [y0, y1], nodes numbered row by
    /// row (x fastest). Groups "left", "right", "bottom", "top" hold the edge nodes and "all" every
    /// cell.
    pub fn rectangle(x0: f64, x1: f64, y0: f64, y1: f64, nx: usize, ny: usize) -> Result<Self> {
        if nx == 0 || ny == 0 {
            return Err(StampError::Mesh(format!("a rectangle needs at least one cell each way, got {nx} x {ny}")));
        }
        let mut coords = Vec::with_capacity((nx + 1) * (ny + 1));
        for j in 0..=ny {
            for i in 0..=nx {
                coords.push([x0 + (x1 - x0) * i as f64 / nx as f64, y0 + (y1 - y0) * j as f64 / ny as f64]);
            }
        }
        let id = |i: usize, j: usize| j * (nx + 1) + i;
        let mut cells = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                cells.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let mut mesh = QuadMesh::new(coords, cells)?;
        mesh.node_groups.insert("left".into(), (0..=ny).map(|j| id(0, j)).collect());
        mesh.node_groups.insert("right".into(), (0..=ny).map(|j| id(nx, j)).collect());
        mesh.node_groups.insert("bottom".into(), (0..=nx).map(|i| id(i, 0)).collect());
        mesh.node_groups.insert("top".into(), (0..=nx).map(|i| id(i, ny)).collect());
        mesh.cell_groups.insert("all".into(), (0..nx * ny).collect());
        Ok(mesh)
    }
}

/// The Jacobian determinant of the bilinear map of the cell with corners `x` at a point where the
/// shape functions' derivatives are `dn` (see [`bilinear`]).
pub fn bilinear_jacobian(x: &[[f64; 2]], dn: &[[f64; 2]; 4]) -> f64 {
    let mut j = [[0.0; 2]; 2];
    for a in 0..4 {
        for d in 0..2 {
            j[d][0] += x[a][d] * dn[a][0];
            j[d][1] += x[a][d] * dn[a][1];
        }
    }
    j[0][0] * j[1][1] - j[0][1] * j[1][0]
}

/// Bilinear shape functions and their derivatives with respect to (xi1, xi2) on [-1, 1]^2, nodes
/// ordered (-1,-1), (1,-1), (1,1), (-1,1).
pub fn bilinear(s: f64, t: f64) -> ([f64; 4], [[f64; 2]; 4]) {
    const XI: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
    let mut n = [0.0; 4];
    let mut dn = [[0.0; 2]; 4];
    for a in 0..4 {
        let (xa, ya) = (XI[a][0], XI[a][1]);
        n[a] = 0.25 * (1.0 + xa * s) * (1.0 + ya * t);
        dn[a][0] = 0.25 * xa * (1.0 + ya * t);
        dn[a][1] = 0.25 * ya * (1.0 + xa * s);
    }
    (n, dn)
}

/// The point of the bilinear quadrilateral `x` (corners in the order of [`bilinear`]) at the local
/// coordinates `xi`.
pub fn bilinear_point(x: &[[f64; 2]; 4], xi: [f64; 2]) -> [f64; 2] {
    let (n, _) = bilinear(xi[0], xi[1]);
    let mut p = [0.0; 2];
    for a in 0..4 {
        for i in 0..2 {
            p[i] += n[a] * x[a][i];
        }
    }
    p
}

/// Invert the isoparametric map of the bilinear quadrilateral `x` (corners in the order of
/// [`bilinear`]) at `p` by Newton's method from the centre. Returns (xi1, xi2), which lie in
/// [-1, 1]^2 when `p` is inside; None when Newton does not converge (a degenerate cell, or a point
/// far outside).
pub fn inverse_bilinear(x: &[[f64; 2]; 4], p: [f64; 2]) -> Option<[f64; 2]> {
    let size = (0..4).map(|a| (x[a][0] - x[(a + 2) % 4][0]).hypot(x[a][1] - x[(a + 2) % 4][1])).fold(0.0, f64::max);
    let mut xi = [0.0, 0.0];
    for _ in 0..30 {
        let (n, dn) = bilinear(xi[0], xi[1]);
        let mut r = [-p[0], -p[1]];
        let mut j = [[0.0; 2]; 2];
        for a in 0..4 {
            for i in 0..2 {
                r[i] += n[a] * x[a][i];
                for k in 0..2 {
                    j[i][k] += dn[a][k] * x[a][i];
                }
            }
        }
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if det.abs() <= 1e-14 * size * size || !det.is_finite() {
            return None;
        }
        let d = [(j[1][1] * r[0] - j[0][1] * r[1]) / det, (-j[1][0] * r[0] + j[0][0] * r[1]) / det];
        xi = [xi[0] - d[0], xi[1] - d[1]];
        if xi.iter().any(|v| !v.is_finite() || v.abs() > 1e3) {
            return None;
        }
        // Newton converges quadratically: after a correction below 1e-10 the error is round-off
        // (an absolute 1e-14 is out of reach for small cells far from the origin)
        if d[0].abs().max(d[1].abs()) < 1e-10 {
            return Some(xi);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn skewed() -> [[f64; 2]; 4] {
        [[0.0, 0.0], [3.0, 0.5], [2.5, 2.0], [-0.5, 1.5]]
    }

    #[test]
    fn inverse_map_recovers_local_coordinates_of_a_distorted_quad() {
        let x = skewed();
        for xi in [[0.3, -0.7], [-1.0, -1.0], [1.0, 1.0], [0.999, -0.2], [-0.5, 0.95]] {
            let back = inverse_bilinear(&x, bilinear_point(&x, xi)).expect("converges");
            assert!((back[0] - xi[0]).abs() < 1e-12 && (back[1] - xi[1]).abs() < 1e-12, "{xi:?} -> {back:?}");
        }
        // a small cell far from the origin: round-off in x is large against the cell
        let far = x.map(|c| [1.0e3 + 1e-3 * c[0], -2.0e3 + 1e-3 * c[1]]);
        let back = inverse_bilinear(&far, bilinear_point(&far, [0.25, -0.5])).expect("converges far from the origin");
        assert!((back[0] - 0.25).abs() < 1e-8 && (back[1] + 0.5).abs() < 1e-8, "{back:?}");
        // a point outside maps to |xi| > 1
        let out = inverse_bilinear(&x, [5.0, 5.0]).map(|v| v[0].abs().max(v[1].abs()));
        assert!(out.is_none_or(|m| m > 1.0), "{out:?}");
        // a degenerate (zero-area) cell is refused
        assert!(inverse_bilinear(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]], [1.0, 0.0]).is_none());
    }
}
