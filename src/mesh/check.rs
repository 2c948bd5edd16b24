//! Checks of a [`QuadMesh`] as a whole: every cell usable, and the cells together a conforming
//! tiling — no duplicate cells, no edge shared by more than two cells, no two cells on the same side
//! of their shared edge (a fold), no overlapping or crossing cells, no node on the inside of another
//! cell's edge (a hanging node) and no two distinct nodes at one point (a crack).
//!
//! The checks return a [`Defect`] with 0-based cell and node indices; a reader that knows the
//! file's tags turns it into a message (see `io::gmsh`). The geometric searches use an R-tree of
//! the cells' bounding boxes, so the cost is O(n log n) for meshes of even size; a 400 x 400 mesh
//! takes well under a second (see the ignored test `mesh_check_cost` in tests/mesh_check.rs).

use crate::mesh::{quad_corner_jacobians, quad_signed_area, QuadMesh};
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};

/// What is wrong with a mesh (0-based indices).
#[derive(Debug, Clone, PartialEq)]
pub enum Defect {
    /// The mesh has no nodes or no cells.
    Empty,
    /// A node with a NaN or infinite coordinate.
    NonFiniteNode { node: usize },
    /// A cell refers to a node index out of range.
    MissingNode { cell: usize, node: usize },
    /// A cell that lists one node twice.
    RepeatedNode { cell: usize, node: usize },
    /// A cell with a non-positive corner Jacobian or (almost) zero area.
    BadCell { cell: usize, inverted: bool, area: f64, jacobians: [f64; 4] },
    /// Two cells on the same four nodes.
    DuplicateCells { first: usize, second: usize },
    /// An edge used by more than two cells.
    EdgeSharedByMore { edge: [usize; 2], cells: Vec<usize> },
    /// Two cells that share an edge but lie on the same side of it (the mesh folds over).
    Folded { first: usize, second: usize, edge: [usize; 2] },
    /// Two cells whose insides overlap.
    Overlap { first: usize, second: usize },
    /// A node on the inside of an edge of a cell it does not belong to (a non-conforming edge).
    HangingNode { node: usize, cell: usize, edge: [usize; 2] },
    /// Two distinct nodes at the same point (the mesh is cut along a crack there).
    CoincidentNodes { first: usize, second: usize },
}

/// Checks each cell alone: node indices, distinct nodes, finite coordinates, counter-clockwise and
/// strictly convex (all four corner Jacobians positive, area above round-off).
pub fn check_cells(mesh: &QuadMesh) -> Result<(), Defect> {
    if mesh.coords.is_empty() || mesh.cells.is_empty() {
        return Err(Defect::Empty);
    }
    if let Some(node) = mesh.coords.iter().position(|x| !x[0].is_finite() || !x[1].is_finite()) {
        return Err(Defect::NonFiniteNode { node });
    }
    for (c, cell) in mesh.cells.iter().enumerate() {
        if let Some(&node) = cell.iter().find(|&&n| n >= mesh.coords.len()) {
            return Err(Defect::MissingNode { cell: c, node });
        }
        for i in 0..4 {
            if cell[i + 1..].contains(&cell[i]) {
                return Err(Defect::RepeatedNode { cell: c, node: cell[i] });
            }
        }
        let x = mesh.cell_coords(c);
        let area = quad_signed_area(&x);
        let d = diameter(&x);
        let jacobians = quad_corner_jacobians(&x);
        if area <= 1e-12 * d * d || jacobians.iter().any(|&j| j <= 1e-14 * d * d) {
            return Err(Defect::BadCell { cell: c, inverted: area < 0.0, area, jacobians });
        }
    }
    Ok(())
}

fn diameter(x: &[[f64; 2]; 4]) -> f64 {
    let d = |a: [f64; 2], b: [f64; 2]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
    d(x[0], x[2]).max(d(x[1], x[3]))
}

/// Checks the cells together (after [`check_cells`] passed): see the module documentation.
pub fn check_topology(mesh: &QuadMesh) -> Result<(), Defect> {
    check_duplicates(mesh)?;
    check_edges(mesh)?;
    check_geometry(mesh)
}

/// [`check_cells`] then [`check_topology`].
pub fn check_mesh(mesh: &QuadMesh) -> Result<(), Defect> {
    check_cells(mesh)?;
    check_topology(mesh)
}

fn check_duplicates(mesh: &QuadMesh) -> Result<(), Defect> {
    let mut keys: Vec<([usize; 4], usize)> = mesh
        .cells
        .iter()
        .enumerate()
        .map(|(c, cell)| {
            let mut k = *cell;
            k.sort_unstable();
            (k, c)
        })
        .collect();
    keys.sort_unstable();
    match keys.windows(2).find(|w| w[0].0 == w[1].0) {
        Some(w) => Err(Defect::DuplicateCells { first: w[0].1.min(w[1].1), second: w[0].1.max(w[1].1) }),
        None => Ok(()),
    }
}

/// Every edge in at most two cells, and then traversed in opposite directions (all cells are
/// counter-clockwise, so two cells on opposite sides of an edge run along it in opposite senses).
fn check_edges(mesh: &QuadMesh) -> Result<(), Defect> {
    // (sorted edge, cell, traversed from the smaller node to the larger)
    let mut edges: Vec<([usize; 2], usize, bool)> = Vec::with_capacity(4 * mesh.cells.len());
    for (c, cell) in mesh.cells.iter().enumerate() {
        for i in 0..4 {
            let (a, b) = (cell[i], cell[(i + 1) % 4]);
            edges.push(([a.min(b), a.max(b)], c, a < b));
        }
    }
    edges.sort_unstable();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == edges[i].0 {
            j += 1;
        }
        let group = &edges[i..j];
        if group.len() > 2 {
            return Err(Defect::EdgeSharedByMore { edge: group[0].0, cells: group.iter().map(|e| e.1).collect() });
        }
        if group.len() == 2 && group[0].2 == group[1].2 {
            return Err(Defect::Folded { first: group[0].1, second: group[1].1, edge: group[0].0 });
        }
        i = j;
    }
    Ok(())
}

type Boxed = GeomWithData<Rectangle<[f64; 2]>, usize>;

fn bounding_box(x: &[[f64; 2]; 4], pad: f64) -> AABB<[f64; 2]> {
    let lo = [x.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min) - pad, x.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min) - pad];
    let hi = [x.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max) + pad, x.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max) + pad];
    AABB::from_corners(lo, hi)
}

/// Overlaps, hanging nodes and coincident nodes, found with an R-tree of the cells' boxes.
fn check_geometry(mesh: &QuadMesh) -> Result<(), Defect> {
    let n = mesh.cells.len();
    let cells: Vec<[[f64; 2]; 4]> = (0..n).map(|c| mesh.cell_coords(c)).collect();
    let diam: Vec<f64> = cells.iter().map(diameter).collect();
    let boxes: Vec<Boxed> = (0..n)
        .map(|c| {
            let b = bounding_box(&cells[c], 1e-9 * diam[c]);
            GeomWithData::new(Rectangle::from_aabb(b), c)
        })
        .collect();
    let tree = RTree::bulk_load(boxes);

    // Overlapping cells: separating-axis test on every pair of cells whose boxes meet.
    for c in 0..n {
        let env = bounding_box(&cells[c], 1e-9 * diam[c]);
        for other in tree.locate_in_envelope_intersecting(&env) {
            let d = other.data;
            if d <= c {
                continue;
            }
            let tol = 1e-9 * diam[c].min(diam[d]);
            if interiors_overlap(&cells[c], &cells[d], tol) {
                return Err(Defect::Overlap { first: c, second: d });
            }
        }
    }

    // Hanging and coincident nodes: every node against the cells whose boxes hold it.
    let mut used = vec![false; mesh.coords.len()];
    for cell in &mesh.cells {
        for &v in cell {
            used[v] = true;
        }
    }
    for (node, &p) in mesh.coords.iter().enumerate() {
        if !used[node] {
            continue;
        }
        for found in tree.locate_in_envelope_intersecting(&AABB::from_point(p)) {
            let c = found.data;
            let cell = mesh.cells[c];
            if cell.contains(&node) {
                continue;
            }
            let tol = 1e-9 * diam[c];
            for i in 0..4 {
                let (a, b) = (cells[c][i], cells[c][(i + 1) % 4]);
                if dist(p, a) <= tol {
                    return Err(Defect::CoincidentNodes { first: node.min(cell[i]), second: node.max(cell[i]) });
                }
                let e = [b[0] - a[0], b[1] - a[1]];
                let len2 = e[0] * e[0] + e[1] * e[1];
                let t = ((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / len2;
                let cross = (p[0] - a[0]) * e[1] - (p[1] - a[1]) * e[0];
                if t > 0.0 && t < 1.0 && cross.abs() <= tol * len2.sqrt() && dist(p, b) > tol {
                    return Err(Defect::HangingNode { node, cell: c, edge: [cell[i], cell[(i + 1) % 4]] });
                }
            }
        }
    }
    Ok(())
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// True if the insides of two convex quadrilaterals overlap by more than `tol` along every edge
/// normal of both (by the separating-axis theorem, convex polygons whose insides are disjoint are
/// separated along one of their edge normals; cells that only touch have an overlap of 0).
pub fn interiors_overlap(a: &[[f64; 2]; 4], b: &[[f64; 2]; 4], tol: f64) -> bool {
    for poly in [a, b] {
        for i in 0..4 {
            let (p, q) = (poly[i], poly[(i + 1) % 4]);
            let nrm = [q[1] - p[1], p[0] - q[0]];
            let len = (nrm[0] * nrm[0] + nrm[1] * nrm[1]).sqrt();
            if len == 0.0 {
                continue;
            }
            let proj = |x: &[[f64; 2]; 4]| {
                x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    let s = (v[0] * nrm[0] + v[1] * nrm[1]) / len;
                    (lo.min(s), hi.max(s))
                })
            };
            let (alo, ahi) = proj(a);
            let (blo, bhi) = proj(b);
            if ahi.min(bhi) - alo.max(blo) <= tol {
                return false;
            }
        }
    }
    true
}
